#pragma once
// Private pieces of the matcher shared with recognition.
#include <opencv2/core.hpp>

#include <vector>

#include "sketchnav/landmarks/matcher.h"

namespace sketchnav::landmarks::detail {

/// One window of a frame, ready for matching: its keypoint indices, descriptors, histogram.
struct WindowQuery {
  std::vector<int> idx;
  cv::Mat descriptors;
  cv::Mat histogram;
};

std::vector<int> keypointsInWindow(const FrameFeatures& frame, const cv::Rect& window);
/// The query restricted to some of its rows (indices into q.idx); no histogram.
struct WindowQuery;
WindowQuery makeQuery(const LandmarkModel& model, const FrameFeatures& frame,
                      const std::vector<int>& idx);
WindowQuery subQuery(const WindowQuery& q, const std::vector<int>& rows);
/// Whether a window keypoint and a database keypoint have compatible colours (always true
/// when the tolerance is 0 or either side has no colours).
class ColourGate {
 public:
  ColourGate(const LandmarkModel& model, const FrameFeatures& frame, const WindowQuery& q,
             int photo, double tolerance)
      : frame_(frame.features.colours), q_(q), tol2_(static_cast<float>(tolerance * tolerance)) {
    if (photo >= 0) db_ = &model.photos()[photo].colours;
    on_ = tolerance > 0 && !frame_.empty();
  }
  void setPhoto(const LandmarkModel& model, int photo) { db_ = &model.photos()[photo].colours; }
  bool operator()(int query_row, int db_keypoint) const {
    if (!on_ || !db_ || db_->empty()) return true;
    return chromaDistance2(frame_.ptr<unsigned char>(q_.idx[query_row]),
                           db_->ptr<unsigned char>(db_keypoint)) <= tol2_;
  }
  bool on() const { return on_; }

 private:
  const cv::Mat& frame_;
  const WindowQuery& q_;
  const cv::Mat* db_ = nullptr;
  float tol2_;
  bool on_;
};

/// BoW cosine similarity of a window histogram to every database photo.
std::vector<float> photoSimilarities(const LandmarkModel& model, const cv::Mat& hist);
MatchResult verifyPhoto(const LandmarkModel& model, const FrameFeatures& frame,
                        const WindowQuery& q, int photo, const MatchParams& p);
/// A tentative correspondence: query row (in the window), database keypoint, squared distance.
struct Corr {
  int q, d;
  float dist;
};
/// RANSAC hypotheses worth drawing among n tentative correspondences: enough to find a model
/// with min_inliers inliers, if there is one, with the given confidence — 1 − confidence ≥
/// (1 − C(min_inliers, 4) / C(n, 4))^iterations — and never more than max_iterations. Below
/// min_inliers correspondences nothing can verify, and the best consensus (still reported as
/// evidence) is sought among at most C(n, 4) draws, the number of distinct 4-point samples.
int ransacIterations(int n, int min_inliers, int max_iterations, double confidence);
/// RANSAC homography database photo -> frame over tentative correspondences (one per
/// database keypoint kept, the closest).
MatchResult ransacPhoto(const LandmarkModel& model, const FrameFeatures& frame,
                        const WindowQuery& q, int photo, std::vector<Corr> corr,
                        const MatchParams& p);

/// Nearest-neighbour votes of a window's descriptors in the whole database (one kNN search):
/// a query descriptor votes for the class of its nearest database descriptor when that is
/// closer than `class_ratio` × the nearest descriptor of any other class (a ratio test between
/// classes, so artwork shared by sibling products does not vote); its neighbours of that
/// class become tentative correspondences of their photos.
struct Votes {
  std::vector<int> class_votes;
  // Per class, the window rows with at least one neighbour of that class among the k: the
  // only rows that can plausibly match that class's photos, so verification searches these.
  std::vector<std::vector<int>> class_rows;
  std::vector<std::vector<Corr>> photo_corr;  // per database photo
  std::vector<int> row_class;                 // per window row, the class it votes for, -1 = none
};
Votes computeVotes(const LandmarkModel& model, const FrameFeatures& frame, const WindowQuery& q,
                   int knn, double class_ratio, int checks, double colour_tolerance);

/// Best of the class's max_photos most promising photos (MatchParams::photo_order_checks).
MatchResult matchClass(const LandmarkModel& model, const FrameFeatures& frame, const WindowQuery& q,
                       int class_id, const std::vector<float>& sims, const MatchParams& p);

}  // namespace sketchnav::landmarks::detail
