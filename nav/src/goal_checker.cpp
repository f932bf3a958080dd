#include "sketchnav/nav/goal_checker.h"

namespace sketchnav::nav {

bool GoalChecker::reached(const SectionTracker& route, const hw::Pose2D& odom) const {
  if (route.finished()) return true;
  return route.current() + 1 == route.count() && route.progress(odom).to_end_m <= radius_m_;
}

bool GoalChecker::overrules(FailureCode code) {
  return code == FailureCode::Lost;
}

}  // namespace sketchnav::nav
