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
