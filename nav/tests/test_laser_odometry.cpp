// Laser-aided odometry: a robot drives a loop in a furnished room while its wheel odometry
// drifts in heading; scan matching against keyframes must keep the heading and position close
// to the truth, and a scan that cannot be matched (nothing in range, or a pedestrian-sized
// disagreement) must leave the wheel odometry as it is.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <optional>
#include <random>

#include "sketchnav/core/error.h"
#include "sketchnav/nav/laser_odometry.h"
#include "sketchnav/nav/sections.h"

using namespace sketchnav;
using namespace sketchnav::nav;

namespace {
// Drive a pose ds along its heading, then turn it by dth (the simulated truth and wheels).
void advance(hw::Pose2D& p, double ds, double dth) {
  p.x += ds * std::cos(p.theta);
  p.y += ds * std::sin(p.theta);
  p.theta = wrapAngle(p.theta + dth);
}
struct Seg {
  double ax, ay, bx, by;
};
// The outline of an axis-aligned box [x0, x1] x [y0, y1], appended to `s`.
void addBox(std::vector<Seg>& s, double x0, double y0, double x1, double y1) {
  s.push_back({x0, y0, x1, y0});
  s.push_back({x1, y0, x1, y1});
  s.push_back({x1, y1, x0, y1});
  s.push_back({x0, y1, x0, y0});
}
// A 10 x 7 m room with a table and a cabinet (world frame), as line segments.
std::vector<Seg> room() {
  std::vector<Seg> s;
  addBox(s, 0, 0, 10, 7);
  auto box = [&](double x0, double y0, double x1, double y1) { addBox(s, x0, y0, x1, y1); };
  box(3, 2.5, 4.6, 3.3);
  box(7.5, 5.6, 8.2, 6.6);
  box(1.0, 5.5, 1.4, 5.9);
  return s;
}

hw::RangeScan scanAt(const hw::Pose2D& p, const std::vector<Seg>& segs, double stamp,
                     std::mt19937& rng, double max_range = 8.0) {
  hw::RangeScan s;
  s.kind = hw::RangeScan::Kind::Laser;
  s.min_range = 0.05f;
  s.max_range = static_cast<float>(max_range);
  s.stamp = stamp;
  std::normal_distribution<double> noise(0, 0.01);
  for (int i = -120; i <= 120; ++i) {
    const double a = i * M_PI / 180, dx = std::cos(p.theta + a), dy = std::sin(p.theta + a);
    double best = max_range;
    for (const auto& g : segs) {
      // Ray p + t d against segment a + u (b - a).
      const double ex = g.bx - g.ax, ey = g.by - g.ay, den = dx * ey - dy * ex;
      if (std::abs(den) < 1e-12) continue;
      const double wx = g.ax - p.x, wy = g.ay - p.y;
      const double t = (wx * ey - wy * ex) / den, u = (wx * dy - wy * dx) / den;
      if (t > 0 && u >= 0 && u <= 1) best = std::min(best, t);
    }
    s.angles.push_back(static_cast<float>(a));
    s.ranges.push_back(static_cast<float>(best < max_range ? best + noise(rng) : max_range));
  }
  return s;
}

struct Result {
  double raw_heading_err = 0, fixed_heading_err = 0, raw_pos_err = 0, fixed_pos_err = 0;
  LaserOdometryStats stats;
};

// Drives a 6 x 3 m rectangle round the table (straight at 0.3 m/s, 90 deg turns on the spot at
// 0.6 rad/s) for `seconds`; the wheel odometry turns `drift` rad per metre too much (a
// wheel-radius mismatch). Errors are at the end.
Result drive(double drift, double seconds, bool with_laser, unsigned seed,
             LaserOdometryParams p = {}, double wheel_scale = 1.0) {
  std::mt19937 rng(seed);
  const auto segs = room();
  LaserOdometry lo(p);
  hw::Pose2D truth{1.5, 1.2, 0}, wheel{0, 0, 0};
  const double dt = 0.05, v = 0.3, w_turn = 0.6;
  double leg = 0, turned = 0;
  bool turning = false;
  int legs = 0;
  Result r;
  for (int k = 0; k * dt < seconds; ++k) {
    const double t = k * dt;
    double ds = 0, dth = 0;
    if (turning) {
      dth = std::min(w_turn * dt, M_PI / 2 - turned);
      turned += dth;
      if (turned >= M_PI / 2 - 1e-9) turning = false, turned = 0, leg = 0;
    } else {
      const double len = legs % 2 == 0 ? 6.0 : 3.0;
      ds = std::min(v * dt, len - leg);
      leg += ds;
      if (leg >= len - 1e-9) turning = true, ++legs;
    }
    advance(truth, ds, dth);
    advance(wheel, wheel_scale * ds, dth + drift * ds);
    lo.wheel(wheel, t);
    if (with_laser && k % 2 == 0) lo.scan(scanAt(truth, segs, t, rng));
  }
  // Odometry frame = the start pose.
  const hw::Pose2D start{1.5, 1.2, 0};
  const double tx = truth.x - start.x, ty = truth.y - start.y;
  const auto fixed = lo.pose();
  r.raw_heading_err = std::abs(wrapAngle(wheel.theta - truth.theta));
  r.fixed_heading_err = std::abs(wrapAngle(fixed.theta - truth.theta));
  r.raw_pos_err = std::hypot(wheel.x - tx, wheel.y - ty);
  r.fixed_pos_err = std::hypot(fixed.x - tx, fixed.y - ty);
  r.stats = lo.stats();
  return r;
}
}  // namespace

