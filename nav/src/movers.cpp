#include "sketchnav/nav/movers.h"

#include <algorithm>
#include <bitset>
#include <cmath>

#include "sketchnav/core/config.h"
#include "sketchnav/nav/local_planner.h"

namespace sketchnav::nav {

void MoverParams::validate() const {
  require(cluster_gap_m > 0, "nav.movers.cluster_gap_m", "must be > 0");
  require(max_width_m > 0, "nav.movers.max_width_m", "must be > 0");
  require(gate_m > 0, "nav.movers.gate_m", "must be > 0");
  require(follow_gap_m >= 0 && follow_gap_m <= 10, "nav.movers.follow_gap_m",
          "must be in [0, 10] m");
  require(follow_time_s > 0, "nav.movers.follow_time_s", "must be > 0 s");
  require(min_speed > 0, "nav.movers.min_speed", "must be > 0");
  require(min_updates >= 2, "nav.movers.min_updates", "must be >= 2");
  require(forget_s > 0, "nav.movers.forget_s", "must be > 0");
  require(horizon_s > 0 && horizon_s <= 20, "nav.movers.horizon_s", "must be in (0, 20] s");
  require(person_radius_m > 0 && robot_radius_m > 0 && margin_m >= 0, "nav.movers.margin_m",
          "radii must be > 0 and the margin >= 0");
  require(look_ahead_s > 0, "nav.movers.look_ahead_s", "must be > 0");
  require(range_m > 0, "nav.movers.range_m", "must be > 0");
}

MoverTracker::MoverTracker(MoverParams params) : p_(params) {
  p_.validate();
}

namespace {
double segDist(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d d = b - a;
  const double l2 = d.squaredNorm();
  const double t = l2 > 1e-12 ? std::clamp((p - a).dot(d) / l2, 0.0, 1.0) : 0.0;
  return (a + t * d - p).norm();
}
}  // namespace

void MoverTracker::update(const hw::Pose2D& robot, const hw::RangeScan& s,
                          const LocalPlanner& grid) {
  // Tracking runs whether or not the lanes are kept (`enabled`): the avoider follows the
  // movers found here (ObstacleAvoider::offerWalker).
  if (s.kind != hw::RangeScan::Kind::Laser) return;
  const double c = std::cos(robot.theta), sn = std::sin(robot.theta);
  // Clusters of consecutive valid beams (odometry frame).
  struct Cluster {
    Eigen::Vector2d sum{0, 0}, first{0, 0}, last{0, 0};
    int n = 0, free = 0;
  };
  std::vector<Cluster> clusters;
  Cluster cur;
  Eigen::Vector2d prev(0, 0);
  bool have_prev = false;
  // A cluster of one or two beams is no body within range_m (a person 4 m off spans 7 beams
  // of 1 deg): it is a surface seen at a grazing angle, each beam its own cluster, or a beam
  // split off an edge. Tracked, such fragments of a wall slid along it as the robot drove,
  // came towards it and were taken for walkers.
  auto close = [&]() {
    if (cur.n >= 3 && (cur.last - cur.first).norm() <= p_.max_width_m) clusters.push_back(cur);
    cur = Cluster{};
  };
  const size_t n = std::min(s.angles.size(), s.ranges.size());
  for (size_t i = 0; i < n; ++i) {
    const double r = s.ranges[i];
    if (!std::isfinite(r) || r >= s.max_range || r < s.min_range) {
      close();
      have_prev = false;
      continue;
    }
    const double x = s.mount.x + r * std::cos(s.angles[i]);
    const double y = s.mount.y + r * std::sin(s.angles[i]);
    const Eigen::Vector2d w(robot.x + c * x - sn * y, robot.y + sn * x + c * y);
    if (have_prev && (w - prev).norm() > p_.cluster_gap_m) close();
    if (cur.n == 0) cur.first = w;
    cur.last = w;
    cur.sum += w;
    ++cur.n;
    cur.free += grid.seenFree(w);
    prev = w;
    have_prev = true;
  }
  close();

  // Associate with the tracks' predictions, nearest pair first over all clusters and tracks,
  // then filter position and velocity (alpha-beta). (Taken cluster by cluster in beam order, a
  // one-beam fragment split off a person's edge came first, took their track 0.3 m off its
  // prediction, and the person went on as a new track: 1.4 s without a walker.)
  const double t = s.stamp;
  std::vector<Eigen::Vector2d> centres;
  centres.reserve(clusters.size());
  for (const auto& cl : clusters) {
    const Eigen::Vector2d z = cl.sum / cl.n;
    // Where the beams hit is the near surface: the body's centre is further away.
    centres.push_back(z + (z - Eigen::Vector2d(robot.x, robot.y)).normalized() * 0.5 *
                              p_.person_radius_m);
  }
  struct Pair {
    double d;
    size_t c, k;
  };
  std::vector<Pair> pairs;
  for (size_t c = 0; c < clusters.size(); ++c)
    for (size_t k = 0; k < tracks_.size(); ++k) {
      const Eigen::Vector2d pred = tracks_[k].pos + tracks_[k].vel * (t - tracks_[k].t);
      const double d = (pred - centres[c]).norm();
      if (d < p_.gate_m) pairs.push_back({d, c, k});
    }
  std::sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) {
    return a.d != b.d ? a.d < b.d : (a.c != b.c ? a.c < b.c : a.k < b.k);
  });
  std::vector<int> track_of(clusters.size(), -1);
  std::vector<bool> used(tracks_.size(), false);
  for (const auto& pr : pairs)
    if (track_of[pr.c] < 0 && !used[pr.k])
      track_of[pr.c] = static_cast<int>(pr.k), used[pr.k] = true;
  std::vector<Track> born;
  for (size_t c = 0; c < clusters.size(); ++c) {
    const auto& cl = clusters[c];
    const Eigen::Vector2d centre = centres[c];
    const int best = track_of[c];
    const bool on_free = 2 * cl.free > cl.n;
    if (best < 0) {
      Track tr;
      tr.pos = centre;
      tr.t = t;
      tr.updates = 1;
      tr.free_hits = on_free;
      tr.born_free = on_free;
      tr.free_bits = on_free;
      tr.history.push_back({t, centre});
      born.push_back(tr);
      continue;
    }
    Track& tr = tracks_[best];
    const double dt = t - tr.t;
    if (dt <= 1e-6) continue;
    const Eigen::Vector2d pred = tr.pos + tr.vel * dt;
    const Eigen::Vector2d res = centre - pred;
    tr.pos = pred + 0.6 * res;
    tr.vel += (0.3 / dt) * res;
    tr.t = t;
    ++tr.updates;
    tr.free_hits += on_free;
    tr.free_bits = ((tr.free_bits << 1) | (on_free ? 1u : 0u)) & 0xFFFFu;
    tr.history.push_back({t, centre});
    while (!tr.history.empty() && t - tr.history.front().first > 1.2)
      tr.history.erase(tr.history.begin());
    // Straight-line fit over the last 1.2 s: a walking person's centre moves steadily; a
    // track that jumped between two objects, or a visible part that grows and shrinks, does
    // not fit a line.
    const size_t m = tr.history.size();
    tr.steady = false;
    if (m >= 6 && tr.history.back().first - tr.history.front().first >= 0.5) {
      double st = 0, stt = 0;
      Eigen::Vector2d sp(0, 0), stp(0, 0);
      for (const auto& [ti, pi] : tr.history) st += ti, stt += ti * ti, sp += pi, stp += ti * pi;
      const double den = m * stt - st * st;
      if (den > 1e-9) {
        const Eigen::Vector2d v = (m * stp - st * sp) / den;
        const Eigen::Vector2d p0 = (sp - v * st) / static_cast<double>(m);
        double ss = 0;
        for (const auto& [ti, pi] : tr.history) ss += (p0 + v * ti - pi).squaredNorm();
        tr.fit_vel = v;
        tr.steady = std::sqrt(ss / m) <= 0.06;
      }
    }
    const Eigen::Vector2d to_robot = Eigen::Vector2d(robot.x, robot.y) - tr.pos;
    const double sp = tr.fit_vel.norm();
    const bool coming = tr.steady && sp >= p_.min_speed && sp <= 1.2 &&
                        tr.fit_vel.dot(to_robot) >= std::cos(M_PI / 4) * sp * to_robot.norm();
    tr.coming_in_row = coming ? tr.coming_in_row + 1 : 0;
  }
  tracks_.erase(std::remove_if(tracks_.begin(), tracks_.end(),
                               [&](const Track& tr) { return t - tr.t > p_.forget_s; }),
                tracks_.end());
  tracks_.insert(tracks_.end(), born.begin(), born.end());
}

