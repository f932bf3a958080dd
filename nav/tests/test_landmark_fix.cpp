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

// driveBy() heading for a landmark whose centre stands dh above the camera (the camera
// `camera_along` ahead of the origin), from x0 to x1 in n sightings: bearings and elevations
// with Gaussian noise of sigma_deg, laser ranges `range_bias` long (<= -1: none), the
// database photo alternating between `photos` of them whose centres sit dh_step apart in
// height (each photo frames the object differently).
std::vector<Sighting> approach(const Eigen::Vector2d& lm, double x0, double x1, int n,
                               double sigma_deg, double dh, double range_bias, int photos = 1,
                               double dh_step = 0.0, std::uint32_t seed = 5) {
  const double camera_along = 0.13;
  auto ss = driveBy(lm, x0, x1, n, sigma_deg, std::max(range_bias, 0.0), seed);
  std::mt19937 rng(seed + 1);
  std::normal_distribution<double> ne(0.0, sigma_deg * M_PI / 180);
  for (int i = 0; i < n; ++i) {
    Sighting& s = ss[i];
    const Eigen::Vector2d d = lm - s.origin;
    if (range_bias <= -1) s.range_m = 0;
    s.photo = i % photos;
    s.camera_along_m = camera_along * std::cos(std::atan2(d.y(), d.x()));
    s.elevation = std::atan2(dh + s.photo * dh_step, d.norm() - s.camera_along_m) + ne(rng);
  }
  return ss;
}

TEST(LocateLandmark, HeightRangesALandmarkTheLaserPassesUnder) {
  // Nearly head-on (the bearings barely cross) to a carton 0.7 m above the camera, from 4.5
  // to 1.8 m; the laser passes under it to the bench 0.45 m behind (lab: L5, 0.30 m median).
  const Eigen::Vector2d lm(5.5, 0.4);
  const auto ss = approach(lm, 0.5, 3.2, 10, 0.1, 0.7, 0.45);
  LocateParams laser_only;
  laser_only.height_ranging = false;
  const LandmarkFix fl = locateLandmark(ss, laser_only);
  ASSERT_TRUE(fl.ok);
  EXPECT_FALSE(fl.triangulated);
  EXPECT_GT((fl.position - lm).norm(), 0.25);  // what the laser alone says
  EXPECT_EQ(fl.height_ranges, 0);

  const LandmarkFix f = locateLandmark(ss, LocateParams{});
  ASSERT_TRUE(f.ok);
  EXPECT_FALSE(f.bearing_only);
  // The far sightings' ranges are too uncertain (elevation noise x r^2 / dh) to be used.
  EXPECT_GE(f.height_ranges, 5);
  EXPECT_EQ(f.ranges_used, f.height_ranges);
  EXPECT_LT((f.position - lm).norm(), 0.1) << f.position.transpose();
  EXPECT_GE(f.height_sigma_m, LocateParams{}.height_min_sigma_m);
  EXPECT_LE(f.height_sigma_m, LocateParams{}.height_max_sigma_m);

  const HeightRanges hr = heightRanges(ss, LocateParams{});
  ASSERT_EQ(hr.range_m.size(), ss.size());
  for (size_t i = 0; i < ss.size(); ++i)
    if (hr.range_m[i] > 0) EXPECT_NEAR(hr.range_m[i], (lm - ss[i].origin).norm(), 0.15) << i;
}

TEST(LocateLandmark, HeightRangesWithoutALaserRangeAndPerPhoto) {
  // No laser range at all (it read beyond), two database photos whose centres differ by 6 cm
  // in height (one height each): a ranged fix instead of a bearing-only one.
  const Eigen::Vector2d lm(5.0, -0.3);
  auto ss = approach(lm, 0.0, 2.8, 12, 0.1, 0.75, -1, 2, 0.06);
  for (auto& s : ss) s.beyond_m = 7.0;
  const LandmarkFix f = locateLandmark(ss, LocateParams{});
  ASSERT_TRUE(f.ok);
  EXPECT_FALSE(f.bearing_only);
  EXPECT_GE(f.height_ranges, 6);
  EXPECT_LT((f.position - lm).norm(), 0.1) << f.position.transpose();
}

