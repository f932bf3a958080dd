// Recording to an MRPT rawlog and reading it back, including after the recorder was killed.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <opencv2/core.hpp>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <thread>

#include "sketchnav/core/error.h"
#include "sketchnav/core/log.h"
#include "sketchnav/drivers/laser_sensors.h"
#include "sketchnav/drivers/rawlog.h"
#include "sketchnav/drivers/register.h"
#include "sketchnav/hw/registry.h"
#include "test_data.h"

using namespace sketchnav;
using namespace sketchnav::hw;
using namespace sketchnav::drivers;
namespace fs = std::filesystem;

namespace {
Frame makeFrame(int i) {
  Frame f;
  f.image = cv::Mat(48, 64, CV_8UC3, cv::Scalar(10 * i, 255 - 10 * i, 7 * i));
  cv::Mat patch = f.image(cv::Rect(0, 0, 16, 16));
  cv::RNG(static_cast<std::uint64_t>(i + 1)).fill(patch, cv::RNG::UNIFORM, 0, 255);  // not flat
  f.stamp = 100.0 + 0.1 * i;
  f.seq = static_cast<std::uint64_t>(i);
  return f;
}
RangeScan makeLaser() {
  RangeScan s;
  s.kind = RangeScan::Kind::Laser;
  s.max_range = 8.0f;
  s.mount = {0.2, 0.0, 0.1};
  for (int i = 0; i <= 180; ++i) {
    s.angles.push_back(static_cast<float>(0.1 - M_PI / 2 + i * M_PI / 180));
    s.ranges.push_back(i % 10 == 0 ? 8.0f : 1.0f + 0.01f * i);
  }
  s.stamp = 100.05;
  return s;
}
std::string fileBytes(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}
// One record exactly as RawlogRecorder writes it.
std::string recordOf(const std::string& dir, const std::function<void(RawlogRecorder&)>& add) {
  const std::string path = dir + "/one.rawlog";
  {
    RawlogRecorder rec(path);
    add(rec);
  }
  return fileBytes(path);
}
void putU32(std::string& bytes, std::size_t at, std::uint32_t v) {
  ASSERT_LE(at + 4, bytes.size());
  std::memcpy(&bytes[at], &v, 4);
}
}  // namespace