std::vector<Mover> MoverTracker::movers() const {
  std::vector<Mover> out;
  for (const auto& tr : tracks_) {
    // First seen on floor the grid had seen free (a wall or a table edge is where the grid
    // saw something; a cluster that slides along one as the beams sweep it, or as a shadow
    // moves over it, is not born there), mostly on free floor since, at a walking pace.
    const double sp = tr.fit_vel.norm();
    if (tr.steady && tr.born_free && 4 * tr.free_hits >= tr.updates &&
        tr.updates >= p_.min_updates && sp >= p_.min_speed && sp <= 1.8)
      out.push_back({tr.pos, tr.fit_vel, tr.updates});
  }
  return out;
}

std::vector<Mover> MoverTracker::walkers() const {
  // Phantoms (occlusion edges sliding along a wall as the robot drives, a static thing's
  // visible part changing) come and go within a second or move at 1.3-1.7 m/s; a person walks
  // steadily for seconds at a walking pace. In an exp2-moved-b trial, which has no walker on
  // the robot's way, phantoms with 5-11 updates, or at 1.4-1.7 m/s, held the robot in
  // "lanes" until it missed three landmarks.
  // Mostly on free floor *lately* (the last 16 scans): a person who stood where the grid saw
  // them (at the turning point of their walk) starts on floor it holds occupied. Over the
  // whole track those first points held an exp4-pedestrian-left walker under three quarters
  // for 3.5 s after it set off towards the robot, and it was taken 1.4 s before contact.
  std::vector<Mover> out;
  for (const auto& tr : tracks_) {
    const double sp = tr.fit_vel.norm();
    const int recent = std::min(tr.updates, 16);
    const int recent_free = std::bitset<16>(tr.free_bits).count();
    const bool on_free_floor = tr.steady && 4 * recent_free >= 3 * recent &&
                               tr.updates >= 3 * p_.min_updates && sp >= 1.5 * p_.min_speed &&
                               sp <= 1.2;
    if (on_free_floor || tr.coming_in_row >= 2 * p_.min_updates)
      out.push_back({tr.pos, tr.fit_vel, tr.updates});
  }
  return out;
}