TEST(LocateLandmark, LaserRangesThatAgreeWithTheHeightAreKept) {
  const Eigen::Vector2d lm(5.5, 0.4);
  const auto ss = approach(lm, 0.5, 3.2, 10, 0.1, 0.7, 0.02);
  const LandmarkFix f = locateLandmark(ss, LocateParams{});
  ASSERT_TRUE(f.ok);
  EXPECT_EQ(f.height_ranges, 0);  // the laser sees the landmark itself: its ranges are better
  EXPECT_EQ(f.ranges_used, 10);
  EXPECT_LT((f.position - lm).norm(), 0.1);
}

TEST(LocateLandmark, TakesBackLaserRangesTheSketchRefusedWhenTheHeightAgrees) {
  // Straight at a poster on the wall ahead, from 4.2 to 3.4 m, its centre 0.9 m above the
  // camera: the bearings never cross, the sketch put the poster 2 m nearer so its range gate
  // refused every laser range (gated_range_m), and the height ranges alone are too loose
  // (sigma ~0.35 m) to replace a laser range.
  const Eigen::Vector2d lm(5.0, 0.1);
  auto ss = approach(lm, 0.8, 1.6, 20, 0.1, 0.9, 0.0);
  for (auto& s : ss) s.gated_range_m = s.range_m, s.range_m = 0;
  EXPECT_TRUE(heightRanges(ss, LocateParams{}).range_m.empty());
  const LandmarkFix f = locateLandmark(ss, LocateParams{});
  ASSERT_TRUE(f.ok);
  EXPECT_FALSE(f.bearing_only);
  EXPECT_EQ(f.gated_ranges, 20);
  EXPECT_EQ(f.ranges_used, 20);
  EXPECT_LT((f.position - lm).norm(), 0.1) << f.position.transpose();

  // Without taking them back the landmark is only somewhere along its rays.
  LocateParams never;
  never.gated_confirm_sigma_m = 0;
  const LandmarkFix fb = locateLandmark(ss, never);
  ASSERT_TRUE(fb.ok);
  EXPECT_TRUE(fb.bearing_only);
  EXPECT_EQ(fb.gated_ranges, 0);

  // The laser hits a box 1.2 m in front of the poster: the height says the landmark is
  // further, so those ranges stay refused.
  auto boxed = ss;
  for (auto& s : boxed) s.gated_range_m -= 1.2;
  const LandmarkFix fx = locateLandmark(boxed, LocateParams{});
  ASSERT_TRUE(fx.ok);
  EXPECT_TRUE(fx.bearing_only);
  EXPECT_EQ(fx.gated_ranges, 0);
}

TEST(LocateLandmark, NoHeightFromOneDistanceOrAtTheCameraHeight) {
  const Eigen::Vector2d lm(5.5, 0.4);
  // Standing still: every sighting from the same place, the height is not observable.
  auto still = approach(lm, 1.0, 1.0, 8, 0.2, 0.7, 0.45);
  EXPECT_TRUE(heightRanges(still, LocateParams{}).range_m.empty());
  // At the camera's height the elevations say nothing (below height_min_elevation_deg).
  auto level = approach(lm, 0.5, 3.2, 10, 0.0, 0.02, 0.45);
  EXPECT_TRUE(heightRanges(level, LocateParams{}).range_m.empty());
  // Too few sightings.
  auto few = approach(lm, 0.5, 3.2, 3, 0.2, 0.7, 0.45);
  EXPECT_TRUE(heightRanges(few, LocateParams{}).range_m.empty());
  // Unknown elevations (a perception without them) range nothing either.
  auto none = approach(lm, 0.5, 3.2, 10, 0.2, 0.7, 0.45);
  for (auto& s : none) s.elevation = NAN;
  EXPECT_TRUE(heightRanges(none, LocateParams{}).range_m.empty());
}

TEST(LocateLandmark, ParamsAreChecked) {
  LocateParams p;
  p.bearing_sigma_deg = 0;
  EXPECT_THROW(p.validate(), InputError);
  p = {};
  p.range_gate_m = -1;
  EXPECT_THROW(p.validate(), InputError);
  p = {};
  p.height_min_sightings = 2;
  EXPECT_THROW(p.validate(), InputError);
  p = {};
  p.height_max_sigma_m = 0;
  EXPECT_THROW(p.validate(), InputError);
  EXPECT_NO_THROW(LocateParams{}.validate());
}

}  // namespace
}  // namespace sketchnav::nav
