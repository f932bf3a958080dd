#include <gtest/gtest.h>

#include <cmath>

#include "sketch_fixtures.h"
#include "sketchnav/core/error.h"
#include "sketchnav/mapsketch/io.h"
#include "sketchnav/mapsketch/route.h"

using namespace sketchnav;
using namespace sketchnav::mapsketch;
using fixtures::kTrueScale;

namespace {
std::vector<std::string> orderOf(const Route& r) {
  std::vector<std::string> ids;
  for (const auto& s : r.sections)
    for (const auto& l : s.landmarks) ids.push_back(l.id);
  return ids;
}
const ExpectedLandmark& find(const Route& r, const std::string& id) {
  for (const auto& s : r.sections)
    for (const auto& l : s.landmarks)
      if (l.id == id) return l;
  throw std::logic_error("no landmark " + id);
}
int sectionOf(const Route& r, const std::string& id) {
  for (const auto& s : r.sections)
    for (const auto& l : s.landmarks)
      if (l.id == id) return s.index;
  return -1;
}
}  // namespace

TEST(Simplify, NoisyStraightLineBecomesTwoPoints) {
  const auto pts = fixtures::wobbly({{0, 0}, {500, 0}}, 5, 3, 1);
  const auto kept = simplifyPolyline(pts, 10);
  ASSERT_EQ(kept.size(), 2u);
  EXPECT_EQ(kept.front(), 0);
  EXPECT_EQ(kept.back(), static_cast<int>(pts.size()) - 1);
}

TEST(Simplify, KeepsTheCornersOfAWobblyL) {
  const auto pts = fixtures::wobbly({{0, 0}, {500, 0}, {500, 400}}, 5, 3, 2);
  const auto kept = simplifyPolyline(pts, 20);
  ASSERT_EQ(kept.size(), 3u);
  EXPECT_LT((pts[kept[1]] - Eigen::Vector2d(500, 0)).norm(), 10);
}

TEST(Simplify, ShortInputsAreKept) {
  EXPECT_EQ(simplifyPolyline({}, 1).size(), 0u);
  EXPECT_EQ(simplifyPolyline({{0, 0}, {1, 1}}, 1).size(), 2u);
}

TEST(ClosestOnPolyline, DistanceAndArcLengthOfTheNearestPoint) {
  const std::vector<Eigen::Vector2d> l = {{0, 0}, {4, 0}, {4, 3}};
  auto at = closestOnPolyline({2, 1}, l);  // above the first leg
  EXPECT_DOUBLE_EQ(at.distance, 1);
  EXPECT_DOUBLE_EQ(at.arc, 2);
  at = closestOnPolyline({5, 2}, l);  // beside the second leg
  EXPECT_DOUBLE_EQ(at.distance, 1);
  EXPECT_DOUBLE_EQ(at.arc, 6);
  at = closestOnPolyline({-3, -4}, l);  // before the start: the start
  EXPECT_DOUBLE_EQ(at.distance, 5);
  EXPECT_DOUBLE_EQ(at.arc, 0);
  at = closestOnPolyline({4, 10}, l);  // past the end: the end
  EXPECT_DOUBLE_EQ(at.distance, 7);
  EXPECT_DOUBLE_EQ(at.arc, 7);
  EXPECT_DOUBLE_EQ(closestOnPolyline({3, 4}, {{0, 0}}).distance, 5);
  EXPECT_TRUE(std::isinf(closestOnPolyline({0, 0}, {}).distance));
}

TEST(ScaleFit, ConsistentDistancesGiveExactScaleAndZeroResidual) {
  const auto f = fitScale({100, 200, 50}, {2, 4, 1});
  EXPECT_NEAR(f.scale, 0.02, 1e-12);
  EXPECT_NEAR(f.rms_relative, 0, 1e-9);
}

TEST(ScaleFit, OneWildDistanceBarelyMovesTheScale) {
  // Four consistent pairs at 0.02 m/px, one distance three times too long.
  const auto f = fitScale({100, 200, 150, 120, 80}, {2, 4, 3, 2.4, 4.8});
  EXPECT_NEAR(f.scale, 0.02, 0.02 * 0.03);
  EXPECT_GT(f.rms_relative, 0.2);  // the inconsistency is reported, not hidden
  EXPECT_LT(f.weight[4], 0.1);
  EXPECT_GT(f.weight[0], 0.9);
}

TEST(ScaleFit, NoUsablePairThrows) {
  EXPECT_THROW(fitScale({0, 0}, {1, 2}), InputError);
}

