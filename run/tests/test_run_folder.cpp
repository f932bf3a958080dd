// The run folder (run/run_folder.h): telemetry.csv written and read back through its one column
// list, and a run folder read into a scenario result.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>

#include "sketchnav/run/run_folder.h"
#include "sketchnav/run/scenario.h"
#include "test_data.h"

namespace sketchnav::run {
namespace {

nav::TelemetryRow row(double t, double w, const std::string& landmark = "") {
  nav::TelemetryRow r;
  r.t = t;
  r.odom = {1.5, -0.25, 0.125};
  r.v_cmd = 0.3;
  r.w_cmd = w;
  r.servo_error = NAN;
  r.mode = nav::Mode::Follow;
  r.turn = servo::Turn::Left;
  r.section = 2;
  r.landmark = landmark;
  r.front_free_m = 1.75;
  return r;
}

// The header is the file format other tools read (tests/hardware/record_replay_same.cmake,
// the browser tests, users' scripts): it must not change by accident.
TEST(TelemetryCsv, HeaderIsTheDocumentedColumnList) {
  EXPECT_EQ(telemetryCsvHeader(),
            "t,odom_x,odom_y,odom_theta,true_x,true_y,true_theta,v_cmd,w_cmd,servo_error,mode,"
            "turn,section,landmark,front_free_m\n");
}

TEST(TelemetryCsv, RowWithoutTruthLeavesItsColumnsEmpty) {
  EXPECT_EQ(telemetryCsvRow(row(0.5, -0.2), nullptr),
            "0.5,1.5,-0.25,0.125,,,,0.3,-0.2,,follow,Left,2,,1.75\n");
  const hw::Pose2D truth{3, 4, 0.5};
  nav::TelemetryRow servoing = row(1, 0.1, "L3");
  servoing.servo_error = 0.0625;
  EXPECT_EQ(telemetryCsvRow(servoing, &truth),
            "1,1.5,-0.25,0.125,3,4,0.5,0.3,0.1,0.0625,follow,Left,2,L3,1.75\n");
}

TEST(TelemetryCsv, WhatTheWriterWritesTheReaderReads) {
  const std::string dir = test::tempDir("telemetry-roundtrip");
  const std::string path = dir + "/telemetry.csv";
  {
    TelemetryWriter w;
    ASSERT_TRUE(w.open(path));
    const hw::Pose2D truth{3, 4, 0.5};
    w.write(row(0.05, 0.1, "L1"), &truth);
    nav::TelemetryRow servoing = row(0.1, -0.1);
    servoing.servo_error = -0.03;
    servoing.mode = nav::Mode::Servo;
    w.write(servoing, nullptr);
  }
  const auto rs = readTelemetryCsv(path);
  ASSERT_EQ(rs.size(), 2u);
  EXPECT_DOUBLE_EQ(rs[0].t, 0.05);
  EXPECT_DOUBLE_EQ(rs[0].odom.x, 1.5);
  EXPECT_DOUBLE_EQ(rs[0].odom.y, -0.25);
  EXPECT_DOUBLE_EQ(rs[0].odom.theta, 0.125);
  ASSERT_TRUE(rs[0].truth.has_value());
  EXPECT_DOUBLE_EQ(rs[0].truth->x, 3);
  EXPECT_DOUBLE_EQ(rs[0].truth->y, 4);
  EXPECT_DOUBLE_EQ(rs[0].truth->theta, 0.5);
  EXPECT_DOUBLE_EQ(rs[0].v_cmd, 0.3);
  EXPECT_DOUBLE_EQ(rs[0].w_cmd, 0.1);
  EXPECT_TRUE(std::isnan(rs[0].servo_error));
  EXPECT_EQ(rs[0].mode, "follow");
  EXPECT_EQ(rs[0].turn, "Left");
  EXPECT_EQ(rs[0].section, 2);
  EXPECT_EQ(rs[0].landmark, "L1");
  EXPECT_DOUBLE_EQ(rs[0].front_free_m, 1.75);
  EXPECT_FALSE(rs[1].truth.has_value());  // no simulator
  EXPECT_DOUBLE_EQ(rs[1].servo_error, -0.03);
  EXPECT_EQ(rs[1].mode, "servo");
  EXPECT_EQ(rs[1].landmark, "");
}

// Columns are found by name: another order, a missing column (an older file) or an unknown
// one (a newer file) still read; what is absent stays unset.
TEST(TelemetryCsv, ReaderFindsColumnsByName) {
  const std::string dir = test::tempDir("telemetry-by-name");
  std::ofstream(dir + "/t.csv") << "w_cmd,extra,true_y,true_x,t\n"
                                << "0.5,x,2,1,0.25\n"
                                << "-0.5,x,,1,0.3\n"
                                << "0.1,x,3";  // a run killed mid-row
  const auto rs = readTelemetryCsv(dir + "/t.csv");
  ASSERT_EQ(rs.size(), 3u);
  EXPECT_DOUBLE_EQ(rs[0].w_cmd, 0.5);
  ASSERT_TRUE(rs[0].truth.has_value());
  EXPECT_DOUBLE_EQ(rs[0].truth->x, 1);
  EXPECT_DOUBLE_EQ(rs[0].truth->y, 2);
  EXPECT_DOUBLE_EQ(rs[0].truth->theta, 0);  // no true_theta column
  EXPECT_DOUBLE_EQ(rs[0].t, 0.25);
  EXPECT_TRUE(std::isnan(rs[0].odom.x));
  EXPECT_EQ(rs[0].section, -1);
  EXPECT_FALSE(rs[1].truth.has_value());  // true_y empty
  EXPECT_FALSE(rs[2].truth.has_value());
  EXPECT_TRUE(std::isnan(rs[2].t));
  EXPECT_TRUE(readTelemetryCsv(dir + "/absent.csv").empty());
}

// A run folder as the scenario runner reads it: the summary's figures, the true trajectory and
// the commanded yaw rate's sign changes per metre from telemetry.csv.
TEST(RunFolder, ReadsSummaryTrajectoryAndOscillation) {
  const std::string dir = test::tempDir("run-folder");
  std::ofstream(dir + "/summary.json")
      << R"({"success": false, "reason": "lost", "failure": "lost", "time_s": 12.5,
             "path_length_m": 2.0, "min_clearance_m": 0.4, "wall_time_s": 3.0,
             "deviation_m": {"mean": 0.1, "max": 0.3}})";
  {
    TelemetryWriter w;
    ASSERT_TRUE(w.open(dir + "/telemetry.csv"));
    // Yaw rate +, 0 (straight: not a change), +, -, + : two sign changes over 2 m.
    int k = 0;
    for (double wz : {0.2, 0.0, 0.3, -0.2, 0.1}) {
      const hw::Pose2D truth{0.5 * k, 1.0, 0.0};
      w.write(row(0.1 * k++, wz), &truth);
    }
  }
  const ScenarioResult r = readRunFolder(dir);
  EXPECT_TRUE(r.ran);
  EXPECT_FALSE(r.success);
  EXPECT_EQ(r.reason, "lost");
  EXPECT_EQ(r.failure, "lost");
  EXPECT_DOUBLE_EQ(r.time_s, 12.5);
  EXPECT_DOUBLE_EQ(r.path_m, 2.0);
  EXPECT_DOUBLE_EQ(r.min_clearance_m, 0.4);
  EXPECT_DOUBLE_EQ(r.deviation_max_m, 0.3);
  ASSERT_EQ(r.trajectory.size(), 5u);
  EXPECT_DOUBLE_EQ(r.trajectory[4].x, 2.0);
  EXPECT_DOUBLE_EQ(r.oscillation_per_m, 1.0);

  const ScenarioResult none = readRunFolder(dir + "/absent");
  EXPECT_FALSE(none.ran);
  EXPECT_EQ(none.failure, "no_summary");
}

}  // namespace
}  // namespace sketchnav::run
