// The progress and goal-settle checkers on their own (the executive's stuck test and its
// "could not get closer" arrival).
#include <gtest/gtest.h>

#include "sketchnav/nav/goal_checker.h"
#include "sketchnav/nav/progress_checker.h"

using namespace sketchnav;
using namespace sketchnav::nav;

TEST(ProgressChecker, StuckWhenAWindowEndsWithoutMovingFarEnough) {
  ProgressChecker pc(10.0, 0.3);
  pc.reset({0, 0, 0}, 0.0);
  EXPECT_FALSE(pc.due(9.99));
  ASSERT_TRUE(pc.due(10.0));
  // Turning on the spot and 0.2 m of creeping is not progress.
  EXPECT_TRUE(pc.stuck({0.2, 0.0, 3.0}, 10.0));
  // The next window starts where the last one ended: 0.35 m on from there is progress.
  EXPECT_FALSE(pc.due(19.0));
  ASSERT_TRUE(pc.due(20.0));
  EXPECT_FALSE(pc.stuck({0.2, 0.35, 0.0}, 20.0));
  // Distance is measured straight from the window's start: a loop back is no progress.
  ASSERT_TRUE(pc.due(30.0));
  EXPECT_TRUE(pc.stuck({0.25, 0.4, 0.0}, 30.0));
  // reset() starts a fresh window (the end of a recovery).
  pc.reset({5, 5, 0}, 31.0);
  EXPECT_FALSE(pc.due(40.0));
  EXPECT_FALSE(pc.stuck({5.5, 5, 0}, 41.0));
  // expire() makes a window that is over at once, started where the robot is (after a
  // recovery that only turned to look): due now, and stuck unless it moves.
  pc.expire({6, 5, 0}, 50.0);
  ASSERT_TRUE(pc.due(50.0));
  EXPECT_TRUE(pc.stuck({6, 5, 2.0}, 50.0));
  EXPECT_FALSE(pc.due(59.0));
}

TEST(SettleChecker, SettlesWhenNoLongerGettingCloserNearTheGoal) {
  SettleChecker sc(1.0, 8.0);
  // Not on the last section, or farther than near_m: never settled, the clock follows.
  EXPECT_FALSE(sc.update(false, 0.5, 0.0, false));
  EXPECT_FALSE(sc.update(true, 1.5, 1.0, false));
  // Within 1 m from t = 2 and creeping by less than 5 cm at a time: settled after 8 s.
  EXPECT_FALSE(sc.update(true, 0.9, 2.0, false));
  EXPECT_FALSE(sc.update(true, 0.87, 6.0, false));
  EXPECT_FALSE(sc.update(true, 0.86, 10.0, false));
  EXPECT_TRUE(sc.update(true, 0.86, 10.01, false));
  // 5 cm closer than the best restarts the clock.
  SettleChecker closer(1.0, 8.0);
  EXPECT_FALSE(closer.update(true, 0.9, 2.0, false));
  EXPECT_FALSE(closer.update(true, 0.84, 9.0, false));
  EXPECT_FALSE(closer.update(true, 0.84, 16.0, false));
  EXPECT_TRUE(closer.update(true, 0.84, 17.5, false));
  // A restart (the final look) holds it off however long it lasts; leaving the area resets.
  SettleChecker look(1.0, 8.0);
  for (double t = 0; t <= 20; t += 1) EXPECT_FALSE(look.update(true, 0.5, t, true));
  EXPECT_FALSE(look.update(true, 0.5, 28.0, false));
  EXPECT_TRUE(look.update(true, 0.5, 28.5, false));
  EXPECT_FALSE(look.update(true, 1.2, 29.0, false));
  // Back within 1 m at t = 36: its clock starts there.
  EXPECT_FALSE(look.update(true, 0.5, 36.0, false));
  EXPECT_FALSE(look.update(true, 0.5, 44.0, false));
  EXPECT_TRUE(look.update(true, 0.5, 44.5, false));
}

TEST(SectionSettleChecker, SettlesWhereTheRobotCameClosestToAnEndItCannotReach) {
  // A 10 m section: near = max(1 m, 0.3 x 10 m) = 3 m; settle after 15 s without 5 cm gained.
  SectionSettleChecker sc(0.3, 1.0, 15.0);
  EXPECT_DOUBLE_EQ(sc.nearM(10.0), 3.0);
  EXPECT_DOUBLE_EQ(sc.nearM(2.0), 1.0);
  sc.restart(0.0);
  // Driving towards the end at 0.3 m/s, 5 cm per tick... of 1/6 s: always gaining.
  double t = 0, d = 10;
  for (; d > 2.5; d -= 0.05, t += 1.0 / 6) EXPECT_FALSE(sc.update(10, d, t, false));
  // Against the wall 2.5 m from it; then the avoider drives it 5 m back along the corridor
  // and it comes back to the same spot: leaving does not restart the clock.
  const double closest_t = t;
  for (; t < closest_t + 10; t += 0.5)
    EXPECT_FALSE(sc.update(10, 2.5 + (t - closest_t) * 0.3, t, false));
  for (; t < closest_t + 20; t += 0.5) EXPECT_FALSE(sc.update(10, 5.5, t, false));  // far: not here
  // Driving back towards it at 0.3 m/s: inside 3 m again, but closing in, so not yet.
  double d2 = 5.5;
  for (; d2 > 2.6; d2 -= 0.15, t += 0.5) EXPECT_FALSE(sc.update(10, d2, t, false));
  // Back against the wall 2.6 m from it: settled once it has stopped closing in (3 s).
  const double back_t = t;
  bool settled = false;
  for (; t < back_t + 4 && !settled; t += 0.5) settled = sc.update(10, 2.6, t, false);
  EXPECT_TRUE(settled);
  EXPECT_GT(t, back_t + 2.5);
  // A hold (servoing, a side look, waiting for a person) restarts the clock.
  SectionSettleChecker held(0.3, 1.0, 15.0);
  held.restart(0.0);
  EXPECT_FALSE(held.update(10, 2.0, 1.0, false));
  EXPECT_FALSE(held.update(10, 2.0, 10.0, true));
  EXPECT_FALSE(held.update(10, 2.0, 24.0, false));
  EXPECT_TRUE(held.update(10, 2.0, 25.5, false));
  // A new section starts afresh; 0 = off.
  held.restart(30.0);
  EXPECT_FALSE(held.update(10, 2.0, 31.0, false));
  EXPECT_FALSE(held.update(10, 2.0, 45.0, false));
  EXPECT_TRUE(held.update(10, 2.0, 46.5, false));
  SectionSettleChecker off(0.0, 1.0, 15.0);
  off.restart(0.0);
  for (double u = 0; u < 100; u += 1) EXPECT_FALSE(off.update(10, 2.0, u, false));
  // Within min_near_m (end_blocked_m) of the end it is left to the rules that see the end.
  SectionSettleChecker in_view(0.3, 1.0, 15.0);
  in_view.restart(0.0);
  for (double u = 0; u < 100; u += 1) EXPECT_FALSE(in_view.update(10, 0.8, u, false));
  // Once that near, the end was reachable: led away from it (a servo), it never settles.
  for (double u = 100; u < 200; u += 1) EXPECT_FALSE(in_view.update(10, 2.0, u, false));
}
