#pragma once
// The route: what the robot follows. Produced by toRoute(sketch) (pure function).
//
// Route frame: the sketch canvas scaled to metres, origin at the sketch's start point,
// x to the right on the canvas, y UP on the canvas (canvas y is flipped), so angles are CCW
// like REP 103. The navigation executive aligns this frame with odometry by assuming the
// robot starts at `start_m` facing `start_heading_rad` (along the first section).
#include <Eigen/Core>

#include <string>
#include <vector>

#include "sketchnav/mapsketch/sketch.h"

namespace sketchnav::mapsketch {

enum class Side { Left, Right, Ahead };

/// A landmark the robot should pass while on a section.
struct ExpectedLandmark {
  std::string id;          // sketch landmark id
  std::string class_name;  // class of the landmark set
  int order = 0;           // sequence order along the whole route (0-based)
  Side side = Side::Ahead; // relative to the direction of travel on the section
  double range_m = 0;      // approximate lateral distance from the section [m]
  double along_m = 0;      // approximate distance from the section's start where it is passed [m]
  Eigen::Vector2d position_m{0, 0};  // approximate position in the route frame [m]
};

/// The part of the path between two consecutive guide points.
struct PathSection {
  int index = 0;
  Eigen::Vector2d start_m{0, 0}, end_m{0, 0};  // guide points in the route frame [m]
  double length_m = 0;                         // approximate length [m]
  double heading_rad = 0;                      // direction of travel in the route frame
  double heading_change_rad = 0;               // turn at the section's start (CCW +)
  std::vector<ExpectedLandmark> landmarks;     // in the order they are passed
};

struct Route {
  std::vector<PathSection> sections;
  std::vector<Eigen::Vector2d> guide_points_m;  // sections.size() + 1 points
  Eigen::Vector2d start_m{0, 0}, goal_m{0, 0};
  double start_heading_rad = 0;
  double scale_m_per_px = 0;   // estimated from the user's distances (least squares)
  double scale_residual = 0;   // relative RMS residual of that fit (0 = consistent distances)
  double total_length_m = 0;
};

}  // namespace sketchnav::mapsketch
