#pragma once
// Keypoint correspondences between a camera frame window and a landmark's database photos,
// for the visual servo.
//
// Coordinates: x_t are pixels in the frame, x_d pixels in the matched database photo
// (database_size). They are NOT directly comparable (different images, scales). The paper's
// servo feature is x_t − x_d with both measured from their own image's vertical centre line;
// use servoOffset() instead, which maps the database photo's centre into the frame through the
// verified homography: object_u is the frame column of the matched object's centre and
// offset_px = object_u − frame_width / 2 (> 0: the landmark is right of the image centre, so
// the robot should turn right). The servo law can use offset_px (pixels) or
// offset_px / f_x (normalised x) directly, and needs no geometry of its own.
#include <opencv2/core.hpp>

#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <tuple>
#include <vector>

#include "sketchnav/landmarks/model.h"

namespace sketchnav::landmarks {

/// Matching settings ("landmarks.match.*").
struct MatchParams {
  double ratio = 0.8;            // Lowe ratio test on the two nearest database descriptors
  int min_inliers = 12;          // fewer RANSAC inliers -> not matched (never a guess)
  double ransac_px = 6.0;        // [px in frame] RANSAC reprojection threshold
  int ransac_iterations = 1000;  // RANSAC hypotheses at most (the cost of a failed verification)
  int max_photos = 3;            // database photos tried, most promising first
  // Which photos are most promising: > 0 = those where most window descriptors have their
  // nearest neighbour among the class's photos (one kd-tree search, this many leaves checked;
  // in the lab simulation twice as many frames match as with the BoW order); 0 = the photos
  // most BoW-similar to the window (a whole frame's histogram is mostly background).
  int photo_order_checks = 16;
  int strong_inliers = 40;      // stop trying further photos once one has this many
  int min_window_features = 8;  // fewer keypoints in the window -> not matched
  // [chroma units of keypointColours()] a correspondence whose keypoint neighbourhoods differ more
  // in chroma is dropped before RANSAC: sibling products share artwork (same SIFT descriptors) on
  // differently coloured cartons. 0 = off (grey images are never colour-checked).
  double colour_tolerance = 20;
  // Not matched when fewer than this fraction of the correspondences consistent with the
  // homography have the right colour (the same artwork on a sibling product).
  double colour_min_fraction = 0.5;
  // Distinctiveness (a ratio test between classes, after RANSAC): an inlier is distinct when
  // its database descriptor is closer than distinct_ratio x the frame descriptor's nearest
  // descriptor of any other class (one approximate search of the whole database per frame,
  // distinct_neighbours neighbours, distinct_checks leaves). Artwork shared by sibling products
  // (a brand's logo) gives inliers that are not distinct: not matched when fewer than
  // distinct_min_fraction of the inliers are distinct. In [0, 1]; 0 = off. The evidence for the
  // default: doc/perception-benchmark.md "Distinct inliers and tracking".
  double distinct_min_fraction = 0.3;
  double distinct_ratio = 0.9;   // in (0, 1]
  int distinct_neighbours = 12;  // database neighbours searched per frame keypoint, >= 2
  int distinct_checks = 32;      // kd-tree leaves checked in that search, >= 1