TEST(Rawlog, RecordsFramesOdometryRangesAndCommandsAndReadsThemBack) {
  const std::string dir = test::tempDir("rawlog");
  const std::string path = dir + "/run.rawlog";
  Intrinsics k = Intrinsics::fromFov(64, 48, 1.0);
  {
    RawlogRecorder rec(path);
    EXPECT_EQ(rec.imageDir(), dir + "/run_Images");
    for (int i = 0; i < 3; ++i) {
      rec.addFrame(makeFrame(i), k);
      Odometry o;
      o.pose = {0.1 * i, -0.05 * i, 0.2 * i};
      o.v = 0.3;
      o.w = -0.1;
      o.stamp = 100.0 + 0.1 * i + 0.01;
      rec.addOdometry(o);
      rec.addCommand(0.3, 0.05 * i, 100.0 + 0.1 * i + 0.02);
    }
    rec.addRange(makeLaser());
    RangeScan sonar;
    sonar.kind = RangeScan::Kind::Sonar;
    sonar.angles = {0.0f, 0.5f};
    sonar.ranges = {1.5f, 3.0f};
    sonar.max_range = 3.0f;
    sonar.beam_width = 0.4f;
    sonar.stamp = 100.3;
    rec.addRange(sonar);
    EXPECT_EQ(rec.records(), 11u);
  }
  EXPECT_EQ(std::distance(fs::directory_iterator(dir + "/run_Images"), fs::directory_iterator()),
            3);

  RawlogReader rd(path);
  RawlogEntry e;
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE(rd.next(e));
    ASSERT_EQ(e.kind, RawlogEntry::Kind::Frame);
    EXPECT_EQ(e.label, "CAMERA");
    EXPECT_NEAR(e.stamp, 100.0 + 0.1 * i, 1e-6);
    EXPECT_EQ(e.intrinsics.width, 64);
    EXPECT_NEAR(e.intrinsics.fx, k.fx, 1e-9);
    ASSERT_FALSE(e.frame.image.empty());
    EXPECT_EQ(cv::norm(e.frame.image, makeFrame(i).image, cv::NORM_INF), 0.0) << "frame " << i;
    ASSERT_TRUE(rd.next(e));
    ASSERT_EQ(e.kind, RawlogEntry::Kind::Odometry);
    EXPECT_NEAR(e.odometry.pose.x, 0.1 * i, 1e-9);
    EXPECT_NEAR(e.odometry.pose.theta, 0.2 * i, 1e-9);
    EXPECT_NEAR(e.odometry.v, 0.3, 1e-9);
    EXPECT_NEAR(e.odometry.w, -0.1, 1e-9);
    ASSERT_TRUE(rd.next(e));
    ASSERT_EQ(e.kind, RawlogEntry::Kind::Command);
    EXPECT_NEAR(e.w, 0.05 * i, 1e-9);
    EXPECT_NEAR(e.stamp, 100.0 + 0.1 * i + 0.02, 1e-6);
  }
  ASSERT_TRUE(rd.next(e));
  ASSERT_EQ(e.kind, RawlogEntry::Kind::Range);
  const RangeScan want = makeLaser();
  ASSERT_EQ(e.range.kind, RangeScan::Kind::Laser);
  ASSERT_EQ(e.range.ranges.size(), want.ranges.size());
  EXPECT_NEAR(e.range.mount.theta, 0.1, 1e-6);
  for (std::size_t i = 0; i < want.ranges.size(); ++i) {
    EXPECT_NEAR(e.range.angles[i], want.angles[i], 1e-5) << i;
    EXPECT_FLOAT_EQ(e.range.ranges[i], want.ranges[i]) << i;
  }
  ASSERT_TRUE(rd.next(e));
  ASSERT_EQ(e.kind, RawlogEntry::Kind::Range);
  EXPECT_EQ(e.range.kind, RangeScan::Kind::Sonar);
  ASSERT_EQ(e.range.ranges.size(), 2u);
  EXPECT_FLOAT_EQ(e.range.angles[1], 0.5f);
  EXPECT_FLOAT_EQ(e.range.ranges[0], 1.5f);
  EXPECT_FALSE(rd.next(e));
  EXPECT_EQ(rd.truncated(), 0u);

  // The same file through the registry: frames as a camera, the laser as a range sensor.
  registerDrivers();
  DeviceContext ctx;
  auto cam = Registry::instance().createCamera("rawlog://" + path, ctx);
  EXPECT_EQ(cam->intrinsics().width, 64);
  Frame f;
  for (int i = 0; i < 3; ++i) {
    ASSERT_EQ(cam->grab(f), GrabStatus::Ok);
    EXPECT_NEAR(f.stamp, 100.0 + 0.1 * i, 1e-6);
  }
  EXPECT_EQ(cam->grab(f), GrabStatus::EndOfStream);
  auto laser = Registry::instance().createRange("rawlog://" + path + "?realtime=0", ctx);
  RangeScan s;
  ASSERT_TRUE(laser->read(s));
  EXPECT_EQ(s.ranges.size(), want.ranges.size());
  EXPECT_FALSE(laser->read(s)) << "the sonar is not part of the default (laser) stream";
  auto sonar_replay =
      Registry::instance().createRange("rawlog://" + path + "?realtime=0&label=SONAR", ctx);
  ASSERT_TRUE(sonar_replay->read(s));
  EXPECT_EQ(s.kind, RangeScan::Kind::Sonar);
  EXPECT_FLOAT_EQ(s.ranges[1], 3.0f);

  // Odometry as a base, paced on the run's clock: records come due as the clock advances.
  auto clock = std::make_shared<SimClock>();
  DeviceContext sim_ctx;
  sim_ctx.clock = clock;
  auto base = Registry::instance().createBase("rawlog://" + path, sim_ctx);
  Odometry o;
  // The log starts with a frame at 100.00; the first odometry record is 10 ms later.
  EXPECT_FALSE(base->odometry(o)) << "odometry before its recorded time";
  clock->advance(0.01);
  ASSERT_TRUE(base->odometry(o));
  EXPECT_NEAR(o.pose.x, 0.0, 1e-9);
  EXPECT_NEAR(o.stamp, 0.01, 1e-6);
  clock->advance(0.1);
  ASSERT_TRUE(base->odometry(o));
  EXPECT_NEAR(o.pose.x, 0.1, 1e-9);
  EXPECT_TRUE(base->ok());
  clock->advance(0.1);
  ASSERT_TRUE(base->odometry(o));
  EXPECT_NEAR(o.pose.x, 0.2, 1e-9);
  EXPECT_FALSE(base->ok()) << "the last record was replayed: the recording has ended";

  // A paced camera on another simulated clock: frames come due at their recorded offsets from
  // the log's first record, stamped on the replay clock.
  auto clock2 = std::make_shared<SimClock>();
  DeviceContext paced;
  paced.clock = clock2;
  auto cam2 = Registry::instance().createCamera("rawlog://" + path + "?realtime=1", paced);
  ASSERT_EQ(cam2->grab(f, 1.0), GrabStatus::Ok);
  EXPECT_NEAR(f.stamp, 0.0, 1e-6);
  ASSERT_EQ(cam2->grab(f, 0.05), GrabStatus::Timeout) << "a frame came before it was due";
  ASSERT_EQ(cam2->grab(f, 1.0), GrabStatus::Ok);
  EXPECT_NEAR(f.stamp, 0.1, 1e-6);
  EXPECT_NEAR(clock2->now(), 0.1, 1e-6);
}

