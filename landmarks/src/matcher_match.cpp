#include <opencv2/calib3d.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <unordered_map>

#include "matcher_internal.h"
#include "sketchnav/core/error.h"
#include "sketchnav/landmarks/bow.h"
#include "sketchnav/landmarks/matcher.h"

namespace sketchnav::landmarks {

void MatchParams::validate() const {
  require(ratio > 0 && ratio <= 1, "match.ratio", "must be in (0, 1]");
  require(min_inliers >= 4, "match.min_inliers", "must be >= 4 (a homography needs 4 points)");
  require(ransac_px > 0, "match.ransac_px", "must be > 0");
  require(max_photos >= 1, "match.max_photos", "must be >= 1");
  require(strong_inliers >= min_inliers, "match.strong_inliers", "must be >= min_inliers");
  require(min_window_features >= 4, "match.min_window_features", "must be >= 4");
}

FrameFeatures computeFrameFeatures(const LandmarkModel& model, const cv::Mat& bgr) {
  FrameFeatures f;
  f.features = extractFeatures(bgr, model.params().features);
  f.words = model.vocabulary().assign(f.features.descriptors);
  return f;
}

FrameFeatures computeFrameFeatures(const LandmarkModel& model, const cv::Mat& bgr,
                                   FeatureParams frame_params) {
  frame_params.root_sift = model.params().features.root_sift;  // must match the database
  frame_params.validate();
  FrameFeatures f;
  f.features = extractFeatures(bgr, frame_params);
  f.words = model.vocabulary().assign(f.features.descriptors);
  return f;
}

namespace detail {

std::vector<int> keypointsInWindow(const FrameFeatures& frame, const cv::Rect& window) {
  std::vector<int> idx;
  const auto& kps = frame.features.keypoints;
  idx.reserve(kps.size());
  const bool all = window.area() <= 0;
  const cv::Rect2f w(window);
  for (size_t i = 0; i < kps.size(); ++i)
    if (all || w.contains(kps[i].pt)) idx.push_back(static_cast<int>(i));
  return idx;
}

WindowQuery makeQuery(const LandmarkModel& model, const FrameFeatures& frame,
                      const std::vector<int>& idx) {
  WindowQuery q;
  q.idx = idx;
  q.descriptors.create(static_cast<int>(idx.size()), frame.features.descriptors.cols, CV_32F);
  std::vector<int> words(idx.size());
  for (size_t i = 0; i < idx.size(); ++i) {
    frame.features.descriptors.row(idx[i]).copyTo(q.descriptors.row(static_cast<int>(i)));
    words[i] = frame.words[idx[i]];
  }
  q.histogram = bowHistogram(words, model.vocabulary().idf());
  return q;
}

MatchResult ransacPhoto(const LandmarkModel& model, const FrameFeatures& frame,
                        const WindowQuery& q, int photo, std::vector<Corr> corr,
                        const MatchParams& p) {
  MatchResult r;
  const DatabasePhoto& ph = model.photos()[photo];
  r.database_photo = photo;
  r.database_image = ph.path;
  r.database_size = ph.size;
  r.photos_tried = 1;
  // One query per database keypoint (the closest), so a repeated texture cannot vote many
  // times for one point.
  std::sort(corr.begin(), corr.end(),
            [](const Corr& a, const Corr& b) { return a.d != b.d ? a.d < b.d : a.dist < b.dist; });
  corr.erase(std::unique(corr.begin(), corr.end(),
                         [](const Corr& a, const Corr& b) { return a.d == b.d; }),
             corr.end());
  if (static_cast<int>(corr.size()) < p.min_inliers) return r;
  std::vector<cv::Point2f> src, dst;  // database -> frame
  src.reserve(corr.size());
  dst.reserve(corr.size());
  for (const auto& c : corr) {
    src.push_back(ph.keypoints[c.d].pt);
    dst.push_back(frame.features.keypoints[q.idx[c.q]].pt);
  }
  std::vector<unsigned char> mask;
  cv::Mat H = cv::findHomography(src, dst, cv::RANSAC, p.ransac_px, mask, 1000, 0.995);
  if (H.empty()) return r;
  // A plausible view of a planar-ish package: orientation-preserving, scale within 1/30..30.
  const double det =
      H.at<double>(0, 0) * H.at<double>(1, 1) - H.at<double>(0, 1) * H.at<double>(1, 0);
  if (!(det > 1.0 / 900 && det < 900)) return r;
  int inl = 0;
  for (size_t i = 0; i < mask.size(); ++i)
    if (mask[i]) {
      ++inl;
      r.x_d.push_back(src[i]);
      r.x_t.push_back(dst[i]);
    }
  r.inliers = inl;
  r.H = H;
  if (inl >= p.min_inliers) {
    r.matched = true;
    r.confidence = static_cast<float>(1.0 - std::exp(-(inl - p.min_inliers + 1) / 15.0));
  } else {
    r.x_d.clear();
    r.x_t.clear();
    r.H.release();
  }
  return r;
}

MatchResult verifyPhoto(const LandmarkModel& model, const FrameFeatures& frame,
                        const WindowQuery& q, int photo, const MatchParams& p) {
  const DatabasePhoto& ph = model.photos()[photo];
  std::vector<Corr> corr;
  if (q.descriptors.rows >= 2 && ph.descriptors.rows >= 2) {
    cv::Mat nn, d2;
    model.knn2(photo, q.descriptors, nn, d2);
    // Lowe's ratio test (FLANN returns squared L2 distances).
    const float r2 = static_cast<float>(p.ratio * p.ratio);
    for (int i = 0; i < nn.rows; ++i) {
      const float a = d2.at<float>(i, 0), b = d2.at<float>(i, 1);
      if (a < r2 * b) corr.push_back({i, nn.at<int>(i, 0), a});
    }
  }
  return ransacPhoto(model, frame, q, photo, std::move(corr), p);
}

Votes computeVotes(const LandmarkModel& model, const WindowQuery& q, int knn, double class_ratio,
                   int checks) {
  Votes v;
  v.class_votes.assign(model.classes().size(), 0);
  v.photo_corr.resize(model.photos().size());
  if (q.descriptors.rows == 0 || model.photos().empty()) return v;
  cv::Mat nn, d2;
  model.knnAll(q.descriptors, knn, checks, nn, d2);
  const float r2 = static_cast<float>(class_ratio * class_ratio);
  std::vector<int> seen_photo;
  for (int i = 0; i < nn.rows; ++i) {
    const int* id = nn.ptr<int>(i);
    const float* ds = d2.ptr<float>(i);
    if (id[0] < 0) continue;
    const int c1 = model.photos()[model.globalOwner(id[0]).first].class_id;
    float other = std::numeric_limits<float>::infinity();
    for (int k = 1; k < nn.cols; ++k) {
      if (id[k] < 0) break;
      if (model.photos()[model.globalOwner(id[k]).first].class_id != c1) {
        other = ds[k];
        break;
      }
    }
    if (!(ds[0] < r2 * other)) continue;
    ++v.class_votes[c1];
    seen_photo.clear();
    for (int k = 0; k < nn.cols; ++k) {
      if (id[k] < 0 || !(ds[k] < r2 * other)) break;
      const auto [photo, kp] = model.globalOwner(id[k]);
      if (model.photos()[photo].class_id != c1) break;
      if (std::find(seen_photo.begin(), seen_photo.end(), photo) != seen_photo.end()) continue;
      seen_photo.push_back(photo);
      v.photo_corr[photo].push_back({i, kp, ds[k]});
    }
  }
  return v;
}

std::vector<float> photoSimilarities(const LandmarkModel& model, const cv::Mat& hist) {
  std::vector<float> s(model.photos().size());
  for (size_t i = 0; i < s.size(); ++i)
    s[i] = static_cast<float>(hist.dot(model.photos()[i].histogram));
  return s;
}

MatchResult matchClass(const LandmarkModel& model, const FrameFeatures& frame, const WindowQuery& q,
                       int class_id, const std::vector<float>& sims, const MatchParams& p) {
  std::vector<int> photos = model.photosOfClass(class_id);
  std::stable_sort(photos.begin(), photos.end(), [&](int a, int b) { return sims[a] > sims[b]; });
  MatchResult best;
  int tried = 0;
  for (int ph : photos) {
    if (tried >= p.max_photos) break;
    ++tried;
    MatchResult r = verifyPhoto(model, frame, q, ph, p);
    if (r.inliers > best.inliers || best.database_photo < 0) best = std::move(r);
    if (best.matched && best.inliers >= p.strong_inliers) break;
  }
  best.photos_tried = tried;
  return best;
}

}  // namespace detail

MatchResult matchPhoto(const LandmarkModel& model, const FrameFeatures& frame,
                       const std::vector<int>& window_keypoints, int photo,
                       const MatchParams& params) {
  return detail::verifyPhoto(model, frame, detail::makeQuery(model, frame, window_keypoints), photo,
                             params);
}

MatchResult match(const LandmarkModel& model, const FrameFeatures& frame, const cv::Rect& window,
                  const std::string& target_class, const MatchParams& params) {
  const int cls = model.classId(target_class);
  if (cls < 0) throw InputError("landmark class '" + target_class + "' is not in the model");
  const auto idx = detail::keypointsInWindow(frame, window);
  MatchResult r;
  if (static_cast<int>(idx.size()) >= params.min_window_features) {
    const auto q = detail::makeQuery(model, frame, idx);
    r = detail::matchClass(model, frame, q, cls, detail::photoSimilarities(model, q.histogram),
                           params);
  }
  r.window = window.area() > 0 ? window : cv::Rect(cv::Point(), frame.features.image_size);
  return r;
}

MatchResult match(const LandmarkModel& model, const cv::Mat& frame_bgr, const cv::Rect& window,
                  const std::string& target_class, const MatchParams& params) {
  return match(model, computeFrameFeatures(model, frame_bgr), window, target_class, params);
}

ServoOffset servoOffset(const MatchResult& m, int frame_width) {
  ServoOffset o;
  if (!m.matched || m.x_t.empty()) return o;
  const float cx = 0.5f * static_cast<float>(frame_width);
  const float dcx = 0.5f * static_cast<float>(m.database_size.width);
  const float dcy = 0.5f * static_cast<float>(m.database_size.height);
  auto median = [](std::vector<float> v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  double scale = 1.0;
  bool h_ok = false;
  float u = 0;
  if (!m.H.empty()) {
    const cv::Mat& H = m.H;
    const double w = H.at<double>(2, 0) * dcx + H.at<double>(2, 1) * dcy + H.at<double>(2, 2);
    if (std::abs(w) > 1e-9) {
      u = static_cast<float>(
          (H.at<double>(0, 0) * dcx + H.at<double>(0, 1) * dcy + H.at<double>(0, 2)) / w);
      const double det =
          H.at<double>(0, 0) * H.at<double>(1, 1) - H.at<double>(0, 1) * H.at<double>(1, 0);
      scale = std::sqrt(std::abs(det)) / std::abs(w);
      // The centre may fall outside a partly visible object's frame, but not absurdly far.
      h_ok = std::isfinite(u) && u > -2.0f * frame_width && u < 3.0f * frame_width;
    }
  }
  std::vector<float> xs, paper;
  for (size_t i = 0; i < m.x_t.size(); ++i) {
    xs.push_back(m.x_t[i].x);
    paper.push_back((m.x_t[i].x - cx) - static_cast<float>(scale) * (m.x_d[i].x - dcx));
  }
  o.valid = true;
  o.object_u = h_ok ? u : median(xs);
  o.offset_px = o.object_u - cx;
  o.paper_offset_px = median(paper);
  return o;
}

}  // namespace sketchnav::landmarks
