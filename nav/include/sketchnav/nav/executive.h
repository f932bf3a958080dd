#pragma once
// The navigation executive: follows a route section by section on odometry, looks for each
// section's expected landmark, servos on it (servo::TurnLaw) and judges its distance with the
// range sensors, avoids obstacles (ObstacleAvoider) and stops on any fault (SafetySupervisor).
//
// Lifecycle: configure (constructor) -> start() -> step() at the clock's pace until done()
// -> stop(). run() is that loop: clock->sleepUntil(next tick), step(). Time is the Clock's, so
// the same code runs the simulator (as fast as the CPU allows) and the real robot.
// The executive owns none of the devices; they must outlive it.
#include <nlohmann/json.hpp>

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "sketchnav/core/config.h"
#include "sketchnav/core/percentiles.h"
#include "sketchnav/hw/clock.h"
#include "sketchnav/hw/devices.h"
#include "sketchnav/mapsketch/route.h"
#include "sketchnav/nav/avoidance.h"
#include "sketchnav/nav/behaviours.h"
#include "sketchnav/nav/doorway.h"
#include "sketchnav/nav/events.h"
#include "sketchnav/nav/landmark_stage.h"
#include "sketchnav/nav/landmark_tracker.h"
#include "sketchnav/nav/laser_odometry.h"
#include "sketchnav/nav/local_planner.h"
#include "sketchnav/nav/movers.h"
#include "sketchnav/nav/perception.h"
#include "sketchnav/nav/route_anchor.h"
#include "sketchnav/nav/safety.h"
#include "sketchnav/nav/sections.h"
#include "sketchnav/servo/turn_law.h"

