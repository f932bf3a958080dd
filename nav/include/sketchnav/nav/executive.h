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
#include "sketchnav/nav/doorway.h"
#include "sketchnav/nav/events.h"
#include "sketchnav/nav/landmark_stage.h"
#include "sketchnav/nav/laser_odometry.h"
#include "sketchnav/nav/local_planner.h"
#include "sketchnav/nav/movers.h"
#include "sketchnav/nav/perception.h"
#include "sketchnav/nav/safety.h"
#include "sketchnav/nav/sections.h"
#include "sketchnav/servo/turn_law.h"

namespace sketchnav::nav {

struct ExecutiveParams {
  double tick_s = 0.05;              // [s] control period
  double camera_period_s = 0.1;      // [s] expected frame period (frames are grabbed at this pace)
  double v_cruise = 0.30;            // [m/s] forward speed along the route
  double k_heading = 1.2;            // [1/s] path following: yaw rate per rad of bearing error
  double max_w = 0.8;                // [rad/s]
  double turn_in_place_deg = 60;     // [deg] bearing error above which the robot turns on the spot
  double max_time_s = 900;           // [s] whole run
  double section_time_factor = 4;    // a section taking longer than factor * length / v
  double section_time_extra_s = 40;  // + extra seconds has failed ("no progress")
  // Landmark stage
  double approach_m = 1.4;      // [m] a servoed landmark is passed at max(this, its range_m)
                                // (more than avoid.trigger_m + radius: pass before dodging)
  double max_approach_m = 2.5;  // [m] cap on the sketch's range_m for that test
  double servo_hold_s = 0.5;    // [s] keep the last servo command this long between frames
  double lost_after_s = 2.0;    // [s] a tracked landmark unseen this long: back to searching
  double miss_slack_m = 2.0;    // [m] past a landmark's along position without seeing it: missed
  double reanchor_gain = 0.8;   // how much a passed landmark re-anchors the route (0 = never)
  double end_blocked_m = 1.0;   // [m] dodging this close to a section's end point, with an
                                // obstacle at or before it, ends the section
  // Once fixes (the start and passed landmarks) span fit_min_span_m, the route's rotation,
  // scale and position are refitted by least squares to the last fit_fixes of them
  // (SectionTracker::fitSimilarityWeighted), then shifted fit_local_gain of the way to the
  // newest; before that, realign/reanchor below. 0 fixes = always realign/reanchor.
  // All fixes, no local shift: each drawn box is off on its own, so every fix is worth the
  // same to the fit wherever it is, and pulling the route to the newest only adds that box's
  // error. A sketch distorted smoothly (one room drawn too small) would want fewer fixes and
  // a local shift. Evidence: doc/navigation.md "Evidence for the defaults".
  int fit_fixes = 100;
  double fit_min_span_m = 5.0;         // [m]
  double fit_max_scale_change = 0.5;  // relative to the drawing's own scale, over all fits
  double fit_local_gain = 0.0;
  // The start stays in every fit: it is where the user put the robot, and it gives the fit a
  // baseline as long as the route (fitting only the newest landmarks lets the scale swing).
  bool fit_keep_start = true;
  // [m] a fix this far off the others' fit (Mahalanobis x the sketch's 0.3 m) is left out;
  // too tight a gate leaves good fixes out and the rest turn the route.
  double fit_outlier_m = 0.9;
  // A landmark seen only from afar or from one place without a usable range still counts:
  // its rays place it across them (locateLandmark: bearing_only), which turns the route.
  bool fit_bearing_only = true;
  bool fit_weighted = true;   // each fix weighted by how well it was located (across / along
                              // its rays, SectionTracker::fitSimilarityWeighted); false: equal
                              // weights (fitSimilarity)
  double realign_gain = 0.8;  // how much it re-rotates the route about the previous fix
  double realign_baseline_m = 5.0;   // [m] minimum fix-to-landmark distance for that: a
                                     // sighting is good to ~0.3 m, so a shorter baseline
                                     // turns the route by more than it corrects
  double perception_period_s = 0.2;  // [s] frames given to perception at most this often
  double attend_bearing_deg = 75;    // [deg] look for the landmark only when the sketch puts it
  double attend_range_m = 12;        // [m]  within this bearing and range
  int max_missed_in_row = 2;         // more consecutive missed landmarks than this: lost, fail
  // Looking for a landmark: the camera sees +-30 deg and a 0.4 m sign is recognised out to
  // ~3 m, so a landmark sketched beside the path is only in view for a moment. While one is
  // expected within look_range_m and not yet seen, the heading is kept within look_bearing_deg
  // of where the sketch puts it (the robot turns towards it, as the paper's robot does).
  // It never turns back for one: beyond look_max_bearing_deg the landmark is left to the
  // miss test (a robot turning round for a landmark behind it livelocks against obstacles).
  double look_range_m = 5.0;         // [m]
  double look_bearing_deg = 10;      // [deg]
  double look_max_bearing_deg = 60;  // [deg]
  // Looking to the side: a landmark the look above cannot keep in view (the sketch puts it
  // beyond look_max_bearing_deg, or the robot is already abreast of it, or dodging turned it
  // away) would pass unseen. When the attended landmark has never been seen, its predicted
  // bearing (odometry + sketch) is outside the camera's field of view minus
  // side_look_margin_deg, and it is between side_look_min_range_m and side_look_range_m away,
  // the robot stops and turns on the spot towards it (events side_look_start / _end) until it
  // is recognised (the servo then takes over) or for at most side_look_s, then resumes
  // following. Once per landmark; none beyond side_look_max_bearing_deg (a landmark behind
  // is left to the miss test, as above). side_look_s = 0: off.
  double side_look_s = 4.0;                // [s] time budget per landmark
  double side_look_range_m = 4.0;          // [m] predicted range within which it is tried
  double side_look_min_range_m = 0.5;      // [m] closer than this its bearing means little
  double side_look_margin_deg = 5;         // [deg] inside the half field of view
  double side_look_max_bearing_deg = 110;  // [deg] angle budget: furthest the robot turns
  double goal_stop_s = 0.5;                // [s] settle time at the goal
  double dock_m = 1.5;  // [m] this close to the goal, with a free line to it, drive straight there
  double goal_settle_m = 1.0;  // [m] within this of the goal, not 5 cm closer for
  double goal_settle_s = 8;    // [s] this long: arrived as close as it can get
  double stuck_s = 10;         // [s] not having moved stuck_m in this long (not docking): stuck
  double stuck_m = 0.3;        // [m]
  double recover_m = 1.0;      // [m] then drive this far towards the most open direction
  double recover_s = 8;        // [s] (at most this long) and resume
  // Detours (local_planner.h): when the avoider is dodging something that is not coming
  // towards the robot, the robot follows a path planned on the laser's occupancy grid to the
  // route point detour_ahead_m on, instead of the reactive dodge; and near the goal, with no
  // free straight line to it, a path to the goal. Replanned every replan_s.
  // A repeated class: a detection (or a fix) within this of where an earlier landmark of the
  // same class was fixed is that landmark seen again, not the next one. A robot took the
  // first of three Bravo cartons for the second, refitted the sketch to it (scale -12 %) and
  // stopped 2.8 m from the goal.
  double same_class_gate_m = 1.0;  // [m]
  // At the goal, a landmark never seen (too far on the way, or out of view) that the sketch
  // puts within final_look_range_m: turn to it and look for up to final_look_s before
  // arriving; seen, it is passed and the refit moves the goal. The goal is often extrapolated
  // metres past the last landmark seen, and a missed last landmark was the commonest way to
  // stop 0.5-0.8 m short. 0 = off.
  double final_look_range_m = 4.0;  // [m]
  double final_look_s = 5.0;        // [s]
  bool final_look_fovea = true;     // hand the expected bearing to perception (foveal look)
  // ...on every frame, not only in the final look: landmarks are then recognised about twice
  // as far away (3 -> 5 m), and with far sightings kept as bearings (fit_bearing_only) their
  // rays cross over a longer baseline, which places them without the laser's range.
  bool fovea_hints = true;
  bool detour = true;
  double detour_ahead_m = 3.0;  // [m]
  // A detour once started is followed until the straight line to that route point is clear
  // on the grid (or no way is found, someone comes towards the robot, or the servo takes
  // over), not only while the reactive avoider is dodging: the avoider lets go when the
  // corridor towards the route is free avoid.release_m ahead, which round a box or a door
  // frame comes before the robot is past it. false = ends with the avoider's manoeuvre.
  // Off by default: doc/navigation.md "Evidence for the defaults".
  bool detour_hold = false;
  double replan_s = 0.5;        // [s]
  template <class B>
  void bind(B& b) {
    b("tick_s", tick_s);
    b("camera_period_s", camera_period_s);
    b("v_cruise", v_cruise);
    b("k_heading", k_heading);
    b("max_w", max_w);
    b("turn_in_place_deg", turn_in_place_deg);
    b("max_time_s", max_time_s);
    b("section_time_factor", section_time_factor);
    b("section_time_extra_s", section_time_extra_s);
    b("approach_m", approach_m);
    b("max_approach_m", max_approach_m);
    b("servo_hold_s", servo_hold_s);
    b("lost_after_s", lost_after_s);
    b("miss_slack_m", miss_slack_m);
    b("reanchor_gain", reanchor_gain);
    b("end_blocked_m", end_blocked_m);
    b("fit_fixes", fit_fixes);
    b("fit_min_span_m", fit_min_span_m);
    b("fit_max_scale_change", fit_max_scale_change);
    b("fit_local_gain", fit_local_gain);
    b("fit_outlier_m", fit_outlier_m);
    b("fit_keep_start", fit_keep_start);
    b("fit_weighted", fit_weighted);
    b("fit_bearing_only", fit_bearing_only);
    b("realign_gain", realign_gain);
    b("realign_baseline_m", realign_baseline_m);
    b("perception_period_s", perception_period_s);
    b("attend_bearing_deg", attend_bearing_deg);
    b("attend_range_m", attend_range_m);
    b("max_missed_in_row", max_missed_in_row);
    b("look_range_m", look_range_m);
    b("look_bearing_deg", look_bearing_deg);
    b("look_max_bearing_deg", look_max_bearing_deg);
    b("side_look_s", side_look_s);
    b("side_look_range_m", side_look_range_m);
    b("side_look_min_range_m", side_look_min_range_m);
    b("side_look_margin_deg", side_look_margin_deg);
    b("side_look_max_bearing_deg", side_look_max_bearing_deg);
    b("goal_stop_s", goal_stop_s);
    b("dock_m", dock_m);
    b("goal_settle_m", goal_settle_m);
    b("goal_settle_s", goal_settle_s);
    b("stuck_s", stuck_s);
    b("stuck_m", stuck_m);
    b("recover_m", recover_m);
    b("recover_s", recover_s);
    b("same_class_gate_m", same_class_gate_m);
    b("final_look_range_m", final_look_range_m);
    b("final_look_s", final_look_s);
    b("final_look_fovea", final_look_fovea);
    b("fovea_hints", fovea_hints);
    b("detour", detour);
    b("detour_ahead_m", detour_ahead_m);
    b("detour_hold", detour_hold);
    b("replan_s", replan_s);
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