TEST(LaserOdometry, TakesOutWheelHeadingDrift) {
  const Result r = drive(0.02, 130, true, 7);  // ~33 m driven, 0.66 rad of wheel drift
  EXPECT_GT(r.raw_heading_err, 0.3);           // the wheels alone are far off...
  EXPECT_LT(r.fixed_heading_err, 0.03);        // ...scan matching keeps within ~2 degrees
  EXPECT_GT(r.raw_pos_err, 1.5);
  EXPECT_LT(r.fixed_pos_err, 0.3);
  EXPECT_GT(r.stats.aligned, r.stats.scans * 8 / 10);
  EXPECT_GT(r.stats.keyframes, 20);
}

// A wheel-radius error (the wheels count 6 % too far) is corrected in a furnished room: its
// walls and furniture face every direction, so no axis is left to the wheels.
TEST(LaserOdometry, TakesOutWheelScaleErrorInAFurnishedRoom) {
  const Result r = drive(0.0, 100, true, 8, {}, 1.06);  // 1.5 loops, ending mid-leg
  std::printf("room, wheels 6 %% long: wheels %.2f m off, fused %.2f m\n", r.raw_pos_err,
              r.fixed_pos_err);
  EXPECT_GT(r.raw_pos_err, 0.3);    // the wheels alone (0.38 m)...
  EXPECT_LT(r.fixed_pos_err, 0.1);  // ...scan matching (0.01 m)
  EXPECT_LT(r.fixed_heading_err, 0.03);
  EXPECT_GT(r.stats.aligned, r.stats.scans * 8 / 10);
  EXPECT_LT(r.stats.degenerate, r.stats.aligned / 10);
}

TEST(LaserOdometry, WithoutScansItIsTheWheelOdometry) {
  const Result r = drive(0.02, 30, false, 7);
  EXPECT_NEAR(r.fixed_heading_err, r.raw_heading_err, 1e-9);
  EXPECT_NEAR(r.fixed_pos_err, r.raw_pos_err, 1e-9);
  EXPECT_EQ(r.stats.scans, 0);
}

TEST(LaserOdometry, EmptyScansAreNotAligned) {
  LaserOdometry lo;
  std::mt19937 rng(1);
  lo.wheel({0, 0, 0}, 0.0);
  lo.wheel({0.5, 0.1, 0.2}, 1.0);
  hw::RangeScan empty = scanAt({0, 0, 0}, {}, 1.0, rng);  // nothing in range
  lo.scan(empty);
  const auto p = lo.pose();
  EXPECT_NEAR(p.x, 0.5, 1e-12);
  EXPECT_NEAR(p.y, 0.1, 1e-12);
  EXPECT_NEAR(p.theta, 0.2, 1e-12);
  EXPECT_EQ(lo.stats().aligned, 0);
}

TEST(LaserOdometry, SonarScansAreIgnored) {
  LaserOdometry lo;
  std::mt19937 rng(1);
  lo.wheel({0, 0, 0}, 0.0);
  auto s = scanAt({1.5, 1.2, 0}, room(), 0.0, rng);
  s.kind = hw::RangeScan::Kind::Sonar;
  lo.scan(s);
  EXPECT_EQ(lo.stats().scans, 0);
}

