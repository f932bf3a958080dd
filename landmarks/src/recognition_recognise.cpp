#include <algorithm>
#include <cmath>
#include <numeric>
#include <set>
#include <tuple>

#include "appearance_internal.h"
#include "matcher_internal.h"
#include "sketchnav/landmarks/colour_layout.h"
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
  require(colour_rescue_rank >= 1, "recognition.colour_rescue_rank", "must be >= 1");
  require(colour_rescue_probability >= 0 && colour_rescue_probability <= 1,
          "recognition.colour_rescue_probability", "must be in [0, 1]");
  require(colour_rescue_inliers >= 0, "recognition.colour_rescue_inliers", "must be >= 0");
  require(sibling_vote_ratio >= 0 && sibling_vote_ratio <= 1, "recognition.sibling_vote_ratio",
          "must be in [0, 1]");
  require(sibling_margin >= 0, "recognition.sibling_margin", "must be >= 0");
  match.validate();
}

double RecognitionParams::combinedScore(int inliers, int votes, int total_votes, double bow_p,
                                        bool verified, double colour_p) const {
  const double vote_share = total_votes > 0 ? static_cast<double>(votes) / total_votes : 0.0;
  return score_bias + score_inliers * std::log1p(inliers) + score_vote_share * vote_share +
         score_votes * std::log1p(votes) + score_bow * bow_p + (verified ? score_verified : 0.0) +
         score_colour * colour_p;
}

namespace {

// What recognise() learnt about one class in one window.
struct Evidence {
  int inliers = 0;       // best photo's RANSAC inliers, also below min_inliers
  int vote_inliers = 0;  // the same on the vote correspondences only (distinctive matches)
  bool verified = false;
  bool tried = false;
  float confidence = 0;
  MatchResult best;
  std::vector<MatchResult> others;  // other photos that verified (sibling check only)
};

// Keeps the verification of the answer in the frame's cache, so match() on the same frame,
// window and class (the servo, right after recognition) does not search the photos again.
void remember(const FrameFeatures& frame, const LandmarkModel& model, const cv::Rect& win,
              const std::string& cls, const std::vector<Evidence>& ev, const RecognitionParams& p) {
  const int c = model.classId(cls);
  if (c < 0 || !ev[c].verified || !frame.photo_cache) return;
  std::lock_guard<std::mutex> lock(frame.photo_cache->mutex);
  MatchResult m = ev[c].best;
  m.window = win;
  frame.photo_cache->verified.push_back({&model, c, win, p.match, std::move(m)});
}

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

  // Colour-layout evidence: one descriptor per window, over its keypoints' box (colour_layout.h
  // says why that region), scored by every class's colour classifier.
  std::vector<float> colour_p(n_classes, 0.0f);
  if (!frame.colour_thumbnail.empty() && model.colourClassifier().classes() == n_classes) {
    std::vector<cv::Point2f> pts;
    pts.reserve(idx.size());
    for (int i : idx) pts.push_back(frame.features.keypoints[i].pt);
    const cv::Size size = frame.features.image_size;
    colour_p = model.colourClassifier().probabilities(
        colourLayoutDescriptor(frame.colour_thumbnail, size, colourRegion(pts, size, win)));
  }
  const int colour_best =
      static_cast<int>(std::max_element(colour_p.begin(), colour_p.end()) - colour_p.begin());
  const bool have_colour = !frame.colour_thumbnail.empty() && n_classes > 1;

