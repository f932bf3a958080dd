// People from the laser: a walking person becomes a mover with its velocity, furniture does
// not (also while the robot drives past it); the yield advice steps out of a lane on the
// robot's side and stops short of entering one.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>

#include "scan_sim.h"
#include "sketchnav/core/error.h"
#include "sketchnav/nav/local_planner.h"
#include "sketchnav/nav/movers.h"

using namespace sketchnav;
using namespace sketchnav::nav;
using namespace sketchnav::nav::test;

namespace {
// The robot at `robot` watches the empty room (the floor is seen free), then a person walks
// from `from` with `vel` for `secs` at 10 Hz; `each` (when given) sees the tracker after every
// scan, with the scan's time and the person's position.
using EachScan = std::function<void(double, const Eigen::Vector2d&, const MoverTracker&)>;
MoverTracker watch(LocalPlanner& grid, const hw::Pose2D& robot, Eigen::Vector2d from,
                   Eigen::Vector2d vel, double secs, bool enabled = true,
                   const EachScan& each = {}) {
  auto boxes = room();
  for (int i = 0; i < 5; ++i) grid.insert(robot, scanAt(robot, boxes, {}, 0.1 * i));
  MoverParams on;
  on.enabled = enabled;
  on.follow_gap_m = 1.5;  // the setting measured in doc/navigation.md
  MoverTracker tr(on);
  const LocalPlanner before = grid.snapshot();  // the grid before the person walked in
  for (double t = 0.5; t <= 0.5 + secs + 1e-9; t += 0.1) {
    const Eigen::Vector2d p = from + vel * (t - 0.5);
    const auto s = scanAt(robot, boxes, {{p.x(), p.y(), 0.25}}, t);
    tr.update(robot, s, before);
    grid.insert(robot, s);
    if (each) each(t, p, tr);
  }
  return tr;
}
}  // namespace

TEST(Movers, AWalkingPersonIsAMoverWithItsVelocity) {
  LocalPlanner grid;
  const auto tr = watch(grid, {0, 0, 0}, {3.0, 2.0}, {0.0, -0.4}, 3.0);
  const auto m = tr.movers();
  ASSERT_EQ(m.size(), 1u);
  EXPECT_NEAR(m[0].velocity.x(), 0.0, 0.1);
  EXPECT_NEAR(m[0].velocity.y(), -0.4, 0.1);
  EXPECT_NEAR(m[0].position.y(), 2.0 - 0.4 * 3.0, 0.25);
}

TEST(Movers, AWalkerStaysOneTrackWhenABeamSplitsOffTheirEdge) {
  // Walking across 3 m in front of the robot, the beam grazing the person's edge lands far
  // enough along the body to make a one-beam cluster of its own (at y ~ 1.1 here). Taken first,
  // it used to steal their track, and they were no walker for 1.4 s; once a walker, they stay
  // one.
  LocalPlanner grid;
  bool walker = false;
  watch(grid, {0, 0, 0}, {3.0, 2.0}, {0.0, -0.4}, 4.0, false,
        [&](double t, const Eigen::Vector2d& p, const MoverTracker& tr) {
          const auto w = tr.walkers();
          if (walker) {
            ASSERT_EQ(w.size(), 1u) << "t=" << t << " y=" << p.y();
            EXPECT_NEAR(w[0].position.y(), p.y(), 0.15) << "t=" << t;
          }
          walker = walker || !w.empty();
        });
  EXPECT_TRUE(walker);
}

