#include "sketchnav/nav/avoidance.h"

#include <mrpt/math/TPoint2D.h>
#include <mrpt/nav/holonomic/CHolonomicND.h>

#include <algorithm>
#include <cmath>
#include <deque>

#include <Eigen/Core>

#include "sketchnav/core/config.h"
#include "sketchnav/nav/sections.h"

namespace sketchnav::nav {

namespace {
// [s] How long the followed walker's trail has to be before it can bear out (or refute) the
// walker's velocity (AvoidParams::lane_trail_s): a walker at 0.2 m/s covers 6 cm in it.
constexpr double kMinTrailS = 0.3;
}  // namespace

const char* toString(DodgeSide s) {
  switch (s) {
    case DodgeSide::Left:
      return "left";
    case DodgeSide::Right:
      return "right";
    default:
      return "none";
  }
}

void AvoidParams::validate() const {
  require(robot_radius_m > 0 && robot_radius_m < 2, "nav.avoid.robot_radius_m",
          "must be in (0, 2) m");
  require(trigger_m > 0, "nav.avoid.trigger_m", "must be > 0");
  require(release_m >= trigger_m, "nav.avoid.release_m", "must be >= trigger_m");
  require(corridor_margin_m >= 0, "nav.avoid.corridor_margin_m", "must be >= 0");
  require(min_clearance_m >= 0 && min_clearance_m < trigger_m, "nav.avoid.min_clearance_m",
          "must be in [0, trigger_m)");
  require(slow_m > min_clearance_m, "nav.avoid.slow_m", "must be > min_clearance_m");
  require(max_range_m > trigger_m, "nav.avoid.max_range_m", "must be > trigger_m");
  require(side_bias_deg >= 0 && side_bias_deg < 90, "nav.avoid.side_bias_deg",
          "must be in [0, 90)");
  require(moving_side_bias_deg >= 0 && moving_side_bias_deg < 90, "nav.avoid.moving_side_bias_deg",
          "must be in [0, 90)");
  require(moving_away_m >= 0, "nav.avoid.moving_away_m", "must be >= 0 m");
  require(route_cone_deg > 0 && route_cone_deg <= 150, "nav.avoid.route_cone_deg",
          "must be in (0, 150]");
  require(same_side_s >= 0, "nav.avoid.same_side_s", "must be >= 0");
  require(min_active_s >= 0, "nav.avoid.min_active_s", "must be >= 0");
  require(k_heading > 0, "nav.avoid.k_heading", "must be > 0");
  require(sectors >= 36 && sectors <= 1440, "nav.avoid.sectors", "must be in [36, 1440]");
  require(lane_horizon_s >= 0, "nav.avoid.lane_horizon_s", "must be >= 0 s (0 = no lanes)");
  require(person_radius_m > 0 && person_radius_m < 2, "nav.avoid.person_radius_m",
          "must be in (0, 2) m");
  require(lane_margin_m >= 0, "nav.avoid.lane_margin_m", "must be >= 0 m");
  require(lane_escape_deg >= 0 && lane_escape_deg <= 85, "nav.avoid.lane_escape_deg",
          "must be in [0, 85]");
  require(max_turn_rate > 0, "nav.avoid.max_turn_rate", "must be > 0 rad/s");
  require(lane_reverse_speed >= 0 && lane_reverse_speed <= 1.0, "nav.avoid.lane_reverse_speed",
          "must be in [0, 1] m/s (0 = no backing out of a lane)");
  require(lane_trail_s == 0 || (lane_trail_s >= 0.5 && lane_trail_s <= 5), "nav.avoid.lane_trail_s",
          "must be 0 (off) or in [0.5, 5] s");
  require(rear_memory_s >= 0 && rear_memory_s <= 30, "nav.avoid.rear_memory_s",
          "must be in [0, 30] s");
}

std::vector<std::pair<double, double>> scanPoints(const std::vector<hw::RangeScan>& scans,
                                                  bool lasers_only) {
  std::vector<std::pair<double, double>> pts;
  for (const auto& s : scans) {
    if (lasers_only && s.kind != hw::RangeScan::Kind::Laser) continue;
    const size_t n = std::min(s.angles.size(), s.ranges.size());
    for (size_t i = 0; i < n; ++i) {
      const double r = s.ranges[i];
      if (!std::isfinite(r) || r >= s.max_range || r < s.min_range) continue;
      const double a = s.angles[i];
      // A sonar only says "something within the cone at r": put points across the cone.
      const double half = s.kind == hw::RangeScan::Kind::Sonar ? 0.5 * s.beam_width : 0.0;
      for (double da : half > 0 ? std::vector<double>{-half, 0.0, half} : std::vector<double>{0.0})
        pts.emplace_back(s.mount.x + r * std::cos(a + da), s.mount.y + r * std::sin(a + da));
    }
  }
  return pts;
}

double corridorFree(const std::vector<std::pair<double, double>>& pts, double direction,
                    double half_width, double max_len) {
  const double c = std::cos(direction), s = std::sin(direction);
  double best = max_len;
  for (const auto& [x, y] : pts) {
    const double fwd = c * x + s * y, lat = -s * x + c * y;
    if (std::abs(lat) >= half_width) continue;
    if (fwd < -half_width) continue;
    const double touch = fwd - std::sqrt(half_width * half_width - lat * lat);
    best = std::min(best, std::max(0.0, touch));
  }
  return best;
}

struct ObstacleAvoider::Impl {
  mrpt::nav::CHolonomicND nd;
  // Laser scans of the last rear_memory_s with the robot's pose when each came in (newest
  // last): what the floor behind the robot, outside the laser's view now, looked like.
  struct Seen {
    double x, y, theta;  // the sensor's pose in the odometry frame when the scan came in
    hw::RangeScan scan;
  };
  std::deque<Seen> seen;
};

ObstacleAvoider::ObstacleAvoider(AvoidParams params) : params_(params) {
  params_.validate();
  impl_ = std::make_unique<Impl>();
  impl_->nd.enableApproachTargetSlowDown(false);
}
ObstacleAvoider::~ObstacleAvoider() = default;
ObstacleAvoider::ObstacleAvoider(ObstacleAvoider&&) noexcept = default;
ObstacleAvoider& ObstacleAvoider::operator=(ObstacleAvoider&&) noexcept = default;

void ObstacleAvoider::reset() {
  active_ = false;
  side_ = DodgeSide::None;
}

void ObstacleAvoider::followWalker(const std::vector<hw::RangeScan>& scans, double stamp,
                                   bool acquire) {
  // Laser points only: a sonar cone says nothing of where in it the person is.
  const double c = std::cos(pose_.theta), sn = std::sin(pose_.theta);
  std::vector<Eigen::Vector2d> pts;
  for (const auto& [x, y] : scanPoints(scans, true))
    pts.emplace_back(pose_.x + c * x - sn * y, pose_.y + sn * x + c * y);
  // The centre of the points within a person's reach of `p` (the side of them in view), when
  // they stand apart from anything else. A wall or a bench edge is not followed: a centre
  // slid along it by the predicted motion would keep its speed, a walker that never was.
  const double gate = params_.person_radius_m + 0.15;
  auto centre = [&](const Eigen::Vector2d& p, Eigen::Vector2d& out) {
    Eigen::Vector2d sum(0, 0);
    int n = 0, ring = 0;
    for (const auto& q : pts) {
      const double d = (q - p).norm();
      if (d < gate)
        sum += q, ++n;
      else if (d < gate + 0.2)
        ++ring;
    }
    if (n == 0 || ring > 2) return false;
    // The beams hit the near side: the body's centre is further away (as the mover tracker
    // takes it, so a walker it hands over does not jump).
    const Eigen::Vector2d mean = sum / n, robot(pose_.x, pose_.y);
    out = mean + (mean - robot).normalized() * 0.5 * params_.person_radius_m;
    return true;
  };
  if (walker_.valid) {
    const double dt = stamp - walker_.t;
    Eigen::Vector2d m;
    if (dt > 1e-6 && centre(walker_.pos + walker_.vel * dt, m)) {
      Eigen::Vector2d vel = 0.7 * walker_.vel + 0.3 * (m - walker_.pos) / dt;
      if (vel.norm() > 2.0) vel *= 2.0 / vel.norm();
      walker_.vel = vel;
      walker_.pos = m;
      walker_.t = stamp;
      if (params_.lane_trail_s > 0) {  // kept only for walkerWalks(), which needs it on
        walker_.trail.emplace_back(stamp, m);
        while (stamp - walker_.trail.front().first > params_.lane_trail_s)
          walker_.trail.pop_front();
      }
    } else if (stamp - walker_.t > 0.6) {
      walker_.valid = false;
    }
    return;
  }
  Eigen::Vector2d m;
  if (acquire && have_prev_pt_ && centre(prev_pt_, m)) {
    // At rest until its own motion is measured: the approach estimate also fires on static
    // things (noise, a surface sliding into view), and seeded with it such a thing had a lane
    // for half a second (in 2 of 4 exp2-redrawn-c trials, at the start in room A).
    walker_ = {true, m, {0, 0}, stamp, false, {{stamp, m}}};
  }
}

void ObstacleAvoider::offerWalker(const Eigen::Vector2d& position,
                                  const Eigen::Vector2d& velocity) {
  if (walker_.valid || !have_pose_ || prev_stamp_ < -1e299) return;
  const Eigen::Vector2d d = Eigen::Vector2d(pose_.x, pose_.y) - position;
  if (velocity.dot(d) <= 0) return;  // walking away
  const Walker keep = walker_;
  walker_ = {true, position, velocity, prev_stamp_, true, {{prev_stamp_, position}}};
  Eigen::Vector2d n;
  double off;
  if (!inLane(n, off)) walker_ = keep;
}

void ObstacleAvoider::observe(const std::vector<hw::RangeScan>& scans, const hw::Pose2D& pose) {
  setPose(pose);
  rememberScans(scans);
}

void ObstacleAvoider::rememberScans(const std::vector<hw::RangeScan>& scans) {
  const auto& P = params_;
  if (!have_pose_ || P.rear_memory_s <= 0 || (P.lane_reverse_speed <= 0 && !P.unseen_not_open))
    return;
  double stamp = -1;
  for (const auto& sc : scans) stamp = std::max(stamp, sc.stamp);
  if (stamp <= seen_stamp_ + 1e-9) return;  // nothing new since the last
  seen_stamp_ = stamp;
  auto& seen = impl_->seen;
  for (const auto& sc : scans)
    if (sc.kind == hw::RangeScan::Kind::Laser)
      // The sensor's pose once per scan, not per sample looked up in it.
      seen.push_back(
          {pose_.x + std::cos(pose_.theta) * sc.mount.x - std::sin(pose_.theta) * sc.mount.y,
           pose_.y + std::sin(pose_.theta) * sc.mount.x + std::cos(pose_.theta) * sc.mount.y,
           pose_.theta + sc.mount.theta, sc});
  // A few metres of driving, or a while of turning on the spot; bounded in size whatever
  // the laser's rate.
  while (!seen.empty() && (seen.front().scan.stamp < stamp - P.rear_memory_s || seen.size() > 200))
    seen.pop_front();
}

bool ObstacleAvoider::sweptSeenFree(double direction, double len, double half_width) const {
  const auto& seen = impl_->seen;
  if (seen.empty() || !have_pose_) return false;
  const double R = half_width > 0 ? half_width : params_.robot_radius_m + 0.02;
  const double c = std::cos(pose_.theta), sn = std::sin(pose_.theta);
  const double dc = std::cos(direction), ds = std::sin(direction);
  // Samples over the swept disc: its centre line and both edges every 0.1 m, and the far end's
  // rim; a person or a chair leg is wider than the spacing.
  for (double d = 0.1; d <= len + R + 1e-9; d += 0.1) {
    for (const double l : {-R, 0.0, R}) {
      if (d > len && l != 0.0) continue;
      const double px = d * dc - l * ds, py = d * ds + l * dc;  // robot frame
      const double qx = pose_.x + c * px - sn * py, qy = pose_.y + sn * px + c * py;
      bool decided = false;
      for (auto it = seen.rbegin(); it != seen.rend() && !decided; ++it) {
        const auto& sc = it->scan;
        const size_t n = std::min(sc.angles.size(), sc.ranges.size());
        if (n < 2) continue;
        // The sample in this scan's sensor frame.
        const double ex = qx - it->x, ey = qy - it->y;
        const double r = std::hypot(ex, ey);
        const double b = wrapAngle(std::atan2(ey, ex) - it->theta);
        const double a0 = sc.angles.front(), a1 = sc.angles[n - 1];
        if (b < std::min(a0, a1) || b > std::max(a0, a1)) continue;  // outside its view
        const double step = (a1 - a0) / static_cast<double>(n - 1);
        const auto k = static_cast<size_t>(
            std::clamp(std::lround((b - a0) / step), 0L, static_cast<long>(n) - 1));
        const double rb = std::isfinite(sc.ranges[k]) ? std::min<double>(sc.ranges[k], sc.max_range)
                                                      : sc.max_range;
        if (rb > r + 0.05) {
          decided = true;  // the beam went past it: free
        } else if (rb > r - 0.15) {
          return false;  // something there
        }
        // else hidden behind something nearer: an older scan may have seen it
      }
      if (!decided) return false;  // never seen: not known free
    }
  }
  return true;
}

namespace {
// The lane test (AvoidParams: lane_horizon_s, both radii, lane_margin_m): whether a person at
// `pos` walking at `vel` will pass within the lane's half-width of `robot`; then the unit
// normal from the lane's axis towards the robot and the robot's offset from it [m].
bool laneCovers(const AvoidParams& P, const Eigen::Vector2d& robot, const Eigen::Vector2d& pos,
                const Eigen::Vector2d& vel, Eigen::Vector2d& normal, double& offset) {
  const double speed = vel.norm();
  if (P.lane_horizon_s <= 0 || speed < 0.2) return false;
  const Eigen::Vector2d u = vel / speed;
  const Eigen::Vector2d d = robot - pos;
  const double reach = P.robot_radius_m + P.person_radius_m;
  const double along = d.dot(u);
  // Passed (the robot is behind them, by the gap kept), or not reached within the horizon.
  if (along < -(reach + P.lane_margin_m) || along > speed * P.lane_horizon_s + reach) return false;
  const Eigen::Vector2d lateral = d - along * u;
  offset = lateral.norm();
  if (offset >= reach + P.lane_margin_m) return false;
  normal = offset > 1e-6 ? Eigen::Vector2d(lateral / offset) : Eigen::Vector2d(-u.y(), u.x());
  return true;
}
}  // namespace

bool ObstacleAvoider::walkerWalks() const {
  // The follower's velocity is a filter over scan-to-scan steps of the visible side's centre.
  // A person standing still jumps a few centimetres between scans while the robot turns
  // (another side of them in view, the odometry's heading error), which the filter takes for
  // 0.1-0.3 m/s in a direction that flips from one jump to the next; a lane from that sent the
  // dodge left and right on the spot beside a person waiting in a corridor. A walker covers
  // the ground their speed says: over the trail (lane_trail_s), at least half of it, along it.
  if (params_.lane_trail_s <= 0) return true;
  const auto& tr = walker_.trail;
  const double span = tr.empty() ? 0.0 : tr.back().first - tr.front().first;
  // Handed over by the mover tracker: its velocity is a line fit over a second of steady
  // motion already, trusted until the follower's own trail can check it.
  if (span < kMinTrailS) return walker_.handed_over;
  const double speed = walker_.vel.norm();
  if (speed < 1e-9) return false;
  const double moved = (tr.back().second - tr.front().second).dot(walker_.vel / speed);
  return moved >= 0.5 * speed * span;
}

bool ObstacleAvoider::inLane(Eigen::Vector2d& normal, double& offset) const {
  if (!walker_.valid || !have_pose_ || !walkerWalks()) return false;
  return laneCovers(params_, {pose_.x, pose_.y}, walker_.pos, walker_.vel, normal, offset);
}

bool ObstacleAvoider::walkerLaneCovers(const Eigen::Vector2d& robot,
                                       const Eigen::Vector2d& position,
                                       const Eigen::Vector2d& velocity) const {
  if (velocity.dot(robot - position) <= 0) return false;  // walking away
  Eigen::Vector2d n;
  double off;
  return laneCovers(params_, robot, position, velocity, n, off);
}

double ObstacleAvoider::capSpeed(const std::vector<hw::RangeScan>& scans, double v) const {
  const auto pts = scanPoints(scans);
  const double free = corridorFree(pts, 0.0, params_.robot_radius_m + params_.corridor_margin_m,
                                   params_.max_range_m);
  if (free <= params_.min_clearance_m) return 0.0;
  const double k = std::clamp(
      (free - params_.min_clearance_m) / (params_.slow_m - params_.min_clearance_m), 0.0, 1.0);
  return v * std::max(k, 0.25 * (free > params_.min_clearance_m + 0.05));
}

double ObstacleAvoider::forwardSpeed(double dir, double v, AvoidOutput& out) const {
  const auto& P = params_;
  v *= std::max(0.0, std::cos(dir));
  if (std::abs(dir) > 1.0) v = 0;  // turn first, then go
  // Slow down as the corridor ahead closes, down to the minimum clearance.
  v *=
      std::clamp((out.front_free_m - P.min_clearance_m) / (P.slow_m - P.min_clearance_m), 0.0, 1.0);
  if (out.front_free_m <= P.min_clearance_m) {
    v = 0;
    out.blocked = true;
  }
  return v;
}

void ObstacleAvoider::laneEscape(const std::vector<std::pair<double, double>>& pts,
                                 double target_bearing, double heading, double v_nominal,
                                 const Eigen::Vector2d& lane_n, double lane_off, AvoidOutput& out) {
  // Out of the walker's lane to the side with room, steeply, then stand still there until they
  // have passed. Room is what the laser shows along each normal to the lane's axis (a corridor
  // wall, furniture): the robot goes as far out as the lane's width asks, or as far as that
  // side allows with the minimum clearance kept, whichever is less; where neither side leaves
  // the lane entirely, the side that leaves the larger gap. Moving only while it gains
  // sideways, it does not turn back and forth in front of the walker.
  const auto& P = params_;
  const double c = std::cos(heading), sn = std::sin(heading);
  auto toRobot = [&](const Eigen::Vector2d& w) {
    return Eigen::Vector2d(c * w.x() + sn * w.y(), -sn * w.x() + c * w.y());
  };
  const Eigen::Vector2d u = walker_.vel.normalized();
  const Eigen::Vector2d perp(-u.y(), u.x());
  const double clear = P.robot_radius_m + P.person_radius_m + P.lane_margin_m;  // offset wanted
  const double steep = std::sin(P.lane_escape_deg * M_PI / 180);
  // Signed offset of the robot from the axis along perp.
  const double so = lane_n.dot(perp) >= 0 ? lane_off : -lane_off;
  // When the walker's body reaches the robot's along their line, at their speed.
  const double walker_speed = walker_.vel.norm();
  const double arrive_s = std::max(0.0, (Eigen::Vector2d(pose_.x, pose_.y) - walker_.pos).dot(u) -
                                            (P.robot_radius_m + P.person_radius_m)) /
                          std::max(walker_speed, 0.05);
  // The room a side leaves (along its normal, the robot's disc kept min_clearance_m off what
  // the laser sees), the offset it allows (capped at `clear`) and the time to get there (turn
  // + sideways drive).
  struct Side {
    double room = 0, reach = 0, time = 0;
  };
  auto side = [&](int sign) {
    const Eigen::Vector2d n = sign * perp, nr = toRobot(n);
    const double a = std::atan2(nr.y(), nr.x());
    Side r;
    r.room =
        std::max(0.0, corridorFree(pts, a, P.robot_radius_m, P.max_range_m) - P.min_clearance_m);
    const double now_off = sign * so;
    r.reach = std::min(clear, now_off + r.room);
    const double slack = M_PI / 2 - P.lane_escape_deg * M_PI / 180;
    const double turn = std::max(0.0, std::abs(a) - slack);
    const double dist = std::max(0.0, r.reach - now_off);
    r.time = turn / P.max_turn_rate + dist / (std::max(v_nominal, 0.05) * steep);
    // Or backwards, where driving out forwards means turning on the spot first (below).
    const double back_turn = std::max(0.0, std::abs(wrapAngle(a - M_PI)) - slack);
    if (P.lane_reverse_speed > 0 && turn > 1.0 && back_turn < turn && arrive_s > 0.3 &&
        now_off >= 0 && sweptSeenFree(a, dist + P.min_clearance_m))
      r.time =
          std::min(r.time, back_turn / P.max_turn_rate + dist / (P.lane_reverse_speed * steep));
    return r;
  };
  const Side s_pos = side(1), s_neg = side(-1);
  const int own = so >= 0 ? 1 : -1;
  const Side& own_side = own > 0 ? s_pos : s_neg;
  const Side& across = own > 0 ? s_neg : s_pos;
  // The side kept (lane_side_) is a direction on the floor, not the walker's left or right:
  // when their heading turns round (a walker who turns back, or is first estimated walking
  // the wrong way), "their left" is the other side, and a sign kept would send the robot
  // across their line (generated corridor-1: a walker turned 0.7 m from the robot and it
  // drove 0.4 m towards their axis).
  int lane_sign = lane_side_.isZero() ? 0 : (lane_side_.dot(perp) >= 0 ? 1 : -1);
  if (lane_sign == 0 && std::abs(so) >= 0.15 &&
      (own_side.reach >= P.robot_radius_m + P.person_radius_m + 0.1 || across.time >= arrive_s)) {
    // Off the axis: that side when it has room, and also when it has not but going across
    // (crossing in front of the walker) would not be over before they get there: standing
    // at the edge of their way is a near miss, being in the middle of it when they arrive is
    // a collision.
    lane_sign = own;
  } else if (lane_sign == 0) {
    // Near the axis: the side that gets there before the walker does, when only one does (a
    // robot facing a wall half a metre away chose the open side behind it for its larger gap,
    // 6 s of turning and driving with the walker 4.5 s away, and was walked into: generated
    // mixed-7312); else the side that leaves the larger gap; where both leave the lane (or
    // about the same), the sooner out.
    const bool pos_in_time = s_pos.time < arrive_s, neg_in_time = s_neg.time < arrive_s;
    if (pos_in_time != neg_in_time)
      lane_sign = pos_in_time ? 1 : -1;
    else if (s_pos.reach > s_neg.reach + 0.1)
      lane_sign = 1;
    else if (s_neg.reach > s_pos.reach + 0.1)
      lane_sign = -1;
    else
      lane_sign = s_neg.time < s_pos.time ? -1 : 1;
  } else {
    // Kept once chosen: near the axis the side the robot is on flips with the walker's
    // estimated heading, and so would the robot. Given up only while the robot is still near
    // the axis, when its side is closed and the other is not (further out, going back across
    // is crossing in front of the walker).
    const Side& mine = lane_sign > 0 ? s_pos : s_neg;
    const Side& other = lane_sign > 0 ? s_neg : s_pos;
    if (lane_sign * so < 0.15 && mine.room < 0.1 && other.room > 0.3 &&
        other.reach > mine.reach + 0.2)
      lane_sign = -lane_sign;
  }
  const Side& goal = lane_sign > 0 ? s_pos : s_neg;
  lane_side_ = lane_sign * perp;
  const Eigen::Vector2d nr = toRobot(lane_side_);
  const double now_off = lane_sign * so;
  side_ = nr.y() >= 0 ? DodgeSide::Left : DodgeSide::Right;
  double v = 0, dir = 0;
  bool steer = false;
  const double togo = std::min(goal.reach, clear) - now_off;
  if (togo > 0.03 && goal.room > 0.03) {
    // Of the directions that leave steeply enough and have room for the next few centimetres,
    // the quickest out: the turn to it plus the drive sideways; ties to the route's. A
    // direction behind the robot may also be taken backwards (lane_reverse_speed): turning
    // round first stands the robot in the lane for seconds (a turn of 150 degrees is 3.3 s
    // at 0.8 rad/s) while backing gains sideways at once.
    double best = 1e300, best_free = 0;
    bool backwards = false;
    const double v_back = P.lane_reverse_speed;
    // A way out along robot-frame direction `a` (every 5 degrees round): how steeply it leaves
    // the lane (`away`, the sine of its angle to the axis) and how far it is free (`free`);
    // false when it is not steep enough or has no room for the next few centimetres. Ties go
    // to the route's direction (tie()).
    const auto wayOut = [&](double a, double& away, double& free) {
      away = std::cos(a) * nr.x() + std::sin(a) * nr.y();
      if (away < steep - 1e-9) return false;
      free = corridorFree(pts, a, P.robot_radius_m, P.max_range_m);
      return free >= P.min_clearance_m + 0.02;
    };
    const auto tie = [&](double a) { return 0.01 * std::abs(wrapAngle(a - target_bearing)); };
    for (int i = -35; i <= 36; ++i) {
      const double a = i * 5 * M_PI / 180;
      double away, free;
      if (!wayOut(a, away, free)) continue;
      const double t =
          std::abs(a) / P.max_turn_rate + togo / (std::max(v_nominal, 0.05) * away) + tie(a);
      if (t < best) best = t, dir = a, best_free = free, steer = true;
    }
    // Backwards only where every forward way out means turning on the spot first (more than
    // 1 rad): elsewhere the two would take turns from one scan to the next as the walker passes.
    // And only while the walker is still coming: once they are level with the robot their
    // heading, and so the way out, is estimated from the side of them in view and swings.
    // And never across the walker's axis: backing is for getting further out on the side the
    // robot is on (backing across it, with two walkers about, took a robot 0.1 m towards
    // their line in generated hall-7310).
    if (v_back > 0 && (!steer || std::abs(dir) > 1.0) && arrive_s > 0.3 && now_off >= 0) {
      for (int i = -35; i <= 36; ++i) {
        const double a = i * 5 * M_PI / 180;
        double away, free;
        if (std::abs(a) <= M_PI / 2 || !wayOut(a, away, free)) continue;
        const double e = wrapAngle(a - M_PI);  // heading change for the back to face `a`
        const double tb = std::abs(e) / P.max_turn_rate + togo / (v_back * away) + tie(a);
        if (tb < best && sweptSeenFree(a, togo + P.min_clearance_m))
          best = tb, dir = a, best_free = free, steer = true, backwards = true;
      }
    }
    if (steer && backwards) {
      // The back towards `dir`: turn first beyond 1 rad, then reverse, slowing over the last
      // 0.1 m of the offset wanted. (The floor was seen free: no slowing for what is ahead.)
      const double e = wrapAngle(dir - M_PI);
      v = std::abs(e) > 1.0 ? 0.0 : -v_back * (std::abs(e) > 0.5 ? std::cos(e) : 1.0);
      v *= std::clamp(togo / 0.1, 0.3, 1.0);
      out.direction = dir;
      out.w = P.k_heading * e;
      out.v = v;
      have_prev_ = false;
      return;
    }
    if (steer) {
      // Turn first beyond 1 rad; then drive, slowing down over the last 0.15 m before what is
      // ahead in that direction and over the last 0.1 m of the offset wanted.
      v = std::abs(dir) > 1.0 ? 0.0 : v_nominal * (std::abs(dir) > 0.5 ? std::cos(dir) : 1.0);
      v *= std::clamp((best_free - P.min_clearance_m) / 0.15, 0.3, 1.0);
      v *= std::clamp(togo / 0.1, 0.3, 1.0);
      prev_dir_odom_ = wrapAngle(heading + dir);
      have_prev_ = true;
    } else {
      // Nothing open leads further out: stand still (turning now only costs time), backing off
      // only when that also leads out of the lane.
      if (-nr.x() >= steep && corridorFree(pts, M_PI, P.robot_radius_m, P.max_range_m) > 0.5)
        v = -P.reverse_speed;
      out.blocked = true;
      have_prev_ = false;
    }
  } else {
    // As far out as this side allows: stand still until the walker has passed.
    have_prev_ = false;
  }
  out.direction = dir;
  out.w = steer ? P.k_heading * dir : 0.0;
  out.v = v;
}

AvoidOutput ObstacleAvoider::step(const std::vector<hw::RangeScan>& scans, double target_bearing,
                                  DodgeSide landmark_side, double heading, double v_nominal,
                                  double now) {
  const auto& P = params_;
  const auto pts = scanPoints(scans);
  const double hw = P.robot_radius_m + P.corridor_margin_m;
  AvoidOutput out;
  out.front_free_m = corridorFree(pts, 0.0, hw, P.max_range_m);
  out.clearance_m = P.max_range_m;
  for (const auto& [x, y] : pts)
    out.clearance_m = std::min(out.clearance_m, std::hypot(x, y) - P.robot_radius_m);
  // How fast is the thing ahead coming towards us, beyond our own motion? (A static obstacle:
  // ~0; a pedestrian walking at us: its speed.) Filtered over scans.
  // Only on a new scan, and only while driving straight: when the robot turns, "ahead" is
  // another obstacle; between scans the reading has not changed.
  double stamp = -1;
  for (const auto& sc : scans) stamp = std::max(stamp, sc.stamp);
  const bool fresh = stamp > prev_stamp_ + 1e-9;
  const bool straight = std::abs(wrapAngle(heading - prev_heading_)) < 0.05;
  rememberScans(scans);
  if (fresh && have_pose_) {
    // With the robot's pose: follow the nearest obstacle point in front (odometry frame) from
    // scan to scan. A point on something static only slides along its surface (across the
    // line of sight); a pedestrian's comes towards the robot. Works while turning too.
    // The point followed is the one closing the corridor ahead (else the nearest within
    // 35 degrees): what the robot would run into, not the nearest thing beside it.
    double best = 1e300;
    Eigen::Vector2d near(0, 0);
    for (const auto& [x, y] : pts) {
      const double cw = hw + 0.15;
      if (x > 0 && std::abs(y) < cw && x < P.max_range_m + 1.0) {
        const double touch = x - std::sqrt(cw * cw - y * y);
        if (touch < best) best = touch, near = {x, y};
      }
    }
    if (best >= 1e300)
      for (const auto& [x, y] : pts) {
        const double r = std::hypot(x, y);
        if (r < best && r < P.max_range_m + 1.0 && std::abs(std::atan2(y, x)) <= 0.6)
          best = r, near = {x, y};
      }
    if (best < 1e300) {
      const double c = std::cos(pose_.theta), sn = std::sin(pose_.theta);
      const Eigen::Vector2d robot(pose_.x, pose_.y);
      const Eigen::Vector2d world =
          robot + Eigen::Vector2d(c * near.x() - sn * near.y(), sn * near.x() + c * near.y());
      const double dt = stamp - prev_pt_t_;
      if (have_prev_pt_ && dt > 1e-6 && dt < 0.5 && (world - prev_pt_).norm() < 0.3) {
        const Eigen::Vector2d vel = (world - prev_pt_) / dt;
        const Eigen::Vector2d los = (world - robot).normalized();
        double rate = -vel.dot(los);                               // > 0: coming towards the robot
        if (rate > 0 && moved_in_ && !moved_in_(world)) rate = 0;  // static: it slid
        approach_ = 0.6 * approach_ + 0.4 * std::clamp(rate, -2.0, 2.0);
      } else {
        approach_ *= 0.5;
      }
      prev_pt_ = world;
      prev_pt_t_ = stamp;
      have_prev_pt_ = true;
    } else {
      approach_ = 0;
      have_prev_pt_ = false;
    }
    prev_heading_ = heading;
    prev_stamp_ = stamp;
  } else if (fresh) {
    if (!straight) {
      approach_ *= 0.5;
    } else if (prev_free_ >= 0 && stamp > prev_t_ + 1e-6 &&
               out.front_free_m < P.max_range_m - 0.05 && prev_free_ < P.max_range_m - 0.05) {
      const double rate = (prev_free_ - out.front_free_m) / (stamp - prev_t_) - prev_v_;
      if (std::abs(rate) < 2.0) approach_ = 0.6 * approach_ + 0.4 * rate;
    } else if (out.front_free_m >= P.max_range_m - 0.05) {
      approach_ = 0;
    }
    prev_heading_ = heading;
    prev_stamp_ = stamp;
  }
  if (fresh) {
    prev_free_ = out.front_free_m;
    prev_t_ = stamp;
  }
  out.approach_speed = approach_;
  const double moving = approach_ > 0.25 ? approach_ : 0.0;
  if (fresh && have_pose_) followWalker(scans, stamp, moving > 0);
  Eigen::Vector2d lane_n(0, 0);
  double lane_off = 0;
  const bool lane = inLane(lane_n, lane_off);
  out.in_lane = lane;
  if (lane) out.walker_pos = walker_.pos, out.walker_vel = walker_.vel;
  if (lane) lane_t_ = now;
  if (!lane && now - lane_t_ > 2.0) lane_side_.setZero();
  const double trigger = std::min(P.trigger_m + moving * P.approach_horizon_s, P.max_range_m - 0.3);
  const double toward = std::clamp(target_bearing, -0.6, 0.6);
  const double target_free = corridorFree(pts, toward, hw, P.max_range_m);

  // A walker whose lane covers the robot, this near: time to step out of it.
  const double walker_gap = lane ? (walker_.pos - Eigen::Vector2d(pose_.x, pose_.y)).norm() -
                                       P.robot_radius_m - P.person_radius_m
                                 : 1e9;
  if (!active_) {
    if (std::min(out.front_free_m, target_free) >= trigger &&
        walker_gap >= P.trigger_m + walker_.vel.norm() * P.lane_horizon_s) {
      prev_v_ = v_nominal;
      return out;
    }
    // Start a manoeuvre: remember where we were going and which side the landmark is on.
    active_ = true;
    have_prev_ = false;
    out.started = true;
    since_ = now;
    original_heading_ = heading;
    auto room = [&](double sgn) {
      return corridorFree(pts, sgn * 0.5, hw, P.max_range_m) +
             corridorFree(pts, sgn * 1.0, hw, P.max_range_m);
    };
    const double left = room(+1), right = room(-1);
    side_ = landmark_side;
    // A manoeuvre right after another keeps its side: crossing over in front of the same
    // pedestrian (or round the far side of the same obstacle) is how near-misses happen.
    if (last_side_ != DodgeSide::None && now - last_end_t_ <= P.same_side_s) side_ = last_side_;
    if (side_ == DodgeSide::None) side_ = left >= right ? DodgeSide::Left : DodgeSide::Right;
    // Someone coming towards the robot off to one side of its heading: step away from them,
    // whichever side the landmark is on (dodging towards it, into their lane, is how the
    // experiments' pedestrian walked into the robot).
    // Judged by the middle of the returns around the point followed (that point is the edge
    // nearest the robot's path, not where the person is).
    if (moving > 0 && have_prev_pt_ && P.moving_away_m > 0) {
      const Eigen::Vector2d d = prev_pt_ - Eigen::Vector2d(pose_.x, pose_.y);
      const Eigen::Vector2d q(std::cos(pose_.theta) * d.x() + std::sin(pose_.theta) * d.y(),
                              -std::sin(pose_.theta) * d.x() + std::cos(pose_.theta) * d.y());
      double sum = 0;
      int n = 0;
      for (const auto& [x, y] : pts)
        if (std::hypot(x - q.x(), y - q.y()) < 0.45) sum += y, ++n;
      const double lateral = n > 0 ? sum / n : q.y();
      if (std::abs(lateral) >= P.moving_away_m)
        side_ = lateral < 0 ? DodgeSide::Left : DodgeSide::Right;
    }
    // The landmark's side is preferred unless it is closed while the other is open.
    const double mine = side_ == DodgeSide::Left ? left : right;
    const double other = side_ == DodgeSide::Left ? right : left;
    if (mine < 2 * P.trigger_m && other > 2 * mine)
      side_ = side_ == DodgeSide::Left ? DodgeSide::Right : DodgeSide::Left;
  } else if (now - since_ >= P.min_active_s && !lane &&
             target_free >= std::max(P.release_m, trigger) &&
             corridorFree(pts, target_bearing, hw, P.max_range_m) >= P.trigger_m) {
    active_ = false;
    prev_v_ = v_nominal;
    out.ended = true;
    last_side_ = side_;
    last_end_t_ = now;
    out.side = side_;
    out.original_heading = original_heading_;
    side_ = DodgeSide::None;
    return out;
  }
  out.active = true;
  if (lane) {
    laneEscape(pts, target_bearing, heading, v_nominal, lane_n, lane_off, out);
    out.side = side_;
    out.original_heading = original_heading_;
    prev_v_ = out.v;
    return out;
  }
  out.side = side_;
  out.original_heading = original_heading_;

  // Configuration-space polar diagram for MRPT's ND: for each direction, how far the robot's
  // centre can travel before its disc touches an obstacle point, normalised by max_range.
  const int N = P.sectors;
  std::vector<double> obst(N, 1.0);
  const double R = P.robot_radius_m;
  for (const auto& [x, y] : pts) {
    const double d = std::hypot(x, y);
    if (d - R >= P.max_range_m) continue;
    const double phi = std::atan2(y, x);
    const double half = d <= R ? M_PI : std::asin(R / d);
    const int span = static_cast<int>(std::ceil(half / (2 * M_PI / N))) + 1;
    const int k0 = static_cast<int>(std::floor((phi + M_PI) / (2 * M_PI) * N));
    for (int dk = -span; dk <= span; ++dk) {
      const int k = ((k0 + dk) % N + N) % N;
      const double alpha = M_PI * (-1.0 + 2.0 * (k + 0.5) / N);
      const double delta = wrapAngle(alpha - phi);
      double t;
      if (d <= R) {
        t = 0;
      } else {
        const double ls = d * std::sin(delta);
        if (std::abs(ls) > R || std::cos(delta) <= 0) continue;
        t = std::max(0.0, d * std::cos(delta) - std::sqrt(R * R - ls * ls));
      }
      obst[k] = std::min(obst[k], t / P.max_range_m);
    }
  }
  const double sgn = side_ == DodgeSide::Left ? 1.0 : -1.0;
  const double bias = sgn * (moving > 0 ? P.moving_side_bias_deg : P.side_bias_deg) * M_PI / 180;
  const double tb = wrapAngle(target_bearing + bias);
  mrpt::nav::CAbstractHolonomicReactiveMethod::NavInput ni;
  ni.obstacles = obst;
  ni.targets.emplace_back(0.9 * std::cos(tb), 0.9 * std::sin(tb));
  ni.maxRobotSpeed = 1.0;
  ni.maxObstacleDist = 1.0;
  mrpt::nav::CAbstractHolonomicReactiveMethod::NavOutput no;
  impl_->nd.navigate(ni, no);
  double dir = wrapAngle(no.desiredDirection);

  // ND knows nothing of the chosen side and can flip between gaps from one scan to the next.
  // Its direction is kept only when it is open and does not cross to the other side of the
  // route direction; otherwise the first open direction is searched from the route direction
  // towards the chosen side (then the other side): a stable tangent around the obstacle.
  const double open_m = P.trigger_m;
  // A direction outside every range sensor's view now is open only where a scan of the last
  // rear_memory_s saw its floor free. Taken for open because nothing was seen there, a gap just
  // beyond the laser's edge drew a robot turning on the spot towards it, was seen closed once
  // the robot faced it, and the robot turned back to the other gap, which left its view in
  // turn: it swung left and right for seconds (generated mixed-8, 34 alternating ticks).
  // In view: the band the robot would sweep, out to open_m, lies inside a sensor's span.
  // Each sensor's span (robot frame, sonar cones included), once per step: open() is asked
  // for dozens of directions.
  const double band = std::atan2(hw, open_m);
  std::vector<std::pair<double, double>> spans;
  if (P.unseen_not_open)
    for (const auto& sc : scans) {
      if (sc.angles.empty()) continue;
      const auto [lo, hi] = std::minmax_element(sc.angles.begin(), sc.angles.end());
      spans.emplace_back(*lo - 0.5 * sc.beam_width, *hi + 0.5 * sc.beam_width);
    }
  auto in_view = [&](double a) {
    for (const auto& [lo, hi] : spans)
      if (a - band >= lo && a + band <= hi) return true;
    return false;
  };
  auto open = [&](double a) {
    return corridorFree(pts, a, hw, P.max_range_m) >= open_m &&
           (!P.unseen_not_open || in_view(a) || sweptSeenFree(a, open_m, hw));
  };
  // On the chosen side of the route direction, or not more than 0.35 rad the other way.
  // Against someone coming towards the robot, a direction close to the route's runs along
  // their lane: at least half the side bias out of it (an exp4-pedestrian-left robot drifted
  // along the walker's lane at 0.12 m/s sideways and was walked into 0.08 m from clear).
  const double min_rel = moving > 0 ? 0.5 * P.moving_side_bias_deg * M_PI / 180 : -0.35;
  auto sided = [&](double a) { return wrapAngle(a - target_bearing) * sgn > min_rel; };
  // The first open direction from the route's, towards the chosen side, then the other side,
  // for deviations in [lo, hi] (a walker's lane: from the least way out of it on the chosen
  // side).
  auto search = [&](double lo, double hi, double& out_dir) {
    const double step = 5 * M_PI / 180;
    for (int pass = 0; pass < 2; ++pass) {
      const double s2 = pass == 0 ? sgn : -sgn;
      const double off0 = std::max(lo, pass == 0 && moving > 0 ? min_rel : 0.0);
      for (double off = off0; off <= hi + 1e-9; off += step) {
        const double a = wrapAngle(target_bearing + s2 * off);
        if (std::abs(a) <= 2.2 && open(a)) {
          out_dir = a;
          return true;
        }
      }
    }
    return false;
  };
  // Within the route cone, the chosen side may cost any detour, but a direction outside it is
  // taken only when nothing inside is open: with "on the chosen side" alone, ND or the kept
  // direction led an exp4-pedestrian-right robot 150-180 deg away from the route for 6 s, back
  // into the walker's lane, while the way on along the route's side of the bench was open.
  const double cone = P.route_cone_deg * M_PI / 180;
  auto in_cone = [&](double a) { return std::abs(wrapAngle(a - target_bearing)) <= cone + 1e-9; };
  double cone_dir = 0;
  const bool cone_open = search(0.0, cone, cone_dir);
  auto allowed = [&](double a) { return in_cone(a) || !cone_open; };
  const bool nd_ok =
      no.desiredSpeed > 0.05 && open(dir) && sided(dir) && allowed(dir) && std::abs(dir) < 2.0;
  bool found = nd_ok;
  // Hysteresis: a direction chosen before (kept in the odometry frame) that is still open is
  // kept, so the robot does not swing between two gaps while the target bearing moves.
  // With unseen_not_open, a direction kept is given up only when the current scan shows it
  // closing (less than half of open_m free): chosen as open, it is not dropped for leaving the
  // sensors' view as the robot turns on the spot, nor for a reading that sits at the threshold,
  // so the robot does not reverse its turn from one scan to the next.
  auto still_open = [&](double a) {
    return P.unseen_not_open ? corridorFree(pts, a, hw, P.max_range_m) >= 0.5 * open_m : open(a);
  };
  if (!found && have_prev_) {
    const double a = wrapAngle(prev_dir_odom_ - heading);
    if (std::abs(a) <= 2.2 && still_open(a) && (moving <= 0 || sided(a)) && allowed(a)) {
      dir = a;
      found = true;
    }
  }
  if (!found && cone_open) {
    dir = cone_dir;
    found = true;
  }
  if (!found) found = search(cone, 150 * M_PI / 180, dir);
  double speed = 1.0;
  if (!found) {  // boxed in: turn on the spot towards the chosen side
    dir = sgn * 1.2;
    speed = 0;
    have_prev_ = false;
  } else {
    prev_dir_odom_ = wrapAngle(heading + dir);
    have_prev_ = true;
  }
  out.direction = dir;
  out.w = P.k_heading * dir;
  double v = forwardSpeed(dir, v_nominal * speed, out);
  // Something keeps coming at us while we cannot go forward: back off (the way we came is
  // normally free) rather than wait to be walked into.
  if (moving > 0 && out.front_free_m <= P.min_clearance_m + 0.25 &&
      corridorFree(pts, M_PI, hw, P.max_range_m) > 0.5)
    v = -P.reverse_speed;
  out.v = v;
  prev_v_ = v;
  return out;
}

}  // namespace sketchnav::nav
