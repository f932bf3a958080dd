// kill -9 at any moment leaves telemetry.csv readable to its last whole row (issue 28: a run
// killed at 4.3 s left it empty, at 7.7 s and 10 s the last row was cut to 9 and 4 of 15
// columns). `sketchnav run` is killed with SIGKILL at several moments of its run.
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "child_process.h"
#include "test_data.h"

namespace fs = std::filesystem;

namespace {
constexpr int kColumns = 15;

std::uintmax_t sizeOf(const std::string& p) {
  std::error_code ec;
  const auto s = fs::file_size(p, ec);
  return ec ? 0 : s;
}

// Every line complete (ends in '\n') with the header's column count; returns the row count.
int checkWholeRows(const std::string& path, const std::string& moment) {
  std::ifstream in(path, std::ios::binary);
  const std::string all((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (all.empty()) {
    ADD_FAILURE() << moment << ": telemetry.csv exists but is empty (no header)";
    return 0;
  }
  EXPECT_EQ(all.back(), '\n') << moment << ": last row cut: ..."
                              << all.substr(all.size() > 80 ? all.size() - 80 : 0);
  std::istringstream ss(all);
  std::string line;
  int n = 0;
  while (std::getline(ss, line)) {
    const int cols = 1 + static_cast<int>(std::count(line.begin(), line.end(), ','));
    EXPECT_EQ(cols, kColumns) << moment << ": line " << n + 1 << ": " << line;
    ++n;
  }
  return n - 1;
}
}  // namespace

TEST(RunKill, TelemetryIsWholeRowsAfterSigkillAtAnyMoment) {
  const std::string base = sketchnav::test::tempDir("run-kill");
  // Kill when telemetry.csv first appears and after about 15, 40 and 100 rows (about 100
  // bytes each): the old block-buffered writer left it empty or with a cut last row.
  const std::uintmax_t thresholds[] = {1, 1500, 4100, 10100};
  int max_rows = 0;
  for (const auto threshold : thresholds) {
    const std::string out = base + "/k" + std::to_string(threshold);
    fs::remove_all(out);
    fs::create_directories(out);
    const std::string tele = out + "/telemetry.csv";
    sketchnav::test::ChildProcess run(
        {SKETCHNAV_EXE, "run", "--max-time", "120", "--out", out, "--seed", "3"});
    ASSERT_TRUE(run.started());
    const auto t0 = std::chrono::steady_clock::now();
    bool exited = false;
    while (sizeOf(tele) < threshold) {
      if (std::chrono::steady_clock::now() - t0 > std::chrono::seconds(120)) break;
      if (::kill(run.pid(), 0) != 0) {
        exited = true;
        break;
      }
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    run.kill();
    const std::string moment = "killed at " + std::to_string(sizeOf(tele)) + " bytes";
    if (exited) continue;  // finished first: nothing to check at this moment
    ASSERT_TRUE(fs::exists(tele)) << moment;
    max_rows = std::max(max_rows, checkWholeRows(tele, moment));
  }
  EXPECT_GT(max_rows, 50) << "the runs were killed too early to test anything";
}