TEST(Route, LSketchHasTwoSectionsWithTheRightTurnAndLengths) {
  const Route r = toRoute(fixtures::lSketch());
  ASSERT_EQ(r.sections.size(), 2u);
  ASSERT_EQ(r.guide_points_m.size(), 3u);
  EXPECT_NEAR(r.scale_m_per_px, kTrueScale, kTrueScale * 0.01);
  EXPECT_LT(r.scale_residual, 1e-9);
  EXPECT_NEAR(r.sections[0].length_m, 14.0, 0.3);
  EXPECT_NEAR(r.sections[1].length_m, 10.0, 0.3);
  EXPECT_NEAR(r.total_length_m, 24.0, 0.5);
  // Route frame: origin at the start, canvas y flipped, so the first leg heads +x and the
  // turn up the canvas is a left (CCW, positive) turn.
  EXPECT_NEAR(r.start_m.norm(), 0, 1e-12);
  EXPECT_NEAR(r.start_heading_rad, 0, 0.03);
  EXPECT_NEAR(r.sections[0].heading_change_rad, 0, 1e-12);
  EXPECT_NEAR(r.sections[1].heading_change_rad, M_PI / 2, 0.03);
  EXPECT_NEAR(r.goal_m.x(), 14.0, 1e-9);
  EXPECT_NEAR(r.goal_m.y(), 10.0, 1e-9);
  EXPECT_TRUE(r.distance_outliers.empty());
}

TEST(Route, LandmarksInSequenceOrderWithSideRangeAndAlong) {
  const Route r = toRoute(fixtures::lSketch());
  EXPECT_EQ(orderOf(r), (std::vector<std::string>{"A", "B", "C", "D"}));
  EXPECT_EQ(sectionOf(r, "A"), 0);
  EXPECT_EQ(sectionOf(r, "B"), 0);
  EXPECT_EQ(sectionOf(r, "C"), 1);
  EXPECT_EQ(sectionOf(r, "D"), 1);
  const auto& a = find(r, "A");
  EXPECT_EQ(a.side, Side::Left);
  EXPECT_EQ(a.order, 0);
  EXPECT_NEAR(a.range_m, 80 * kTrueScale, 0.15);
  EXPECT_NEAR(a.along_m, 200 * kTrueScale, 0.15);
  EXPECT_EQ(find(r, "B").side, Side::Right);
  EXPECT_NEAR(find(r, "B").range_m, 80 * kTrueScale, 0.15);
  const auto& c = find(r, "C");
  EXPECT_EQ(c.side, Side::Right);
  EXPECT_NEAR(c.range_m, 80 * kTrueScale, 0.15);
  EXPECT_NEAR(c.along_m, 300 * kTrueScale, 0.15);
  EXPECT_EQ(find(r, "D").side, Side::Ahead);
  EXPECT_EQ(find(r, "D").order, 3);
  EXPECT_NEAR(find(r, "D").position_m.y(), 560 * kTrueScale, 1e-9);
}

TEST(Route, ScaleOffByThirtyPercentScalesTheRouteAndStaysConsistent) {
  Sketch s = fixtures::lSketch();
  for (auto& l : s.landmarks) l.distance_m *= 1.3;  // the user thinks everything is 30 % farther
  const Route r = toRoute(s);
  EXPECT_NEAR(r.scale_m_per_px, 1.3 * kTrueScale, 1e-3 * kTrueScale);
  EXPECT_LT(r.scale_residual, 1e-9);
  EXPECT_NEAR(r.sections[0].length_m, 1.3 * 14.0, 0.4);
  EXPECT_EQ(orderOf(r), (std::vector<std::string>{"A", "B", "C", "D"}));
}

TEST(Route, OneDistanceThirtyPercentOffIsToleratedAndReported) {
  Sketch s = fixtures::lSketch();
  s.landmarks[2].distance_m *= 1.3;
  const Route r = toRoute(s);
  EXPECT_NEAR(r.scale_m_per_px, kTrueScale, 0.08 * kTrueScale);
  EXPECT_GT(r.scale_residual, 0.05);
  EXPECT_EQ(r.sections.size(), 2u);
}

TEST(Route, AWildDistanceIsNamedAsAnOutlier) {
  Sketch s = fixtures::lSketch();
  s.landmarks[1].distance_m *= 4;
  const Route r = toRoute(s);
  EXPECT_NEAR(r.scale_m_per_px, kTrueScale, 0.05 * kTrueScale);
  ASSERT_EQ(r.distance_outliers.size(), 1u);
  EXPECT_EQ(r.distance_outliers[0], "B");
  EXPECT_FALSE(r.warnings.empty());
}

