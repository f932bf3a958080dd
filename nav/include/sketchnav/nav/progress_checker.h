#pragma once
// Whether the robot is still making progress (the role of Nav2's nav2_core::ProgressChecker):
// the executive's stuck test, which starts a recovery (RecoverParams::stuck_s, stuck_m;
// Recovery in behaviours.h).
#include "sketchnav/hw/types.h"

namespace sketchnav::nav {

/// Judged over consecutive windows of window_s [s]: stuck when the robot moved less than
/// min_move_m [m] (straight-line, odometry frame) between a window's start and its end.
class ProgressChecker {
 public:
  ProgressChecker(double window_s, double min_move_m)
      : window_s_(window_s), min_move_m_(min_move_m) {}

  /// Starts a window at `pose`, time `now` [s] (the run's start; the end of a recovery).
  void reset(const hw::Pose2D& pose, double now) {
    from_ = pose;
    t_ = now;
  }
  /// Makes the current window over at `now`, started at `pose`: the next stuck test is due at
  /// once (after a recovery that only turned to look, the way out is chosen right away).
  void expire(const hw::Pose2D& pose, double now) {
    from_ = pose;
    t_ = now - window_s_;
  }
  /// Whether the current window is over at `now`.
  bool due(double now) const { return now - t_ >= window_s_; }
  /// Ends the current window at `pose`, `now` (call when due()): whether the robot moved less
  /// than min_move_m over it. The next window starts here.
  bool stuck(const hw::Pose2D& pose, double now);

 private:
  double window_s_, min_move_m_;
  hw::Pose2D from_;
  double t_ = 0;
};

}  // namespace sketchnav::nav
