// Laser scans: MRPT's recorded real laser data (mrpt-common's datasets) replayed as a device,
// and the MRPT hwdrivers front end's input checking.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "scip_emulator.h"
#include "sketchnav/core/error.h"
#include "sketchnav/drivers/laser_sensors.h"
#include "sketchnav/drivers/register.h"
#include "sketchnav/hw/registry.h"

using namespace sketchnav;
using namespace sketchnav::hw;
using namespace sketchnav::drivers;

namespace {
// A real SICK LMS200 recording (University of Malaga, 2006), shipped by mrpt-common.
const std::string kMalaga =
    "/usr/share/mrpt/datasets/2006-01ENE-21-SENA_Telecom Faculty_one_loop_only.rawlog";

#define REQUIRE_MRPT_DATASET(path)    \
  if (!std::filesystem::exists(path)) \
  GTEST_SKIP() << "MRPT dataset " << (path) << " not found (apt-get install mrpt-common)"
}  // namespace

TEST(RawlogLaser, ReplaysEveryRealScanInTheRobotFrame) {
  REQUIRE_MRPT_DATASET(kMalaga);
  RawlogRangeSensor laser(kMalaga, /*realtime=*/false, /*loop=*/false, "", nullptr);
  RangeScan s;
  int n = 0;
  std::size_t beams = 0;
  while (laser.read(s)) {
    ++n;
    ASSERT_EQ(s.kind, RangeScan::Kind::Laser);
    ASSERT_EQ(s.angles.size(), s.ranges.size());
    ASSERT_GT(s.ranges.size(), 100u);
    beams = s.ranges.size();
    ASSERT_GT(s.max_range, 1.0f);
    // Bearings increase CCW across a half-plane field of view in front of the robot.
    for (std::size_t i = 1; i < s.angles.size(); ++i) ASSERT_GT(s.angles[i], s.angles[i - 1]);
    EXPECT_NEAR(s.angles.front() + s.angles.back(), 2 * s.mount.theta, 1e-3);
    int hits = 0;
    for (float r : s.ranges) {
      ASSERT_TRUE(std::isfinite(r));
      ASSERT_GE(r, 0.0f);
      ASSERT_LE(r, s.max_range);
      hits += r < s.max_range;
    }
    EXPECT_GT(hits, 10) << "scan " << n << " sees nothing: not real data?";
  }
  EXPECT_GT(n, 50);
  EXPECT_EQ(beams, 361u);  // LMS200, 180 deg at 0.5 deg
  EXPECT_TRUE(laser.exhausted());
  EXPECT_EQ(laser.stats().received, static_cast<std::uint64_t>(n));
  EXPECT_EQ(laser.stats().dropped, 0u);
}

TEST(RawlogLaser, RealtimeReplayPacesScansOnTheDeviceClock) {
  REQUIRE_MRPT_DATASET(kMalaga);
  auto clock = std::make_shared<SimClock>();
  RawlogRangeSensor laser(kMalaga, /*realtime=*/true, false, "", clock);
  RangeScan s;
  ASSERT_TRUE(laser.read(s));  // the first scan is due at once
  EXPECT_FALSE(laser.read(s)) << "the next scan came before its recorded time";
  int delivered = 1;
  for (int i = 0; i < 100 && delivered < 5; ++i) {
    clock->advance(0.05);
    if (laser.read(s)) {
      ++delivered;
      // Stamped when it was due (when the scanner scanned), within the step that released it.
      EXPECT_LE(s.stamp, clock->now());
      EXPECT_GT(s.stamp, clock->now() - 0.05 - 1e-9);
    }
  }
  EXPECT_EQ(delivered, 5) << "scans not released as the clock advances";
  // A reader that falls 30 s behind gets the newest due scan; the skipped ones are dropped.
  clock->advance(30.0);
  ASSERT_TRUE(laser.read(s));
  EXPECT_GT(laser.stats().dropped, 0u);
}

