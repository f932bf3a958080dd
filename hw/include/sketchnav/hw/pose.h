#pragma once
// 2-D pose algebra on hw::Pose2D (x, y [m], theta [rad] CCW), with the one angle wrap of
// core/angles.h: the simulator's odometry and ground truth, and the commands that convert
// between the odometry and world frames.
#include <cmath>

#include "sketchnav/core/angles.h"
#include "sketchnav/hw/types.h"

namespace sketchnav::hw {

/// a ⊕ b: the pose b, given in the frame of a, expressed in a's parent frame.
inline Pose2D composePose(const Pose2D& a, const Pose2D& b) {
  const double c = std::cos(a.theta), s = std::sin(a.theta);
  return {a.x + c * b.x - s * b.y, a.y + s * b.x + c * b.y, wrapAngle(a.theta + b.theta)};
}

/// ⊖a: the inverse, so composePose(inversePose(a), a) is the identity.
inline Pose2D inversePose(const Pose2D& a) {
  const double c = std::cos(a.theta), s = std::sin(a.theta);
  return {-c * a.x - s * a.y, s * a.x - c * a.y, wrapAngle(-a.theta)};
}

}  // namespace sketchnav::hw