double MoverTracker::followSpeed(const hw::Pose2D& robot, double v) const {
  if (p_.follow_gap_m <= 0 || v <= 0) return v;
  const Eigen::Vector2d u(std::cos(robot.theta), std::sin(robot.theta));
  const Eigen::Vector2d P(robot.x, robot.y);
  const double reach = p_.person_radius_m + p_.robot_radius_m;
  double cap = v;
  for (const auto& tr : tracks_) {
    const double sp = tr.fit_vel.norm();
    if (!tr.steady || tr.updates < 2 * p_.min_updates || sp < p_.min_speed || sp > 1.2) continue;
    const Eigen::Vector2d d = tr.pos - P;
    const double along = d.dot(u), lateral = std::abs(u.x() * d.y() - u.y() * d.x());
    if (along <= 0 || along > p_.range_m || lateral > reach + p_.margin_m) continue;
    const double away = tr.fit_vel.dot(u);  // its speed along the robot's heading
    if (away < 0.5 * sp) continue;          // not walking the same way: the avoider's case
    const double gap = along - reach;
    cap = std::min(cap, std::max(0.0, away + (gap - p_.follow_gap_m) / p_.follow_time_s));
  }
  return cap;
}

YieldAdvice MoverTracker::advise(const hw::Pose2D& robot, double v, double w, double k_heading,
                                 double v_max) const {
  YieldAdvice a;
  if (!p_.enabled) return a;
  const double R = p_.person_radius_m + p_.robot_radius_m + p_.margin_m;
  const Eigen::Vector2d P(robot.x, robot.y);
  a.clearance_m = 1e9;
  const std::vector<Mover> ms = movers();
  for (const auto& m : ms) {
    if ((m.position - P).norm() > p_.range_m) continue;
    a.clearance_m =
        std::min(a.clearance_m, (m.position - P).norm() - p_.person_radius_m - p_.robot_radius_m);
    const Eigen::Vector2d A = m.position, B = m.position + m.velocity * p_.horizon_s;
    if (segDist(P, A, B) < R) {
      // In its lane: step out sideways, on the side of its line the robot is already on
      // (crossing in front of it is how near-misses happen).
      const Eigen::Vector2d u = m.velocity.normalized();
      const double side = u.x() * (P - A).y() - u.y() * (P - A).x() >= 0 ? 1.0 : -1.0;
      const Eigen::Vector2d out(-u.y() * side, u.x() * side);
      double err = std::atan2(out.y(), out.x()) - robot.theta;
      err = std::atan2(std::sin(err), std::cos(err));
      // Backing out is as good as driving out when the way out is behind.
      double dir = 1.0;
      if (std::abs(err) > 100 * M_PI / 180) {
        dir = -1.0;
        err = std::atan2(std::sin(err + M_PI), std::cos(err + M_PI));
      }
      a.active = a.in_lane = true;
      a.mover = m;
      a.w = k_heading * err;
      a.v = std::abs(err) < M_PI / 3 ? dir * v_max * std::cos(err) : 0.0;
      return a;
    }
  }
  // Not in a lane: would the command take the robot into one within look_ahead_s?
  return holdShort(ms, robot, v, w, a);
}

