#include <algorithm>
#include <numeric>
#include <set>
#include <tuple>

#include "matcher_internal.h"
#include "sketchnav/landmarks/recognition.h"

namespace sketchnav::landmarks {

void RecognitionParams::validate() const {
  require(shortlist_classes >= 1, "recognition.shortlist_classes", "must be >= 1");
  require(shortlist_votes >= 0, "recognition.shortlist_votes", "must be >= 0");
  require(knn >= 2 && knn <= 64, "recognition.knn", "must be in [2, 64]");
  require(search_checks >= 1, "recognition.search_checks", "must be >= 1");
  require(class_ratio > 0 && class_ratio <= 1, "recognition.class_ratio", "must be in (0, 1]");
  require(max_verified_photos >= 0, "recognition.max_verified_photos",
          "must be >= 0 (0 = no limit)");
  require(reject_probability >= 0 && reject_probability <= 1, "recognition.reject_probability",
          "must be in [0, 1]");
  match.validate();
}

namespace {

std::vector<Recognition> recogniseWindow(const LandmarkModel& model, const FrameFeatures& frame,
                                         const cv::Rect& window, int top_k,
                                         const RecognitionParams& p) {
  std::vector<Recognition> out;
  const auto idx = detail::keypointsInWindow(frame, window);
  if (static_cast<int>(idx.size()) < p.match.min_window_features) return out;
  const cv::Rect win =
      window.area() > 0 ? window : cv::Rect(cv::Point(), frame.features.image_size);
  const auto q = detail::makeQuery(model, frame, idx);
  const std::vector<float> prob = model.classifier().probabilities(q.histogram);
  const int n_classes = static_cast<int>(prob.size());
  std::vector<int> order(n_classes);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return prob[a] > prob[b]; });

  auto entry = [&](int c) {
    Recognition r;
    r.class_name = model.classes()[c];
    r.bow_probability = prob[c];
    r.score = prob[c];
    r.window = win;
    return r;
  };

  if (!p.verify) {
    for (int i = 0; i < std::min(top_k, n_classes); ++i) out.push_back(entry(order[i]));
    const bool reject = out.empty() || out.front().bow_probability < p.reject_probability;
    for (auto& r : out) r.rejected = reject;
    return out;
  }

  // Shortlist: the SVM's best classes plus the classes with the most nearest-neighbour votes
  // (the votes catch classes the linear SVM ranks low on an unusual view).
  const detail::Votes votes = detail::computeVotes(model, frame, q, p.knn, p.class_ratio,
                                                   p.search_checks, p.match.colour_tolerance);
  std::vector<int> shortlist;
  for (int i = 0; i < std::min(p.shortlist_classes, n_classes); ++i) shortlist.push_back(order[i]);
  {
    std::vector<int> by_votes(n_classes);
    std::iota(by_votes.begin(), by_votes.end(), 0);
    std::stable_sort(by_votes.begin(), by_votes.end(),
                     [&](int a, int b) { return votes.class_votes[a] > votes.class_votes[b]; });
    for (int i = 0; i < std::min(p.shortlist_votes, n_classes); ++i) {
      const int c = by_votes[i];
      if (votes.class_votes[c] == 0) break;
      if (std::find(shortlist.begin(), shortlist.end(), c) == shortlist.end())
        shortlist.push_back(c);
    }
  }

