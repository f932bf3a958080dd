#include "sketchnav/nav/goal_checker.h"

#include <algorithm>

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

void SectionSettleChecker::restart(double now) {
  best_m_ = 1e300;
  best_t_ = now;
  recent_.clear();
}

double SectionSettleChecker::nearM(double length_m) const {
  return std::max(min_near_m_, near_frac_ * length_m);
}

bool SectionSettleChecker::update(double length_m, double to_end_m, double now, bool hold) {
  if (to_end_m < best_m_ - min_gain_m_) best_m_ = to_end_m, best_t_ = now;
  if (hold) best_m_ = std::min(best_m_, to_end_m), best_t_ = now;
  recent_.emplace_back(now, to_end_m);
  while (recent_.size() > 1 && recent_[1].first <= now - closing_s_) recent_.pop_front();
  // Once within min_near_m the end was reachable: the robot went away from it for a reason
  // (a landmark's servo holds the section open) and this section never settles.
  if (near_frac_ <= 0 || best_m_ <= min_near_m_) return false;
  const bool closing = recent_.front().second - to_end_m > min_gain_m_;
  return to_end_m > min_near_m_ && to_end_m <= nearM(length_m) && now - best_t_ > settle_s_ &&
         !closing;
}

}  // namespace sketchnav::nav
