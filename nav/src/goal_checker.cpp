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

namespace sketchnav::nav {

bool SettleChecker::update(bool last_section, double to_end_m, double now, bool restart) {
  if (!(last_section && to_end_m <= near_m_)) {
    best_m_ = 1e300;
    best_t_ = now;
    return false;
  }
  if (to_end_m < best_m_ - min_gain_m_) best_m_ = to_end_m, best_t_ = now;
  if (restart) best_m_ = to_end_m, best_t_ = now;
  return now - best_t_ > settle_s_;
}

}  // namespace sketchnav::nav
