// The servo law: sign conventions, the Jacobian against finite differences of the true
// camera projection, saturation / dead band, and closed-loop convergence on a unicycle.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "sketchnav/core/error.h"
#include "sketchnav/servo/turn_law.h"

using namespace sketchnav;
using namespace sketchnav::servo;

namespace {

struct Pose {
  double x = 0, y = 0, th = 0;
};

// Projects a world point (px, py, pz) into the normalised image of a camera mounted at
// (cam_x, 0, cam_z) on a unicycle at `r`, looking along the robot x axis. Independent of
// ViSP on purpose: it is the ground truth the ViSP Jacobian is checked against.
struct Proj {
  double x, y, Z;
};
Proj project(const Pose& r, double px, double py, double pz, const TurnLawParams& p) {
  const double c = std::cos(r.th), s = std::sin(r.th);
  const double cxw = r.x + c * p.camera_x_m, cyw = r.y + s * p.camera_x_m;
  const double dx = px - cxw, dy = py - cyw;
  const double fwd = c * dx + s * dy, left = -s * dx + c * dy, up = pz - p.camera_z_m;
  return {-left / fwd, -up / fwd, fwd};
}

Pose step(const Pose& r, double v, double w, double dt) {
  // Exact unicycle integration (arc), so the test model is not the law's own linearisation.
  Pose n = r;
  if (std::abs(w) < 1e-12) {
    n.x += v * dt * std::cos(r.th);
    n.y += v * dt * std::sin(r.th);
  } else {
    n.x += v / w * (std::sin(r.th + w * dt) - std::sin(r.th));
    n.y -= v / w * (std::cos(r.th + w * dt) - std::cos(r.th));
    n.th += w * dt;
  }
  return n;
}

}  // namespace

TEST(TurnLaw, KeypointsRightOfDatabaseTurnRight) {
  TurnLaw law;
  const auto c = law.compute(0.2, 0.0);
  EXPECT_LT(c.w, 0);
  EXPECT_EQ(c.state, Turn::Right);
  EXPECT_DOUBLE_EQ(c.v, law.params().v_forward);
  EXPECT_GT(c.error, 0);
}

TEST(TurnLaw, KeypointsLeftOfDatabaseTurnLeft) {
  TurnLaw law;
  const auto c = law.compute(-0.15, 0.05);
  EXPECT_GT(c.w, 0);
  EXPECT_EQ(c.state, Turn::Left);
}

TEST(TurnLaw, SignsAgreeWithTheGeometry) {
  // A landmark right of the camera axis: turning right (w < 0) must move its image point
  // towards the centre, i.e. decrease x.
  TurnLawParams p;
  TurnLaw law(p);
  const Pose r;
  const double px = 3, py = -0.8, pz = 0.5;
  const auto before = project(r, px, py, pz, p);
  ASSERT_GT(before.x, 0);
  const auto cmd = law.compute(before.x, 0.0, before.Z);
  const auto after = project(step(r, cmd.v, cmd.w, 0.05), px, py, pz, p);
  EXPECT_LT(std::abs(after.x), std::abs(before.x));
}

TEST(TurnLaw, DeadBandGivesStraight) {
  TurnLawParams p;
  p.dead_band = 0.05;
  TurnLaw law(p);
  const auto c = law.compute(0.04, 0.0);
  EXPECT_EQ(c.state, Turn::Straight);
  EXPECT_EQ(c.w, 0.0);
  EXPECT_TRUE(std::isinf(c.radius_m));
  EXPECT_NE(law.compute(0.06, 0.0).state, Turn::Straight);
}

TEST(TurnLaw, SaturatesAndBoundsTheTurnRadius) {
  TurnLawParams p;
  p.max_w = 0.4;
  p.lambda = 5;
  TurnLaw law(p);
  for (double e : {-0.9, -0.5, 0.5, 0.9}) {
    const auto c = law.compute(e, 0.0);
    EXPECT_LE(std::abs(c.w), p.max_w + 1e-12) << e;
    EXPECT_TRUE(c.saturated) << e;
    EXPECT_GE(c.radius_m, p.v_forward / p.max_w - 1e-9) << e;
  }
  const auto small = law.compute(0.03, 0.0);
  EXPECT_FALSE(small.saturated);
  EXPECT_LT(std::abs(small.w), p.max_w);
}

TEST(TurnLaw, GainScalesTheTurn) {
  TurnLawParams lo, hi;
  lo.lambda = 0.3;
  hi.lambda = 0.9;
  lo.feed_forward = hi.feed_forward = false;
  const auto a = TurnLaw(lo).compute(0.1, 0.0), b = TurnLaw(hi).compute(0.1, 0.0);
  EXPECT_NEAR(b.w / a.w, 3.0, 1e-9);
  EXPECT_GT(a.radius_m, b.radius_m);
}