// RangeScan::angles are robot-frame bearings (the mount's yaw included): a laser mounted
// turned 0.4 rad must not have its points turned again, or the motion it measures comes out
// turned too (here 0.2 m off sideways, refused).
TEST(LaserOdometry, TakesTheBearingsOfATurnedLaserAsRobotFrame) {
  LaserOdometry lo;
  std::mt19937 rng(2);
  auto scan = [&](double x, double t) {
    auto s = scanAt({x, 1.2, 0}, room(), t, rng);
    s.mount = {0, 0, 0.4};
    return s;
  };
  lo.wheel({0, 0, 0}, 0.0);
  lo.scan(scan(1.5, 0.0));
  lo.wheel({0.45, 0, 0}, 1.0);  // the wheels say 0.45 m, the robot went 0.5 m
  lo.scan(scan(2.0, 1.0));
  EXPECT_EQ(lo.stats().aligned, 1);
  EXPECT_NEAR(lo.pose().x, 0.5, 0.04);  // point-to-point ICP slides a little along the walls
  EXPECT_NEAR(lo.pose().y, 0.0, 0.02);
}

TEST(LaserOdometry, ValidatesItsSettings) {
  LaserOdometryParams p;
  p.min_goodness = 1.5;
  EXPECT_THROW(LaserOdometry{p}, InputError);
  p = {};
  p.keyframe_dist_m = 0;
  EXPECT_THROW(LaserOdometry{p}, InputError);
  p = {};
  p.submap_keyframes = 0;
  EXPECT_THROW(LaserOdometry{p}, InputError);
}

namespace {
// A furnished 16 x 11 m hall, its walls 3-8 m from the robot (1-degree beams land 5-14 cm apart
// there): the robot weaves between a box and a bench 1 m apart (exp4-static-obstacle's detour)
// while its wheels over-turn by 6 % and drift 0.01 rad/m. Returns the worst heading error
// along the way as fixed_heading_err.
Result weave(unsigned seed, LaserOdometryParams p = {}) {
  std::mt19937 rng(seed);
  std::vector<Seg> segs;
  addBox(segs, 0, 0, 16, 11);
  auto box = [&](double x0, double y0, double x1, double y1) { addBox(segs, x0, y0, x1, y1); };
  box(7.7, 6.05, 8.3, 6.65);  // the box the robot goes round...
  box(7.0, 7.72, 10.0, 8.3);  // ...and a bench 1 m beyond it
  box(3.0, 2.0, 4.6, 2.8);
  box(11.0, 3.5, 11.6, 4.5);
  box(13.5, 9.0, 14.5, 10.4);
  box(1.0, 9.6, 2.2, 10.4);
  LaserOdometry lo(p);
  const hw::Pose2D start{2.0, 6.3, 0};
  hw::Pose2D truth = start, wheel{0, 0, 0};
  const double dt = 0.05, v = 0.3;
  Result r;
  double worst = 0;
  for (int k = 0; k * dt < 40; ++k) {
    const double t = k * dt;
    // Straight, left up to the gap, right through it and down past the box, straight again.
    const double w = t < 12   ? 0.0
                     : t < 16 ? 0.2
                     : t < 20 ? -0.2
                     : t < 24 ? -0.15
                     : t < 28 ? 0.15
                              : 0.0;
    const double ds = v * dt, dth = w * dt;
    advance(truth, ds, dth);
    advance(wheel, ds, 1.06 * dth + 0.01 * ds);
    lo.wheel(wheel, t);
    if (k % 2 == 0) lo.scan(scanAt(truth, segs, t, rng));
    worst = std::max(worst, std::abs(wrapAngle(lo.pose().theta - (truth.theta - start.theta))));
  }
  r.raw_heading_err = std::abs(wrapAngle(wheel.theta - (truth.theta - start.theta)));
  r.fixed_heading_err = worst;
  r.stats = lo.stats();
  return r;
}
}  // namespace

// The failure seen in exp4-static-obstacle #2: moving away from the keyframe, fewer beams
// land where the keyframe's did, so ICP's own goodness (pairs within its final 2-4 cm
// threshold) fell under min_goodness after 1-1.5 m although the alignments were right, and the
// robot ran on its wheels through the detour. Here that refused 13-16 % of the scans and the
// heading went 1.9-3.5 degrees off; the alignments must be kept.
TEST(LaserOdometry, KeepsAligningAwayFromTheKeyframeInAWideHall) {
  for (unsigned seed : {3u, 4u, 5u, 6u}) {
    const Result r = weave(seed);
    EXPECT_GT(r.raw_heading_err, 0.04) << seed;    // the wheels lose > 2.3 degrees...
    EXPECT_LT(r.fixed_heading_err, 0.03) << seed;  // ...scan matching never more than 1.7
    EXPECT_GT(r.stats.aligned, r.stats.scans * 95 / 100) << seed;
  }
}

