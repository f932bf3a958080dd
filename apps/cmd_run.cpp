// sketchnav run: navigate: the simulated lab by default, or a real robot via device URIs.
#include <cstdio>
#include <iostream>

#include "cli.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/paths.h"
#include "sketchnav/run/run.h"
#include "sketchnav/run/summary.h"

namespace sketchnav::app {
namespace {

int runRun(const std::vector<std::string>& argv, GlobalOptions& g) {
  Args args("run", "navigate: the simulated lab by default, or a real robot via device URIs",
            "[--world NAME|FILE] [--sketch FILE] [--model FILE] [--seed N] [--realtime] "
            "[--out DIR] [--robot URI --camera URI --laser URI --sonar URI] [--record FILE] "
            "[--replay FILE]");
  args.option("world", "simulated world: a name in share/worlds or a .world.json file", "lab")
      .option("sketch", "the hand-drawn map (.sketch.json); default: the world's sketch")
      .option("model",
              "landmark model (.slm); default: the demo landmark set, trained on "
              "first use and cached")
      .option("landmarks", "landmark set folder to train the model from (default: share/landmarks)")
      .option("cache-dir", "where trained models are cached (default: ~/.cache/sketchnav)")
      .option("seed", "simulator seed (noise, odometry errors; default: sim.seed, else 1)")
      .flag("realtime", "simulate at wall-clock pace (default: as fast as the CPU allows)")
      .option("max-time", "give up after this many seconds of run time (default: nav.max_time_s)")
      .option("out", "output folder (default: runs/<UTC timestamp>)")
      .option("robot", "base URI for a real robot, e.g. dani://192.168.1.20:5000")
      .option("camera", "camera URI, e.g. aravis://192.168.1.10 or video://0")
      .option("laser", "laser URI")
      .option("sonar", "sonar URI")
      .option("record",
              "also write frames, odometry, scans and commands to this MRPT rawlog, or to a ROS "
              "bag when the name ends in .bag")
      .option("replay",
              "run simulator-free on a recorded rawlog or ROS bag (from --record, or a bag of ros "
              "sim's topics)");
  if (!args.parse(argv)) return 0;
  run::RunOptions o;
  o.world = args.get("world");
  o.sketch = args.get("sketch");
  o.model = args.get("model");
  o.landmark_dir = args.get("landmarks");
  o.cache_dir = args.get("cache-dir");
  // --seed, else the setting sim.seed (so a run's summary settings as --config repeat its seed).
  if (!args.get("seed").empty())
    o.seed = args.getInt("seed");
  else if (g.config.has("sim.seed")) {
    const Json& v = g.config.at("sim.seed");
    if (!v.is_number_integer() || v.get<long long>() < 0 || v.get<long long>() > 2147483647)
      throw InputError(g.config.origin("sim.seed") +
                       ": setting 'sim.seed' must be an integer in [0, 2^31)");
    o.seed = v.get<int>();
  }
  o.realtime = args.flagSet("realtime");
  if (!args.get("max-time").empty()) {
    o.max_time_s = args.getDouble("max-time");
    // 0 or less was ignored (the run took nav.max_time_s without a word).
    if (o.max_time_s <= 0) throw InputError("sketchnav run: --max-time must be > 0 s");
  }
  o.robot = args.get("robot");
  o.camera = args.get("camera");
  o.laser = args.get("laser");
  o.sonar = args.get("sonar");
  o.record = args.get("record");
  o.replay = args.get("replay");
  o.config = g.config;
  o.out_dir = makeOutputDir(args.get("out"));
  o.progress = true;
  const run::RunSummary summary = run::RunSummary::fromJson(run::runNavigation(o));
  if (g.json) {
    printJson(summary.json);
  } else {
    std::cout << (summary.success ? "success" : "FAILED") << ": " << summary.reason << "\n"
              << "time " << summary.time_s << " s (real-time factor " << summary.real_time_factor
              << "), path " << summary.path_length_m << " m\n";
    // Simulation only: which part of a goal error is the robot's and which the drawing's.
    if (const auto& d = summary.diagnostics) {
      char buf[200];
      std::snprintf(buf, sizeof buf, "ground truth: odometry off %.2f m", d->odometry_error_m);
      std::cout << buf;
      if (d->goal_estimate_error_m) {
        std::snprintf(buf, sizeof buf, "; goal estimate off %.2f m", *d->goal_estimate_error_m);
        std::cout << buf;
      }
      if (d->sketch_goal_error_m) {
        std::snprintf(buf, sizeof buf,
                      "; the sketch alone puts the goal %.2f m off (every landmark fixed exactly)",
                      *d->sketch_goal_error_m);
        std::cout << buf;
      }
      std::cout << "\n";
    }
    std::cout << "outputs in " << o.out_dir << "\n";
  }
  return summary.success ? 0 : 1;
}

const CommandRegistration reg(
    "run", "navigate: the simulated lab by default, or a real robot via device URIs", runRun);
}  // namespace
}  // namespace sketchnav::app
