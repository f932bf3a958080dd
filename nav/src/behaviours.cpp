#include "sketchnav/nav/behaviours.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "sketchnav/core/angles.h"
#include "sketchnav/core/config.h"
#include "sketchnav/nav/avoidance.h"

namespace sketchnav::nav {

void DriveParams::validate() const {
  require(v_cruise > 0 && v_cruise <= 2, "nav.v_cruise", "must be in (0, 2] m/s");
  require(k_heading > 0, "nav.k_heading", "must be > 0");
  require(max_w > 0 && max_w <= 5, "nav.max_w", "must be in (0, 5] rad/s");
  require(turn_in_place_deg > 0 && turn_in_place_deg <= 180, "nav.turn_in_place_deg",
          "must be in (0, 180]");
}

void LookParams::validate() const {
  require(look_range_m >= 0, "nav.look_range_m", "must be >= 0");
  require(look_max_bearing_deg > 0 && look_max_bearing_deg <= 180, "nav.look_max_bearing_deg",
          "must be in (0, 180]");
  require(look_bearing_deg > 0 && look_bearing_deg <= 90, "nav.look_bearing_deg",
          "must be in (0, 90]");
}

void SideLookParams::validate() const {
  require(side_look_s >= 0, "nav.side_look_s", "must be >= 0 (0 = off)");
  require(side_look_range_m > 0, "nav.side_look_range_m", "must be > 0");
  require(side_look_min_range_m >= 0 && side_look_min_range_m < side_look_range_m,
          "nav.side_look_min_range_m", "must be in [0, nav.side_look_range_m)");
  require(side_look_margin_deg >= 0 && side_look_margin_deg < 90, "nav.side_look_margin_deg",
          "must be in [0, 90)");
  require(side_look_max_bearing_deg > 0 && side_look_max_bearing_deg <= 180,
          "nav.side_look_max_bearing_deg", "must be in (0, 180]");
  require(side_look_max_looks >= 1, "nav.side_look_max_looks", "must be >= 1");
  require(side_look_rebearing_deg > 0 && side_look_rebearing_deg <= 180,
          "nav.side_look_rebearing_deg", "must be in (0, 180]");
  require(side_look_walker_m >= 0, "nav.side_look_walker_m", "must be >= 0 m (0 = off)");
}

void DockParams::validate() const {
  require(dock_m >= 0, "nav.dock_m", "must be >= 0");
}

std::optional<Docking::Proposal> Docking::propose(
    const Polar& goal, double free_m, const std::function<std::optional<WayRound>()>& plan,
    const DriveParams& drive) const {
  double bearing = goal.bearing, left = goal.range;
  if (free_m < goal.range) {
    const auto way = plan ? plan() : std::nullopt;
    // Only a short way round: a long one means the estimate sits behind a wall.
    if (!way || way->length_m > p_.dock_m + 1.5) return std::nullopt;
    bearing = way->bearing;
    left = way->left_m;
  }
  Proposal out;
  out.bearing = bearing;
  // Slow in the last 0.6 m.
  out.command = headFor(bearing, std::clamp(left / 0.6, 0.3, 1.0), drive);
  out.command.turn = turnOf(bearing);
  return out;
}

void FinalLookParams::validate() const {
  require(final_look_range_m >= 0, "nav.final_look_range_m", "must be >= 0 (0 = off)");
  require(final_look_s > 0, "nav.final_look_s", "must be > 0");
}

void RecoverParams::validate() const {
  require(stuck_s > 0, "nav.stuck_s", "must be > 0");
  require(stuck_m >= 0, "nav.stuck_m", "must be >= 0");
  require(recover_m > 0, "nav.recover_m", "must be > 0");
  require(recover_s > 0, "nav.recover_s", "must be > 0");
  require(recover_back_m >= 0 && recover_back_m <= 3, "nav.recover_back_m",
          "must be in [0, 3] m (0 = never back out; the trail keeps 3 m)");
  require(recover_back_speed > 0 && recover_back_speed <= 0.5, "nav.recover_back_speed",
          "must be in (0, 0.5] m/s");
}

servo::Turn turnOf(double x) {
  return std::abs(x) < 0.05 ? servo::Turn::Straight
                            : (x > 0 ? servo::Turn::Left : servo::Turn::Right);
}

Command headFor(double bearing, double scale, const DriveParams& p) {
  Command c;
  c.w = std::clamp(p.k_heading * bearing, -p.max_w, p.max_w);
  c.v = std::abs(bearing) > p.turn_in_place_deg * M_PI / 180
            ? 0.0
            : p.v_cruise * std::max(0.2, std::cos(bearing)) * scale;
  return c;
}

FollowBehaviour::Proposal FollowBehaviour::propose(double lookahead_bearing,
                                                   const Polar* unseen) const {
  Proposal out;
  out.target_bearing = lookahead_bearing;
  bool looking = false;
  // Not seen yet and near: keep it in view (LookParams).
  if (unseen && unseen->range <= look_.look_range_m && unseen->range > approach_m_ &&
      std::abs(unseen->bearing) <= look_.look_max_bearing_deg * M_PI / 180) {
    const double m = look_.look_bearing_deg * M_PI / 180;
    out.target_bearing = std::clamp(out.target_bearing, unseen->bearing - m, unseen->bearing + m);
    looking = out.target_bearing != lookahead_bearing;
  }
  out.command = headFor(out.target_bearing, 1.0, drive_);
  out.command.turn = turnOf(out.target_bearing);
  out.behaviour = looking ? Behaviour::Look : Behaviour::Follow;
  return out;
}

SideLook::Outcome SideLook::update(const LandmarkTracker& landmarks, const AttendedLandmark* a,
                                   double now, bool can_look, bool busy, bool final_looking,
                                   bool give_way, double heading) {
  Outcome out;
  const double max_b = p_.side_look_max_bearing_deg * M_PI / 180;
  if (active_) {
    const bool same = a && a->k == k_ && a->i == i_;
    const bool seen = landmarks.track(k_, i_).frames_seen > 0;
    if (seen || !same || final_looking || now - t0_ > p_.side_look_s ||
        std::abs(a->pred.bearing) > max_b) {
      active_ = false;
      out.ended = event::SideLookEnd{landmarks.landmark(k_, i_).id, seen, now - t0_};
    }
  } else if (a && can_look && p_.side_look_s > 0 && !busy && !final_looking) {
    const auto& t = landmarks.track(a->k, a->i);
    const double b = std::abs(a->pred.bearing);
    const double sight = heading + a->pred.bearing;
    const auto it = looked_.find({a->k, a->i});
    const bool may = it == looked_.end() || (it->second.looks < p_.side_look_max_looks &&
                                             std::abs(wrapAngle(sight - it->second.sight)) >=
                                                 p_.side_look_rebearing_deg * M_PI / 180);
    if (may && t.state == LandmarkState::Pending && t.frames_seen == 0 &&
        b > half_fov_ - p_.side_look_margin_deg * M_PI / 180 && b <= max_b &&
        a->pred.range <= p_.side_look_range_m && a->pred.range >= p_.side_look_min_range_m) {
      active_ = true;
      k_ = a->k;
      i_ = a->i;
      t0_ = now;
      auto& l = looked_[{a->k, a->i}];
      ++l.looks;
      l.sight = sight;
      out.started = event::SideLookStart{landmarks.landmark(a->k, a->i).id, a->k,
                                         a->pred.bearing * 180 / M_PI, a->pred.range};
    }
  }
  if (active_ && !give_way) {
    const double w = std::clamp(k_heading_ * a->pred.bearing, -max_w_, max_w_);
    out.command = Command{0.0, w, turnOf(w)};
  }
  return out;
}

FinalLook::Outcome FinalLook::step(LandmarkTracker& landmarks, const SectionTracker& route,
                                   const hw::Pose2D& pose, double now) {
  Outcome out;
  if (done_ || route.finished() || p_.final_look_range_m <= 0) return out;
  if (k_ < 0) {
    // Any section's: a landmark a few metres before the goal was often missed on the way (out
    // of recognition range, or out of view) and is within range from the goal.
    double at = 0;
    const auto c = landmarks.finalLookCandidate(route, pose, p_.final_look_range_m, at);
    if (!c) {
      done_ = true;
      return out;
    }
    k_ = c->first;
    i_ = c->second;
    t0_ = now;
    was_missed_ = landmarks.track(k_, i_).state == LandmarkState::Missed;
    landmarks.track(k_, i_).state = LandmarkState::Pending;  // a missed one is looked for again
    out.started = event::FinalLookStart{landmarks.landmark(k_, i_).id, at};
  }
  const auto& t = landmarks.track(k_, i_);
  const bool seen = t.frames_seen > 0;
  // Seen: a few frames for its bearings to cross (the fix), then passed.
  const bool enough = t.frames_seen >= 3 || t.state == LandmarkState::Passed;
  if (enough || now - t0_ > p_.final_look_s) {
    done_ = true;
    out.ended = event::FinalLookEnd{landmarks.landmark(k_, i_).id, seen};
    if (t.state == LandmarkState::Tracking || (t.state == LandmarkState::Pending && seen)) {
      out.verdict = Verdict::Pass;
    } else if (t.state == LandmarkState::Pending && was_missed_) {
      landmarks.track(k_, i_).state = LandmarkState::Missed;  // as it was (counted then)
      out.verdict = Verdict::Kept;
    } else if (t.state == LandmarkState::Pending) {
      out.verdict = Verdict::Miss;
    }
    return out;
  }
  out.looking = true;
  return out;
}

Command FinalLook::command(double bearing) const {
  const double w = std::abs(bearing) < 0.1 ? 0.0 : k_heading_ * bearing;
  return {0.0, w, turnOf(w)};
}

std::optional<double> Recovery::openDirection(
    const std::vector<std::pair<double, double>>& pts, double half_width_m, double max_range_m,
    double route_bearing, const std::function<bool(double, double)>& known_free) const {
  double best = -1e9, best_a = 0;
  std::vector<std::pair<double, double>> ahead;
  ahead.reserve(pts.size());
  for (int i = 0; i < 36; ++i) {
    const double a = wrapAngle(i * M_PI / 18);
    // Only what lies ahead of the robot's centre along `a` is in the way: driving off, the
    // robot only gets further from the rest. (corridorFree also counts a point within the
    // corridor's half-width behind the centre, which freezes every direction once someone
    // stands within the margin: a person who walked up to a robot's side boxed it in.)
    ahead.clear();
    const double c = std::cos(a), sn = std::sin(a);
    for (const auto& p : pts)
      if (c * p.first + sn * p.second > 0) ahead.push_back(p);
    const double free = corridorFree(ahead, a, half_width_m, max_range_m);
    const double score =
        std::min(free, p_.recover_m + 0.5) - 0.3 * std::abs(wrapAngle(a - route_bearing));
    if (free >= 0.5 && score > best && (!known_free || known_free(a, 0.5)))
      best = score, best_a = a;
  }
  if (best > -1e9) return best_a;
  return std::nullopt;
}

event::RecoverStart Recovery::start(double direction, const hw::Pose2D& pose, double now,
                                    bool look) {
  active_ = true;
  look_ = look;
  back_ = false;
  ++count_;
  dir_ = wrapAngle(pose.theta + direction);
  t0_ = now;
  from_ = pose;
  return event::RecoverStart{direction * 180 / M_PI, look};
}

event::RecoverStart Recovery::startBack(const Eigen::Vector2d& to, const hw::Pose2D& pose,
                                        double now) {
  active_ = true;
  look_ = false;
  back_ = true;
  ++count_;
  to_ = to;
  t0_ = now;
  const double bearing = std::atan2(to.y() - pose.y, to.x() - pose.x) - pose.theta;
  event::RecoverStart e{wrapAngle(bearing) * 180 / M_PI, false};
  e.back = true;
  return e;
}

Recovery::Step Recovery::step(const hw::Pose2D& pose, double now, double v_capped) {
  Step out;
  if (back_) {
    // Reversing: the heading that points away from `to_` (recomputed, so the robot stays on
    // the line as odometry drifts), turning on the spot first when it is far off.
    const Eigen::Vector2d d = to_ - Eigen::Vector2d(pose.x, pose.y);
    const double away = wrapAngle(std::atan2(d.y(), d.x()) + M_PI - pose.theta);
    const double w = std::clamp(k_heading_ * away, -max_w_, max_w_);
    const double v = std::abs(away) > 0.35 ? 0.0 : -p_.recover_back_speed;
    out.command = {v, w, turnOf(w)};
    // Over once there, out of time, or when the point is no longer behind (passed it).
    const double behind = -(std::cos(pose.theta) * d.x() + std::sin(pose.theta) * d.y());
    if (d.norm() <= 0.05 || behind <= 0 || now - t0_ > p_.recover_s) {
      active_ = false;
      out.ended = true;
    }
    return out;
  }
  const double a = wrapAngle(dir_ - pose.theta);
  const double w = std::clamp(k_heading_ * a, -max_w_, max_w_);
  const double v = std::abs(a) > 0.35 || look_ ? 0.0 : v_capped;
  out.command = {v, w, turnOf(w)};
  // Looking: over once the direction is ahead, where the laser sees its floor.
  const bool blocked = std::abs(a) <= 0.35 && (v <= 0 || look_);
  if (std::hypot(pose.x - from_.x, pose.y - from_.y) >= p_.recover_m || now - t0_ > p_.recover_s ||
      blocked) {
    active_ = false;
    out.ended = true;
  }
  return out;
}

void Trail::add(const Eigen::Vector2d& p) {
  if (!pts_.empty() && (p - pts_.back()).norm() < spacing_m_) return;
  pts_.push_back(p);
  // Keep the newest keep_m of path.
  double len = 0;
  size_t first = pts_.size() - 1;
  while (first > 0 && len + (pts_[first] - pts_[first - 1]).norm() <= keep_m_) {
    len += (pts_[first] - pts_[first - 1]).norm();
    --first;
  }
  if (first > 0) pts_.erase(pts_.begin(), pts_.begin() + static_cast<long>(first));
}

void Trail::backTo(const Eigen::Vector2d& p) {
  if (pts_.empty()) return;
  size_t best = 0;
  for (size_t i = 1; i < pts_.size(); ++i)
    if ((pts_[i] - p).norm() < (pts_[best] - p).norm()) best = i;
  pts_.resize(best + 1);
}

std::optional<Eigen::Vector2d> Trail::backOut(const Eigen::Vector2d& from, double len_m,
                                              double tolerance_m) const {
  if (pts_.empty() || len_m <= 0) return std::nullopt;
  // Walk back from the robot until len_m of path lies behind.
  double len = 0;
  Eigen::Vector2d prev = from;
  int k = static_cast<int>(pts_.size()) - 1;
  for (; k >= 0; --k) {
    len += (pts_[k] - prev).norm();
    prev = pts_[k];
    if (len >= len_m) break;
  }
  if (k < 0) return std::nullopt;  // a shorter trail
  const Eigen::Vector2d to = pts_[k];
  const Eigen::Vector2d u = to - from;
  const double n = u.norm();
  if (n < 0.5 * len_m) return std::nullopt;  // the path doubles back on itself
  for (int i = static_cast<int>(pts_.size()) - 1; i >= k; --i) {
    const Eigen::Vector2d q = pts_[i] - from;
    const double along = std::clamp(q.dot(u) / (n * n), 0.0, 1.0);
    if ((q - along * u).norm() > tolerance_m) return std::nullopt;  // it bends away
  }
  return to;
}

void DetourParams::validate() const {
  require(detour_ahead_m > 0.5 && detour_ahead_m <= 10, "nav.detour_ahead_m",
          "must be in (0.5, 10] m");
  require(replan_s > 0, "nav.replan_s", "must be > 0");
}

double Detour::planTowards(const LocalPlanner& planner, const hw::Pose2D& pose,
                           const Eigen::Vector2d& goal, double now) {
  if (now - planned_t_ >= p_.replan_s - 1e-9 || (goal - planned_to_).norm() > 0.3) {
    path_ = planner.plan({pose.x, pose.y}, goal);
    planned_t_ = now;
    planned_to_ = goal;
  }
  if (!path_.found) return std::numeric_limits<double>::quiet_NaN();
  const Eigen::Vector2d c =
      LocalPlanner::carrot(path_, {pose.x, pose.y}, planner.params().carrot_m);
  return polarFrom(pose, c).bearing;
}

std::optional<event::DetourEnd> Detour::end(const char* reason) {
  if (!active_) return std::nullopt;
  active_ = false;
  return event::DetourEnd{reason};
}

Command Detour::follow(double bearing, const std::function<double(double)>& cap) const {
  Command c = headFor(bearing, 1.0, drive_);
  c.v = cap(c.v);
  c.turn = turnOf(c.w);
  return c;
}

Detour::Outcome Detour::whileDodging(const AvoidOutput& av, const LocalPlanner& planner,
                                     const hw::Pose2D& pose, const Eigen::Vector2d& route_point,
                                     double now, int section,
                                     const std::function<double(double)>& cap) {
  Outcome out;
  // Once something has come towards the robot in this manoeuvre it stays reactive: the
  // approach estimate drops while the robot backs off and turns.
  if (av.started) moving_seen_ = false;
  moving_seen_ |= av.approach_speed >= 0.25 || av.in_lane;
  double b = std::numeric_limits<double>::quiet_NaN();
  if (p_.detour && !moving_seen_) b = planTowards(planner, pose, route_point, now);
  if (std::isfinite(b)) {
    if (!active_) {
      active_ = true;
      ++count_;
      out.started = event::DetourStart{path_.length_m, path_.goal, path_.goal_moved, section};
    }
    out.command = follow(b, cap);
  } else {
    out.ended = end(moving_seen_ ? "coming towards the robot" : "no way found");
  }
  return out;
}

Detour::Outcome Detour::afterDodge(const LocalPlanner& planner, const hw::Pose2D& pose,
                                   const Eigen::Vector2d& route_point, double now, bool servoing,
                                   double half_width_m, const std::function<double(double)>& cap) {
  Outcome out;
  if (p_.detour_hold && active_ && !servoing) {
    // Round a box or through a door, heading back to the route before the robot is past it
    // drives into the same obstacle again.
    const double b = planTowards(planner, pose, route_point, now);
    if (planner.segmentClear({pose.x, pose.y}, route_point, half_width_m)) {
      out.ended = end("route clear");
    } else if (!std::isfinite(b)) {
      out.ended = end("no way found");
    } else {
      out.command = follow(b, cap);
    }
  } else if (servoing) {
    out.ended = end("servoing");
  }
  return out;
}

YieldBehaviour::Outcome YieldBehaviour::update(const YieldAdvice& adv, const Command& cur,
                                               const hw::Pose2D& pose,
                                               const std::function<double(double)>& cap,
                                               const std::function<double()>& rear_free_m) {
  Outcome out;
  if (!adv.active) {
    if (active_) {
      active_ = false;
      out.ended = event::YieldEnd{};
    }
    return out;
  }
  Command c = cur;
  if (!adv.in_lane) {
    c.v = 0;  // about to enter a lane: wait, turning is harmless
  } else if (adv.v >= 0) {
    c.v = cap(adv.v);
    c.w = adv.w;
  } else {
    c.v = rear_free_m() > kRearRoomM ? -reverse_speed_ : 0.0;
    c.w = adv.w;
  }
  c.turn = turnOf(c.w);
  out.command = c;
  if (!active_) {
    active_ = true;
    ++count_;
    out.started = event::YieldStart{adv.in_lane, adv.clearance_m, adv.mover.position,
                                    adv.mover.velocity, pose};
  }
  return out;
}

}  // namespace sketchnav::nav
