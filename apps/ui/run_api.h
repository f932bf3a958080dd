#pragma once
// The live run page of `sketchnav ui` (doc/ui.md, "Run page"): starts one navigation run on a
// background thread, keeps what the page shows (state, latest camera frame with the
// recognised landmarks, map geometry and the trajectory), stops it on request and saves
// camera captures into the landmark set.
//
// The run itself is not done here: a Runner (in the command, `sketchnav run`'s harness) is
// handed RunHooks and reports through them. That keeps this library free of the simulator
// and the vision stack, and lets the HTTP tests drive the page's API with a scripted runner.
//
//   POST /api/run/start   {mode: sim|hardware|camera, world, sketch, robot, camera, laser,
//                          sonar, seed, max_time_s, camera_only}
//   POST /api/run/stop    stops the base at once, then ends the run ("stopped by user")
//   GET  /api/run/state   status, section k/n, mode, turn, v, w, pose, landmarks, health...
//   GET  /api/run/frame.jpg  latest camera frame, detections drawn (404 before the first)
//   GET  /api/run/map     map geometry (odometry frame) and the trajectory so far
//   POST /api/capture     {class, box?: [x, y, w, h]} -> <capture dir>/<class>/capture_<n>.jpg
//   GET  /api/run/worlds  simulated worlds and sketches the page offers
//   GET  /api/run/series?tick=N&obs=M  the run's time series from row N / M on (plots)
//   GET  /api/runs        the run folders written so far (newest first), with their outcome
//   GET  /api/runs/<id>/<file>  summary.json, trajectory.png, telemetry.csv or events.jsonl
// Eigen-using headers (through nav) before httplib.h (server.h): a macro of httplib's breaks
// Eigen's headers.
#include "sketchnav/nav/executive.h"
#include "sketchnav/nav/perception.h"
// clang-format off
#include <opencv2/core/mat.hpp>

#include <atomic>
#include <condition_variable>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "run_request.h"
#include "server.h"
#include "sketchnav/core/config.h"
#include "sketchnav/hw/devices.h"
// clang-format on

namespace sketchnav::ui {

/// How a runner reports to the page. All are set by RunController and called on the run's
/// thread.
struct RunHooks {
  std::function<void(const nav::NavEvent&)> on_event;     // executive events
  std::function<void(const nav::TelemetryRow&)> on_tick;  // every control tick
  std::function<void(const hw::Frame&, const nav::Observation&)> on_observation;
  std::function<std::unique_ptr<hw::Camera>(std::unique_ptr<hw::Camera>)> wrap_camera;
  std::function<std::unique_ptr<hw::Base>(std::unique_ptr<hw::Base>)> wrap_base;
  std::function<bool()> stop_requested;     // polled every tick: true -> stop and end the run
  std::function<void(const Json&)> on_map;  // map geometry, once before the run starts
  /// The route as the executive places it now (odometry frame), once at the start and again
  /// whenever it refits the sketch to a landmark fix: {path, guide_points, landmarks, goal,
  /// rotation_deg, scale, start, refits, t}. Optional.
  std::function<void(const Json&)> on_placement;
  /// The run folder to write (summary.json, trajectory.png, telemetry.csv, events.jsonl, as
  /// `sketchnav run --out` does); "" = none (camera only, or no runs folder configured).
  std::string out_dir;
};

/// Runs one navigation to the end (or until stop_requested()), returns its summary. Throws
/// InputError / RuntimeError like runNavigation().
using Runner = std::function<Json(const RunRequest&, const RunHooks&)>;

struct RunApiOptions {
  Runner runner;
  std::string capture_dir;            // where captures go: one folder per class (the landmark set)
  std::vector<std::string> worlds;    // offered on the page (names)
  std::vector<std::string> sketches;  // offered on the page (paths or names), fixed
  /// Sketches offered on the page, listed again on every request (so sketches saved in the
  /// editor appear): [{path, file, source: "example" | "user"}]. Optional.
  std::function<Json()> list_sketches;
  /// True when capture_dir is the landmark set the runs train on (the next run retrains
  /// with the captures); false when captures only collect photos for later.
  bool captures_train = false;
  /// The objectness windows perception examined in a frame, drawn on the live view; computed
  /// on demand (only while someone watches), optional.
  std::function<std::vector<cv::Rect>(const cv::Mat&)> propose_windows;
  /// Called by start() before the run starts; throws for a request that cannot run, e.g. a
  /// world or sketch file that does not load. start() then throws InputError with that text
  /// (the page gets a 400 naming the file, not a run that starts and then ends in an error),
  /// after recording the refusal as a run: its folder's summary.json and the state (status
  /// "error", the reason). Optional; not called for camera-only requests.
  std::function<void(const RunRequest&)> check_request;
  /// Where every run started from the page gets its folder (<runs_dir>/<UTC time>); "" = no
  /// run folders.
  std::string runs_dir;
};

/// What the live view draws over a frame: the `windows` first objectness windows (in the
/// proposer's order, best first; -1 = all) and the `detections` best detections (-1 = all).
struct FrameOverlay {
  int windows = -1;
  int detections = -1;
};

class RunController {
 public:
  explicit RunController(RunApiOptions options);
  /// Stops a run still going and waits for it.
  ~RunController();
  RunController(const RunController&) = delete;
  RunController& operator=(const RunController&) = delete;

  /// Starts a run on the background thread. InputError when one is already going.
  void start(const RunRequest& request);
  /// Stops the base at once (real robot: hw::Base::stop() on the calling thread, the HTTP
  /// server's, serialised with the run thread's calls by StoppableBase's mutex; simulator: at
  /// its next command, on the run thread), then the run ends with "stopped by user" (the
  /// executive polls RunHooks::stop_requested between ticks; it is never called from this
  /// thread). Returns false when no run was going. Thread-safe.
  bool stop();
  /// Waits for the run thread to finish (tests, shutdown).
  void join();

  Json state() const;
  Json map() const;
  /// JPEG of the frame shown (the last one perception examined while it is recent, else the
  /// latest) with the objectness windows and the detections drawn; empty before any frame.
  std::vector<unsigned char> frameJpeg(const FrameOverlay& overlay = {}) const;
  /// The run's time series from tick row `from_tick` and observation row `from_obs` on:
  /// {ticks: [[t, v, w, servo_error|null, x, y, theta, section], ...], obs: [[t, inliers of
  /// the best detection (0 = none), perception ms], ...], tick_rows, obs_rows}.
  Json series(std::size_t from_tick, std::size_t from_obs) const;
  /// Saves the frame shown (or the box [x, y, w, h] of it, in its pixels) into
  /// <capture_dir>/<class>/capture_<n>.jpg. Returns {file, class, width, height}.
  Json capture(const std::string& class_name, const std::optional<cv::Rect>& box);

  const RunApiOptions& options() const { return opt_; }

  // Called by the hooks (public for the wrappers in run_api.cpp).
  struct Live;

 private:
  void runThread(RunRequest request);
  std::string newRunDir(const RunRequest& request) const;
  RunApiOptions opt_;
  std::shared_ptr<Live> live_;
  std::thread thread_;
  std::mutex start_mutex_;
};

/// Registers the routes above on `server` (the controller must outlive it).
void addRunRoutes(Server& server, RunController& controller);

}  // namespace sketchnav::ui