namespace {
// Through a door from a 6 x 6 m room into an 8 x 9 m one and at once a quarter turn left,
// wheels over-turning 6 %: the first room's keyframe explains little of the second.
Result throughTheDoor(unsigned seed) {
  std::mt19937 rng(seed);
  std::vector<Seg> segs{
      {0, 0, 14, 0},     {14, 0, 14, 9},     {14, 9, 0, 9},      {0, 9, 0, 0},
      {0, 6, 6, 6},      {6, 9, 6, 6},       {6, 0, 6, 2.5},     {6, 3.5, 6, 6},
      {9, 6.5, 10, 6.5}, {10, 6.5, 10, 7.5}, {10, 7.5, 9, 7.5},  {9, 7.5, 9, 6.5},
      {12, 1, 13, 1},    {13, 1, 13, 1.6},   {13, 1.6, 12, 1.6}, {12, 1.6, 12, 1}};
  LaserOdometry lo;
  const hw::Pose2D start{2.0, 3.0, 0};
  hw::Pose2D truth = start, wheel{0, 0, 0};
  const double dt = 0.05, v = 0.3;
  Result r;
  for (int k = 0; k * dt < 30; ++k) {
    const double t = k * dt;
    const double w = truth.x > 6.6 && truth.theta < M_PI / 2 - 0.02 ? 0.3 : 0.0;
    const double ds = v * dt, dth = w * dt;
    advance(truth, ds, dth);
    advance(wheel, ds, 1.06 * dth);
    lo.wheel(wheel, t);
    if (k % 2 == 0) lo.scan(scanAt(truth, segs, t, rng));
    if (truth.y > 8.0) break;
  }
  r.raw_heading_err = std::abs(wrapAngle(wheel.theta - (truth.theta - start.theta)));
  r.fixed_heading_err = std::abs(wrapAngle(lo.pose().theta - (truth.theta - start.theta)));
  r.stats = lo.stats();
  return r;
}
}  // namespace

// Once the reference explains too little of the scan, waiting for the keyframe distance leaves
// the robot on its wheels through the turn (here 3.7 degrees lost of the wheels' 5.4; the
// exp2-redrawn-d #2 trial lost 1.8 in a weave): the keyframe must be renewed at once.
TEST(LaserOdometry, RenewsTheKeyframeWhenTheViewMovesOn) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const Result r = throughTheDoor(seed);
    EXPECT_GT(r.raw_heading_err, 0.08) << seed;    // the wheels: 5.4 degrees off
    EXPECT_LT(r.fixed_heading_err, 0.02) << seed;  // (0.5 at most)
    EXPECT_GT(r.stats.aligned, r.stats.scans * 95 / 100) << seed;
  }
}

namespace {
// 20 m along a plain 2.2 m wide corridor (two parallel walls, the ends beyond the laser's
// 8 m), wheels counting `wheel_scale` of the distance and drifting 0.01 rad/m in heading.
// The along-axis error is the final |x| error; the wheels' own is that of their path length.
struct CorridorResult {
  double along_err = 0, across_err = 0, heading_err = 0, wheel_along_err = 0;
  LaserOdometryStats stats;
};
// A person (a 0.4 m octagon) may walk along it: from walker_x0 at walker_v m/s (negative:
// towards the robot).
struct Walker {
  double x0 = 0, v = 0, y = 1.3;  // [m], [m/s], [m] across (the robot keeps to 1.1)
};
CorridorResult corridor(unsigned seed, double wheel_scale, LaserOdometryParams p = {},
                        std::optional<Walker> walker = std::nullopt) {
  std::mt19937 rng(seed);
  std::vector<Seg> segs{{-15, 0, 45, 0}, {-15, 2.2, 45, 2.2}};
  const size_t walls = segs.size();
  LaserOdometry lo(p);
  const hw::Pose2D start{0, 1.1, 0};
  hw::Pose2D truth = start, wheel{0, 0, 0};
  const double dt = 0.05, v = 0.4;
  double wheel_path = 0;
  for (int k = 0; truth.x < 20.0; ++k) {
    const double t = k * dt;
    // A gentle weave round the centre line, as a robot following it does.
    const double w = 0.1 * std::sin(0.4 * t) - 0.5 * (truth.y - 1.1) - 0.5 * truth.theta;
    const double ds = v * dt, dth = w * dt;
    advance(truth, ds, dth);
    advance(wheel, wheel_scale * ds, dth + 0.01 * ds);
    wheel_path += wheel_scale * ds;
    lo.wheel(wheel, t);
    if (walker) {
      segs.resize(walls);
      const double cx = walker->x0 + walker->v * t, cy = walker->y, rad = 0.2;
      for (int j = 0; j < 8; ++j) {
        const double a0 = j * M_PI / 4, a1 = (j + 1) * M_PI / 4;
        segs.push_back({cx + rad * std::cos(a0), cy + rad * std::sin(a0), cx + rad * std::cos(a1),
                        cy + rad * std::sin(a1)});
      }
    }
    if (k % 2 == 0) lo.scan(scanAt(truth, segs, t, rng));
  }
  CorridorResult r;
  const auto f = lo.pose();
  r.along_err = std::abs(f.x - (truth.x - start.x));
  r.across_err = std::abs(f.y - (truth.y - start.y));
  r.heading_err = std::abs(wrapAngle(f.theta - truth.theta));
  r.wheel_along_err = std::abs(wheel_path - wheel_path / wheel_scale);
  r.stats = lo.stats();
  return r;
}
}  // namespace

