// locateLandmark(): bearings crossing at the landmark beat laser ranges that hit what stands
// behind it; ranges decide when the bearings do not cross well.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "sketchnav/core/error.h"
#include "sketchnav/nav/landmark_stage.h"

namespace sketchnav::nav {
namespace {

// The robot drives along y = 0 from x0 to x1 past a landmark at `lm`, taking n sightings;
// bearings get Gaussian noise of sigma_deg, ranges are the true range plus `range_bias`.
std::vector<Sighting> driveBy(const Eigen::Vector2d& lm, double x0, double x1, int n,
                              double sigma_deg, double range_bias, std::uint32_t seed = 7) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> nb(0.0, sigma_deg * M_PI / 180);
  std::vector<Sighting> ss;
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d o(x0 + (x1 - x0) * i / std::max(1, n - 1), 0.0);
    const Eigen::Vector2d d = lm - o;
    ss.push_back({o, std::atan2(d.y(), d.x()) + nb(rng), d.norm() + range_bias});
  }
  return ss;
}

TEST(LocateLandmark, BearingsOutvoteRangesThatHitTheFurnitureBehind) {
  // A carton 0.9 m right of the path, seen from 4.5 to 1.5 m; the laser passes under it and
  // returns 0.65 m further (the bench face behind it), as in the lab's moved-L7 experiment.
  const Eigen::Vector2d lm(5.0, -0.9);
  const auto ss = driveBy(lm, 0.5, 3.5, 12, 0.5, 0.65);
  const LandmarkFix f = locateLandmark(ss, LocateParams{});
  ASSERT_TRUE(f.ok);
  EXPECT_TRUE(f.triangulated);
  EXPECT_EQ(f.ranges_used, 0);
  EXPECT_EQ(f.ranges_dropped, 12);
  EXPECT_LT((f.position - lm).norm(), 0.15) << f.position.transpose();
  // What the ranges alone say: the bench face.
  double mean_err = 0;
  for (const auto& s : ss)
    mean_err +=
        (s.origin + s.range_m * Eigen::Vector2d(std::cos(s.direction), std::sin(s.direction)) - lm)
            .norm();
  EXPECT_GT(mean_err / ss.size(), 0.5);
}

TEST(LocateLandmark, RangesThatAgreeWithTheCrossingAddInformationAlongTheView) {
  const Eigen::Vector2d lm(5.0, -0.9);
  const auto ss = driveBy(lm, 0.5, 3.5, 12, 1.0, 0.0);
  const LandmarkFix f = locateLandmark(ss, LocateParams{});
  ASSERT_TRUE(f.ok);
  EXPECT_TRUE(f.triangulated);
  EXPECT_EQ(f.ranges_used, 12);
  EXPECT_LT((f.position - lm).norm(), 0.2);
  auto bearings_only = ss;
  for (auto& s : bearings_only) s.range_m = 0;
  const LandmarkFix fb = locateLandmark(bearings_only, LocateParams{});
  ASSERT_TRUE(fb.ok);
  const Eigen::Vector2d view = (lm - Eigen::Vector2d(2.0, 0.0)).normalized();
  // Together the ranges count as one range of range_sigma_m (1 / 0.35^2 = 8 per m^2).
  EXPECT_GT(view.dot(f.information * view), view.dot(fb.information * view) + 6.0);
}

TEST(LocateLandmark, TooLittleSpreadLeavesItToTheRanges) {
  // Straight ahead: the bearings are all the same, they cannot cross.
  const Eigen::Vector2d lm(6.0, 0.0);
  const auto ss = driveBy(lm, 0.0, 2.0, 8, 0.0, 0.05);
  const LandmarkFix f = locateLandmark(ss, LocateParams{});
  ASSERT_TRUE(f.ok);
  EXPECT_FALSE(f.triangulated);
  EXPECT_NEAR(f.position.x(), 6.05, 1e-6);
  EXPECT_NEAR(f.position.y(), 0.0, 1e-6);
}

TEST(LocateLandmark, NoRangeAndNoCrossingIsABearingOnlyFix) {
  auto ss = driveBy({6.0, 0.0}, 0.0, 2.0, 5, 0.0, 0.0);
  for (auto& s : ss) s.range_m = 0;
  const LandmarkFix b = locateLandmark(ss, LocateParams{});
  ASSERT_TRUE(b.ok);
  EXPECT_TRUE(b.bearing_only);
  EXPECT_FALSE(b.triangulated);
  EXPECT_EQ(b.rays, 5);
  EXPECT_NEAR(b.position.y(), 0.0, 1e-6);  // on the rays
  // Across the rays (y) as well as five bearings at ~3 m allow; along them (x) nothing.
  EXPECT_GT(b.information(1, 1), 100.0);
  EXPECT_LT(b.information(0, 0), 1e-3);
  // Read as far away (the laser beyond), the same bearings are worth less across.
  for (auto& s : ss) s.beyond_m = 7.0;
  const LandmarkFix far = locateLandmark(ss, LocateParams{});
  ASSERT_TRUE(far.ok && far.bearing_only);
  EXPECT_LT(far.information(1, 1), 0.5 * b.information(1, 1));
  EXPECT_FALSE(locateLandmark({}, LocateParams{}).ok);
  // Unranged bearings that do cross are enough.
  auto crossing = driveBy({5.0, -2.0}, 0.0, 4.0, 9, 0.3, 0.0);
  for (auto& s : crossing) s.range_m = 0;
  const LandmarkFix f = locateLandmark(crossing, LocateParams{});
  ASSERT_TRUE(f.ok);
  EXPECT_TRUE(f.triangulated);
  EXPECT_LT((f.position - Eigen::Vector2d(5.0, -2.0)).norm(), 0.15);
}

TEST(LocateLandmark, OneStrayRangeDoesNotMoveARangesOnlyFix) {
  auto ss = driveBy({6.0, 0.0}, 0.0, 1.0, 5, 0.0, 0.0);
  ss[2].range_m += 3.0;  // a return from the wall behind
  const LandmarkFix f = locateLandmark(ss, LocateParams{});
  ASSERT_TRUE(f.ok);
  EXPECT_NEAR(f.position.x(), 6.0, 1e-6);
}

TEST(LocateLandmark, ParamsAreChecked) {
  LocateParams p;
  p.bearing_sigma_deg = 0;
  EXPECT_THROW(p.validate(), InputError);
  p = {};
  p.range_gate_m = -1;
  EXPECT_THROW(p.validate(), InputError);
  EXPECT_NO_THROW(LocateParams{}.validate());
}

}  // namespace
}  // namespace sketchnav::nav
