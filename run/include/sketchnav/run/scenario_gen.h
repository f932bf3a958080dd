#pragma once
// Generated navigation scenarios (`sketchnav scenarios`, doc/experiments.md "Generated
// scenarios"): seeded worlds of several families (corridors with L/T junctions, large halls,
// offices with rooms and doors, mixed lobby-corridor-room routes) in the world-file format,
// each with a sketch a person would draw of it, with drawing errors whose kinds and sizes are
// recorded. Same family and seed -> the same files, on every machine (own uniform / normal
// draws from std::mt19937_64, whose output the standard fixes).
//
// Every scenario returned passes the world checks (sim/world_check.h: no errors), its
// landmark classes are in the given set, its sketch loads and routes, its start heading is not
// refused against the sketch, and a free path exists for the robot (sim::freePathLength).
#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

#include "sketchnav/core/config.h"

namespace sketchnav::run {

/// Bounds of the drawing errors; each kind is applied to a scenario with probability `p_kind`.
/// An applied rotation is at least 5 deg, a start heading error at least 5 deg, a distance
/// bias at least 10 %, an anisotropic scale at least 4 % on one axis: a kind applied is never
/// negligible, so the per-kind figures mean something.
struct SketchErrorBounds {
  double rotation_deg = 30;     // [deg] the whole drawing turned by up to this (either way)
  double scale = 0.10;          // anisotropic scale: x and y of the drawing each x (1 +- this)
  double distance_bias = 0.30;  // every distance estimate x one factor in 1 +- this
  double corner_m = 0.6;        // [m] a misplaced corner moves up to this
  double heading_deg = 20;      // [deg] the robot put down up to this off the first stroke
  double move_min_m = 1.0;      // [m] a moved landmark moves at least this ...
  double move_max_m = 2.5;      // [m] ... and at most this
  double p_kind = 0.4;          // probability of each kind
  // Always present (a person's drawing is never exact):
  double landmark_sigma_m = 0.15;  // [m] where a landmark box is drawn (clipped at 2 sigma)
  double distance_noise = 0.05;    // relative noise of each distance (clipped at 2 sigma)
  double distance_round_m = 0.5;   // [m] distances said to the nearest this (at least this)
  double jitter_px = 1.0;          // [px] hand jitter of each drawn point
};

/// The error kinds, in report order.
const std::vector<std::string>& sketchErrorKinds();
/// corridor, hall, office, mixed.
const std::vector<std::string>& scenarioFamilies();

struct SketchErrorRecord {
  std::string kind;  // one of sketchErrorKinds()
  Json params;       // its size, e.g. {"deg": -12.5}
};

struct GeneratedScenario {
  std::string name;  // "<family>-<seed>"
  std::string family;
  std::uint64_t seed = 0;
  int attempts = 1;                       // layouts drawn until one passed every check
  Json world;                             // world-file JSON (doc/world-format.md)
  Json sketch;                            // .sketch.json (doc/sketch-format.md)
  std::vector<Eigen::Vector2d> route;     // [m] the way as intended, world frame
  std::vector<SketchErrorRecord> errors;  // the drawing errors applied
  Json meta;                              // pedestrians, obstacles in the way, lengths...
  std::vector<std::string> warnings;      // world-check warnings (no errors by design)
  bool hasError(const std::string& kind) const;
  /// scenario.json: everything but the world and the sketch.
  Json toJson() const;
};

/// Generates one scenario of `family` from `seed`; landmark classes are drawn from `classes`
/// (the landmark set), textures from share/textures/<class>/ (never the model's photos).
/// InputError for an unknown family; RuntimeError when 30 layouts all fail the checks.
GeneratedScenario generateScenario(const std::string& family, std::uint64_t seed,
                                   const std::vector<std::string>& classes,
                                   const SketchErrorBounds& bounds = {});

/// The checks every generated scenario must pass; one line per problem (empty = fine).
std::vector<std::string> scenarioProblems(const GeneratedScenario& s,
                                          const std::vector<std::string>& classes);

/// Writes <dir>/<name>.world.json, <name>.sketch.json and <name>.scenario.json (dir created);
/// returns the world file's path.
std::string writeScenario(const GeneratedScenario& s, const std::string& dir);

}  // namespace sketchnav::run
