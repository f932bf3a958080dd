#pragma once
// Detect, then track: a verified landmark match (database photo -> frame homography and its
// inlier keypoints) followed from frame to frame with pyramidal Lucas-Kanade optical flow
// (cv::calcOpticalFlowPyrLK), a forward-backward check per point and a RANSAC homography of
// the surviving points. Between two full detections the landmark's position then costs a few
// milliseconds instead of a full perception pass, and a landmark the detector misses in one
// frame (blur, a view the photos do not show closely) keeps its position while its points
// still track. doc/landmark-model.md "Tracking between detections".
#include <opencv2/core.hpp>

#include <string>
#include <vector>

#include "sketchnav/landmarks/matcher.h"

namespace sketchnav::nav {

struct TrackParams {
  // Track detections between full perception passes at all (LandmarkPerception: a looked-for
  // class being tracked is served by the tracker; the full pass runs every redetect_frames).
  bool enabled = true;
  int redetect_frames = 3;  // a full pass at least every this many observe() calls, >= 1
  // A track not confirmed by a full detection in this many observe() calls is dropped (bounds
  // how long a track can follow something the detector does not recognise), >= redetect_frames.
  int max_unconfirmed_frames = 9;
  int min_points = 8;             // fewer points tracked, or fewer homography inliers: lost, >= 4
  double min_inlier_share = 0.6;  // homography inliers / points tracked below this: lost, (0, 1]
  double fb_max_px = 1.0;         // [px] forward-backward error above this: the point is dropped
  double ransac_px = 3.0;         // [px] reprojection threshold of the frame-to-frame homography
  int window_px = 21;             // Lucas-Kanade window side, odd, >= 5
  int pyramid_levels = 3;         // pyramid levels above the frame (each halves it), in [0, 6]
  // The tracked quadrilateral's area may change at most by this factor per call (approaching
  // at speed changes it a little; a flow that collapses or explodes the quad is a failure).
  double max_area_change = 1.6;
  template <class B>
  void bind(B& b) {
    b("enabled", enabled);
    b("redetect_frames", redetect_frames);
    b("max_unconfirmed_frames", max_unconfirmed_frames);
    b("min_points", min_points);
    b("min_inlier_share", min_inlier_share);
    b("fb_max_px", fb_max_px);
    b("ransac_px", ransac_px);
    b("window_px", window_px);
    b("pyramid_levels", pyramid_levels);
    b("max_area_change", max_area_change);
  }
  void validate() const;  // InputError "nav.perception.track.<field> = ...: ..."
};

/// One landmark followed from frame to frame. Thread-compatible.
class KltTrack {
 public:
  explicit KltTrack(TrackParams p = {});
  /// Starts (or restarts) from a verified match `m` in `grey`'s pixels (inliers x_t / x_d and
  /// H); false when it has fewer than min_points inliers or no homography.
  bool start(const cv::Mat& grey, const landmarks::MatchResult& m);
  /// Follows the points into `grey` (the next frame, same size); on success `out` is the match
  /// moved to this frame (inliers = points that still agree with the homography) and the
  /// track continues from it. False: lost (the track is inactive afterwards).
  bool step(const cv::Mat& grey, landmarks::MatchResult& out);
  bool active() const { return active_; }
  void reset() { active_ = false; }
  /// step() calls since start().
  int age() const { return age_; }

 private:
  TrackParams p_;
  bool active_ = false;
  int age_ = 0;
  cv::Mat prev_;
  std::vector<cv::Point2f> pts_;  // in the previous frame
  std::vector<cv::Point2f> db_;   // the same points in the database photo
  landmarks::MatchResult match_;  // the current match (H, photo, size)
};

}  // namespace sketchnav::nav