TEST(Movers, WalkersForTheAvoiderAreTrackedForLongerAtAWalkingPace) {
  LocalPlanner g1, g2, g3;
  // 1 s after coming into view a mover, not yet a walker; after 2 s both.
  const auto early = watch(g1, {0, 0, 0}, {3.0, 2.0}, {0.0, -0.4}, 1.0);
  EXPECT_EQ(early.movers().size(), 1u);
  EXPECT_TRUE(early.walkers().empty());
  const auto later = watch(g2, {0, 0, 0}, {3.0, 2.0}, {0.0, -0.4}, 2.0);
  ASSERT_EQ(later.walkers().size(), 1u);
  EXPECT_NEAR(later.walkers()[0].velocity.y(), -0.4, 0.1);
  // Faster than a walk (the phantoms sliding along walls went at 1.3-1.7 m/s): not a walker.
  const auto fast = watch(g3, {0, 0, 0}, {3.0, 2.4}, {0.0, -1.6}, 2.5);
  EXPECT_EQ(fast.movers().size(), 1u);
  EXPECT_TRUE(fast.walkers().empty());
}

TEST(Movers, AWalkerWhoStoodWhereTheGridSawThemIsTakenOnceWalkingOnFreeFloor) {
  // A person stands 3 s at (4, 1.5): the grid's snapshot holds that floor occupied. Then they
  // walk towards the robot's side at 0.4 m/s over floor seen free. What counts is where the
  // track has been lately, not the standing start (with the start counted, 30 of its first
  // 50 points were on occupied floor and it was no walker 2 s after setting off).
  LocalPlanner grid;
  const hw::Pose2D robot{0, 0, 0};
  auto boxes = room();
  for (int i = 0; i < 5; ++i) grid.insert(robot, scanAt(robot, boxes, {}, 0.1 * i));
  MoverTracker tr(MoverParams{});
  const Eigen::Vector2d stand(4.0, 1.5), vel(-0.4, 0.0);
  for (double t = 0.5; t <= 3.5 + 1e-9; t += 0.1)
    grid.insert(robot, scanAt(robot, boxes, {{stand.x(), stand.y(), 0.25}}, t));
  const LocalPlanner before = grid.snapshot();  // the person standing, seen
  for (double t = 0.5; t <= 3.5 + 1e-9; t += 0.1)
    tr.update(robot, scanAt(robot, boxes, {{stand.x(), stand.y(), 0.25}}, t), before);
  EXPECT_TRUE(tr.walkers().empty());  // standing: no walker
  for (double t = 3.6; t <= 5.6 + 1e-9; t += 0.1) {
    const Eigen::Vector2d p = stand + vel * (t - 3.5);
    tr.update(robot, scanAt(robot, boxes, {{p.x(), p.y(), 0.25}}, t), before);
  }
  ASSERT_EQ(tr.walkers().size(), 1u);
  EXPECT_NEAR(tr.walkers()[0].velocity.x(), -0.4, 0.1);
}

TEST(Movers, AWalkerComingBackAlongTheirOwnTraceIsTakenWhileComingAtTheRobot) {
  // A person in front of the robot from the start walks away along a line, turns and walks
  // back towards it. Going away, the side of them in view sweeps floor their body hid (never
  // seen free); coming back, it sweeps their own trace, which the grid of a few seconds ago
  // holds occupied. (A slow walker turning in a corridor was taken only when 0.8 m from the
  // robot, and walked into it.) Coming back they are a walker within 2 s of turning.
  LocalPlanner grid;
  const hw::Pose2D robot{0, 0, 0};
  auto boxes = room();
  MoverTracker tr(MoverParams{});
  LocalPlanner before = grid.snapshot(), snap = grid.snapshot();
  double snap_t = 0.5;
  const Eigen::Vector2d start(1.5, 0.2), vel(0.35, 0.0);
  const double turn_t = 0.5 + 6.0;  // 2.1 m away, then back
  double taken_at = -1;
  for (double t = 0.5; t <= turn_t + 4.0 + 1e-9; t += 0.1) {
    const Eigen::Vector2d p =
        t <= turn_t ? Eigen::Vector2d(start + vel * (t - 0.5))
                    : Eigen::Vector2d(start + vel * (turn_t - 0.5) - vel * (t - turn_t));
    const auto s = scanAt(robot, boxes, {{p.x(), p.y(), 0.25}}, t);
    tr.update(robot, s, before);
    grid.insert(robot, s);
    if (t - snap_t >= 1.5) before = std::move(snap), snap = grid.snapshot(), snap_t = t;
    const auto w = tr.walkers();
    if (t <= turn_t) {
      for (const auto& m : w) EXPECT_GT(m.velocity.x(), 0.2) << "t=" << t;  // going away
    } else if (taken_at < 0 && !w.empty() && w[0].velocity.x() < -0.2) {
      taken_at = t;
    }
  }
  ASSERT_GT(taken_at, 0) << "the walker coming back was never taken";
  EXPECT_LE(taken_at - turn_t, 2.0);  // on free floor only: 3.5 s
  const auto w = tr.walkers();
  ASSERT_EQ(w.size(), 1u);
  EXPECT_NEAR(w[0].velocity.x(), -0.35, 0.1);
}