TEST(Rawlog, AKilledRecorderLeavesALogReadableUpToItsLastRecord) {
  const std::string dir = test::tempDir("rawlog-kill");
  const std::string path = dir + "/killed.rawlog";
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {  // the run being recorded, until it is killed mid-flight
    RawlogRecorder rec(path);
    for (int i = 0;; ++i) {
      rec.addFrame(makeFrame(i % 20), Intrinsics::fromFov(64, 48, 1.0));
      Odometry o;
      o.stamp = i;
      rec.addOdometry(o);
    }
  }
  // Kill it once it has written a fair amount (bounded wait).
  for (int i = 0; i < 500 && (!fs::exists(path) || fs::file_size(path) < 20000); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  ::kill(child, SIGKILL);
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status));

  RawlogReader rd(path);
  RawlogEntry e;
  int frames = 0, odos = 0;
  while (rd.next(e)) {
    if (e.kind == RawlogEntry::Kind::Frame) {
      ++frames;
      EXPECT_FALSE(e.frame.image.empty()) << "a record names an image that was never written";
    }
    odos += e.kind == RawlogEntry::Kind::Odometry;
  }
  EXPECT_GT(frames, 10);
  EXPECT_GE(frames, odos);  // records alternate frame, odometry
  EXPECT_LE(frames, odos + 1);

  // A record cut in half (the kill landing inside a write) ends the log quietly.
  const auto size = fs::file_size(path);
  fs::resize_file(path, size - 7);
  RawlogReader cut(path);
  int n = 0;
  while (cut.next(e, false)) ++n;
  EXPECT_GE(n, frames + odos - 1);
  EXPECT_LE(cut.truncated(), 1u);
}

TEST(Rawlog, ARecordWhoseLengthFieldClaimsGigabytesEndsTheLogWithoutBeingAllocated) {
  const std::string dir = test::tempDir("rawlog-huge");
  Odometry o;
  o.stamp = 100.0;
  const std::string odo = recordOf(dir, [&](RawlogRecorder& r) { r.addOdometry(o); });
  RangeScan sonar;
  sonar.kind = RangeScan::Kind::Sonar;
  sonar.angles = {0.0f, 0.5f};
  sonar.ranges = {1.5f, 3.0f};
  sonar.max_range = 3.0f;
  std::string sonar_rec = recordOf(dir, [&](RawlogRecorder& r) { r.addRange(sonar); });
  std::string laser_rec = recordOf(dir, [&](RawlogRecorder& r) { r.addRange(makeLaser()); });
  // CObservationRange: header byte, class name, version, three floats, then the count.
  const std::string range_class = "mrpt::obs::CObservationRange";
  ASSERT_EQ(sonar_rec.substr(1, range_class.size()), range_class);
  putU32(sonar_rec, 1 + range_class.size() + 1 + 3 * 4, 0xF0000000u);
  // The scan's sensorLabel: its length field sits just before the label.
  const std::size_t label = laser_rec.rfind("LASER");
  ASSERT_NE(label, std::string::npos);
  putU32(laser_rec, label - 4, 0xE0000000u);

  const struct {
    std::string name, record, field;
  } cases[] = {{"sonar-count", sonar_rec, "field=\"sensedData count 4026531840"},
               {"scan-label", laser_rec, "field=\"sensorLabel (length 3758096384)"}};
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string path = dir + "/" + c.name + ".rawlog";
    std::ofstream(path, std::ios::binary) << odo << odo << c.record << odo;

    testing::internal::CaptureStderr();
    const auto t0 = std::chrono::steady_clock::now();
    RawlogReader rd(path);
    RawlogEntry e;
    int n = 0;
    while (rd.next(e, false)) {
      EXPECT_EQ(e.kind, RawlogEntry::Kind::Odometry);
      ++n;
    }
    const double took =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const std::string err = testing::internal::GetCapturedStderr();
    EXPECT_EQ(n, 2) << "the records before the corrupt one, and none after it";
    EXPECT_EQ(rd.truncated(), 1u);
    EXPECT_NE(err.find("log ends at a corrupt record file=" + path + " record=3 " + c.field),
              std::string::npos)
        << err;
    EXPECT_LT(took, 1.0) << "gigabytes were allocated and filled";

#ifndef __SANITIZE_ADDRESS__  // ASan reserves terabytes of address space up front
    // The same read with 1 GiB of address space to spare: what the field claims cannot be had.
    // (MRPT's own reader met bad_alloc here and ended the log without a word.)
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      long pages = 0;
      std::ifstream("/proc/self/statm") >> pages;
      const rlim_t limit = static_cast<rlim_t>(pages) * ::sysconf(_SC_PAGESIZE) + (rlim_t{1} << 30);
      const rlimit lim{limit, limit};
      ::setrlimit(RLIMIT_AS, &lim);
      log::setQuiet(true);
      RawlogReader bounded(path);
      int m = 0;
      while (bounded.next(e, false)) ++m;
      ::_exit(m == 2 && bounded.truncated() == 1 ? 0 : 1);
    }
    int status = 0;
    ::waitpid(child, &status, 0);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "status " << status;
