#pragma once
// The paper's experiments 2-4 as simulated scenarios, generated from the lab world
// (share/worlds/lab.world.json) by documented transformations (doc/experiments.md), plus a
// hand-drawn-like sketch made per seeded trial (sketch noise). Odometry noise comes from the
// simulator's own seeded odometry model. Names are stable so reports stay comparable.
#include <Eigen/Core>

#include <cstdint>
#include <string>
#include <vector>

#include "sketchnav/core/config.h"

namespace sketchnav::run {

/// One experiment variant: the world it runs in and the guide line the user draws.
struct Variant {
  std::string name;
  std::string description;
  Json world;                               // world-file JSON (share/worlds format)
  std::vector<Eigen::Vector2d> drawn_path;  // [m] world frame: the guide line as intended
  std::vector<std::string> sketched;        // landmark ids the user puts on the sketch
};

/// How inaccurate the generated sketches are (per trial, seeded).
struct SketchNoise {
  double landmark_sigma_m = 0.25;  // [m] error of where a landmark box is drawn
  double distance_sigma = 0.10;    // relative (log-normal) error of each distance estimate
  double distance_round_m = 0.5;   // [m] people round distances
  double path_sigma_m = 0.15;      // [m] error of each guide-line corner
  double jitter_px = 1.0;          // [px] hand jitter of each drawn point
  // A goal standing in front of an open door (within 1.5 m of its centre) is sketched as that
  // doorway (mapsketch::GoalPlace), its standoff the distance rounded to 0.1 m: the paper's
  // goal is "the right door in room B", and that is how a person says it. false: a point.
  bool goal_doorway = true;
  template <class B>
  void bind(B& b) {
    b("landmark_sigma_m", landmark_sigma_m);
    b("distance_sigma", distance_sigma);
    b("distance_round_m", distance_round_m);
    b("path_sigma_m", path_sigma_m);
    b("jitter_px", jitter_px);
    b("goal_doorway", goal_doorway);
  }
  void validate() const;
};

/// The 13 variant names, in report order.
const std::vector<std::string>& variantNames();

/// Builds a variant; InputError naming the unknown variant and the known ones.
Variant makeVariant(const std::string& name);

/// A sketch (.sketch.json content) of `v` as a person would draw it; `seed` draws the noise.
/// Canvas 1000 x 720 px, u = 32 + 52 x, v = 698 - 52 y (like share/sketches/lab.sketch.json).
Json makeSketch(const Variant& v, const SketchNoise& noise, std::uint64_t seed);

// --- batch set-up shared by `experiments` and `tune` ------------------------------------------

/// The sketch noise from "experiments.sketch.*" settings over the defaults, validated.
SketchNoise sketchNoiseFrom(const Config& config);

/// Writes the variant's world to <dir>/<name>.world.json (dir created); returns the path.
std::string writeVariantWorld(const Variant& v, const std::string& dir);

/// The sketch of `v` for simulator seed `seed`. The variant's place in variantNames() is mixed
/// into the noise seed, so variants do not share drawing errors and a trial's sketch is the
/// same whichever variants are run with it (--variants a,b).
Json variantSketch(const Variant& v, const SketchNoise& noise, int seed);

/// Writes variantSketch(v, noise, seed) to `path`.
void writeVariantSketch(const Variant& v, const SketchNoise& noise, int seed,
                        const std::string& path);

/// A failed trial as the report counts it.
struct TrialFailure {
  std::string code;    // summary.json "failure" (ScenarioResult::failure)
  std::string reason;  // the reason text: shown for a trial without a code (an old summary)
  std::string detail;  // per trial: short_of_goal's distance [m], collision's obstacle, or ""
};
/// The failure of a trial from its result: code, reason, and detail from its summary.
TrialFailure trialFailure(const std::string& code, const std::string& reason, const Json& summary);

/// The report's failure column: trials counted by failure code, in order of first appearance,
/// with their details, e.g. "2x stopped short of the goal [m] (0.52, 0.68); 1x lost".
std::string summariseFailures(const std::vector<TrialFailure>& failures);

/// Writes the run's --config/--set settings to <out>/config.json for the child runs; returns
/// its path, or "" when there are none.
std::string writeBatchConfig(const Config& config, const std::string& out);

}  // namespace sketchnav::run
