#pragma once
// A run's summary, typed: the figures of summary.json (run.h runNavigation) that the run's
// users read back (`sketchnav run`'s report, the scenario runner's results, the experiments
// report), written (toJson) and read (fromJson) here, by type, rather than by key wherever
// they are used. summary.json itself stays the complete record (RunSummary::json).
#include <array>
#include <cmath>
#include <optional>
#include <string>

#include "sketchnav/core/config.h"

namespace sketchnav::run {

struct RunSummary {
  bool success = false;            // simulation: ground truth (judge.h judgeSimulatedRun); else the
                                   // executive's verdict
  bool executive_success = false;  // the executive's own verdict
  std::string reason;              // why the run ended
  std::string failure;     // judge.h failureCode: "" on success (and from a summary older than it)
  double time_s = 0;       // [s] on the run's clock (simulated time in simulation)
  double wall_time_s = 0;  // [s]
  double real_time_factor = 0;          // time_s / wall_time_s
  double path_length_m = 0;             // [m] the true distance in simulation, else odometry's
  double min_clearance_m = NAN;         // [m] simulation only
  double min_clearance_people_m = NAN;  // [m] to a pedestrian's body (simulation, with people)
  double deviation_mean_m = NAN, deviation_max_m = NAN;  // [m] from the sketched path
  /// Against ground truth (simulation only, "diagnostics"): how far the odometry ended off
  /// [m], where the executive finally put the goal [m], and how far the drawing alone puts it
  /// [m] (judge.h sketchGoalErrorM); each absent when the run could not tell.
  struct Diagnostics {
    double odometry_error_m = 0;
    double odometry_heading_error_deg = 0;  // [deg] the final odometry heading's error
    std::optional<double> goal_estimate_error_m;
    std::optional<std::array<double, 2>> goal_estimate_world;  // [m] where it put the goal
    std::optional<double> sketch_goal_error_m;
  };
  std::optional<Diagnostics> diagnostics;
  Json json;  // the whole summary

  /// The figures of a summary object. A missing figure, or one of the wrong type, stays as
  /// initialised above, except "success", "reason" and "failure": of the wrong type they throw
  /// Json's type_error (a summary.json that is not this program's), as does a summary that is
  /// not an object.
  static RunSummary fromJson(const Json& summary);
  /// The figures above as summary.json holds them (a figure the run could not measure, NaN,
  /// is null; no diagnostics, no key); `json` is not part of it: the rest of summary.json
  /// (settings, landmarks, timing, ...) is the run's to add. fromJson(toJson()) gives the
  /// figures back.
  Json toJson() const;
};

}  // namespace sketchnav::run