#endif
  }
}

// The same corrupt records replayed as a laser or a sonar (rawlog:// as a range device, which
// `run --replay` opens): the scans before the bad record come back, the log ends there with
// the field named, and what the length field claims is never allocated.
TEST(Rawlog, ARangeReplayOfARecordClaimingGigabytesEndsWithoutAllocatingIt) {
  const std::string dir = test::tempDir("rawlog-huge-range");
  RangeScan sonar;
  sonar.kind = RangeScan::Kind::Sonar;
  sonar.angles = {0.0f, 0.5f};
  sonar.ranges = {1.5f, 3.0f};
  sonar.max_range = 3.0f;
  const std::string sonar_ok = recordOf(dir, [&](RawlogRecorder& r) { r.addRange(sonar); });
  const std::string laser_ok = recordOf(dir, [&](RawlogRecorder& r) { r.addRange(makeLaser()); });
  std::string sonar_bad = sonar_ok, laser_bad = laser_ok;
  const std::string range_class = "mrpt::obs::CObservationRange";
  ASSERT_EQ(sonar_bad.substr(1, range_class.size()), range_class);
  putU32(sonar_bad, 1 + range_class.size() + 1 + 3 * 4, 0xF0000000u);
  const std::size_t label = laser_bad.rfind("LASER");
  ASSERT_NE(label, std::string::npos);
  putU32(laser_bad, label - 4, 0xE0000000u);

  const struct {
    std::string name, ok, bad, label, field;
  } cases[] = {{"sonar-count", sonar_ok, sonar_bad, "SONAR", "field=\"sensedData count 4026531840"},
               {"scan-label", laser_ok, laser_bad, "", "field=\"sensorLabel (length 3758096384)"}};
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string path = dir + "/" + c.name + ".rawlog";
    std::ofstream(path, std::ios::binary) << c.ok << c.ok << c.bad << c.ok;
    const auto readAll = [&](RawlogRangeSensor& r) {
      RangeScan s;
      int n = 0;
      while (r.read(s)) ++n;
      return n;
    };

    testing::internal::CaptureStderr();
    const auto t0 = std::chrono::steady_clock::now();
    RawlogRangeSensor range(path, /*realtime=*/false, /*loop=*/false, c.label, nullptr);
    const int n = readAll(range);
    const double took =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const std::string err = testing::internal::GetCapturedStderr();
    EXPECT_EQ(n, 2) << "the scans before the corrupt record, and none after it";
    EXPECT_EQ(range.stats().incomplete, 1u);
    EXPECT_NE(err.find("log ends at a corrupt record file=" + path + " record=3 " + c.field),
              std::string::npos)
        << err;
    EXPECT_LT(took, 1.0) << "gigabytes were allocated and filled";

#ifndef __SANITIZE_ADDRESS__  // ASan reserves terabytes of address space up front
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      long pages = 0;
      std::ifstream("/proc/self/statm") >> pages;
      const rlim_t limit = static_cast<rlim_t>(pages) * ::sysconf(_SC_PAGESIZE) + (rlim_t{1} << 30);
      const rlimit lim{limit, limit};
      ::setrlimit(RLIMIT_AS, &lim);
      log::setQuiet(true);
      RawlogRangeSensor bounded(path, false, false, c.label, nullptr);
      ::_exit(readAll(bounded) == 2 && bounded.stats().incomplete == 1 ? 0 : 1);
    }
    int status = 0;
    ::waitpid(child, &status, 0);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "status " << status;
#endif
  }
}