  auto entry = [&](int c) {
    Recognition r;
    r.class_name = model.classes()[c];
    r.bow_probability = prob[c];
    r.colour_probability = colour_p[c];
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

  // Verification in ranking order (votes, then BoW).
  if (p.rank_by_votes || p.combined_score)
    std::stable_sort(shortlist.begin(), shortlist.end(), [&](int a, int b) {
      return std::make_pair(votes.class_votes[a], prob[a]) >
             std::make_pair(votes.class_votes[b], prob[b]);
    });
  std::vector<Evidence> ev(n_classes);
  int budget = p.max_verified_photos > 0 ? p.max_verified_photos : 1 << 30;
  bool any_verified = false;
  // Verifies class c on its most promising photos while `budget` (photos) lasts; first_only:
  // stop at the first photo that verifies.
  auto verifyClass = [&](int c, int& budget, bool first_only = false) {
    // The class's photos with the most tentative correspondences first.
    std::vector<int> photos = model.photosOfClass(c);
    std::stable_sort(photos.begin(), photos.end(), [&](int a, int b) {
      return votes.photo_corr[a].size() > votes.photo_corr[b].size();
    });
    MatchResult best;
    // Only the rows with a neighbour of this class can match its photos (a third to a tenth
    // of the window's rows, so the exhaustive per-photo search is that much cheaper).
    const std::vector<int>& rows = votes.class_rows[c];
    if (p.class_rows && static_cast<int>(rows.size()) < p.match.min_inliers) return;
    const detail::WindowQuery cq = p.class_rows ? detail::subQuery(q, rows) : detail::WindowQuery();
    ev[c].tried = true;
    for (int i = 0; i < std::min<int>(p.match.max_photos, static_cast<int>(photos.size())); ++i) {
      if (budget-- <= 0) break;
      const int ph = photos[i];
      // Cascade: RANSAC on the vote search's correspondences costs ~0.2 ms and settles most
      // clear views; only when it does not verify is the photo searched exhaustively.
      MatchResult m;
      if (p.vote_correspondences || p.votes_first || p.combined_score) {
        m = detail::ransacPhoto(model, frame, q, ph, votes.photo_corr[ph], p.match);
        ev[c].vote_inliers = std::max(ev[c].vote_inliers, m.inliers);
      }
      if (!p.vote_correspondences && !m.matched)
        m = detail::verifyPhoto(model, frame, p.class_rows ? cq : q, ph, p.match);
      if (std::make_pair(m.matched, m.inliers) > std::make_pair(best.matched, best.inliers)) {
        if (best.matched && p.sibling_check) ev[c].others.push_back(std::move(best));
        best = std::move(m);
      } else if (m.matched && p.sibling_check) {
        ev[c].others.push_back(std::move(m));
      }
      if (best.matched && (first_only || best.inliers >= p.match.strong_inliers)) break;
      // A class far below min_inliers on its most promising photo rarely does better on the
      // next ones: with the combined score, spend the budget on the other candidates.
      if (p.combined_score && best.inliers < p.match.min_inliers / 2) break;
    }
    ev[c].inliers = best.inliers;
    ev[c].verified = best.matched;
    ev[c].confidence = best.confidence;
    any_verified = any_verified || best.matched;
    ev[c].best = std::move(best);
  };
  for (int c : shortlist) {
    // Old rule, ranked by votes: the first class that verifies is the answer, so the rest need
    // not be verified. Combined score: every shortlisted class gets at least one photo (its
    // inlier count is evidence even below min_inliers), later classes only while the budget
    // lasts.
    if (budget <= 0) break;
    if (!p.combined_score && p.rank_by_votes && any_verified) break;
    verifyClass(c, budget);
  }

  // Sibling check (RecognitionParams::sibling_check): classes with nearly the answer's votes
  // are verified too, and among those that verify, the one whose photo best explains the
  // frame's pixels (dense aligned comparison) is the answer.
  int preferred = -1;
  std::vector<float> appearance(n_classes, -2.0f);
  if (p.sibling_check && !p.combined_score && p.rank_by_votes && any_verified &&
      !frame.colour_thumbnail.empty()) {
    for (int c : shortlist)
      if (ev[c].verified) {
        preferred = c;
        break;
      }
    const int answer = preferred;
    for (int c : shortlist) {
      if (c == answer || (ev[c].tried && !ev[c].verified)) continue;
      if (votes.class_votes[c] == 0 ||
          votes.class_votes[c] < p.sibling_vote_ratio * votes.class_votes[answer])
        continue;
      if (!ev[c].tried) {
        int sibling_budget = p.match.max_photos;
        // Up to max_photos photos, stopping at the first that verifies: the same val top-1
        // as trying all of them, ~6 ms less on the photos where the check runs.
        verifyClass(c, sibling_budget, true);
      }
      if (!ev[c].verified) continue;
      // Each class's similarity: the best of its verified photos (one photo may show the
      // package from another side or in other light), over the region of both best photos.
      std::vector<const MatchResult*> ms = {&ev[preferred].best, &ev[c].best};
      std::vector<int> owner = {preferred, c};
      for (int k : {preferred, c})
        for (const auto& m : ev[k].others) {
          ms.push_back(&m);
          owner.push_back(k);
        }
      const std::vector<double> s = detail::appearanceSimilarities(model, frame, ms, 2);
      if (std::isnan(s[0]) || std::isnan(s[1])) continue;
      double best_pref = s[0], best_c = s[1];
      for (size_t i = 2; i < s.size(); ++i) {
        if (std::isnan(s[i])) continue;
        double& b = owner[i] == c ? best_c : best_pref;
        b = std::max(b, s[i]);
      }
      appearance[preferred] = static_cast<float>(best_pref);
      appearance[c] = static_cast<float>(best_c);
      if (best_c > best_pref + p.sibling_margin) preferred = c;
    }
  }

  int total_votes = 0;
  for (int v : votes.class_votes) total_votes += v;
  auto evidence = [&](int c) {
    return static_cast<float>(p.combinedScore(ev[c].inliers, votes.class_votes[c], total_votes,
                                              prob[c], ev[c].verified, colour_p[c]));
  };
  auto make = [&](int c) {
    Recognition r = entry(c);
    r.inliers = ev[c].inliers;
    r.vote_inliers = ev[c].vote_inliers;
    r.verified = ev[c].verified;
    r.votes = votes.class_votes[c];
    r.score = ev[c].confidence;
    r.evidence = evidence(c);
    r.vote_share = total_votes > 0 ? static_cast<float>(votes.class_votes[c]) / total_votes : 0.0f;
    r.appearance = appearance[c];
    return r;
  };

  if (p.combined_score) {
    // One score per candidate from all the evidence; the best candidate is the answer when its
    // score reaches accept_score, whether or not it reached min_inliers; otherwise none.
    std::vector<int> cand = shortlist;
    for (int c : order)  // then the other classes, for a full top-k list
      if (std::find(cand.begin(), cand.end(), c) == cand.end()) cand.push_back(c);
    std::vector<float> s(n_classes);
    for (int c : cand) s[c] = evidence(c);
    std::stable_sort(cand.begin(), cand.end(), [&](int a, int b) { return s[a] > s[b]; });
    for (int c : cand) {
      if (static_cast<int>(out.size()) >= top_k) break;
      out.push_back(make(c));
    }
    const bool reject = out.empty() || out.front().evidence < p.accept_score;
    for (size_t i = 0; i < out.size(); ++i) out[i].rejected = reject || i > 0;
    if (!out.empty() && !reject) remember(frame, model, win, out.front().class_name, ev, p);
    return out;
  }

  // Old rule: verified classes, best first: by votes (or inliers), ties by the other, then BoW.
  std::vector<std::pair<int, int>> verified;  // (inliers, class)
  for (int c = 0; c < n_classes; ++c)
    if (ev[c].verified) verified.push_back({ev[c].inliers, c});
  auto key = [&](const std::pair<int, int>& v) {
    const int votes_c = votes.class_votes[v.second];
    return p.rank_by_votes ? std::make_tuple(votes_c, v.first, prob[v.second])
                           : std::make_tuple(v.first, votes_c, prob[v.second]);
  };
  std::stable_sort(verified.begin(), verified.end(),
                   [&](const auto& a, const auto& b) { return key(a) > key(b); });
  if (preferred >= 0)  // the sibling check's choice first; the others it displaced are refused
    std::stable_partition(verified.begin(), verified.end(),
                          [&](const auto& v) { return v.second == preferred; });
  std::set<int> used;
  for (const auto& [inl, c] : verified) {
    if (static_cast<int>(out.size()) >= top_k) break;
    out.push_back(make(c));
    out.back().rejected = preferred >= 0 && c != preferred;
    used.insert(c);
  }
  bool none = verified.empty();
  // Colour rescue: no class verified, but one of the classes with most votes is also the colour
  // classifier's confident first choice.
  if (none && p.colour_rescue && have_colour && p.rank_by_votes) {
    const int c = colour_best;
    std::vector<int> by_votes = shortlist;  // sorted by votes (then BoW) above
    by_votes.resize(std::min<size_t>(by_votes.size(), p.colour_rescue_rank));
    if (std::find(by_votes.begin(), by_votes.end(), c) != by_votes.end() &&
        votes.class_votes[c] > 0 && colour_p[c] >= p.colour_rescue_probability &&
        ev[c].inliers >= p.colour_rescue_inliers) {
      Recognition r = make(c);
      r.colour_rescued = true;
      out.push_back(r);
      used.insert(c);
      none = false;
    }
  }
  // The remaining candidates, unverified, in the ranking's order.
  std::vector<int> rest = order;
  if (p.rank_by_votes)
    std::stable_sort(rest.begin(), rest.end(),
                     [&](int a, int b) { return votes.class_votes[a] > votes.class_votes[b]; });
  for (int c : rest) {
    if (static_cast<int>(out.size()) >= top_k) break;
    if (used.count(c)) continue;
    Recognition r = make(c);
    r.rejected = true;  // not verified: a candidate only
    out.push_back(r);
  }
  if (none)
    for (auto& r : out) r.rejected = true;
  if (!none) remember(frame, model, win, out.front().class_name, ev, p);
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

std::vector<int> keypointVotes(const LandmarkModel& model, const FrameFeatures& frame,
                               const RecognitionParams& p) {
  const auto idx = detail::keypointsInWindow(frame, cv::Rect());
  std::vector<int> out(frame.features.keypoints.size(), -1);
  if (idx.empty()) return out;
  const auto q = detail::makeQuery(model, frame, idx);
  const detail::Votes v = detail::computeVotes(model, frame, q, p.knn, p.class_ratio,
                                               p.search_checks, p.match.colour_tolerance);
  for (size_t r = 0; r < idx.size(); ++r) out[idx[r]] = v.row_class[r];
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
    // Verified before colour-rescued: a rescued class of one window must not displace a class
    // another window verified.
    if (p.combined_score) return std::make_tuple(!r.rejected, true, r.evidence, 0, 0.0f);
    return p.rank_by_votes ? std::make_tuple(!r.rejected, !r.colour_rescued,
                                             static_cast<float>(r.votes), r.inliers, r.score)
                           : std::make_tuple(!r.rejected, !r.colour_rescued,
                                             static_cast<float>(r.inliers), r.votes, r.score);
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
