#pragma once
// `sketchnav run` as a function, shared by the command, `sketchnav ui`, `sketchnav ros nav` and
// the closed-loop integration tests: opens the devices from URIs (the simulator by default, or
// hardware, or a recording), loads the sketch -> route and the landmark model (trained on first
// use and cached), runs the navigation executive, judges a simulated run against ground truth
// (judge.h) and writes the run folder: summary.json, trajectory.png, events.jsonl and
// telemetry.csv (run_folder.h).
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "sketchnav/core/camera_mount.h"
#include "sketchnav/core/config.h"
#include "sketchnav/hw/devices.h"
#include "sketchnav/landmarks/model.h"
#include "sketchnav/mapsketch/route.h"
#include "sketchnav/mapsketch/sketch.h"
#include "sketchnav/nav/executive.h"
#include "sketchnav/nav/perception.h"
#include "sketchnav/sim/simulator.h"

namespace sketchnav::run {

struct RunOptions {
  std::string world = "lab";  // sim: a world name in share/worlds or a world file
  std::string sketch;         // default: share/sketches/<world>.sketch.json
  std::string model;          // a .slm file; default: trained from landmark_dir and cached
  std::string landmark_dir;   // default: share/landmarks
  std::string cache_dir;      // model cache; default $XDG_CACHE_HOME/sketchnav or ~/.cache/...
  int seed = 1;
  bool realtime = false;
  double max_time_s = 0;  // > 0 overrides nav.max_time_s
  std::string out_dir;    // "" = write no files
  // Hardware: any of these set -> a real robot (each empty one is absent).
  std::string robot, camera, laser, sonar;
  std::string record;    // non-empty: append every frame, odometry, scan and command to this
                         // MRPT rawlog (images beside it), flushed per record
  std::string replay;    // non-empty: run simulator-free on a recorded rawlog's devices
  Config config;         // --config / --set (nav.*, servo.*, sim.*, ...)
  bool progress = true;  // progress lines on stderr
  /// Wraps the camera (tests: drop it mid-run; `sketchnav ui`: show and capture its frames).
  std::function<std::unique_ptr<hw::Camera>(std::unique_ptr<hw::Camera>)> wrap_camera;
  // Hooks of the live run page (`sketchnav ui`); all called on the run's thread. Unset = none.
  /// Wraps the base (the page's Stop goes through the wrapper).
  std::function<std::unique_ptr<hw::Base>(std::unique_ptr<hw::Base>)> wrap_base;
  std::function<void(const nav::NavEvent&)> on_event;     // every executive event
  std::function<void(const nav::TelemetryRow&)> on_tick;  // every control tick
  /// Every frame perception examined, with what it found.
  std::function<void(const hw::Frame&, const nav::Observation&)> on_observation;
  /// Polled before every control tick: true -> the executive stops the base and the run ends
  /// (failed, reason "stopped by user").
  std::function<bool()> stop_requested;
  /// Called after every control tick with the executive (`ros nav`: the route in the odometry
  /// frame, distance left). On the run's thread; must not call non-const members.
  std::function<void(const nav::Executive&)> after_step;
};

/// Every setting a run uses, over the defaults, validated. Device drivers' settings
/// ("base.dani.*", "camera.aravis.*", "camera.folder.*") are applied when the device is opened.
struct RunSettings {
  CameraMount camera;                // "robot.camera.*" (fed to nav.servo and perception)
  mapsketch::RouteParams route;      // "route.*"
  landmarks::ModelParams train;      // "landmarks.train.*" (when the model is trained)
  nav::NavSettings nav;              // "nav.*" (with its sections) and "servo.*"
  nav::PerceptionParams perception;  // "nav.perception.*", "landmarks.recognition.*",
                                     // "objectness.*" (with .ccs, .scs)
  sim::SimParams sim;                // "sim.*" (simulated runs)
};
/// Reads every run setting from `config` (marking each key used); InputError on a bad value.
RunSettings runSettingsFrom(const Config& config);
/// The settings as a nested JSON object in exactly the --config format (summary.json's
/// "settings"): `sketchnav run --config` on it repeats them. `with_sim` false leaves "sim" out.
Json runSettingsJson(const RunSettings& settings, bool with_sim = true);
/// The prefixes of device drivers' settings, applied only when a device is opened.
const std::vector<std::string>& driverSettingPrefixes();

/// Runs one navigation. Returns the summary object (what summary.json holds; summary.h reads
/// its figures typed: RunSummary::fromJson). Throws
/// InputError for bad options / files, RuntimeError when a device cannot be opened.
Json runNavigation(const RunOptions& options);

/// Whether RunOptions::world names a world file (a path, or a name ending in ".json") rather
/// than a world in share/worlds.
bool isWorldFile(const std::string& world);

/// The sketch a run over `world` (RunOptions::world) uses when it is given none: for a world
/// file "x.world.json", "x.sketch.json" beside it (not checked to exist); for a world name, the
/// shipped share/sketches/<name>.sketch.json (RuntimeError naming it when there is none); ""
/// for a world file of another name.
std::string defaultSketchPath(const std::string& world);

/// The path drawn on `sketch` (canvas pixels) in the frame of `route` = toRoute(sketch) [m]
/// (Route::guide_points_m's frame: the sketch's start at route.start_m, y up).
std::vector<Eigen::Vector2d> drawnPathInRoute(const mapsketch::Sketch& sketch,
                                              const mapsketch::Route& route);

/// The landmark model cache file for a landmark set folder (keyed by its content hash).
std::string modelCachePath(const std::string& landmark_dir, const std::string& cache_dir);

}  // namespace sketchnav::run
