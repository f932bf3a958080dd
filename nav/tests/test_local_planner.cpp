// Local planner: the occupancy grid built from laser scans (marking, clearing a moved
// obstacle), A* round an obstacle on the open side with the clearance kept, goals snapped out
// of an obstacle's clearance, an enclosed goal refused, the carrot along a path.
#include <gtest/gtest.h>

#include <cmath>

#include "scan_sim.h"
#include "sketchnav/core/error.h"
#include "sketchnav/nav/local_planner.h"

using namespace sketchnav;
using namespace sketchnav::nav;
using namespace sketchnav::nav::test;

namespace {
void look(LocalPlanner& p, const std::vector<hw::Pose2D>& poses, const std::vector<Box>& boxes) {
  for (const auto& q : poses) p.insert(q, scanAt(q, boxes));
}
double minDistToBox(const Eigen::Vector2d& p, const Box& b) {
  const double dx = std::max(0.0, std::abs(p.x() - b.cx) - b.hx);
  const double dy = std::max(0.0, std::abs(p.y() - b.cy) - b.hy);
  return std::hypot(dx, dy);
}
}  // namespace

TEST(LocalPlanner, GridMarksWhatTheLaserSees) {
  LocalPlanner p;
  auto boxes = room();
  boxes.push_back({3, 0, 0.3, 0.3});
  look(p, {{0, 0, 0}}, boxes);
  EXPECT_EQ(p.scansInserted(), 1);
  EXPECT_TRUE(p.occupied({2.72, 0.0}));  // the box's near face
  EXPECT_FALSE(p.occupied({1.5, 0.0}));  // seen through
  EXPECT_FALSE(p.segmentClear({0, 0}, {6, 0}, 0.3));
  EXPECT_TRUE(p.segmentClear({0, 0}, {1.5, 1.5}, 0.3));
  // A sonar scan does not mark the grid.
  hw::RangeScan sonar = scanAt({0, 0, 0}, boxes);
  sonar.kind = hw::RangeScan::Kind::Sonar;
  p.insert({0, 0, 0}, sonar);
  EXPECT_EQ(p.scansInserted(), 1);
}

TEST(LocalPlanner, OpenFloorIsFreeAllRoundNotJustInFrontOfASurface) {
  LocalPlanner p;
  auto boxes = room();
  boxes.push_back({3, 0, 0.3, 0.3});
  for (int i = 0; i < 5; ++i) look(p, {{0, 0, 0}}, boxes);
  EXPECT_TRUE(p.seenFreeAround({1.5, 0.0}));
  // The cell just in front of the box's near face (2.7 m) was seen free, the next is the box.
  EXPECT_TRUE(p.seenFree({2.62, 0.0}));
  EXPECT_FALSE(p.seenFreeAround({2.62, 0.0}));
  EXPECT_FALSE(p.seenFreeAround({9.0, 0.0}));  // beyond the room: never seen
}

TEST(LocalPlanner, GoesRoundAnObstacleKeepingClearance) {
  LocalPlanner p;
  auto boxes = room();
  const Box obstacle{3, 0, 0.3, 0.3};
  boxes.push_back(obstacle);
  look(p, {{0, 0, 0}, {1, 1, 0}, {1, -1, 0}}, boxes);
  const auto path = p.plan({0, 0}, {6, 0});
  ASSERT_TRUE(path.found);
  EXPECT_FALSE(path.goal_moved);
  EXPECT_NEAR(path.points.back().x(), 6, 1e-9);
  EXPECT_GT(path.length_m, 6.05);  // not through the box
  EXPECT_LT(path.length_m, 8.0);   // but not a long way round either
  double worst = 1e9;
  for (const auto& q : path.points) worst = std::min(worst, minDistToBox(q, obstacle));
  // Cell-centre geometry costs up to half a cell diagonal against the box's true faces.
  EXPECT_GE(worst, p.params().clearance_m - 0.08);
  EXPECT_GE(path.min_clearance_m, p.params().clearance_m - 1e-6);
}

TEST(LocalPlanner, TakesTheOpenSide) {
  for (double side : {+1.0, -1.0}) {
    LocalPlanner p;
    auto boxes = room();
    // A bench from the obstacle to the wall on one side: only the other side is open.
    boxes.push_back({3, side * 1.5, 0.3, 1.5});
    look(p, {{0, 0, 0}, {1, 1, 0}, {1, -1, 0}, {0, 2, 0}, {0, -2, 0}}, boxes);
    const auto path = p.plan({0, 0}, {6, 0});
    ASSERT_TRUE(path.found) << side;
    double extreme = 0;
    for (const auto& q : path.points)
      if (std::abs(q.x() - 3) < 0.2) extreme = q.y();
    EXPECT_LT(extreme * side, -0.4) << "went round the closed side " << side;
  }
}

TEST(LocalPlanner, KeepsToTheMiddleOfAGap) {
  LocalPlanner p;
  auto boxes = room();
  // Two boxes leave a 1.2 m gap centred on y = 0.4; the rest of x = 3 is closed.
  boxes.push_back({3, 2.0, 0.3, 1.0});   // y in [1.0, 3.0]
  boxes.push_back({3, -1.7, 0.3, 1.5});  // y in [-3.2, -0.2]
  look(p, {{0, 0, 0}, {1, 0.5, 0}, {0, -1, 0}}, boxes);
  const auto path = p.plan({0, 0}, {6, 0});
  ASSERT_TRUE(path.found);
  for (const auto& q : path.points)
    if (std::abs(q.x() - 3) < 0.05) EXPECT_NEAR(q.y(), 0.4, 0.15);
}

