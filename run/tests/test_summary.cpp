// The typed run summary (run/summary.h): summary.json's figures written and read by type.
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


// The typed figures are written where they are read: fromJson(toJson()) gives them back, and
// a figure the run could not measure is null, not a number.
TEST(RunSummary, WritesTheFiguresItReads) {
  RunSummary a;
  a.success = true;
  a.reason = "reached the goal";
  a.time_s = 80.5;
  a.wall_time_s = 40.0;
  a.real_time_factor = 2.0125;
  a.path_length_m = 21.0;
  a.min_clearance_m = 0.12;
  a.deviation_mean_m = 0.3;
  a.deviation_max_m = 0.9;
  RunSummary::Diagnostics d;
  d.odometry_error_m = 0.2;
  d.odometry_heading_error_deg = -3.5;
  d.goal_estimate_world = std::array<double, 2>{4.0, -2.5};
  d.sketch_goal_error_m = 0.07;
  a.diagnostics = d;
  const Json j = a.toJson();
  EXPECT_TRUE(j["min_clearance_people_m"].is_null());
  EXPECT_FALSE(j["diagnostics"].contains("goal_estimate_error_m"));
  const RunSummary b = RunSummary::fromJson(j);
  EXPECT_EQ(b.success, a.success);
  EXPECT_EQ(b.reason, a.reason);
  EXPECT_EQ(b.failure, "");
  EXPECT_DOUBLE_EQ(b.time_s, 80.5);
  EXPECT_DOUBLE_EQ(b.real_time_factor, 2.0125);
  EXPECT_DOUBLE_EQ(b.path_length_m, 21.0);
  EXPECT_DOUBLE_EQ(b.min_clearance_m, 0.12);
  EXPECT_TRUE(std::isnan(b.min_clearance_people_m));
  EXPECT_DOUBLE_EQ(b.deviation_max_m, 0.9);
  ASSERT_TRUE(b.diagnostics);
  EXPECT_DOUBLE_EQ(b.diagnostics->odometry_heading_error_deg, -3.5);
  ASSERT_TRUE(b.diagnostics->goal_estimate_world);
  EXPECT_DOUBLE_EQ((*b.diagnostics->goal_estimate_world)[1], -2.5);
  EXPECT_FALSE(b.diagnostics->goal_estimate_error_m);
  EXPECT_EQ(b.toJson(), j);
  // A real robot's: no clearance, no deviation, no diagnostics.
  const Json r = RunSummary{}.toJson();
  EXPECT_TRUE(r["min_clearance_m"].is_null());
  EXPECT_TRUE(r["deviation_m"].is_null());
  EXPECT_FALSE(r.contains("diagnostics"));
}

}  // namespace
}  // namespace sketchnav::run
