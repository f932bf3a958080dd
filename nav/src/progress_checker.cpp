#include "sketchnav/nav/progress_checker.h"

#include <cmath>

namespace sketchnav::nav {

bool ProgressChecker::stuck(const hw::Pose2D& pose, double now) {
  const bool s = std::hypot(pose.x - from_.x, pose.y - from_.y) < min_move_m_;
  reset(pose, now);
  return s;
}

}  // namespace sketchnav::nav
