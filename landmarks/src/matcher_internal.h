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
WindowQuery makeQuery(const LandmarkModel& model, const FrameFeatures& frame,
                      const std::vector<int>& idx);
/// BoW cosine similarity of a window histogram to every database photo.
std::vector<float> photoSimilarities(const LandmarkModel& model, const cv::Mat& hist);
MatchResult verifyPhoto(const LandmarkModel& model, const FrameFeatures& frame,
                        const WindowQuery& q, int photo, const MatchParams& p);
/// A tentative correspondence: query row (in the window), database keypoint, squared distance.
struct Corr {
  int q, d;
  float dist;
};
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
  std::vector<std::vector<Corr>> photo_corr;  // per database photo
};
Votes computeVotes(const LandmarkModel& model, const WindowQuery& q, int knn, double class_ratio,
                   int checks);

/// Best of the class's max_photos most similar photos.
MatchResult matchClass(const LandmarkModel& model, const FrameFeatures& frame, const WindowQuery& q,
                       int class_id, const std::vector<float>& sims, const MatchParams& p);

}  // namespace sketchnav::landmarks::detail