TEST(TurnLaw, JacobianMatchesFiniteDifferences) {
  TurnLawParams p;
  TurnLaw law(p);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> ux(1.5, 6), uy(-2, 2), uz(-0.3, 1.2);
  const double h = 1e-6;
  for (int i = 0; i < 20; ++i) {
    const Pose r;
    const double px = ux(rng), py = uy(rng), pz = uz(rng);
    const auto s0 = project(r, px, py, pz, p);
    const auto J = law.featureJacobian(s0.x, s0.y, s0.Z);
    const double dv =
        (project(step(r, 1, 0, h), px, py, pz, p).x - project(step(r, -1, 0, h), px, py, pz, p).x) /
        (2 * h);
    const double dw =
        (project(step(r, 0, 1, h), px, py, pz, p).x - project(step(r, 0, -1, h), px, py, pz, p).x) /
        (2 * h);
    EXPECT_NEAR(J[0], dv, 1e-5 * (1 + std::abs(dv))) << "point " << i;
    EXPECT_NEAR(J[1], dw, 1e-5 * (1 + std::abs(dw))) << "point " << i;
  }
}

TEST(TurnLaw, ClosedLoopConvergesOnASimulatedUnicycle) {
  // The robot starts 25 deg off a landmark 6 m ahead; servoing on x_d = 0 must bring the
  // landmark to the image centre (within the dead band) well before reaching it, and keep it.
  TurnLawParams p;
  p.dead_band = 0.01;
  TurnLaw law(p);
  Pose r{0, 0, 0.44};
  const double px = 6, py = 0, pz = 0.6;
  double first_in = -1;
  bool left_after = false;
  for (int k = 0; k < 400; ++k) {
    const double t = 0.05 * k;
    const auto s = project(r, px, py, pz, p);
    ASSERT_GT(s.Z, 0.5) << "drove into the landmark";
    ASSERT_LT(std::abs(s.x), 0.577) << "landmark left the 60 deg field of view";
    const bool in = std::abs(s.x) <= p.dead_band + 0.005;
    if (in && first_in < 0) first_in = t;
    if (!in && first_in >= 0) left_after = true;
    if (s.Z < 1.5) break;
    const auto c = law.compute(s.x, 0.0, s.Z);
    r = step(r, c.v, c.w, 0.05);
  }
  ASSERT_GE(first_in, 0) << "never converged";
  EXPECT_LT(first_in, 8.0);
  EXPECT_FALSE(left_after);
}

TEST(TurnLaw, ClosedLoopWithNoisyKeypoints) {
  // Noisy matches aggregated by robustOffset (with 20% gross outliers) still converge.
  TurnLawParams p;
  TurnLaw law(p);
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0, 0.01);
  std::uniform_real_distribution<double> outlier(-0.5, 0.5);
  Pose r{0, 0, -0.4};
  const double px = 7, py = 0.5, pz = 0.6;
  for (int k = 0; k < 200; ++k) {
    const auto s = project(r, px, py, pz, p);
    std::vector<double> xt, xd;
    for (int i = 0; i < 30; ++i) {
      const double d = 0.05 * (i % 5 - 2);  // keypoints spread over the object
      xd.push_back(d);
      xt.push_back(i % 5 == 0 ? outlier(rng) : s.x + d + noise(rng));
    }
    const auto o = robustOffset(xt, xd);
    const auto c = law.compute(o.x_t, o.x_d, s.Z);
    r = step(r, c.v, c.w, 0.05);
  }
  EXPECT_LT(std::abs(project(r, px, py, pz, p).x), 0.04);
}

TEST(RobustOffset, MedianIgnoresOutliers) {
  const auto o = robustOffset({0.1, 0.2, 0.3, 5.0, 0.25}, {0.0, 0.1, 0.2, -3.0, 0.15});
  EXPECT_NEAR(o.error(), 0.1, 1e-12);
  EXPECT_TRUE(std::isnan(robustOffset({}, {}).x_t));
  EXPECT_TRUE(std::isnan(robustOffset({1.0}, {}).error()));
}

TEST(TurnLawParams, ValidateNamesTheField) {
  TurnLawParams p;
  p.lambda = -1;
  try {
    p.validate();
    FAIL() << "no throw";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("servo.lambda"), std::string::npos);
  }
  EXPECT_THROW(TurnLaw().compute(NAN, 0), std::invalid_argument);
}

// One name per quantity: servoing keeps the robot's cruise speed (nav.v_cruise) and takes the
// camera's position from the mount; the old servo.v_forward names the setting that replaced it.
TEST(TurnLawParams, FromTheSettingsWithTheCruiseSpeedAndTheCameraMount) {
  Config c;
  c.set("nav.v_cruise=0.45");
  c.set("robot.camera.x_m=0.2");
  c.set("servo.lambda=0.5");
  const TurnLawParams p = turnLawParamsFrom(c);
  EXPECT_DOUBLE_EQ(p.v_forward, 0.45);
  EXPECT_DOUBLE_EQ(p.camera_x_m, 0.2);
  EXPECT_DOUBLE_EQ(p.lambda, 0.5);
  EXPECT_TRUE(c.unusedKeys().empty());
  EXPECT_DOUBLE_EQ(TurnLaw(p).compute(0.3, 2.0).v, 0.45);
  Config old;
  old.set("servo.v_forward=0.2");
  try {
    turnLawParamsFrom(old);
    FAIL() << "servo.v_forward accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'servo.v_forward' is now 'nav.v_cruise'"),
              std::string::npos)
        << e.what();
  }
  Config bad;
  bad.set("nav.v_cruise=-1");
  EXPECT_THROW(turnLawParamsFrom(bad), InputError);
}
