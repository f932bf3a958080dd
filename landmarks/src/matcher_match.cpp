#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <unordered_map>

#include "matcher_internal.h"
#include "sketchnav/core/error.h"
#include "sketchnav/landmarks/bow.h"
#include "sketchnav/landmarks/colour_layout.h"
#include "sketchnav/landmarks/matcher.h"

namespace sketchnav::landmarks {

void MatchParams::validate() const {
  require(ratio > 0 && ratio <= 1, "match.ratio", "must be in (0, 1]");
  require(min_inliers >= 4, "match.min_inliers", "must be >= 4 (a homography needs 4 points)");
  require(ransac_px > 0, "match.ransac_px", "must be > 0");
  require(ransac_iterations >= 10, "match.ransac_iterations", "must be >= 10");
  require(photo_order_checks >= 0, "match.photo_order_checks", "must be >= 0 (0 = BoW order)");
  require(max_photos >= 1, "match.max_photos", "must be >= 1");
  require(strong_inliers >= min_inliers, "match.strong_inliers", "must be >= min_inliers");
  require(min_window_features >= 4, "match.min_window_features", "must be >= 4");
  require(colour_tolerance >= 0, "match.colour_tolerance", "must be >= 0 (0 = off)");
  require(colour_min_fraction >= 0 && colour_min_fraction <= 1, "match.colour_min_fraction",
          "must be in [0, 1]");
  require(distinct_min_fraction >= 0 && distinct_min_fraction <= 1, "match.distinct_min_fraction",
          "must be in [0, 1] (0 = off)");
  require(distinct_ratio > 0 && distinct_ratio <= 1, "match.distinct_ratio", "must be in (0, 1]");
  require(distinct_neighbours >= 2, "match.distinct_neighbours", "must be >= 2");
  require(distinct_checks >= 1, "match.distinct_checks", "must be >= 1");
}

FrameFeatures computeFrameFeatures(const LandmarkModel& model, const cv::Mat& bgr) {
  return computeFrameFeatures(model, bgr, model.params().frameFeatures());
}

FrameFeatures computeFrameFeatures(const LandmarkModel& model, const cv::Mat& bgr,
                                   FeatureParams frame_params) {
  frame_params.root_sift = model.params().features.root_sift;  // must match the database
  frame_params.validate();
  FrameFeatures f;
  f.features = extractFeatures(bgr, frame_params);
  f.words = model.vocabulary().assign(f.features.descriptors);
  if (bgr.channels() >= 3) f.colour_thumbnail = colourThumbnail(bgr);  // ~0.2 ms at 640x480
  return f;
}

namespace {
// The settings that decide whether a photo verifies (the photo order and budget do not).
bool sameVerification(const MatchParams& a, const MatchParams& b) {
  return a.ratio == b.ratio && a.min_inliers == b.min_inliers && a.ransac_px == b.ransac_px &&
         a.ransac_iterations == b.ransac_iterations && a.colour_tolerance == b.colour_tolerance &&
         a.colour_min_fraction == b.colour_min_fraction &&
         a.distinct_min_fraction == b.distinct_min_fraction &&
         a.distinct_ratio == b.distinct_ratio && a.distinct_neighbours == b.distinct_neighbours &&
         a.distinct_checks == b.distinct_checks;
}
}  // namespace

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

WindowQuery subQuery(const WindowQuery& q, const std::vector<int>& rows) {
  WindowQuery s;
  s.idx.resize(rows.size());
  s.descriptors.create(static_cast<int>(rows.size()), q.descriptors.cols, CV_32F);
  for (size_t i = 0; i < rows.size(); ++i) {
    s.idx[i] = q.idx[rows[i]];
    q.descriptors.row(rows[i]).copyTo(s.descriptors.row(static_cast<int>(i)));
  }
  return s;
}

int ransacIterations(int n, int min_inliers, int max_iterations, double confidence) {
  if (n < 4) return 0;
  const int m = std::max(4, min_inliers);
  auto choose4 = [](double k) { return k * (k - 1) * (k - 2) * (k - 3) / 24.0; };
  if (n < m) return static_cast<int>(std::min<double>(max_iterations, choose4(n)));
  const double q = choose4(m) / choose4(n);  // P(a random sample is 4 of the m inliers)
  if (q >= 1) return 1;
  const double needed = std::ceil(std::log(1 - confidence) / std::log1p(-q));
  return static_cast<int>(std::clamp<double>(needed, 1, max_iterations));
}

namespace {
// How many of the inlier correspondences `inl` to a photo of class `class_id` are distinct:
// closer than distinct_ratio x the frame keypoint's nearest database descriptor of another
// class. A keypoint whose neighbours searched are all of the class has no other-class rival
// found: distinct.
int countDistinct(const LandmarkModel& model, const FrameFeatures& frame, const WindowQuery& q,
                  int class_id, const std::vector<Corr>& inl, const MatchParams& p) {
  if (!frame.photo_cache || frame.features.descriptors.empty()) return static_cast<int>(inl.size());
  const FrameFeatures::PhotoCache::Neighbours* nb = nullptr;
  {
    std::lock_guard<std::mutex> lock(frame.photo_cache->mutex);
    auto& slot = frame.photo_cache->neighbours[{static_cast<const void*>(&model),
                                                p.distinct_neighbours, p.distinct_checks}];
    if (slot.indices.empty())
      model.knnAll(frame.features.descriptors, p.distinct_neighbours, p.distinct_checks,
                   slot.indices, slot.dists);
    nb = &slot;  // std::map nodes are stable
  }
  const float r2 = static_cast<float>(p.distinct_ratio * p.distinct_ratio);
  int distinct = 0;
  for (const auto& c : inl) {
    const int row = q.idx[c.q];
    if (row >= nb->indices.rows) continue;
    const int* id = nb->indices.ptr<int>(row);
    const float* d2 = nb->dists.ptr<float>(row);
    float other = std::numeric_limits<float>::infinity();
    for (int k = 0; k < nb->indices.cols; ++k) {
      if (id[k] < 0) break;
      if (model.photos()[model.globalOwner(id[k]).first].class_id != class_id) {
        other = d2[k];
        break;
      }
    }
    distinct += c.dist < r2 * other ? 1 : 0;
  }
  return distinct;
}
}  // namespace

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
  // Colour check: correspondences whose neighbourhoods differ in chroma are kept out of
  // RANSAC, and counted afterwards: when most of the geometrically consistent correspondences
  // have the wrong colour, this is the same artwork on a differently coloured product.
  std::vector<Corr> wrong_colour;
  const ColourGate gate(model, frame, q, photo, p.colour_tolerance);
  if (gate.on()) {
    std::vector<Corr> ok;
    ok.reserve(corr.size());
    for (const auto& c : corr) (gate(c.q, c.d) ? ok : wrong_colour).push_back(c);
    corr.swap(ok);
  }
  // Below min_inliers RANSAC still runs (cheap on few points): the inlier count is evidence for
  // recognise()'s combined score.
  if (corr.size() < 4) return r;
  std::vector<cv::Point2f> src, dst;  // database -> frame
  src.reserve(corr.size());
  dst.reserve(corr.size());
  for (const auto& c : corr) {
    src.push_back(ph.keypoints[c.d].pt);
    dst.push_back(frame.features.keypoints[q.idx[c.q]].pt);
  }
  std::vector<unsigned char> mask;
  // OpenCV's RANSAC stops early only once it has a good model, so a photo that does not verify
  // ran all ransac_iterations (329 of 518 calls on 100 val frames). The bound stops it once a
  // min_inliers model would have been found with the same confidence.
  constexpr double kConfidence = 0.995;
  const int iterations = ransacIterations(static_cast<int>(src.size()), p.min_inliers,
                                          p.ransac_iterations, kConfidence);
  cv::Mat H = cv::findHomography(src, dst, cv::RANSAC, p.ransac_px, mask, iterations, kConfidence);
  if (H.empty()) return r;
  // A plausible view of a planar-ish package: orientation-preserving, scale within 1/30..30.
  const double det =
      H.at<double>(0, 0) * H.at<double>(1, 1) - H.at<double>(0, 1) * H.at<double>(1, 0);
  if (!(det > 1.0 / 900 && det < 900)) return r;
  int inl = 0;
  std::vector<Corr> inlier_corr;
  for (size_t i = 0; i < mask.size(); ++i)
    if (mask[i]) {
      ++inl;
      r.x_d.push_back(src[i]);
      r.x_t.push_back(dst[i]);
      inlier_corr.push_back(corr[i]);
    }
  r.inliers = inl;
  r.H = H;
  int wrong = 0;
  if (!wrong_colour.empty()) {
    std::vector<cv::Point2f> ws, wd;
    for (const auto& c : wrong_colour) ws.push_back(ph.keypoints[c.d].pt);
    cv::perspectiveTransform(ws, wd, H);
    const double t2 = p.ransac_px * p.ransac_px;
    for (size_t i = 0; i < wd.size(); ++i) {
      const cv::Point2f d = wd[i] - frame.features.keypoints[q.idx[wrong_colour[i].q]].pt;
      wrong += d.dot(d) <= t2 ? 1 : 0;
    }
  }
  r.wrong_colour = wrong;
  bool distinct_ok = true;
  if (p.distinct_min_fraction > 0 && inl >= p.min_inliers) {
    r.distinct_inliers = countDistinct(model, frame, q, ph.class_id, inlier_corr, p);
    distinct_ok = r.distinct_inliers >= p.distinct_min_fraction * inl;
  }
  if (inl >= p.min_inliers && inl >= p.colour_min_fraction * (inl + wrong) && distinct_ok) {
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

Votes computeVotes(const LandmarkModel& model, const FrameFeatures& frame, const WindowQuery& q,
                   int knn, double class_ratio, int checks, double colour_tolerance) {
  Votes v;
  v.class_votes.assign(model.classes().size(), 0);
  v.photo_corr.resize(model.photos().size());
  v.class_rows.resize(model.classes().size());
  v.row_class.assign(q.descriptors.rows, -1);
  if (q.descriptors.rows == 0 || model.photos().empty()) return v;
  cv::Mat nn, d2;
  model.knnAll(q.descriptors, knn, checks, nn, d2);
  const float r2 = static_cast<float>(class_ratio * class_ratio);
  ColourGate gate(model, frame, q, -1, colour_tolerance);
  std::vector<int> seen_photo;
  std::vector<std::pair<int, int>> owner;  // colour-compatible neighbours: (photo, keypoint)
  std::vector<float> dist;
  for (int i = 0; i < nn.rows; ++i) {
    const int* id = nn.ptr<int>(i);
    const float* ds = d2.ptr<float>(i);
    // Neighbours of another colour are not evidence for their class: the same artwork on a
    // sibling product's differently coloured carton must not out-vote the right product.
    owner.clear();
    dist.clear();
    for (int k = 0; k < nn.cols; ++k) {
      if (id[k] < 0) break;
      const auto o = model.globalOwner(id[k]);
      auto& rows = v.class_rows[model.photos()[o.first].class_id];
      if (rows.empty() || rows.back() != i) rows.push_back(i);
      if (gate.on()) {
        gate.setPhoto(model, o.first);
        if (!gate(i, o.second)) continue;
      }
      owner.push_back(o);
      dist.push_back(ds[k]);
    }
    if (owner.empty()) continue;
    const int c1 = model.photos()[owner[0].first].class_id;
    float other = std::numeric_limits<float>::infinity();
    for (size_t k = 1; k < owner.size(); ++k)
      if (model.photos()[owner[k].first].class_id != c1) {
        other = dist[k];
        break;
      }
    if (!(dist[0] < r2 * other)) continue;
    ++v.class_votes[c1];
    v.row_class[i] = c1;
    seen_photo.clear();
    for (size_t k = 0; k < owner.size(); ++k) {
      if (!(dist[k] < r2 * other)) break;
      const auto [photo, kp] = owner[k];
      if (model.photos()[photo].class_id != c1) break;
      if (std::find(seen_photo.begin(), seen_photo.end(), photo) != seen_photo.end()) continue;
      seen_photo.push_back(photo);
      v.photo_corr[photo].push_back({i, kp, dist[k]});
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
  if (p.photo_order_checks > 0 && static_cast<int>(photos.size()) > p.max_photos) {
    // The photos where most window descriptors find their nearest class neighbour first. The
    // search covers the whole frame once per class and is cached in the frame's features.
    std::vector<int> v(model.photos().size(), 0);
    if (frame.photo_cache) {
      std::lock_guard<std::mutex> lock(frame.photo_cache->mutex);
      auto& nearest =
          frame.photo_cache
              ->nearest[{static_cast<const void*>(&model), class_id, p.photo_order_checks}];
      if (nearest.empty())
        nearest =
            model.classNearestPhoto(class_id, frame.features.descriptors, p.photo_order_checks);
      for (int i : q.idx)
        if (i < static_cast<int>(nearest.size()) && nearest[i] >= 0 &&
            nearest[i] < static_cast<int>(v.size()))
          ++v[nearest[i]];
    } else {
      v = model.classPhotoVotes(class_id, q.descriptors, p.photo_order_checks);
    }
    std::stable_sort(photos.begin(), photos.end(),
                     [&](int a, int b) { return v[a] != v[b] ? v[a] > v[b] : sims[a] > sims[b]; });
  } else {
    std::stable_sort(photos.begin(), photos.end(), [&](int a, int b) { return sims[a] > sims[b]; });
  }
  MatchResult best;
  int tried = 0;
  for (int ph : photos) {
    if (tried >= p.max_photos) break;
    ++tried;
    MatchResult r = verifyPhoto(model, frame, q, ph, p);
    if (std::make_pair(r.matched, r.inliers) > std::make_pair(best.matched, best.inliers) ||
        best.database_photo < 0)
      best = std::move(r);
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
  const cv::Rect win =
      window.area() > 0 ? window : cv::Rect(cv::Point(), frame.features.image_size);
  if (frame.photo_cache) {
    // recognise() already verified this class here with the same settings: reuse it.
    std::lock_guard<std::mutex> lock(frame.photo_cache->mutex);
    for (const auto& v : frame.photo_cache->verified)
      if (v.model == &model && v.class_id == cls && v.window == win &&
          sameVerification(v.params, params))
        return v.result;
  }
  const auto idx = detail::keypointsInWindow(frame, window);
  MatchResult r;
  if (static_cast<int>(idx.size()) >= params.min_window_features) {
    const auto q = detail::makeQuery(model, frame, idx);
    r = detail::matchClass(model, frame, q, cls, detail::photoSimilarities(model, q.histogram),
                           params);
  }
  r.window = win;
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
      o.centre_u = (H.at<double>(0, 0) * dcx + H.at<double>(0, 1) * dcy + H.at<double>(0, 2)) / w;
      o.centre_v = (H.at<double>(1, 0) * dcx + H.at<double>(1, 1) * dcy + H.at<double>(1, 2)) / w;
      const double det =
          H.at<double>(0, 0) * H.at<double>(1, 1) - H.at<double>(0, 1) * H.at<double>(1, 0);
      scale = std::sqrt(std::abs(det)) / std::abs(w);
      // The object's column: the centre of the matched part of the database photo through H.
      // Not the photo's centre: a user's photo frames the object anywhere (a carton held in a
      // hand, on a shelf), so its centre may be far from the object's.
      const cv::Rect2f part = cv::boundingRect(m.x_d);
      const double px = part.x + 0.5 * part.width, py = part.y + 0.5 * part.height;
      const double wp = H.at<double>(2, 0) * px + H.at<double>(2, 1) * py + H.at<double>(2, 2);
      if (std::abs(wp) > 1e-9)
        u = static_cast<float>(
            (H.at<double>(0, 0) * px + H.at<double>(0, 1) * py + H.at<double>(0, 2)) / wp);
      // The centre may fall outside a partly visible object's frame, but not absurdly far.
      h_ok = std::abs(wp) > 1e-9 && std::isfinite(u) && u > -2.0f * frame_width &&
             u < 3.0f * frame_width;
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
