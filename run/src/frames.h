#pragma once
// The simulated run's frames, private to the run library (used by the run and the judge).
#include <Eigen/Core>

#include <cmath>

#include "sketchnav/hw/types.h"

namespace sketchnav::run {

// Odometry frame <-> world frame in simulation: the odometry frame starts at the world's start
// pose (origin there, +x along its heading).
inline Eigen::Vector2d odomToWorld(const hw::Pose2D& start, const Eigen::Vector2d& o) {
  const double cs = std::cos(start.theta), ss = std::sin(start.theta);
  return {start.x + cs * o.x() - ss * o.y(), start.y + ss * o.x() + cs * o.y()};
}
inline Eigen::Vector2d worldToOdom(const hw::Pose2D& start, const Eigen::Vector2d& p) {
  const double cs = std::cos(start.theta), ss = std::sin(start.theta);
  const Eigen::Vector2d d(p.x() - start.x, p.y() - start.y);
  return {cs * d.x() + ss * d.y(), -ss * d.x() + cs * d.y()};
}

}  // namespace sketchnav::run