TEST(Movers, WithLanesOffTheRobotStillHoldsShortOfAWalkersLane) {
  // Lane keeping off (the default): a command that would take the robot into the lane of a
  // walker (not merely a mover) within look_ahead_s waits, turning kept; one in the lane
  // already is the avoider's (no advice); standing still needs none.
  LocalPlanner g1, g2;
  const auto tr = watch(g1, {0, 0, 0}, {3.0, 2.0}, {0.0, -0.4}, 2.0, false);
  ASSERT_EQ(tr.walkers().size(), 1u);  // at about (3, 1.2), walking south
  const auto hold = tr.holdShortOfWalkerLanes({2.0, 0.0, 0.0}, 0.3, 0.1);
  EXPECT_TRUE(hold.active);
  EXPECT_EQ(hold.v, 0.0);
  EXPECT_EQ(hold.w, 0.1);
  EXPECT_FALSE(tr.holdShortOfWalkerLanes({1.0, 0.0, 0.0}, 0.3, 0.0).active);   // not that soon
  EXPECT_FALSE(tr.holdShortOfWalkerLanes({2.0, 0.0, M_PI}, 0.3, 0.0).active);  // driving off
  EXPECT_FALSE(tr.holdShortOfWalkerLanes({2.8, 0.0, 0.0}, 0.3, 0.0).active);   // in it already
  EXPECT_FALSE(tr.holdShortOfWalkerLanes({2.0, 0.0, 0.0}, 0.0, 0.5).active);   // not driving
  // A mover seen for 1 s is not a walker yet: no hold.
  const auto early = watch(g2, {0, 0, 0}, {3.0, 1.4}, {0.0, -0.4}, 1.0, false);
  ASSERT_TRUE(early.walkers().empty());
  EXPECT_FALSE(early.holdShortOfWalkerLanes({2.0, 0.0, 0.0}, 0.3, 0.0).active);
}

TEST(Movers, FurnitureIsNotAMoverEvenWhileTheRobotDrives) {
  LocalPlanner grid;
  MoverParams on;
  on.enabled = true;
  MoverTracker tr(on);
  auto boxes = room();
  boxes.push_back({3, 1.0, 0.25, 0.25});  // a person-sized box
  LocalPlanner before = grid.snapshot();
  for (double t = 0; t <= 4.0 + 1e-9; t += 0.1) {
    const hw::Pose2D robot{0.3 * t, 0, 0.1 * std::sin(t)};
    const auto s = scanAt(robot, boxes, {}, t);
    tr.update(robot, s, before);
    grid.insert(robot, s);
    if (std::fmod(t + 1e-9, 1.0) < 0.05) before = grid.snapshot();  // as the executive does
  }
  EXPECT_TRUE(tr.movers().empty());
  EXPECT_TRUE(tr.walkers().empty());
}

