// The typed run summary (run/summary.h): summary.json's figures read by type.
#include <gtest/gtest.h>

#include <cmath>

#include "sketchnav/run/summary.h"

namespace sketchnav::run {
namespace {

TEST(RunSummary, ReadsTheFiguresOfASimulatedRun) {
  const Json j = Json::parse(R"({
    "success": true, "executive_success": false, "reason": "reached the goal region",
    "failure": "", "time_s": 92.3, "wall_time_s": 80.0, "real_time_factor": 1.15,
    "path_length_m": 22.8, "min_clearance_m": 0.31, "min_clearance_people_m": 0.52,
    "deviation_m": {"mean": 0.2, "max": 0.6},
    "diagnostics": {"odometry_error_m": 0.04, "sketch_goal_error_m": 0.06},
    "seed": 1})");
  const RunSummary s = RunSummary::fromJson(j);
  EXPECT_TRUE(s.success);
  EXPECT_FALSE(s.executive_success);
  EXPECT_EQ(s.reason, "reached the goal region");
  EXPECT_EQ(s.failure, "");
  EXPECT_DOUBLE_EQ(s.time_s, 92.3);
  EXPECT_DOUBLE_EQ(s.wall_time_s, 80.0);
  EXPECT_DOUBLE_EQ(s.real_time_factor, 1.15);
  EXPECT_DOUBLE_EQ(s.path_length_m, 22.8);
  EXPECT_DOUBLE_EQ(s.min_clearance_m, 0.31);
  EXPECT_DOUBLE_EQ(s.min_clearance_people_m, 0.52);
  EXPECT_DOUBLE_EQ(s.deviation_mean_m, 0.2);
  EXPECT_DOUBLE_EQ(s.deviation_max_m, 0.6);
  ASSERT_TRUE(s.diagnostics.has_value());
  EXPECT_DOUBLE_EQ(s.diagnostics->odometry_error_m, 0.04);
  EXPECT_FALSE(s.diagnostics->goal_estimate_error_m.has_value());
  ASSERT_TRUE(s.diagnostics->sketch_goal_error_m.has_value());
  EXPECT_DOUBLE_EQ(*s.diagnostics->sketch_goal_error_m, 0.06);
  EXPECT_EQ(s.json, j);
}

// A real robot's summary: no clearance or deviation (null), no ground-truth diagnostics.
TEST(RunSummary, FiguresARunCouldNotMeasureStayUnset) {
  const RunSummary s = RunSummary::fromJson(
      Json::parse(R"({"success": false, "reason": "lost", "min_clearance_m": null,
                      "min_clearance_people_m": null, "deviation_m": null})"));
  EXPECT_FALSE(s.success);
  EXPECT_EQ(s.reason, "lost");
  EXPECT_EQ(s.failure, "");  // a summary older than the failure code
  EXPECT_DOUBLE_EQ(s.time_s, 0);
  EXPECT_TRUE(std::isnan(s.min_clearance_m));
  EXPECT_TRUE(std::isnan(s.min_clearance_people_m));
  EXPECT_TRUE(std::isnan(s.deviation_mean_m));
  EXPECT_FALSE(s.diagnostics.has_value());
}

TEST(RunSummary, NotThisProgramsSummaryThrows) {
  EXPECT_ANY_THROW(RunSummary::fromJson(Json::parse(R"({"success": "yes"})")));
  EXPECT_ANY_THROW(RunSummary::fromJson(Json::array()));
}

}  // namespace
}  // namespace sketchnav::run
