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

/// Near the goal but no longer getting closer (the estimate sits where the robot cannot stand,
/// e.g. against a door frame): arrived as close as it can get. Settled when, within near_m
/// [m] of the goal on the last section, the distance has not dropped by min_gain_m [m] below
/// the closest so far for settle_s [s] (ExecutiveParams::goal_settle_m, goal_settle_s).
class SettleChecker {
 public:
  SettleChecker(double near_m, double settle_s, double min_gain_m = 0.05)
      : near_m_(near_m), settle_s_(settle_s), min_gain_m_(min_gain_m) {}
  /// One tick at `now` [s]: whether the robot is on the last section, its distance to the
  /// goal [m], and `restart` (closeness is not being judged now: the final look turns on the
  /// spot by design, and the landmark it finds moves the goal; the clock starts again).
  /// Returns whether it has settled.
  bool update(bool last_section, double to_end_m, double now, bool restart);

 private:
  double near_m_, settle_s_, min_gain_m_;
  double best_m_ = 1e300, best_t_ = 0;  // closest to the goal so far, and when
};

}  // namespace sketchnav::nav