  // Verification in ranking order. Ranked by votes, the first class that verifies is the
  // answer, so the rest need not be verified (lazy: most frames verify 1-3 photos instead of
  // up to shortlist x max_photos); ranked by inliers, every shortlisted class is verified.
  if (p.rank_by_votes)
    std::stable_sort(shortlist.begin(), shortlist.end(), [&](int a, int b) {
      return std::make_pair(votes.class_votes[a], prob[a]) >
             std::make_pair(votes.class_votes[b], prob[b]);
    });
  std::vector<std::pair<int, int>> verified;  // (inliers, class)
  std::vector<float> conf(n_classes, 0.0f);
  int budget = p.max_verified_photos > 0 ? p.max_verified_photos : 1 << 30;
  for (int c : shortlist) {
    if (budget <= 0 || (p.rank_by_votes && !verified.empty())) break;
    // The class's photos with the most tentative correspondences first.
    std::vector<int> photos = model.photosOfClass(c);
    std::stable_sort(photos.begin(), photos.end(), [&](int a, int b) {
      return votes.photo_corr[a].size() > votes.photo_corr[b].size();
    });
    MatchResult best;
    // Only the rows with a neighbour of this class can match its photos (a third to a tenth
    // of the window's rows, so the exhaustive per-photo search is that much cheaper).
    const std::vector<int>& rows = votes.class_rows[c];
    if (p.class_rows && static_cast<int>(rows.size()) < p.match.min_inliers) continue;
    const detail::WindowQuery cq = p.class_rows ? detail::subQuery(q, rows) : detail::WindowQuery();
    for (int i = 0; i < std::min<int>(p.match.max_photos, static_cast<int>(photos.size())); ++i) {
      if (budget-- <= 0) break;
      const int ph = photos[i];
      // Cascade: RANSAC on the vote search's correspondences costs ~0.2 ms and settles most
      // clear views; only when it does not verify is the photo searched exhaustively.
      MatchResult m;
      if (p.vote_correspondences || p.votes_first)
        m = detail::ransacPhoto(model, frame, q, ph, votes.photo_corr[ph], p.match);
      if (!p.vote_correspondences && !m.matched)
        m = detail::verifyPhoto(model, frame, p.class_rows ? cq : q, ph, p.match);
      if (m.inliers > best.inliers) best = std::move(m);
      if (best.matched && best.inliers >= p.match.strong_inliers) break;
    }
    if (best.matched) {
      verified.push_back({best.inliers, c});
      conf[c] = best.confidence;
    }
  }
  // Verified classes, best first: by votes (or inliers), ties by the other, then by BoW.
  auto key = [&](const std::pair<int, int>& v) {
    const int votes_c = votes.class_votes[v.second];
    return p.rank_by_votes ? std::make_tuple(votes_c, v.first, prob[v.second])
                           : std::make_tuple(v.first, votes_c, prob[v.second]);
  };
  std::stable_sort(verified.begin(), verified.end(),
                   [&](const auto& a, const auto& b) { return key(a) > key(b); });
  std::set<int> used;
  for (const auto& [inl, c] : verified) {
    if (static_cast<int>(out.size()) >= top_k) break;
    Recognition r = entry(c);
    r.inliers = inl;
    r.votes = votes.class_votes[c];
    r.score = conf[c];
    out.push_back(r);
    used.insert(c);
  }
  const bool none = verified.empty();
  // The remaining candidates, unverified, in the ranking's order.
  std::vector<int> rest = order;
  if (p.rank_by_votes)
    std::stable_sort(rest.begin(), rest.end(),
                     [&](int a, int b) { return votes.class_votes[a] > votes.class_votes[b]; });
  for (int c : rest) {
    if (static_cast<int>(out.size()) >= top_k) break;
    if (used.count(c)) continue;
    Recognition r = entry(c);
    r.votes = votes.class_votes[c];
    r.rejected = true;  // not verified: a candidate only
    out.push_back(r);
  }
  if (none)
    for (auto& r : out) r.rejected = true;
  return out;
}

}  // namespace

std::vector<std::vector<Recognition>> recogniseWindows(const LandmarkModel& model,
                                                       const FrameFeatures& frame,
                                                       const std::vector<cv::Rect>& windows,
                                                       int top_k, const RecognitionParams& p) {
  top_k = std::max(1, top_k);
  std::vector<std::vector<Recognition>> out;
  if (windows.empty()) {
    out.push_back(recogniseWindow(model, frame, cv::Rect(), top_k, p));
  } else {
    for (const auto& w : windows) out.push_back(recogniseWindow(model, frame, w, top_k, p));
  }
  return out;
}

std::vector<Recognition> recognise(const LandmarkModel& model, const cv::Mat& bgr,
                                   const std::vector<cv::Rect>& windows, int top_k,
                                   const RecognitionParams& p) {
  return recognise(model, computeFrameFeatures(model, bgr), windows, top_k, p);
}

std::vector<Recognition> recognise(const LandmarkModel& model, const FrameFeatures& frame,
                                   const std::vector<cv::Rect>& windows, int top_k,
                                   const RecognitionParams& p) {
  top_k = std::max(1, top_k);
  std::vector<Recognition> all;
  for (auto& v : recogniseWindows(model, frame, windows, top_k, p))
    all.insert(all.end(), v.begin(), v.end());
  // Best first: accepted before rejected, then the same order as within a window.
  auto key = [&](const Recognition& r) {
    return p.rank_by_votes ? std::make_tuple(!r.rejected, r.votes, r.inliers, r.score)
                           : std::make_tuple(!r.rejected, r.inliers, r.votes, r.score);
  };
  std::stable_sort(all.begin(), all.end(),
                   [&](const Recognition& a, const Recognition& b) { return key(a) > key(b); });
  std::vector<Recognition> out;
  std::set<std::string> seen;
  for (auto& r : all) {
    if (static_cast<int>(out.size()) >= top_k) break;
    if (seen.insert(r.class_name).second) out.push_back(r);
  }
  return out;
}

}  // namespace sketchnav::landmarks