TEST(Movers, InTheLaneTheRobotStepsOutOnItsOwnSide) {
  LocalPlanner grid;
  // A person 2.5 m ahead walking straight at the robot, slightly to the robot's left.
  const auto tr = watch(grid, {0, 0, 0}, {3.2, 0.15}, {-0.4, 0.0}, 2.0);
  ASSERT_EQ(tr.movers().size(), 1u);
  const auto a = tr.advise({0, 0, 0}, 0.3, 0.0, 1.5, 0.3);
  ASSERT_TRUE(a.active);
  EXPECT_TRUE(a.in_lane);
  EXPECT_LT(a.w, 0.0);  // the person passes on the left: step out to the right
}

TEST(Movers, TheRobotDoesNotDriveIntoALane) {
  LocalPlanner grid;
  // A person crossing 0.8 m ahead from left to right; the robot drives straight on.
  const auto tr = watch(grid, {0, 0, 0}, {0.8, 2.5}, {0.0, -0.4}, 1.0);
  ASSERT_EQ(tr.movers().size(), 1u);
  const auto a = tr.advise({0, 0, 0}, 0.3, 0.0, 1.5, 0.3);
  ASSERT_TRUE(a.active);
  EXPECT_FALSE(a.in_lane);
  EXPECT_EQ(a.v, 0.0);
  // Turned away from the crossing, the same command is fine.
  EXPECT_FALSE(tr.advise({0, 0, M_PI}, 0.3, 0.0, 1.5, 0.3).active);
}

TEST(Movers, LanesOffByDefaultAndThenNoAdviceButStillTracked) {
  EXPECT_FALSE(MoverParams{}.enabled);
  LocalPlanner grid;
  // The same crossing that stops the robot when the lanes are kept: still tracked (the
  // avoider follows it), but no advice.
  const auto tr = watch(grid, {0, 0, 0}, {0.8, 2.5}, {0.0, -0.4}, 1.0, /*enabled=*/false);
  ASSERT_EQ(tr.movers().size(), 1u);
  EXPECT_NEAR(tr.movers()[0].velocity.y(), -0.4, 0.1);
  EXPECT_FALSE(tr.advise({0, 0, 0}, 0.3, 0.0, 1.5, 0.3).active);
  MoverParams p;
  p.min_updates = 1;
  EXPECT_THROW(MoverTracker{p}, InputError);
}

TEST(Movers, BehindSomeoneWalkingTheSameWayTheRobotKeepsTheFollowingGap) {
  // Someone walks away from the robot at 0.4 m/s and is 1.6 m ahead (1.1 m between the
  // bodies, 1.5 m wanted): the robot may go at 0.4 - 0.4 / 2 = 0.2 m/s, not its 0.3 m/s.
  LocalPlanner g1, g2, g3, g4;
  const hw::Pose2D robot{0, 0, 0};
  const auto ahead = watch(g1, robot, {1.0, 0.0}, {0.4, 0.0}, 1.5);
  EXPECT_NEAR(ahead.followSpeed(robot, 0.3), 0.2, 0.06);
  EXPECT_EQ(ahead.followSpeed(robot, 0.0), 0.0);
  // Facing away from them, nothing to follow.
  EXPECT_EQ(ahead.followSpeed({0, 0, M_PI}, 0.3), 0.3);
  // Far enough ahead: the gap closes at the robot's own speed.
  const auto far = watch(g2, robot, {2.0, 0.0}, {0.4, 0.0}, 1.5);
  EXPECT_EQ(far.followSpeed(robot, 0.3), 0.3);
  // Beside the robot's way, or coming towards it (the avoider's case): not followed.
  const auto beside = watch(g3, robot, {1.0, 1.2}, {0.4, 0.0}, 1.5);
  EXPECT_EQ(beside.followSpeed(robot, 0.3), 0.3);
  const auto coming = watch(g4, robot, {3.0, 0.0}, {-0.4, 0.0}, 1.0);
  EXPECT_EQ(coming.followSpeed(robot, 0.3), 0.3);
  // Off.
  MoverParams off;
  off.follow_gap_m = 0;
  EXPECT_EQ(MoverTracker(off).followSpeed(robot, 0.3), 0.3);
}
