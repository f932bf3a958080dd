// Doorways in laser scans (findDoorways): an opening in a straight wall is found with its
// jambs, width and the side the robot stands on, from straight on and obliquely, with noise
// and with the scan's mount offset; an opening too narrow or too wide, the gap between a box
// and the wall behind it, and an opening with something standing in it are not doorways.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "fake_world.h"
#include "sketchnav/nav/doorway.h"

using namespace sketchnav;
using namespace sketchnav::nav;

namespace {

struct Seg {
  Eigen::Vector2d a, b;
};

// A 240 deg, 1 deg laser at `pose` (mount offset `mx` ahead) over line segments, with
// Gaussian range noise; beams that hit nothing read max_range.
hw::RangeScan scanOf(const std::vector<Seg>& segs, const hw::Pose2D& pose, double noise = 0,
                     double mx = 0, unsigned seed = 1) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0, noise > 0 ? noise : 1);
  hw::RangeScan s;
  s.kind = hw::RangeScan::Kind::Laser;
  s.min_range = 0.05f;
  s.max_range = 8.0f;
  s.mount.x = mx;
  const Eigen::Vector2d o(pose.x + mx * std::cos(pose.theta), pose.y + mx * std::sin(pose.theta));
  for (int i = -120; i <= 120; ++i) {
    const double a = i * M_PI / 180, g = pose.theta + a;
    const Eigen::Vector2d d(std::cos(g), std::sin(g));
    double best = 8.0;
    for (const auto& sg : segs) best = std::min(best, test::rayToSegment(o, d, sg.a, sg.b));
    if (best < 8.0 && noise > 0) best += n(rng);
    s.angles.push_back(static_cast<float>(a));
    s.ranges.push_back(static_cast<float>(best));
  }
  return s;
}

// The lab's room B corner: the wall x = 18 with the right door (y 2.0-3.2) and the wall y = 0.
std::vector<Seg> labCorner(double door_from = 2.0, double door_to = 3.2) {
  return {{{18, -1}, {18, door_from}}, {{18, door_to}, {18, 9}}, {{10, 0}, {18, 0}}};
}

}  // namespace

TEST(Doorway, FindsTheOpeningInAWallStraightOn) {
  const hw::Pose2D pose{16.0, 2.6, 0.0};
  const auto doors = findDoorways(scanOf(labCorner(), pose), pose);
  ASSERT_EQ(doors.size(), 1u);
  const auto& d = doors[0];
  // Jambs are the last beams on the wall: within one beam spacing (2 m x 1 deg) of the ends.
  EXPECT_NEAR(d.centre.x(), 18.0, 0.01);
  EXPECT_NEAR(d.centre.y(), 2.6, 0.04);
  EXPECT_NEAR(d.width_m, 1.2, 0.08);
  EXPECT_NEAR(d.normal.x(), -1.0, 1e-3);  // towards the robot's side of the wall
  EXPECT_NEAR(d.normal.y(), 0.0, 0.01);
}

TEST(Doorway, FindsItObliquelyWithNoiseAndAMountOffset) {
  // Where the robot comes from in the lab: up the room, facing down it, the door to its left
  // front... here mirrored: facing -y with the wall on its left.
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const hw::Pose2D pose{16.9, 4.2, -M_PI / 2};
    const auto doors = findDoorways(scanOf(labCorner(), pose, 0.01, 0.15, seed), pose);
    ASSERT_EQ(doors.size(), 1u) << "seed " << seed;
    EXPECT_NEAR(doors[0].centre.x(), 18.0, 0.05);
    EXPECT_NEAR(doors[0].centre.y(), 2.6, 0.08);
    EXPECT_LT(doors[0].normal.x(), -0.99);
    const Eigen::Vector2d stop = doors[0].centre + 0.6 * doors[0].normal;
    EXPECT_LT((stop - Eigen::Vector2d(17.4, 2.6)).norm(), 0.1) << "seed " << seed;
  }
}

TEST(Doorway, ThickWallsJambEndFacesAndCloseRange) {
  // The lab's walls are 0.12 m thick: close to the door and at a slant, the beams hit the
  // jambs' end faces, 6-18 cm behind the wall's face. The robot where it stops for the
  // paper's goal (facing the door), and on its way there.
  auto box = [](double x0, double y0, double x1, double y1) {
    return std::vector<Seg>{
        {{x0, y0}, {x1, y0}}, {{x1, y0}, {x1, y1}}, {{x1, y1}, {x0, y1}}, {{x0, y1}, {x0, y0}}};
  };
  std::vector<Seg> segs = box(17.94, -1, 18.06, 2.0);
  for (const auto& sg : box(17.94, 3.2, 18.06, 9)) segs.push_back(sg);
  for (const auto& sg : box(10, -0.06, 18.06, 0.06)) segs.push_back(sg);
  for (const hw::Pose2D& pose : {hw::Pose2D{17.4, 2.6, 0.0}, hw::Pose2D{17.3, 3.6, -1.3},
                                 hw::Pose2D{17.6, 2.6, 0.3}, hw::Pose2D{16.8, 4.5, -1.4}}) {
    SCOPED_TRACE(pose.x);
    const auto doors = findDoorways(scanOf(segs, pose, 0.01, 0.15), pose);
    ASSERT_EQ(doors.size(), 1u);
    EXPECT_NEAR(doors[0].centre.x(), 17.94, 0.03);  // on the wall's face
    EXPECT_NEAR(doors[0].centre.y(), 2.6, 0.06);
    EXPECT_NEAR(doors[0].width_m, 1.2, 0.1);
  }
}

TEST(Doorway, TooNarrowOrTooWideIsNoDoor) {
  const hw::Pose2D pose{16.0, 2.6, 0.0};
  EXPECT_TRUE(findDoorways(scanOf(labCorner(2.4, 2.8), pose), pose).empty());  // 0.4 m
  EXPECT_TRUE(findDoorways(scanOf(labCorner(1.0, 4.0), pose), pose).empty());  // 3 m walkway
  DoorwayParams wide;
  wide.max_width_m = 3.5;
  EXPECT_EQ(findDoorways(scanOf(labCorner(1.0, 4.0), pose), pose, wide).size(), 1u);
}

TEST(Doorway, AnEdgeInFrontOfAWallIsNoDoor) {
  // A cabinet 0.5 m deep standing 0.4 m before a wall: the beams past its edge read the wall
  // only 0.9 m further, and the cabinet's face is not in line with the wall.
  const hw::Pose2D pose{14.0, 2.0, 0.0};
  std::vector<Seg> segs{
      {{18, -1}, {18, 9}}, {{17.1, 2.5}, {17.1, 4.0}}, {{17.1, 2.5}, {17.6, 2.5}}};
  EXPECT_TRUE(findDoorways(scanOf(segs, pose), pose).empty());
}

TEST(Doorway, SomethingInTheOpeningClosesIt) {
  const hw::Pose2D pose{16.0, 2.6, 0.0};
  auto segs = labCorner();
  segs.push_back({{18.5, 2.5}, {18.5, 2.7}});  // a person standing just beyond the doorway
  EXPECT_TRUE(findDoorways(scanOf(segs, pose), pose).empty());
  hw::RangeScan sonar = scanOf(labCorner(), pose);
  sonar.kind = hw::RangeScan::Kind::Sonar;
  EXPECT_TRUE(findDoorways(sonar, pose).empty());
}

TEST(Doorway, ParamsNameTheBadField) {
  GoalDoorParams p;
  p.min_width_m = 2.0;
  try {
    p.validate();
    FAIL() << "no error";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("nav.goal_door.min_width_m"), std::string::npos)
        << e.what();
  }
}
