// kill -9 at any moment leaves every file a run writes readable to its last whole record
// (issue 28: a run killed at 4.3 s left telemetry.csv empty, at 7.7 s and 10 s the last row was
// cut to 9 and 4 of 15 columns). `sketchnav run` (the simulated lab, recording a rawlog and a
// log file into its folder) is killed with SIGKILL at several moments of its run, and every
// output is read back: telemetry.csv, events.jsonl, the log file, the rawlog and, once they
// exist, summary.json and trajectory.png.
#include <gtest/gtest.h>
#include <signal.h>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <optional>
#include <random>
#include <sstream>
#include <thread>

#include "child_process.h"
#include "sketchnav/drivers/rawlog.h"
#include "sketchnav/drivers/recording.h"
#include "test_data.h"

namespace fs = std::filesystem;

namespace {
constexpr int kColumns = 15;

std::uintmax_t sizeOf(const std::string& p) {
  std::error_code ec;
  const auto s = fs::file_size(p, ec);
  return ec ? 0 : s;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The file's lines, each of which must be complete (the file ends in '\n').
std::vector<std::string> wholeLines(const std::string& path, const std::string& moment) {
  const std::string all = slurp(path);
  std::vector<std::string> lines;
  if (all.empty()) return lines;
  EXPECT_EQ(all.back(), '\n') << moment << ": " << path << ": last line cut: ..."
                              << all.substr(all.size() > 80 ? all.size() - 80 : 0);
  std::istringstream ss(all);
  for (std::string line; std::getline(ss, line);) lines.push_back(line);
  return lines;
}

// A header, then rows with the header's column count; returns the row count.
int checkTelemetry(const std::string& path, const std::string& moment) {
  const auto lines = wholeLines(path, moment);
  if (lines.empty()) {
    ADD_FAILURE() << moment << ": telemetry.csv exists but is empty (no header)";
    return 0;
  }
  EXPECT_EQ(lines[0].rfind("t,odom_x,", 0), 0u) << moment << ": no header: " << lines[0];
  for (size_t i = 0; i < lines.size(); ++i) {
    const int cols = 1 + static_cast<int>(std::count(lines[i].begin(), lines[i].end(), ','));
    EXPECT_EQ(cols, kColumns) << moment << ": telemetry.csv line " << i + 1 << ": " << lines[i];
  }
  return static_cast<int>(lines.size()) - 1;
}

// Every line a JSON object with a "type"; returns the line count.
int checkEvents(const std::string& path, const std::string& moment) {
  const auto lines = wholeLines(path, moment);
  for (size_t i = 0; i < lines.size(); ++i) {
    const auto j = nlohmann::json::parse(lines[i], nullptr, false);
    EXPECT_FALSE(j.is_discarded()) << moment << ": events.jsonl line " << i + 1 << ": " << lines[i];
    if (!j.is_discarded()) EXPECT_TRUE(j.contains("type")) << moment << ": " << lines[i];
  }
  return static_cast<int>(lines.size());
}

// Every line "<UTC time> <LEVEL> <component>: ...".
void checkLog(const std::string& path, const std::string& moment) {
  const auto lines = wholeLines(path, moment);
  EXPECT_FALSE(lines.empty()) << moment << ": the log file is empty";
  for (size_t i = 0; i < lines.size(); ++i) {
    const auto& l = lines[i];
    EXPECT_TRUE(l.size() > 30 && l[4] == '-' && l[10] == 'T' && l[23] == 'Z' &&
                l.find(": ") != std::string::npos)
        << moment << ": log line " << i + 1 << ": " << l;
  }
}

// Readable to its last whole record: at most one cut record at the end, and every frame record
// names an image that is on disk whole. Returns the record count.
int checkRawlog(const std::string& path, const std::string& moment) {
  sketchnav::drivers::RawlogReader rd(path);
  sketchnav::drivers::RawlogEntry e;
  int n = 0;
  while (rd.next(e)) {
    ++n;
    if (e.kind == sketchnav::drivers::RawlogEntry::Kind::Frame)
      EXPECT_FALSE(e.frame.image.empty()) << moment << ": record " << n << " names a missing image";
  }
  EXPECT_LE(rd.truncated(), 1u) << moment;
  return n;
}

struct Outcome {
  int rows = 0, events = 0, records = 0;
  bool exited = false;   // the run ended before the moment came
  bool summary = false;  // summary.json was there (and whole)
  bool trajectory = false;
};

// Starts `sketchnav run`, kills it with SIGKILL as soon as `moment_reached(out)` holds, and
// checks every file in its folder.
// With `before_outputs_ok` the moment may come before the run has opened its outputs.
Outcome killAndCheck(const std::string& out, const std::string& max_time,
                     const std::function<bool(const std::string&)>& moment_reached,
                     const std::string& name, bool before_outputs_ok = false) {
  fs::remove_all(out);
  fs::create_directories(out);
  sketchnav::test::ChildProcess run({SKETCHNAV_EXE, "--log-file", out + "/run.log", "run",
                                     "--max-time", max_time, "--out", out, "--seed", "3",
                                     "--record", out + "/run.rawlog"});
  Outcome r;
  if (!run.started()) {
    ADD_FAILURE() << "cannot start " << SKETCHNAV_EXE;
    return r;
  }
  const auto t0 = std::chrono::steady_clock::now();
  while (!moment_reached(out)) {
    if (std::chrono::steady_clock::now() - t0 > std::chrono::seconds(120)) break;
    if (::kill(run.pid(), 0) != 0) {
      r.exited = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  run.kill();
  if (r.exited) return r;  // finished first: nothing to check at this moment
  const std::string moment =
      name + " (killed at " + std::to_string(sizeOf(out + "/telemetry.csv")) + " bytes)";
  const std::string tele = out + "/telemetry.csv";
  if (!fs::exists(tele)) {
    // Killed before the run opened its outputs (settings, world, model): nothing is written
    // yet but the log. A moment chosen by the outputs themselves must find them.
    if (!before_outputs_ok) ADD_FAILURE() << moment << ": no telemetry.csv";
    if (fs::exists(out + "/run.log")) checkLog(out + "/run.log", moment);
    if (fs::exists(out + "/events.jsonl")) checkEvents(out + "/events.jsonl", moment);
    return r;
  }
  r.rows = checkTelemetry(tele, moment);
  EXPECT_TRUE(fs::exists(out + "/events.jsonl")) << moment;
  r.events = checkEvents(out + "/events.jsonl", moment);
  checkLog(out + "/run.log", moment);
  if (fs::exists(out + "/run.rawlog")) r.records = checkRawlog(out + "/run.rawlog", moment);
  // The run info beside the rawlog (what a replay runs with): whole JSON or absent.
  if (fs::exists(out + "/run.rawlog.run.json")) {
    try {
      EXPECT_TRUE(sketchnav::drivers::readRunInfo(out + "/run.rawlog").is_object()) << moment;
    } catch (const std::exception& e) {
      ADD_FAILURE() << moment << ": run.rawlog.run.json: " << e.what();
    }
  }
  if (fs::exists(out + "/summary.json")) {
    r.summary = true;
    const auto j = nlohmann::json::parse(slurp(out + "/summary.json"), nullptr, false);
    EXPECT_FALSE(j.is_discarded()) << moment << ": summary.json is not whole JSON";
    if (!j.is_discarded()) EXPECT_TRUE(j.contains("success")) << moment;
  }
  if (fs::exists(out + "/trajectory.png")) {
    r.trajectory = true;
    EXPECT_FALSE(cv::imread(out + "/trajectory.png").empty())
        << moment << ": trajectory.png does not decode";
  }
  return r;
}

// True once a file named `name` or its temporary (`name.tmp.<pid>`) is in `dir`.
bool appeared(const std::string& dir, const std::string& name) {
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.path().filename().string().rfind(name, 0) == 0) return true;
  return false;
}
// True once telemetry.csv in `dir` holds its header and a whole first row (the run drives).
bool hasTelemetryRow(const std::string& dir) {
  std::ifstream in(dir + "/telemetry.csv");
  std::string line;
  int lines = 0;
  while (lines < 2 && std::getline(in, line) && !in.eof()) ++lines;
  return lines >= 2;
}
}  // namespace

TEST(RunKill, EveryOutputIsWholeRecordsAfterSigkillDuringTheRun) {
  const std::string base = sketchnav::test::tempDir("run-kill");
  // Kill when telemetry.csv first appears and after about 15, 40 and 100 rows (about 100
  // bytes each): the old block-buffered writer left it empty or with a cut last row.
  const std::uintmax_t thresholds[] = {1, 1500, 4100, 10100};
  Outcome longest;
  for (const auto threshold : thresholds) {
    const std::string out = base + "/k" + std::to_string(threshold);
    const Outcome r = killAndCheck(
        out, "120",
        [threshold](const std::string& dir) { return sizeOf(dir + "/telemetry.csv") >= threshold; },
        "telemetry at " + std::to_string(threshold) + " bytes");
    EXPECT_FALSE(r.exited) << "the run ended before telemetry.csv reached " << threshold;
    if (r.rows > longest.rows) longest = r;
  }
  EXPECT_GT(longest.rows, 50) << "the runs were killed too early to test anything";
  EXPECT_GT(longest.events, 0) << "no event written in the longest run";
  EXPECT_GT(longest.records, 50) << "the rawlog recorded little in the longest run";
}

TEST(RunKill, SummaryAndTrajectoryAreWholeOrAbsentAfterSigkillAsTheRunEnds) {
  const std::string base = sketchnav::test::tempDir("run-kill-end");
  // A 2-second run: killed the moment its summary.json (or its temporary file) appears, and
  // the moment trajectory.png does, i.e. while they are being written.
  for (const std::string name : {"summary.json", "trajectory.png"}) {
    const Outcome r = killAndCheck(
        base + "/" + name, "2", [name](const std::string& dir) { return appeared(dir, name); },
        "as " + name + " appeared");
    EXPECT_FALSE(r.exited) << "the run ended before " << name << " appeared";
    EXPECT_GT(r.rows, 10) << name;
    if (name == "trajectory.png") EXPECT_TRUE(r.summary) << "summary.json comes first";
  }
}

TEST(RunKill, EveryOutputIsWholeRecordsAfterSigkillAtRandomMoments) {
  // Moments not chosen by what the files hold: seeded uniform times. Half are counted from the
  // start of 2-second runs (settings and world, the model, driving, the end's summary and
  // picture: such a run ends within a few seconds of wall time, and a kill after the exit
  // checks nothing, counted); half from the moment a 120-second run first wrote telemetry, so
  // they land while it drives however slowly the machine starts a run (under a loaded suite the
  // start alone can take longer than the whole window counted from the start).
  const std::string base = sketchnav::test::tempDir("run-kill-random");
  std::mt19937 rng(28);
  std::uniform_real_distribution<double> at_s(0.05, 6.0);
  std::uniform_real_distribution<double> driving_s(0.05, 4.0);
  int checked = 0, with_rows = 0;
  for (int i = 0; i < 8; ++i) {
    const bool from_start = i % 2;
    const double t = from_start ? at_s(rng) : driving_s(rng);
    const std::string max_time = from_start ? "2" : "120";
    const auto delay = std::chrono::microseconds(static_cast<long>(t * 1e6));
    // The moment counted from: the start, or the first telemetry row (found on a later call).
    auto origin = std::make_shared<std::optional<std::chrono::steady_clock::time_point>>();
    if (from_start) *origin = std::chrono::steady_clock::now();
    const Outcome r = killAndCheck(
        base + "/r" + std::to_string(i), max_time,
        [origin, delay](const std::string& dir) {
          const auto now = std::chrono::steady_clock::now();
          if (!origin->has_value() && hasTelemetryRow(dir)) *origin = now;
          return origin->has_value() && now >= **origin + delay;
        },
        "random kill " + std::to_string(i) + " at " + std::to_string(t) + " s after the " +
            (from_start ? "start" : "first telemetry") + " of a " + max_time + " s run",
        /*before_outputs_ok=*/true);
    if (!r.exited) ++checked;
    if (r.rows > 0) ++with_rows;
  }
  EXPECT_GE(checked, 4) << "the kills counted from the first telemetry row must land in the run";
  EXPECT_GE(with_rows, 4) << "the kills counted from the first telemetry row found no row";
}