  template <class B>
  void bind(B& b) {
    b("ratio", ratio);
    b("min_inliers", min_inliers);
    b("ransac_px", ransac_px);
    b("ransac_iterations", ransac_iterations);
    b("max_photos", max_photos);
    b("photo_order_checks", photo_order_checks);
    b("strong_inliers", strong_inliers);
    b("min_window_features", min_window_features);
    b("colour_tolerance", colour_tolerance);
    b("colour_min_fraction", colour_min_fraction);
    b("distinct_min_fraction", distinct_min_fraction);
    b("distinct_ratio", distinct_ratio);
    b("distinct_neighbours", distinct_neighbours);
    b("distinct_checks", distinct_checks);
  }
  void validate() const;
};

/// Features of one camera frame, computed once and shared by recognise() and match() for
/// every window of that frame.
struct FrameFeatures {
  Features features;
  std::vector<int> words;  // visual word per keypoint
  // Filled by match() on first use, per class: the class photo nearest to each keypoint, so
  // matching many windows of one frame orders photos with one search per class, not per
  // window. Shared by copies; safe to use from several threads.
  struct PhotoCache;
  std::shared_ptr<PhotoCache> photo_cache = std::make_shared<PhotoCache>();
  cv::Mat colour_thumbnail;  // colourThumbnail() of the frame (colour_layout.h); empty for grey
};
struct MatchResult;
struct FrameFeatures::PhotoCache {
  std::mutex mutex;
  // (model, class, checks) -> nearest photo per keypoint
  std::map<std::tuple<const void*, int, int>, std::vector<int>> nearest;
  // recognise()'s verification of its answer per window, reused by match() with the same
  // window, class and verification settings (recognise + match per frame: one search, not two).
  struct Verified;
  std::vector<Verified> verified;
  // (model, neighbours, checks) -> the whole database's nearest descriptors of every keypoint
  // (global rows and squared distances, LandmarkModel::knnAll), for the distinctiveness check.
  struct Neighbours {
    cv::Mat indices, dists;
  };
  std::map<std::tuple<const void*, int, int>, Neighbours> neighbours;
};
FrameFeatures computeFrameFeatures(const LandmarkModel& model, const cv::Mat& bgr);
/// Same with explicit feature settings for the frame (e.g. a camera frame kept at full
/// resolution with more keypoints, where a small landmark would vanish at the model's
/// photo-sized settings). Descriptors stay comparable: SIFT is scale invariant and the
/// descriptor kind (RootSIFT or SIFT) is forced to the model's.
FrameFeatures computeFrameFeatures(const LandmarkModel& model, const cv::Mat& bgr,
                                   FeatureParams frame_params);

struct MatchResult {
  bool matched = false;
  int inliers = 0;
  float confidence = 0;  // in [0, 1): 1 − exp(−(inliers − min_inliers + 1) / 15) when matched
  std::vector<cv::Point2f> x_t;  // inlier keypoints in the frame [px]
  std::vector<cv::Point2f> x_d;  // the same correspondences in the database photo [px]
  cv::Mat H;                     // 3x3 CV_64F homography database photo -> frame (if matched)
  cv::Size database_size;
  std::string database_image;  // path of the photo relative to the landmark set
  int database_photo = -1;     // index into LandmarkModel::photos()
  cv::Rect window;             // the frame window searched
  int photos_tried = 0;
  int wrong_colour = 0;  // correspondences consistent with H but of another colour (not inliers)
  int distinct_inliers =
      -1;  // inliers that are distinct (MatchParams distinct_*); -1 = not checked
};

struct FrameFeatures::PhotoCache::Verified {
  const void* model;
  int class_id;
  cv::Rect window;
  MatchParams params;
  MatchResult result;
};

/// Matches the window's keypoints against the target class's database photos (the most
/// promising max_photos, see photo_order_checks): ratio test, colour check, then RANSAC
/// homography; the photo with the most inliers wins. An empty window means the whole frame.
/// When recognise() on the same FrameFeatures verified this class in this window with the same
/// ratio / min_inliers / RANSAC / colour settings, its verification is returned (no search).
/// Unknown class -> InputError.
MatchResult match(const LandmarkModel& model, const FrameFeatures& frame, const cv::Rect& window,
                  const std::string& target_class, const MatchParams& params);
/// Convenience: computes the frame's features first.
MatchResult match(const LandmarkModel& model, const cv::Mat& frame_bgr, const cv::Rect& window,
                  const std::string& target_class, const MatchParams& params);
/// Verifies the window against one database photo (used by recognise() too).
MatchResult matchPhoto(const LandmarkModel& model, const FrameFeatures& frame,
                       const std::vector<int>& window_keypoints, int photo,
                       const MatchParams& params);

/// What the servo needs from a match, in frame pixels.
struct ServoOffset {
  bool valid = false;
  float object_u = 0;         // [px] frame column of the matched object's centre: the centre of the
                              // inliers' extent in the database photo through H
  float offset_px = 0;        // [px] object_u − frame_width / 2 (> 0: object right of centre)
  float paper_offset_px = 0;  // [px] median over inliers of (x_t − frame_cx) − s (x_d − db_cx),
                              //      s = frame/database scale from H: the paper's x_t − x_d
  // [px] the database photo's centre through H, unrounded (NaN without a usable H): the row an
  // elevation angle is read from (the same point of a photo in every match of it).
  double centre_u = NAN, centre_v = NAN;
};
/// Robust offsets from a match (the homography-projected centre of the matched part of the
/// database photo; falls back to the median inlier column when the homography is degenerate).
/// Invalid when not matched.
ServoOffset servoOffset(const MatchResult& m, int frame_width);

}  // namespace sketchnav::landmarks