TEST(RawlogLaser, RegistryOpensRawlogAndLaserUrisAndRejectsBadOnes) {
  registerDrivers();
  DeviceContext ctx;
  if (std::filesystem::exists(kMalaga)) {
    auto r = Registry::instance().createRange(
        "rawlog:///usr/share/mrpt/datasets/2006-01ENE-21-SENA_Telecom%20Faculty_one_loop_only."
        "rawlog?realtime=0",
        ctx);
    RangeScan s;
    EXPECT_TRUE(r->read(s));
  }
  EXPECT_THROW(Registry::instance().createRange("rawlog:///no/such/file.rawlog", ctx), InputError);
  // A rawlog without 2-D scans (a 3-D Velodyne log) is refused by name.
  if (std::filesystem::exists("/usr/share/mrpt/datasets/test_velodyne_VLP16.rawlog")) {
    try {
      Registry::instance().createRange(
          "rawlog:///usr/share/mrpt/datasets/test_velodyne_VLP16.rawlog", ctx);
      FAIL() << "a log without 2-D scans was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("no 2-D laser scan"), std::string::npos) << e.what();
    }
  }
  try {
    Registry::instance().createRange("laser://CFancyLidar?port=x", ctx);
    FAIL() << "an unknown laser driver was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("CHokuyoURG"), std::string::npos) << e.what();
  }
  EXPECT_THROW(Registry::instance().createRange("laser:///no/such.ini", ctx), InputError);
}

TEST(MrptLaser, HokuyoDriverReadsRecordedRealScansFromAScipDeviceOnLoopback) {
  REQUIRE_MRPT_DATASET(kMalaga);
  // The recorded scans, served by a SCIP 2.0 device (a Hokuyo on Ethernet) on loopback.
  RawlogRangeSensor log(kMalaga, false, false, "", nullptr);
  std::vector<std::vector<int>> mm;
  RangeScan s;
  float max_range = 0;
  while (mm.size() < 30 && log.read(s)) {
    std::vector<int> r;
    for (float x : s.ranges)
      r.push_back(x >= s.max_range ? 0 : static_cast<int>(std::lround(x * 1000)));
    mm.push_back(r);
    max_range = s.max_range;
  }
  ASSERT_EQ(mm.size(), 30u);
  test::ScipEmulator device(mm, 720, static_cast<int>(max_range * 1000), 0.025);

  registerDrivers();
  DeviceContext ctx;
  auto laser = Registry::instance().createRange(
      "laser://CHokuyoURG?IP_DIR=127.0.0.1&PORT_DIR=" + std::to_string(device.port()) +
          "&pose_x=0.2&pose_yaw=0",
      ctx);
  // Each scan the driver delivers must be one of the recorded ones, to the millimetre, and
  // they must come in recorded order.
  int got = 0;
  long last_index = -1;
  SteadyClock wall;
  while (got < 10 && wall.now() < 10.0) {
    if (!laser->read(s)) {
      wall.sleepUntil(wall.now() + 0.005);
      continue;
    }
    ASSERT_EQ(s.ranges.size(), mm.front().size());
    EXPECT_DOUBLE_EQ(s.mount.x, 0.2f);
    long match = -1;
    for (std::size_t k = 0; k < mm.size() && match < 0; ++k) {
      bool same = true;
      for (std::size_t i = 0; i < s.ranges.size() && same; ++i) {
        const int want = mm[k][i];
        const bool valid = want >= 20;
        same = valid ? std::abs(s.ranges[i] * 1000 - want) < 0.6f : s.ranges[i] >= s.max_range;
      }
      if (same) match = static_cast<long>(k);
    }
    ASSERT_GE(match, 0) << "scan " << got << " matches no recorded scan";
    if (match < last_index) {
      EXPECT_LT(match, 3) << "out of order (only a wrap-around of the replay may go back)";
    }
    last_index = match;
    // Bearings: CCW, centred on the sensor's axis, 0.5 deg apart (ARES 720).
    EXPECT_NEAR(s.angles[1] - s.angles[0], 2 * M_PI / 720, 1e-4);
    EXPECT_NEAR(s.angles.front() + s.angles.back(), 0.0, 1e-3);
    ++got;
  }
  EXPECT_EQ(got, 10) << "the driver delivered " << got << " scans in 10 s";
  EXPECT_EQ(laser->stats().last_error, "");
}