TEST(Route, DisplacedLandmarksKeepOrderAndSides) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-30, 30);
  for (int trial = 0; trial < 20; ++trial) {
    Sketch s = fixtures::lSketch(100 + trial);
    for (auto& l : s.landmarks) {  // moved on the canvas, distances as the user remembers them
      l.rect.x += u(rng);
      l.rect.y += u(rng);
    }
    const Route r = toRoute(s);
    EXPECT_EQ(orderOf(r), (std::vector<std::string>{"A", "B", "C", "D"})) << "trial " << trial;
    EXPECT_EQ(find(r, "A").side, Side::Left) << "trial " << trial;
    EXPECT_EQ(find(r, "B").side, Side::Right) << "trial " << trial;
    EXPECT_EQ(find(r, "C").side, Side::Right) << "trial " << trial;
    EXPECT_NEAR(r.scale_m_per_px, kTrueScale, 0.15 * kTrueScale) << "trial " << trial;
    EXPECT_EQ(r.sections.size(), 2u) << "trial " << trial;
  }
}

TEST(Route, RepeatedClassesAreKeptApartByOrderAndPosition) {
  Sketch s = fixtures::lSketch();
  // A and C share a class; add a third of it on the far side of the first leg.
  SketchLandmark e = fixtures::lm("E", "Oatly-Oat-Milk", 450, 680);
  e.distance_m = 1;
  s.landmarks.push_back(e);
  const Route r = toRoute(s);
  EXPECT_EQ(orderOf(r), (std::vector<std::string>{"A", "E", "B", "C", "D"}));
  const auto& a = find(r, "A");
  const auto& ee = find(r, "E");
  EXPECT_EQ(a.class_name, ee.class_name);
  EXPECT_LT(a.order, ee.order);
  EXPECT_NE(a.side, ee.side);
  EXPECT_GT((a.position_m - ee.position_m).norm(), 1.0);
}

TEST(Route, APathDrawnBackwardsIsReversed) {
  Sketch s = fixtures::lSketch();
  std::reverse(s.path.begin(), s.path.end());
  const Route r = toRoute(s);
  EXPECT_EQ(orderOf(r), (std::vector<std::string>{"A", "B", "C", "D"}));
  EXPECT_NEAR(r.sections[1].heading_change_rad, M_PI / 2, 0.03);
  ASSERT_FALSE(r.warnings.empty());
  EXPECT_NE(r.warnings[0].find("reversed"), std::string::npos);
}

TEST(Route, StartAndGoalAwayFromThePathAreJoinedToIt) {
  Sketch s = fixtures::lSketch();
  s.path.erase(s.path.begin(), s.path.begin() + 20);  // the user began drawing 100 px late
  const Route r = toRoute(s);
  EXPECT_NEAR(r.guide_points_m.front().norm(), 0, 1e-12);
  EXPECT_EQ(r.guide_point_path_index.front(), -1);
  EXPECT_NEAR(r.total_length_m, 24.0, 0.5);
}

TEST(Route, IsAPureFunction) {
  const Sketch s = fixtures::lSketch();
  EXPECT_EQ(routeToJson(toRoute(s)).dump(), routeToJson(toRoute(s)).dump());
}

TEST(Route, InvalidSketchThrows) {
  Sketch s = fixtures::lSketch();
  s.path.resize(1);
  EXPECT_THROW(toRoute(s), InputError);
}

TEST(Route, RouteJsonHasTheContractFields) {
  const Json j = routeToJson(toRoute(fixtures::lSketch()));
  EXPECT_EQ(j["sections"].size(), 2u);
  EXPECT_EQ(j["sections"][0]["landmarks"][0]["side"], "left");
  EXPECT_EQ(j["sections"][1]["landmarks"][1]["side"], "ahead");
  EXPECT_TRUE(j.contains("scale_m_per_px"));
  EXPECT_TRUE(j.contains("scale_residual"));
  EXPECT_EQ(j["guide_points_m"].size(), 3u);
}

TEST(Route, StartHeadingFollowsAShortFirstStrokeTheSimplificationDrops) {
  // The line leaves the start 27 degrees up-canvas for 1.3 m, then bends into a long leg: the
  // bend is within the simplification tolerance, so the first section runs straight from the
  // start, but the robot is put down along the stroke the user drew.
  Sketch s = fixtures::lSketch();
  const double px_per_m = 1.0 / fixtures::kTrueScale;
  const Eigen::Vector2d bend = s.start + Eigen::Vector2d(1.2, -0.6) * px_per_m;
  s.path = fixtures::wobbly({s.start, bend, {800, 600}, {800, 100}}, 5, 0.5, 3);
  s.path.front() = s.start;
  s.path.back() = s.goal;
  const Route r = toRoute(s);
  ASSERT_EQ(r.sections.size(), 2u) << "the bend was expected to be simplified away";
  EXPECT_NEAR(r.sections[0].heading_rad, 0.0, 0.06);
  EXPECT_NEAR(r.start_heading_rad, std::atan2(0.6, 1.2), 0.06);
  RouteParams p;
  p.start_tangent_m = 0;
  EXPECT_THROW(toRoute(s, p), InputError);
}