TEST(LocalPlanner, GoalAgainstAWallMovesOutOfItsClearance) {
  LocalPlanner p;
  look(p, {{0, 0, 0}, {3, 0, 0}}, room());
  const Eigen::Vector2d goal(7.9, 0.0);  // 0.05 m from the far wall
  const auto path = p.plan({0, 0}, goal);
  ASSERT_TRUE(path.found);
  EXPECT_TRUE(path.goal_moved);
  EXPECT_LE((path.goal - goal).norm(), p.params().goal_snap_m);
  EXPECT_GE(7.95 - path.goal.x(), p.params().clearance_m - 0.08);
  EXPECT_NEAR(path.points.back().x(), path.goal.x(), 1e-9);
}

TEST(LocalPlanner, EnclosedGoalIsNotFound) {
  PlannerParams wide;  // a wider window could be tried, but no wider window can help
  wide.max_window_margin_m = 12;
  LocalPlanner p(wide);
  auto boxes = room();
  // A closed pen round (5, 0).
  boxes.push_back({5, 1.5, 1.5, 0.05});
  boxes.push_back({5, -1.5, 1.5, 0.05});
  boxes.push_back({3.5, 0, 0.05, 1.5});
  boxes.push_back({6.5, 0, 0.05, 1.5});
  look(p, {{0, 0, 0}, {1, 2.2, 0}, {1, -2.2, 0}, {7.5, 2.2, M_PI}, {7.5, -2.2, M_PI}}, boxes);
  const auto pen = p.plan({0, 0}, {5, 0});
  EXPECT_FALSE(pen.found);
  EXPECT_TRUE(pen.enclosed);  // proven: the search ran out of cells before the window's edge
  EXPECT_EQ(pen.window_margin_m, p.params().window_margin_m);  // so no wider window was tried
  EXPECT_TRUE(p.plan({0, 0}, {7.5, 0}).found);
}

TEST(LocalPlanner, WidensTheWindowToFindTheWayRoundALongBlockage) {
  // A hall 30 x 24 m; a partition across the straight line, 11 m long, with the way round
  // its ends 5.5 m to either side: outside the first window (3 m round start and goal).
  const std::vector<Box> hall = {
      {3, -12, 15, 0.05}, {3, 12, 15, 0.05}, {-12, 0, 0.05, 12}, {18, 0, 0.05, 12}};
  auto boxes = hall;
  boxes.push_back({3, 0, 0.05, 5.5});
  PlannerParams wide;
  wide.max_window_margin_m = 12;
  LocalPlanner p(wide);
  look(p, {{0, 0, 0}, {0, 4, 0}, {0, -4, 0}, {6, 0, M_PI}, {6, 4, M_PI}, {6, -4, M_PI}}, boxes);
  const auto path = p.plan({0, 0}, {6, 0});
  ASSERT_TRUE(path.found);
  EXPECT_GT(path.window_margin_m, p.params().window_margin_m);
  EXPECT_GT(path.length_m, 2 * std::hypot(3, 5.5));  // round an end, not through
  double worst = 1e9;
  for (const auto& q : path.points) worst = std::min(worst, minDistToBox(q, boxes.back()));
  EXPECT_GE(worst, p.params().robot_radius_m);

  // Limited to the first window, there is no way, and none is claimed proven.
  PlannerParams narrow;
  narrow.max_window_margin_m = narrow.window_margin_m;
  LocalPlanner q(narrow);
  look(q, {{0, 0, 0}, {0, 4, 0}, {0, -4, 0}, {6, 0, M_PI}, {6, 4, M_PI}, {6, -4, M_PI}}, boxes);
  const auto none = q.plan({0, 0}, {6, 0});
  EXPECT_FALSE(none.found);
  EXPECT_FALSE(none.enclosed);
}

TEST(LocalPlanner, MovedObstacleIsErased) {
  LocalPlanner p;
  auto boxes = room();
  auto with = boxes;
  with.push_back({3, 0, 0.3, 0.3});  // a person standing there ...
  for (int i = 0; i < 5; ++i) look(p, {{0, 0, 0}}, with);
  EXPECT_FALSE(p.segmentClear({0, 0}, {6, 0}, 0.3));
  for (int i = 0; i < 10; ++i) look(p, {{0, 0, 0}}, boxes);  // ... who walked away
  EXPECT_TRUE(p.segmentClear({0, 0}, {6, 0}, 0.3));
  EXPECT_FALSE(p.occupied({2.72, 0.0}));
}

TEST(LocalPlanner, StartTooCloseToAnObstacleStillPlansOut) {
  LocalPlanner p;
  auto boxes = room();
  boxes.push_back({1.0, 0.41, 1.0, 0.2});  // a bench 0.21 m beside the robot
  look(p, {{0, 0, 0}}, boxes);
  const auto path = p.plan({0, 0}, {4, -1});
  EXPECT_TRUE(path.found);
}

TEST(LocalPlanner, CarrotFollowsThePath) {
  PlannedPath path;
  path.points = {{0, 0}, {1, 0}, {1, 1}, {1, 2}};
  const auto c = LocalPlanner::carrot(path, {0.1, 0.05}, 1.2);
  EXPECT_NEAR(c.x(), 1.0, 1e-9);
  EXPECT_NEAR(c.y(), 0.2, 1e-9);
  EXPECT_NEAR(LocalPlanner::carrot(path, {1, 1.9}, 5).y(), 2.0, 1e-9);  // clamped at the end
}

TEST(LocalPlanner, ParamsNameTheBadField) {
  PlannerParams p;
  p.clearance_m = 0.1;  // below the robot radius
  try {
    LocalPlanner lp(p);
    FAIL() << "accepted clearance below the radius";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("nav.planner.clearance_m"), std::string::npos);
  }
}
