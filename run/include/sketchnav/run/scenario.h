#pragma once
// Running simulated navigation scenarios in bulk (for `experiments`, `tune` and `scenarios`).
//
// One scenario = one `sketchnav run` (run.h: runNavigation, reused as is) over a world file
// and a sketch file with a seed and settings. Each runs in its own child process (the running
// executable's `run` subcommand, so only the `sketchnav` command can call runScenarios) so
// several run in parallel without sharing state, and a crash or hang of one trial is that
// trial's failure, not the sweep's. Results come from the run folder: summary.json and
// telemetry.csv.
#include <string>
#include <vector>

#include "sketchnav/core/config.h"
#include "sketchnav/hw/types.h"
#include "sketchnav/landmarks/model.h"

namespace sketchnav::run {

struct ScenarioSpec {
  std::string label;              // for progress lines ("exp3-6 #2")
  std::string world_file;         // .world.json
  std::string sketch_file;        // .sketch.json
  int seed = 1;                   // simulator seed (odometry, image, range noise)
  std::string model;              // .slm landmark model
  std::string config_file;        // optional --config for the child ("" = none)
  std::vector<std::string> sets;  // extra "key=value" settings (e.g. servo.lambda=0.6)
  double max_time_s = 0;          // > 0: --max-time
  std::string out_dir;            // the run's output folder (created)
};

struct ScenarioResult {
  bool ran = false;      // the child produced a summary (false: it crashed / bad input)
  bool success = false;  // reached the goal without collision (simulator ground truth)
  std::string reason;
  // summary.json's "failure" code (judge.h failureCode): "" on success; "no_summary" or
  // "crashed" when the child wrote no readable summary; "" from a summary older than the code.
  std::string failure;
  double time_s = 0;                                 // simulated time to the end of the run
  double path_m = 0;                                 // true distance travelled
  double deviation_mean_m = 0, deviation_max_m = 0;  // from the sketched path
  double min_clearance_m = 0;
  double oscillation_per_m = 0;  // sign changes of the commanded yaw rate per metre driven
  double wall_s = 0;
  std::vector<hw::Pose2D> trajectory;  // true poses (world frame), from telemetry.csv
  Json summary;                        // the run's summary.json
};

/// Path of the running executable (/proc/self/exe), used to start the children.
std::string selfExecutable();

/// The landmark model to use: `model` if given, else the demo set's cached model, trained now
/// with `train` (the run's landmarks.train.* settings) when the cache is missing or was trained
/// from another set or with other settings (once, before any child starts, so children never
/// race to train it).
std::string ensureModel(const std::string& model, bool progress,
                        const landmarks::ModelParams& train = {});
/// The same model, loaded: `model` if given, else the demo set's cache (trained or retrained
/// as ensureModel() does), read once (ensureModel() followed by a load reads it twice).
landmarks::LandmarkModel loadModel(const std::string& model, bool progress,
                                   const landmarks::ModelParams& train = {});
/// Builds `model`'s search indexes (kd-trees over every database descriptor and per class) now
/// and logs how long it took, under `component`: done before the first frame, so that frame's
/// perception does not pay seconds for them (a robot standing at the start, a paced simulation
/// falling behind, the latency and per-frame figures' maximum and mean).
void buildIndexes(const landmarks::LandmarkModel& model, const char* component);

/// Runs the specs with up to `jobs` children at once; results in spec order. Progress lines
/// on stderr when `progress`.
std::vector<ScenarioResult> runScenarios(const std::vector<ScenarioSpec>& specs, int jobs,
                                         bool progress);

/// Parses a run folder (summary.json + telemetry.csv) into a result.
ScenarioResult readRunFolder(const std::string& dir);

}  // namespace sketchnav::run
