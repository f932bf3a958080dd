#pragma once
// Doorways in a laser scan: an opening in a straight wall, seen as two wall ends (the jambs)
// with the beams between them reading far beyond the wall (another room, a corridor) or
// nothing at all (outdoors, out of range).
//
// Why: a hand-drawn goal is only as good as the refit of the sketch to the landmarks passed,
// and with few landmarks the goal is extrapolated metres past the last one (exp3-4: one sketch
// in twelve puts the goal > 0.5 m off with every landmark fixed exactly). People give goals as
// places ("stop at the door of room B"), and a doorway is a place the laser recognises by
// itself. The executive looks for the sketch's goal doorway near its goal estimate
// (Executive, GoalDoorParams) and stops `standoff_m` in front of it.
#include <Eigen/Core>

#include <vector>

#include "sketchnav/hw/types.h"

namespace sketchnav::nav {

struct DoorwayParams {
  double min_width_m = 0.6;  // [m] jamb to jamb; narrower is a gap between furniture legs
  double max_width_m = 1.6;  // [m] wider is a passage or a walkway, not a door
  double depth_m = 1.0;      // [m] every beam through the opening reads at least this far past
                             // the jambs' line (or nothing): an occluding edge in front of a
                             // wall a few decimetres behind is not a door
  double wall_m = 0.25;      // [m] the wall runs on at least this far beyond each jamb...
  double wall_tol_m = 0.06;  // [m] ...its points within this of the jambs' line
  double max_range_m = 6.0;  // [m] jambs further than this are not used (beam spacing)
  template <class B>
  void bind(B& b) {
    b("min_width_m", min_width_m);
    b("max_width_m", max_width_m);
    b("depth_m", depth_m);
    b("wall_m", wall_m);
    b("wall_tol_m", wall_tol_m);
    b("max_range_m", max_range_m);
  }
  void validate(const char* prefix = "nav.goal_door") const;  // InputError naming the field
};

/// The executive's search for a doorway goal (mapsketch::GoalPlace::Kind::Doorway):
/// "nav.goal_door.*". Near the goal estimate, every laser scan's doorways are candidates; a
/// doorway's stopping point (its centre, standoff_m towards the robot's side) within search_m
/// of where the sketch puts the goal is one sighting, and once min_scans sightings agree within
/// agree_m their mean is the goal, whatever later refits of the sketch say.
struct GoalDoorParams : DoorwayParams {
  bool enabled = true;    // false: a doorway goal is a drawn point like any other
  double look_m = 4.0;    // [m] look while the sketch's goal is this close to the robot
  double search_m = 1.5;  // [m] how far off the sketch's goal a doorway's stopping point may be
  int min_scans = 3;      // sightings that must agree before the goal moves
  double agree_m = 0.2;   // [m]
  template <class B>
  void bind(B& b) {
    DoorwayParams::bind(b);
    b("enabled", enabled);
    b("look_m", look_m);
    b("search_m", search_m);
    b("min_scans", min_scans);
    b("agree_m", agree_m);
  }
  void validate() const;  // InputError "nav.goal_door.<field> = ...: ..."
};

/// One doorway, in the frame of the pose given to findDoorways() (the odometry frame).
struct Doorway {
  Eigen::Vector2d a{0, 0}, b{0, 0};  // [m] the two jambs (the last wall points either side)
  Eigen::Vector2d centre{0, 0};      // [m] midway between them
  Eigen::Vector2d normal{1, 0};      // unit, across the opening, pointing to the sensor's side
  double width_m = 0;                // [m] |a - b|
};

/// Doorways in one laser scan taken at `pose` (the robot's pose; the scan's mount is applied).
/// A sonar scan, or a scan with fewer than three beams, has none. Pure function.
std::vector<Doorway> findDoorways(const hw::RangeScan& scan, const hw::Pose2D& pose,
                                  const DoorwayParams& p = {});

}  // namespace sketchnav::nav
