// The route anchor on its own: the fixes it keeps, the same-class test, and what a passed
// landmark does to the route (realign and reanchor before the fixes span fit_min_span_m, a
// least-squares refit after).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "route_util.h"
#include "sketchnav/nav/route_anchor.h"

namespace sketchnav::nav {
namespace {

// Sightings of a landmark at `lm` (odometry frame) taken driving along y = 0 from x0 to x1,
// bearings with a little noise, no ranges (the bearings cross: a triangulated fix).
std::vector<Sighting> driveBy(const Eigen::Vector2d& lm, double x0, double x1,
                              std::uint32_t seed = 3) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> nb(0.0, 0.3 * M_PI / 180);
  std::vector<Sighting> ss;
  for (int i = 0; i < 10; ++i) {
    const Eigen::Vector2d o(x0 + (x1 - x0) * i / 9.0, 0.0);
    const Eigen::Vector2d d = lm - o;
    ss.push_back({o, std::atan2(d.y(), d.x()) + nb(rng), 0.0});
  }
  return ss;
}

// A straight 12 m route along x; landmarks A (carton) at 4 m and B, C (cartons) further on.
SectionTracker straightRoute() {
  return SectionTracker(test::makeRoute({{0, 0}, {12, 0}}));
}

TEST(RouteAnchor, StartsWithTheStartAsItsOnlyFix) {
  auto route = straightRoute();
  RouteAnchor anchor;
  anchor.start(route);
  ASSERT_EQ(anchor.fixes().size(), 1u);
  const Fix& f = anchor.fixes()[0];
  EXPECT_EQ(f.class_name, "");
  EXPECT_FALSE(f.bearingOnly());
  EXPECT_NEAR((f.route - Eigen::Vector2d(0, 0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((f.odom - route.toOdom({0, 0})).norm(), 0.0, 1e-12);
  // Trusted to 5 cm: where the user put the robot.
  EXPECT_NEAR(f.information(0, 0), 400.0, 1e-9);
}

TEST(RouteAnchor, AFirstFixShiftsTheRouteByTheReanchorGain) {
  auto route = straightRoute();
  RouteAnchorParams p;
  p.realign_baseline_m = 100;  // no rotation: the shift alone
  RouteAnchor anchor(p);
  anchor.start(route);
  // The sketch puts the carton at (4, 1); it stands at (4, 1.5).
  const Eigen::Vector2d sketch(4, 1), truth(4, 1.5);
  const auto c = anchor.correct(route, sketch, "carton", driveBy(truth, 0.5, 3.0), LocateParams{});
  ASSERT_TRUE(c.fix.has_value());
  EXPECT_FALSE(c.rejected.has_value());
  EXPECT_EQ(c.fix->method, "bearings");
  ASSERT_TRUE(c.fix->realign.has_value());
  EXPECT_FALSE(c.fix->fit.has_value());
  EXPECT_NEAR(c.fix->disagreement_m, 0.5, 0.05);
  EXPECT_NEAR(c.fix->realign->reanchor_m, 0.8 * c.fix->disagreement_m, 1e-9);
  EXPECT_NEAR(c.fix->realign->realign_deg, 0.0, 1e-9);
  // The route moved 0.8 of the way: the sketch's point is now 0.1 m from the carton.
  EXPECT_NEAR((route.toOdom(sketch) - truth).norm(), 0.1, 0.05);
  ASSERT_EQ(anchor.fixes().size(), 2u);
  EXPECT_EQ(anchor.fixes()[1].class_name, "carton");
  EXPECT_EQ(c.fix->sightings.size(), 10u);
}

TEST(RouteAnchor, FixesSpanningFitMinSpanRefitTheRoute) {
  auto route = straightRoute();
  RouteAnchorParams p;
  p.fit_min_span_m = 5.0;
  RouteAnchor anchor(p);
  anchor.start(route);
  // The drawing is 10 % too long: every landmark stands at 0.9 x its sketched place.
  const Eigen::Vector2d a(3, 1), b(6, -1), c(9, 1);
  const auto ca = anchor.correct(route, a, "sign", driveBy(0.9 * a, 0.3, 2.2, 1), {});
  ASSERT_TRUE(ca.fix && ca.fix->realign);  // start and A span 3.2 m: not yet
  const auto cb = anchor.correct(route, b, "carton", driveBy(0.9 * b, 2.5, 4.8, 2), {});
  ASSERT_TRUE(cb.fix);
  ASSERT_TRUE(cb.fix->fit.has_value()) << "start, A, B span 6 m";
  EXPECT_FALSE(cb.fix->realign.has_value());
  EXPECT_EQ(cb.fix->fit->fixes, 3u);
  const auto cc = anchor.correct(route, c, "box", driveBy(0.9 * c, 5.5, 7.6, 3), {});
  ASSERT_TRUE(cc.fix && cc.fix->fit);
  EXPECT_EQ(cc.fix->fit->fixes, 4u);
  EXPECT_NEAR(route.scale(), 0.9, 0.03);
  // The goal comes in with the landmarks: 12 m drawn, 10.8 m true.
  EXPECT_NEAR(route.toOdom({12, 0}).x(), 10.8, 0.15);
}

TEST(RouteAnchor, TheSameClassAtAnEarlierFixIsThatLandmarkAgain) {
  auto route = straightRoute();
  RouteAnchor anchor;
  anchor.start(route);
  const Eigen::Vector2d first(4, 1);
  ASSERT_TRUE(anchor.correct(route, first, "carton", driveBy(first, 0.5, 3.0), {}).fix);
  const Eigen::Vector2d at = anchor.fixes()[1].odom;
  // A ranged detection from (2, 0) pointing at that fix, 0.3 m short of it: the same carton.
  const Eigen::Vector2d o(2, 0);
  const double dir = std::atan2(at.y() - o.y(), at.x() - o.x());
  const double r = (at - o).norm();
  EXPECT_TRUE(anchor.atEarlierFix("carton", o, dir, r - 0.3, 4.0));
  EXPECT_FALSE(anchor.atEarlierFix("carton", o, dir, r + 1.5, 4.0)) << "1.5 m beyond it";
  EXPECT_FALSE(anchor.atEarlierFix("sign", o, dir, r, 4.0)) << "another class";
  // Without a usable range (or beyond the ranged limit), the ray: through it ahead, yes;
  // 0.6 m to its side (more than half the gate), no; pointing away, no.
  EXPECT_TRUE(anchor.atEarlierFix("carton", o, dir, 0.0, 4.0));
  EXPECT_TRUE(anchor.atEarlierFix("carton", o, dir, 9.0, 4.0));
  EXPECT_FALSE(anchor.atEarlierFix("carton", o, dir + std::atan2(0.6, r), 0.0, 4.0));
  EXPECT_FALSE(anchor.atEarlierFix("carton", o, dir + M_PI, 0.0, 4.0));
  // A second carton located there is rejected and changes nothing.
  const Eigen::Vector2d second(8, 1);
  const Eigen::Vector2d before = route.toOdom(second);
  const auto c = anchor.correct(route, second, "carton", driveBy(at, 1.0, 3.2, 5), {});
  EXPECT_FALSE(c.fix.has_value());
  ASSERT_TRUE(c.rejected.has_value());
  EXPECT_EQ(*c.rejected, "where an earlier carton was");
  EXPECT_EQ(anchor.fixes().size(), 2u);
  EXPECT_NEAR((route.toOdom(second) - before).norm(), 0.0, 1e-12);
}

TEST(RouteAnchor, BearingOnlyFixesShiftOnlyAcrossTheirRaysAndNeedTheWeightedFit) {
  // Seen from one place only: the rays do not cross, the fix is bearing-only.
  const Eigen::Vector2d sketch(5, 0.5), truth(5, 1.0);
  std::vector<Sighting> one(5, Sighting{{0, 0}, std::atan2(1.0, 5.0), 0.0});
  {
    auto route = straightRoute();
    RouteAnchorParams p;
    p.realign_baseline_m = 100;
    RouteAnchor anchor(p);
    anchor.start(route);
    const Eigen::Vector2d before = route.toOdom(sketch);
    const auto c = anchor.correct(route, sketch, "sign", one, {});
    ASSERT_TRUE(c.fix.has_value());
    EXPECT_EQ(c.fix->method, "bearing only");
    ASSERT_EQ(anchor.fixes().size(), 2u);
    EXPECT_TRUE(anchor.fixes()[1].bearingOnly());
    // The shift is across the ray (the ray's normal), never along it.
    const Eigen::Vector2d moved = route.toOdom(sketch) - before;
    const Eigen::Vector2d along(std::cos(one.back().direction), std::sin(one.back().direction));
    EXPECT_GT(moved.norm(), 0.2);
    EXPECT_NEAR(moved.dot(along), 0.0, 1e-9);
    // A bearing-only fix is no point: it never makes a later detection "the same one".
    EXPECT_FALSE(anchor.atEarlierFix("sign", {0, 0}, std::atan2(1.0, 5.0), 0.0, 4.0));
  }
  {
    auto route = straightRoute();
    RouteAnchorParams p;
    p.fit_weighted = false;  // an equal-weight fit would take its nominal point as exact
    RouteAnchor anchor(p);
    anchor.start(route);
    const auto c = anchor.correct(route, sketch, "sign", one, {});
    EXPECT_FALSE(c.fix.has_value());
    EXPECT_FALSE(c.rejected.has_value());
    EXPECT_EQ(anchor.fixes().size(), 1u);
  }
}

TEST(RouteAnchor, NoSightingsNoFix) {
  auto route = straightRoute();
  RouteAnchor anchor;
  anchor.start(route);
  const auto c = anchor.correct(route, {4, 1}, "carton", {}, {});
  EXPECT_FALSE(c.fix.has_value());
  EXPECT_FALSE(c.rejected.has_value());
  EXPECT_EQ(anchor.fixes().size(), 1u);
}

TEST(RouteAnchorParams, ValidateNamesTheSetting) {
  RouteAnchorParams p;
  EXPECT_NO_THROW(p.validate());
  p.fit_fixes = 2;
  try {
    p.validate();
    FAIL() << "fit_fixes = 2 accepted";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("nav.fit_fixes"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace sketchnav::nav
