// wrapAngle (core/angles.h) and fnv1a (core/hash.h): the one copy each that the route, the
// navigation, the simulator, the model file and the model cache use.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "sketchnav/core/angles.h"
#include "sketchnav/core/hash.h"

using sketchnav::fnv1a;
using sketchnav::wrapAngle;

TEST(WrapAngle, MapsIntoMinusPiToPiAndKeepsTheDirection) {
  EXPECT_NEAR(wrapAngle(0.0), 0.0, 1e-15);
  EXPECT_NEAR(wrapAngle(M_PI), M_PI, 1e-12);   // pi is in range ...
  EXPECT_NEAR(wrapAngle(-M_PI), M_PI, 1e-12);  // ... -pi is not
  EXPECT_NEAR(wrapAngle(3 * M_PI / 2), -M_PI / 2, 1e-12);
  EXPECT_NEAR(wrapAngle(-3 * M_PI / 2), M_PI / 2, 1e-12);
  EXPECT_NEAR(wrapAngle(20 * M_PI + 0.25), 0.25, 1e-12);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> any(-1000, 1000);
  for (int i = 0; i < 10000; ++i) {
    const double a = any(rng), w = wrapAngle(a);
    ASSERT_GT(w, -M_PI) << a;
    ASSERT_LE(w, M_PI) << a;
    ASSERT_NEAR(std::cos(w), std::cos(a), 1e-9) << a;
    ASSERT_NEAR(std::sin(w), std::sin(a), 1e-9) << a;
  }
}

TEST(Fnv1a, KeepsTheValuesModelFilesWereWrittenWithAndChains) {
  // With the project's offset (see hash.h), computed apart from this code.
  EXPECT_EQ(fnv1a("", 0), 0x14650fb0739d0383ull);
  EXPECT_EQ(fnv1a("a", 1), 0x44bd8ad473cd9906ull);
  EXPECT_EQ(fnv1a("foobar", 6), 0x88fad7c0a8ff07f2ull);
  // The specification's offset gives its published vectors.
  EXPECT_EQ(fnv1a("a", 1, 14695981039346656037ull), 0xaf63dc4c8601ec8cull);
  const std::string all = "landmarks-v7";
  EXPECT_EQ(fnv1a(all.data() + 4, all.size() - 4, fnv1a(all.data(), 4)),
            fnv1a(all.data(), all.size()));
}