YieldAdvice MoverTracker::holdShort(const std::vector<Mover>& ms, const hw::Pose2D& robot, double v,
                                    double w, YieldAdvice a) const {
  if (v <= 0) return a;
  const double R = p_.person_radius_m + p_.robot_radius_m + p_.margin_m;
  const Eigen::Vector2d P(robot.x, robot.y);
  for (const auto& m : ms) {
    if ((m.position - P).norm() > p_.range_m) continue;
    double x = robot.x, y = robot.y, th = robot.theta;
    for (double t = 0.1; t <= p_.look_ahead_s + 1e-9; t += 0.1) {
      x += v * 0.1 * std::cos(th);
      y += v * 0.1 * std::sin(th);
      th += w * 0.1;
      // The lane as it will be then: the mover has moved on too.
      const Eigen::Vector2d A = m.position + m.velocity * t;
      const Eigen::Vector2d B = m.position + m.velocity * p_.horizon_s;
      if (segDist({x, y}, A, B) < R) {
        a.active = true;
        a.mover = m;
        a.v = 0;  // let it pass; turning on the spot is harmless
        a.w = w;
        return a;
      }
    }
  }
  return a;
}

YieldAdvice MoverTracker::holdShortOfWalkerLanes(const hw::Pose2D& robot, double v,
                                                 double w) const {
  const std::vector<Mover> ws = walkers();
  const double R = p_.person_radius_m + p_.robot_radius_m + p_.margin_m;
  const Eigen::Vector2d P(robot.x, robot.y);
  YieldAdvice a;
  a.clearance_m = 1e9;
  for (const auto& m : ws) {
    if ((m.position - P).norm() > p_.range_m) continue;
    a.clearance_m =
        std::min(a.clearance_m, (m.position - P).norm() - p_.person_radius_m - p_.robot_radius_m);
    // Already in one: the avoider steps out of it (ObstacleAvoider::offerWalker).
    if (segDist(P, m.position, m.position + m.velocity * p_.horizon_s) < R) return YieldAdvice{};
  }
  return holdShort(ws, robot, v, w, a);
}

}  // namespace sketchnav::nav
