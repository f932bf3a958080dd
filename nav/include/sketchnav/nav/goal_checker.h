#pragma once
// Whether the robot has reached its goal by its own estimate (the role of Nav2's
// nav2_core::GoalChecker), consulted before the failure rules that judge the way there: a run
// that stands at its goal is not failed for how it got there.
#include "sketchnav/hw/types.h"
#include "sketchnav/nav/events.h"
#include "sketchnav/nav/sections.h"

namespace sketchnav::nav {

class GoalChecker {
 public:
  /// `radius_m` [m]: how close to the route's end counts as there (SectionParams::goal_radius_m).
  explicit GoalChecker(double radius_m) : radius_m_(radius_m) {}

  /// The route is finished, or `odom` is on its last section within radius_m of the end (the
  /// end as the tracker has it now: refitted, or moved to a goal doorway).
  bool reached(const SectionTracker& route, const hw::Pose2D& odom) const;

  /// Whether reaching the goal overrules a failure rule with this code: Lost ("N landmarks in a
  /// row not found", e.g. the final look's landmark not found at the goal) does; a safety stop,
  /// the run's timeout, a stop by the user and NoProgress (a robot at the goal that no longer
  /// gets closer ends by goal_settled first) do not.
  static bool overrules(FailureCode code);

 private:
  double radius_m_;
};

}  // namespace sketchnav::nav
