#include "sketchnav/run/scenario.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <mutex>
#include <sstream>
#include <thread>

#include "sketchnav/core/error.h"
#include "sketchnav/core/log.h"
#include "sketchnav/core/paths.h"
#include "sketchnav/landmarks/model.h"
#include "sketchnav/run/run.h"
#include "sketchnav/run/run_folder.h"
#include "sketchnav/run/summary.h"

namespace sketchnav::run {
namespace fs = std::filesystem;

std::string selfExecutable() {
  std::error_code ec;
  const auto p = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw RuntimeError("cannot find the running executable (/proc/self/exe)");
  return p.string();
}

namespace {
// The model file to use: `model` (checked to exist), or the demo set's cache path (empty
// `demo_dir` otherwise).
std::string modelPath(const std::string& model, std::string& demo_dir) {
  if (!model.empty()) {
    if (!fs::exists(model)) throw InputError("--model " + model + ": no such file");
    return model;
  }
  demo_dir = resourcePath("landmarks");
  return modelCachePath(demo_dir, "");
}

// The demo set's cached model, loaded; trained when the cache is missing, and also when it
// exists but was trained with other landmarks.train settings (another version's defaults, or
// --set): retrained, as `run` does, instead of being used silently.
landmarks::LandmarkModel demoModel(const std::string& dir, const std::string& path, bool progress,
                                   const landmarks::ModelParams& train) {
  if (progress && !fs::exists(path))
    std::cerr << "training the landmark model from " << dir << " (cached in " << path << ")\n";
  return landmarks::loadOrTrainModel(dir, path, train, {});
}
}  // namespace

std::string ensureModel(const std::string& model, bool progress,
                        const landmarks::ModelParams& train) {
  std::string dir;
  const std::string path = modelPath(model, dir);
  if (!dir.empty()) demoModel(dir, path, progress, train);
  return path;
}

landmarks::LandmarkModel loadModel(const std::string& model, bool progress,
                                   const landmarks::ModelParams& train) {
  std::string dir;
  const std::string path = modelPath(model, dir);
  return dir.empty() ? landmarks::LandmarkModel::load(path) : demoModel(dir, path, progress, train);
}

void buildIndexes(const landmarks::LandmarkModel& model, const char* component) {
  const auto t0 = std::chrono::steady_clock::now();
  model.buildIndexes();
  log::info(component, "landmark model's search indexes built",
            {{"ms", std::to_string(std::chrono::duration<double, std::milli>(
                                       std::chrono::steady_clock::now() - t0)
                                       .count())}});
}

namespace {

// Runs one child; returns its exit status (-1 when it could not start).
int spawnRun(const ScenarioSpec& s, const std::string& exe) {
  std::vector<std::string> args = {exe,           "--json",     "run",
                                   "--world",     s.world_file, "--sketch",
                                   s.sketch_file, "--seed",     std::to_string(s.seed),
                                   "--out",       s.out_dir,    "--model",
                                   s.model};
  if (!s.config_file.empty()) args.insert(args.begin() + 1, {"--config", s.config_file});
  for (const auto& kv : s.sets) args.insert(args.begin() + 1, {"--set", kv});
  if (s.max_time_s > 0) {
    std::ostringstream t;
    t << s.max_time_s;
    args.insert(args.end(), {"--max-time", t.str()});
  }
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  const std::string out = s.out_dir + "/stdout.json", err = s.out_dir + "/run.log";
  // fork + exec rather than posix_spawn: the child asks to be killed when this process dies
  // (Ctrl-C or a kill of `experiments` must not leave runs behind). Only async-signal-safe
  // calls between fork and exec.
  const pid_t pid = fork();
  if (pid < 0) return -1;
  if (pid == 0) {
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    const int fo = open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int fe = open(err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fo >= 0) dup2(fo, 1);
    if (fe >= 0) dup2(fe, 2);
    execv(exe.c_str(), argv.data());
    _exit(127);
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return WIFEXITED(status) ? WEXITSTATUS(status)
                           : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

std::string lastLine(const std::string& file) {
  std::ifstream in(file);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  return last;
}

}  // namespace

ScenarioResult readRunFolder(const std::string& dir) {
  ScenarioResult r;
  std::ifstream sj(dir + "/summary.json");
  if (!sj) {
    r.reason = "no summary: " + lastLine(dir + "/run.log");
    r.failure = "no_summary";
    return r;
  }
  try {
    r.summary = Json::parse(sj);
  } catch (const std::exception& e) {
    r.reason = std::string("unreadable summary.json: ") + e.what();
    r.failure = "no_summary";
    return r;
  }
  const RunSummary s = RunSummary::fromJson(r.summary);
  r.ran = true;
  r.success = s.success;
  r.reason = s.reason;
  r.failure = s.failure;
  r.time_s = s.time_s;
  r.path_m = s.path_length_m;
  r.min_clearance_m = s.min_clearance_m;
  r.wall_s = s.wall_time_s;
  r.deviation_mean_m = s.deviation_mean_m;
  r.deviation_max_m = s.deviation_max_m;
  // Telemetry: the true poses and the commanded yaw rate.
  int last_sign = 0, changes = 0;
  for (const TelemetryRecord& t : readTelemetryCsv(dir + "/telemetry.csv")) {
    if (t.truth) r.trajectory.push_back(*t.truth);
    // A sign change counts when |w| is clearly non-zero on both sides (1e-3 rad/s), so
    // going straight between two turns the same way is not an oscillation.
    const double w = t.w_cmd;
    if (std::isfinite(w) && std::abs(w) > 1e-3) {
      const int sg = w > 0 ? 1 : -1;
      if (last_sign != 0 && sg != last_sign) ++changes;
      last_sign = sg;
    }
  }
  r.oscillation_per_m = r.path_m > 0.1 ? changes / r.path_m : 0.0;
  return r;
}

std::vector<ScenarioResult> runScenarios(const std::vector<ScenarioSpec>& specs, int jobs,
                                         bool progress) {
  const std::string exe = selfExecutable();
  std::vector<ScenarioResult> results(specs.size());
  std::atomic<size_t> next{0};
  std::atomic<int> done{0};
  std::mutex io;
  auto worker = [&] {
    for (size_t i = next++; i < specs.size(); i = next++) {
      const auto& s = specs[i];
      fs::create_directories(s.out_dir);
      const auto t0 = std::chrono::steady_clock::now();
      const int rc = spawnRun(s, exe);
      results[i] = readRunFolder(s.out_dir);
      if (rc < 0) {
        results[i].reason = "could not start " + exe;
        results[i].failure = "crashed";
      } else if (!results[i].ran && rc >= 128) {
        results[i].reason = "run crashed (status " + std::to_string(rc) + ")";
        results[i].failure = "crashed";
      }
      const double wall =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      if (progress) {
        std::lock_guard<std::mutex> lk(io);
        char buf[400];
        std::snprintf(buf, sizeof buf, "[%d/%zu] %-28s %-7s %6.1f s sim, %5.1f s wall: %s\n",
                      ++done, specs.size(), s.label.c_str(),
                      results[i].success ? "success" : "FAILED", results[i].time_s, wall,
                      results[i].reason.c_str());
        std::cerr << buf << std::flush;
      }
    }
  };
  std::vector<std::thread> pool;
  const int n = std::max(1, std::min<int>(jobs, static_cast<int>(specs.size())));
  for (int k = 0; k < n; ++k) pool.emplace_back(worker);
  for (auto& t : pool) t.join();
  return results;
}

}  // namespace sketchnav::run
