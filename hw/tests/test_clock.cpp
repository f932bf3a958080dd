#include <gtest/gtest.h>

#include "sketchnav/hw/clock.h"

using namespace sketchnav::hw;

TEST(SimClock, OnlyMovesWhenAdvancedAndNeverBackwards) {
  SimClock c;
  EXPECT_DOUBLE_EQ(c.now(), 0.0);
  c.advance(0.1);
  c.sleepUntil(2.0);
  EXPECT_DOUBLE_EQ(c.now(), 2.0);
  c.sleepUntil(1.0);
  EXPECT_DOUBLE_EQ(c.now(), 2.0);
  c.advance(-5);
  EXPECT_DOUBLE_EQ(c.now(), 2.0);
}

TEST(SteadyClock, IsMonotonic) {
  SteadyClock c;
  const double a = c.now();
  c.sleepUntil(a + 0.01);
  EXPECT_GE(c.now(), a + 0.01);
}