// Between two plain walls a scan pins down the distance to them and the heading, not the
// position along them: ICP's translation along the corridor is what its point pairs settle
// on. The fused estimate must take the wheels' increment there (error within theirs) while
// keeping ICP's heading and across-axis corrections (the wheels drift 0.2 rad here); ICP
// trusted along the axis, as before, ends metres off.
TEST(LaserOdometry, DoesNotDriftAlongAFeaturelessCorridor) {
  for (unsigned seed : {1u, 2u, 3u}) {
    for (double scale : {0.97, 1.03}) {
      const CorridorResult r = corridor(seed, scale);
      EXPECT_LT(r.along_err, r.wheel_along_err + 0.1) << seed << " " << scale;
      EXPECT_LT(r.across_err, 0.1) << seed << " " << scale;
      EXPECT_LT(r.heading_err, 0.02) << seed << " " << scale;
      EXPECT_GT(r.stats.aligned, r.stats.scans * 8 / 10) << seed << " " << scale;
      EXPECT_GT(r.stats.degenerate, r.stats.aligned * 8 / 10) << seed << " " << scale;
      LaserOdometryParams icp_only;
      icp_only.constrained_points = 0;
      const CorridorResult b = corridor(seed, scale, icp_only);
      EXPECT_GT(b.along_err, 2 * r.along_err + 0.3) << seed << " " << scale;
      std::printf("seed %u scale %.2f: along %.2f m (wheels %.2f, ICP only %.2f)\n", seed, scale,
                  r.along_err, r.wheel_along_err, b.along_err);
    }
  }
}

// A person walking ahead at the robot's speed is the only surface facing along the corridor:
// aligned to them, the robot stands still with them (a simulated corridor run: 0.3 m of 3 m
// counted); one coming the other way makes it count too much. Their points are left out as
// moved; a slower person whom the robot overtakes moves too little in half a second to be
// seen so, and is caught by the wheels' disagreement over a keyframe. Without both checks
// the walker ahead puts the robot metres off.
TEST(LaserOdometry, IsNotHeldStillByAPersonWalkingInACorridor) {
  for (unsigned seed : {1u, 2u}) {
    for (const Walker w :
         {Walker{2.5, 0.4, 1.3}, Walker{3.0, 0.25, 1.8}, Walker{14.0, -0.8, 1.3}}) {
      const CorridorResult r = corridor(seed, 1.03, {}, w);
      LaserOdometryParams off;
      off.moving_baseline_s = 0;
      off.wheel_agree_rel = 0;
      const CorridorResult b = corridor(seed, 1.03, off, w);
      std::printf(
          "seed %u walker %.2f m/s: along %.2f m (wheels %.2f, neither check %.2f), "
          "%.1f %% of points left out, wheels' translation %d of %d\n",
          seed, w.v, r.along_err, r.wheel_along_err, b.along_err, 100 * r.stats.moving_share,
          r.stats.wheel_disagree, r.stats.aligned);
      EXPECT_LT(r.along_err, r.wheel_along_err + 0.15) << seed << " " << w.v;
      EXPECT_LT(r.across_err, 0.1) << seed << " " << w.v;
      EXPECT_LT(r.heading_err, 0.02) << seed << " " << w.v;
      EXPECT_GT(r.stats.aligned, r.stats.scans * 8 / 10) << seed << " " << w.v;
      if (w.v == 0.4) EXPECT_GT(b.along_err, r.along_err + 3.0) << seed;
    }
  }
}
