#include "sketchnav/run/judge.h"

#include <cstdio>
#include <map>

#include "sketchnav/nav/sections.h"
#include "sketchnav/sim/world.h"

#include "frames.h"

namespace sketchnav::run {

std::optional<double> sketchGoalErrorM(const sim::World& w, const mapsketch::Route& route,
                                       double fit_outlier_m) {
  // The landmarks' true places in the odometry frame (the robot starts at its origin, facing
  // +x), the refit of nav::goalFromExactFixes, and its goal back in the world. The scale bound
  // is loose: fit after fit, the navigation's scale may move that far too.
  std::map<std::string, Eigen::Vector2d> truth;
  for (const auto& l : w.landmarks) truth[l.id] = worldToOdom(w.start, l.position);
  nav::WeightedFitParams wp;
  wp.outlier_m = fit_outlier_m;
  wp.max_scale_change = 0.5;
  const auto g = nav::goalFromExactFixes(route, truth, wp);
  if (!g) return std::nullopt;
  return (odomToWorld(w.start, *g) - w.goal.centre).norm();
}

std::string failureCode(bool success, bool collided, const nav::ExecutiveSummary& es) {
  if (success) return "";
  if (collided) return "collision";
  if (es.status == nav::RunStatus::Succeeded) return "short_of_goal";
  const std::string code = nav::toString(es.failure);
  return code.empty() ? "unknown" : code;
}

RunVerdict judgeSimulatedRun(bool executive_ok, const std::string& executive_reason, bool at_goal,
                             bool collided, const std::string& collided_with, double to_goal_m) {
  RunVerdict v;
  v.success = at_goal && !collided;
  if (collided) {
    v.reason = "collision with " + collided_with +
               (executive_reason.empty() ? "" : "; " + executive_reason);
  } else if (!at_goal && executive_ok) {
    char b[160];
    std::snprintf(b, sizeof b, "route completed but the robot stopped %.2f m from the goal",
                  to_goal_m);
    v.reason = b;
  } else if (at_goal) {
    v.reason = executive_ok
                   ? "reached the goal"
                   : "reached the goal region, but the executive failed: " + executive_reason;
  } else {
    v.reason = executive_reason;
  }
  return v;
}

}  // namespace sketchnav::run