namespace sketchnav::nav {

/// The executive's settings (keys "nav.<field>"). The stages' own Params are its bases, so their
/// fields keep their keys directly under "nav." (`nav.fit_fixes`, ...).
struct ExecutiveParams : DriveParams,
                         LandmarkTrackerParams,
                         RouteAnchorParams,
                         LookParams,
                         SideLookParams,
                         FinalLookParams,
                         RecoverParams,
                         DockParams,
                         DetourParams {
  double tick_s = 0.05;              // [s] control period
  double camera_period_s = 0.1;      // [s] expected frame period (frames are grabbed at this pace)
  double max_time_s = 900;           // [s] whole run
  double section_time_factor = 4;    // a section taking longer than factor * length / v
  double section_time_extra_s = 40;  // + extra seconds has failed ("no progress")
  double servo_hold_s = 0.5;         // [s] keep the last servo command this long between frames
  double end_blocked_m = 1.0;        // [m] dodging this close to a section's end point, with an
                                     // obstacle at or before it, ends the section
  double perception_period_s = 0.2;  // [s] frames given to perception at most this often
  double goal_stop_s = 0.5;          // [s] settle time at the goal
  double goal_settle_m = 1.0;        // [m] within this of the goal, not 5 cm closer for
  double goal_settle_s = 8;          // [s] this long: arrived as close as it can get
  // A section's end point the robot cannot get near (drawn beyond a wall; goal_checker.h
  // SectionSettleChecker): within section_settle_frac x the section's length of it but beyond
  // end_blocked_m (and never within it before), not 5 cm closer than its closest for
  // section_settle_s (servoing, looking to the side and waiting for a person restart the
  // clock) and not closing in, the section is done. Not the last section (the goal has
  // goal_settle_*). 0 = off.
  double section_settle_frac = 0.3;  // fraction of the section's length
  double section_settle_s = 15;      // [s]
  // Where the sketch puts the attended landmarks goes to perception on every frame, not only in
  // the final look (final_look_fovea), for its foveal second look there (nav.perception.fovea,
  // off by default: it then costs nothing). With the model's own training photos as textures
  // the look recognised landmarks about twice as far away (3 -> 5 m); on photos it was not
  // trained on it rarely finds one (doc/landmark-model.md "Foveal second look").
  bool fovea_hints = true;
  template <class B>
  void bind(B& b) {
    DriveParams::bind(b);
    LandmarkTrackerParams::bind(b);
    RouteAnchorParams::bind(b);
    LookParams::bind(b);
    SideLookParams::bind(b);
    FinalLookParams::bind(b);
    RecoverParams::bind(b);
    DockParams::bind(b);
    DetourParams::bind(b);
    b("tick_s", tick_s);
    b("camera_period_s", camera_period_s);
    b("max_time_s", max_time_s);
    b("section_time_factor", section_time_factor);
    b("section_time_extra_s", section_time_extra_s);
    b("servo_hold_s", servo_hold_s);
    b("end_blocked_m", end_blocked_m);
    b("perception_period_s", perception_period_s);
    b("goal_stop_s", goal_stop_s);
    b("goal_settle_m", goal_settle_m);
    b("goal_settle_s", goal_settle_s);
    b("section_settle_frac", section_settle_frac);
    b("section_settle_s", section_settle_s);
    b("fovea_hints", fovea_hints);
  }
  void validate() const;  // InputError "nav.<field> = ...: ..."
};

/// Every setting of a run, loadable from a Config ("nav.*", "nav.sections.*", "servo.*"...).
struct NavSettings {
  ExecutiveParams exec;
  SectionParams sections;
  SelectParams select;
  LocateParams locate;
  AvoidParams avoid;
  SafetyParams safety;
  LaserOdometryParams laser_odometry;
  PlannerParams planner;
  MoverParams movers;
  GoalDoorParams goal_door;
  servo::TurnLawParams servo;
};

/// Loads every section from `config` ("nav.*", "nav.sections.*", "nav.select.*", "nav.locate.*",
/// "nav.avoid.*", "nav.safety.*", "nav.laser_odometry.*", "nav.planner.*", "nav.movers.*",
/// "nav.goal_door.*", "servo.*") over the defaults and validates.
NavSettings navSettingsFrom(const Config& config);

/// One control tick, for telemetry.csv.
struct TelemetryRow {
  double t = 0;  // [s] since start()
  hw::Pose2D odom;
  double v_cmd = 0, w_cmd = 0;  // [m/s], [rad/s] as commanded to the base
  double servo_error = 0;       // x_t - x_d when servoing, NaN otherwise
  Mode mode = Mode::Follow;     // what drove this tick: follow | look | servo | dock | recover |
                                // avoid | detour | yield (toString(Mode))
  // The turn: servoing, the turn law's; following, looking ahead or docking, the side of the
  // bearing steered to; recovering, avoiding, detouring, yielding or looking on the spot, the
  // sign of the yaw rate (|x| < 0.05 is Straight).
  servo::Turn turn = servo::Turn::Straight;
  int section = 0;
  std::string landmark;     // id of the attended landmark ("" when none)
  double front_free_m = 0;  // [m] free corridor ahead (0 when the avoider did not run)
};

/// Receives what the executive reports. Contract of both calls:
/// - They are made synchronously, on the thread that calls Executive::start(), step() or
///   run() (the executive has no threads of its own), inside that call: a slow observer slows
///   the control loop.
/// - The argument is valid only during the call (copy what is kept).
/// - An observer must not call back into the Executive that calls it.
/// - An exception thrown from a call made inside step() ends the run like any fault in the
///   tick: the base is stopped and the run is Failed (FailureCode::SafetyStop); one thrown from
///   start()'s Start event propagates out of start().
/// Events come in time order: Start first (from start()), then whatever the ticks report;
/// Arrived or Failed once, when the run ends (Failed may follow a Fault).
class ExecutiveObserver {
 public:
  virtual ~ExecutiveObserver() = default;
  virtual void onEvent(const NavEvent& event) {}
  virtual void onTick(const TelemetryRow& row) {}
};

enum class RunStatus { Idle, Running, Succeeded, Failed };

struct LandmarkReport {
  std::string id, class_name;
  int section = 0;
  std::string state;  // pending | tracking | passed | missed
  int frames_seen = 0;
  int max_inliers = 0;
};

/// The control loop's rates and latency budget (summary.json "timing", doc/navigation.md
/// "Loop rates and latency"). Counts cover the run, start() to its last tick; the rates divide
/// them by the run's length on its clock (simulated time in simulation) and by the wall time of
/// the same span.
struct LoopTiming {
  int ticks = 0;              // control ticks run
  int frames = 0;             // camera frames delivered (a new stamp, an image)
  int perception_frames = 0;  // frames given to perception
  int full_passes = 0;        // of those, the ones perception's full pass ran on
  int tracked_frames = 0;     // of those, the ones where the tracker supplied a detection
  int servo_updates = 0;      // servo law evaluations on a new detection of the servoed landmark
  double wall_s = 0;          // [s] wall time from start() to the end of the last tick
  using Stats = PercentileAccumulator::Summary;
  // [ms] from a frame's capture stamp to the base command of the tick that used its perception
  // result (one sample per frame given to perception whose tick reached its command): the run
  // clock from the stamp to the grab's return, plus the wall time from there to the command.
  // In simulation the clock does not run while perception works, so the wall time is what a
  // real robot would wait; on hardware both are the steady clock.
  Stats grab_to_command_ms;
  Stats perception_ms;                         // [ms] wall time per frame given to perception
  Stats objectness_ms, features_ms, match_ms;  // [ms] wall time per full pass, by stage
  Stats track_ms;  // [ms] the tracker's wall time, on frames where it stepped a track
  /// {"time_s", "wall_s", "rates_hz": {"camera_frames": {"n", "clock", "wall"}, ...},
  /// "latency_ms": {"grab_to_command": {"n", "p50", "p95", "p99", "max"}, ...}}; `time_s` is
  /// the run's length on its clock [s]. A rate over a zero span is 0.
  nlohmann::json toJson(double time_s) const;
};

struct ExecutiveSummary {
  RunStatus status = RunStatus::Idle;
  FailureCode failure = FailureCode::None;  // why it failed (None unless status is Failed)
  std::string reason;                       // the verdict in words (with figures), beside it
  double time_s = 0;                        // [s] on the run's clock
  double odom_path_m = 0;                   // distance travelled by odometry
  int sections_done = 0, sections = 0;
  std::vector<LandmarkReport> landmarks;
  int frames = 0;            // camera frames grabbed
  int frames_processed = 0;  // frames given to perception
  double perception_ms_mean = 0, perception_ms_max = 0;
  double objectness_ms_mean = 0, features_ms_mean = 0, match_ms_mean = 0;
  int full_passes = 0;         // processed frames on which perception's full pass ran
  int tracked_detections = 0;  // detections the tracker supplied (PerceptionTiming::tracked)
  int avoidance_manoeuvres = 0;
  int recoveries = 0;  // stuck recoveries
  int detours = 0;     // detours planned round obstacles (local_planner.h)
  int yields = 0;      // times the robot kept out of a walking person's lane (movers.h)
  LaserOdometryStats laser_odometry;
  LoopTiming timing;  // loop rates and latency percentiles
  nlohmann::json toJson() const;
};

struct Devices {
  hw::Camera* camera = nullptr;
  hw::Base* base = nullptr;
  std::vector<hw::RangeSensor*> ranges;  // laser and / or sonar
  hw::Clock* clock = nullptr;
};

/// Not thread-safe: start(), step(), stop(), run() and summary() from one thread (the one that
/// drives it, which is also the one the observer and the devices are called on). To stop a run
/// from another thread, set a flag that the driving thread polls between step()s and calls
/// stop() on (RunOptions::stop_requested), and stop the base itself through a wrapper that
/// serialises with the driving thread (the run page's StoppableBase, hw/devices.h "Threads").
class Executive {
 public:
  /// Configure. Throws InputError for invalid settings or an empty route.
  Executive(mapsketch::Route route, Devices devices, Perception& perception,
            NavSettings settings = {}, ExecutiveObserver* observer = nullptr);
  ~Executive();
  Executive(const Executive&) = delete;
  Executive& operator=(const Executive&) = delete;

  void start();
  /// One control tick at the clock's current time. Never throws: any exception stops the
  /// base and fails the run.
  void step();
  /// Stops the base (idempotent). A run stopped while Running is Failed with `reason`
  /// (FailureCode::Stopped).
  void stop(const std::string& reason = "stopped");
  bool done() const;
  /// start(); loop { clock->sleepUntil(next tick); step(); } until done(); returns summary().
  ExecutiveSummary run();

  ExecutiveSummary summary() const;
  const SectionTracker& sections() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

const char* toString(RunStatus s);

}  // namespace sketchnav::nav
