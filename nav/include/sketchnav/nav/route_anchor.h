#pragma once
// Where the sketch's route lies in the odometry frame, by the landmarks passed: the fixes (the
// start, then each landmark located from its sightings) and the policy that turns a new fix
// into a correction of the route (SectionTracker's alignment). Until the fixes span
// fit_min_span_m the route is rotated about the previous fix and shifted towards the new one
// (realign / reanchor); from then on its rotation, scale and position are refitted by least
// squares to the fixes (SectionTracker::fitSimilarityWeighted).
//
// A RouteAnchor decides nothing about the run: it is told a landmark was passed and reports
// what it did with it (an event::PassedFix, or why the fix was not used).
#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

#include "sketchnav/nav/events.h"
#include "sketchnav/nav/landmark_stage.h"
#include "sketchnav/nav/sections.h"

namespace sketchnav::nav {

/// The anchoring policy's settings. Their keys sit directly under "nav." (ExecutiveParams
/// derives from this struct): `nav.fit_fixes`, `nav.realign_gain`, ...
struct RouteAnchorParams {
  double reanchor_gain = 0.8;  // how much a passed landmark re-anchors the route (0 = never)
  // Once fixes (the start and passed landmarks) span fit_min_span_m, the route's rotation,
  // scale and position are refitted by least squares to the last fit_fixes of them
  // (SectionTracker::fitSimilarityWeighted), then shifted fit_local_gain of the way to the
  // newest; before that, realign/reanchor below. 0 fixes = always realign/reanchor.
  // All fixes, no local shift: each drawn box is off on its own, so every fix is worth the
  // same to the fit wherever it is, and pulling the route to the newest only adds that box's
  // error. A sketch distorted smoothly (one room drawn too small) would want fewer fixes and
  // a local shift. Evidence: doc/navigation.md "Evidence for the defaults".
  int fit_fixes = 100;
  double fit_min_span_m = 5.0;        // [m]
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
  double realign_baseline_m = 5.0;  // [m] minimum fix-to-landmark distance for that: a
                                    // sighting is good to ~0.3 m, so a shorter baseline
                                    // turns the route by more than it corrects
  // A repeated class: a detection (or a fix) within this of where an earlier landmark of the
  // same class was fixed is that landmark seen again, not the next one. A robot took the
  // first of three Bravo cartons for the second, refitted the sketch to it (scale -12 %) and
  // stopped 2.8 m from the goal.
  double same_class_gate_m = 1.0;  // [m]
  template <class B>
  void bind(B& b) {
    b("reanchor_gain", reanchor_gain);
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
    b("same_class_gate_m", same_class_gate_m);
  }
  void validate() const;  // InputError "nav.<field> = ...: ..."
};

/// One fix: a point of the sketch and where it was found in the odometry frame.
struct Fix {
  Eigen::Vector2d route{0, 0};  // [m] where the sketch puts it (route frame)
  Eigen::Vector2d odom{0, 0};   // [m] where it was located (odometry frame)
  std::string class_name;       // the landmark's class ("" for the start)
  Eigen::Matrix2d information = Eigen::Matrix2d::Identity();  // [1/m^2] how well it was seen
  // A bearing-only fix is placed only across its rays (its point along them means nothing):
  // the across-ray unit normal of its newest sighting; zero for the others.
  Eigen::Vector2d across{0, 0};
  bool bearingOnly() const { return !across.isZero(); }
};

class RouteAnchor {
 public:
  explicit RouteAnchor(RouteAnchorParams p = {}) : p_(p) {}
  const RouteAnchorParams& params() const { return p_; }

  /// The first fix: the route's start, where the robot was put (to 5 cm), as `route` places it.
  void start(const SectionTracker& route);
  /// Every fix, the start first.
  const std::vector<Fix>& fixes() const { return fixes_; }

  /// Whether a detection of `cls` seen from `origin` (odometry frame) along `direction` [rad,
  /// odometry frame] is where an earlier landmark of that class was fixed (the same object seen
  /// again, not the next one of a repeated class): with a range in (0, ranged_within_m] its
  /// point within same_class_gate_m of that fix; otherwise its ray passing ahead within half
  /// that. Bearing-only fixes do not count (they are no point).
  bool atEarlierFix(const std::string& cls, const Eigen::Vector2d& origin, double direction,
                    double range_m, double ranged_within_m) const;

  /// What a passed landmark did to the route.
  struct Correction {
    std::optional<std::string> rejected;  // why the fix was not used (same place as an earlier
                                          // landmark of its class)
    std::optional<event::PassedFix> fix;  // the fix and the refit or realign it gave
  };
  /// A landmark of class `cls` that the sketch puts at `route_pt` was passed, seen in
  /// `sightings`: locates it (locateLandmark with `locate`) and, when that gives a usable fix,
  /// adds it and corrects `route` (refit, or realign and reanchor). Neither field set: no fix
  /// (no sighting, or a bearing-only one the settings do not use).
  Correction correct(SectionTracker& route, const Eigen::Vector2d& route_pt, const std::string& cls,
                     const std::vector<Sighting>& sightings, const LocateParams& locate);

 private:
  RouteAnchorParams p_;
  std::vector<Fix> fixes_;
  // The last point fix (the start, then landmarks not located by bearings alone): the centre
  // of the next realign.
  Eigen::Vector2d last_route_{0, 0}, last_odom_{0, 0};
};

}  // namespace sketchnav::nav
