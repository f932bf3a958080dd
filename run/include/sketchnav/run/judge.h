#pragma once
// Judging a run: the verdict of a simulated run against the simulator's ground truth, the
// failure code summary.json carries beside its reason, and how much of a goal error the drawing
// alone accounts for. Pure functions (no I/O), so they are tested without running anything.
#include <optional>
#include <string>

#include "sketchnav/mapsketch/route.h"
#include "sketchnav/nav/executive.h"

namespace sketchnav::sim {
struct World;
}

namespace sketchnav::run {

/// summary.json's "failure", the code beside its "reason": "" when the run succeeded,
/// "collision", "short_of_goal" (the executive arrived, ground truth puts the robot outside the
/// goal region), else the executive's nav::FailureCode ("lost", "timeout", "no_progress",
/// "safety_stop", "stopped").
std::string failureCode(bool success, bool collided, const nav::ExecutiveSummary& es);

/// The verdict of a simulated run (doc/navigation.md): success means the robot's centre is in
/// the goal region and nothing was hit (ground truth), whatever the executive concluded; the
/// executive's own verdict goes beside it (summary.json "executive_success"). The reason says
/// which applied: a collision, a route completed short of the goal, the goal reached (with the
/// executive's failure when it failed there), or the executive's reason.
struct RunVerdict {
  bool success = false;
  std::string reason;
};
/// `to_goal_m` [m]: from the robot's centre to the goal's centre at the end of the run.
RunVerdict judgeSimulatedRun(bool executive_succeeded, const std::string& executive_reason,
                             bool at_goal, bool collided, const std::string& collided_with,
                             double to_goal_m);

/// How far the sketch alone puts the goal [m]: where the navigation's refit of `route`, with
/// every sketched landmark fixed exactly where `w` has it (nav::goalFromExactFixes, outlier
/// gate `fit_outlier_m`), maps the drawn goal, from the goal's centre. None when fewer than two
/// sketched landmarks are in the world. Perfect perception and odometry cannot do better with
/// this refit.
std::optional<double> sketchGoalErrorM(const sim::World& w, const mapsketch::Route& route,
                                       double fit_outlier_m);

}  // namespace sketchnav::run
