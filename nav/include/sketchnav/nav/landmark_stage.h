#pragma once
// Landmark bookkeeping: which detection is the expected landmark. When several landmarks
// share a class, the one consistent with the current section's predicted bearing / range
// (from odometry and the sketch) is chosen; detections far from the prediction are rejected
// rather than followed (the sketch is rough, so the gates are wide).
#include <Eigen/Core>

#include <string>
#include <vector>

#include "sketchnav/nav/perception.h"
#include "sketchnav/nav/sections.h"  // Sighting

namespace sketchnav::nav {

struct SelectParams {
  double bearing_gate_deg = 40;   // [deg] |measured - predicted bearing| above this: rejected
  double range_gate_rel = 0.6;    // relative |measured - predicted range| above this: rejected
  double range_gate_min_m = 1.5;  // [m] ...but never tighter than this
  double bearing_sigma_deg = 10;  // [deg] scale of the bearing term in the cost
  double range_sigma_m = 1.0;     // [m] scale of the range term
  // A detection whose measured range fails the range gate is still taken, as a bearing
  // without a range, when its bearing is within this of the prediction [deg]: the laser passes
  // under or beside a landmark standing on a table or shelf and reads what is behind it. It
  // costs as much as a range at the gate's edge, so a detection whose range agrees wins.
  // 0 = refuse such detections. Evidence: doc/navigation.md "Evidence for the defaults".
  double bearing_only_gate_deg = 10;
  // For a landmark whose class the sketch has once, that rule covers the whole bearing gate:
  // no other landmark can be mistaken for it, and a refit on the landmarks before it can put
  // it metres off its sketched place. Evidence: doc/navigation.md "Evidence for the defaults".
  bool unique_class_bearing_only = true;
  template <class B>
  void bind(B& b) {
    b("bearing_gate_deg", bearing_gate_deg);
    b("range_gate_rel", range_gate_rel);
    b("range_gate_min_m", range_gate_min_m);
    b("bearing_sigma_deg", bearing_sigma_deg);
    b("range_sigma_m", range_sigma_m);
    b("bearing_only_gate_deg", bearing_only_gate_deg);
    b("unique_class_bearing_only", unique_class_bearing_only);
  }
  void validate() const;  // InputError "nav.select.<field> = ...: ..."
};

/// A detection with its measured range (laser / sonar along its bearing; <= 0 = unknown).
struct Candidate {
  const Detection* detection = nullptr;
  double range_m = 0;
};

/// Whether a measured range agrees with the predicted one (the range gate); an unknown range
/// (<= 0) on either side agrees.
bool rangeAgrees(double measured_m, double predicted_m, const SelectParams& p);

/// Index into `candidates` of the one of class `class_name` best matching the prediction,
/// or -1 when none passes the gates. Ties (equal cost) go to more inliers. A candidate taken
/// through SelectParams::bearing_only_gate_deg has a range that does not agree
/// (rangeAgrees()): the caller uses its bearing only.
int selectCandidate(const std::vector<Candidate>& candidates, const std::string& class_name,
                    double predicted_bearing, double predicted_range, const SelectParams& p);

/// Where the landmarks looked for this frame are expected, for handing out its detections.
struct Expected {
  std::string class_name;
  bool tracked = false;  // seen within the last moments: expected where it was last seen
  Polar where;           // from the robot (range 0 = unknown)
};
/// A landmark being tracked is expected where it was last seen (the ray from `origin` along
/// `world_bearing` [rad, odometry frame], at `range` when > 0), not where the sketch puts it.
Polar expectedFromTrack(const hw::Pose2D& robot, const Eigen::Vector2d& origin,
                        double world_bearing, double range);
/// Whether candidate `c` is the detection of a tracked landmark of the same class other than
/// `self` (within 10 degrees and, with both ranges known, 0.75 m of where it is expected).
/// The sketch can put a tracked landmark 25 degrees and a metre off: a repeated class's next
/// landmark, sketched nearer, then took the tracked one's detection and was fixed 2 m off.
bool claimedByTracked(const Candidate& c, size_t self, const std::vector<Expected>& expected);

// Where a landmark is, from all its sightings. The laser range along a landmark's bearing is
// the range to whatever the low laser plane hits there: a carton standing 0.2 m in front of a
// bench face, seen at 17 degrees, is "seen" 0.65 m too far (the bench face behind it), and
// such fixes put the route's goal 0.5-1 m off in the lab experiments. The bearings of the
// sightings taken as the robot drives by cross at the landmark itself, so they pin it across
// each ray (range x bearing error) and, as far as they spread, along it; a range joins only
// when it agrees with that crossing (or, when the bearings do not cross, with the other
// ranges), and then loosely. The result is a point with its information matrix: tight across
// the view, loose along it when the bearings barely spread (the robot mostly heads towards a
// landmark) — which is how the sketch refit weighs it (SectionTracker::fitSimilarityWeighted).
struct LocateParams {
  double bearing_sigma_deg = 1.0;   // [deg] bearing noise of a detection
  double min_spread_deg = 8;        // [deg] "triangulated" needs rays spread at least this...
  double max_along_sigma_m = 0.25;  // [m] ...and the crossing this sharp along the view
  double range_sigma_m = 0.35;      // [m] of a range along a landmark's bearing: loose, it is
                                    // often the furniture behind the landmark
  double range_gate_m = 0.25;       // [m] a range further than this (+ 2 sigma of the
                                    // crossing) from where the bearings cross, or from the
                                    // median range when they do not cross, is left out
  // Height ranging. A landmark's centre stands at a fixed, unknown height; from distance r
  // the camera sees it at elevation e with r = dh cot(e). Sightings from different distances
  // (the robot approaching) give dh and so a range per sighting, from the camera alone: the
  // rays' points o + (dh cot e) u meet at the landmark only for the right dh (linear least
  // squares, one dh per database photo matched, as each photo frames the object a little
  // differently). Where these ranges disagree with the laser's (height_agree_m), the laser hit
  // something else — the lab's cartons stand ~1 m up and the 0.25 m laser plane passes under
  // them to the bench behind: L5 was located 0.30 m too far (median, 84 fixes) — and the
  // height ranges replace them.
  bool height_ranging = true;
  int height_min_sightings = 4;             // per photo, with an elevation
  double height_min_elevation_deg = 3;      // [deg] |elevation| below this ranges nothing
  double height_elevation_sigma_deg = 0.3;  // [deg] elevation noise (a pixel is 0.1 deg; the
                                            // floor tilts the robot a little)
  double height_max_sigma_m = 0.15;         // [m] range error (from the fit) above this: not used
  double height_min_sigma_m = 0.08;         // [m] floor of a height range's error (shared by all)
  double height_agree_m = 0.15;             // [m] laser ranges within this (median) are kept
  // A laser range the sketch's range gate refused (Sighting::gated_range_m: the landmark
  // stands metres from where the drawing says) is taken back when height ranges with an error
  // up to this [m] agree with it: median difference within max(height_agree_m, twice their
  // error). Such height ranges are too loose to replace a laser range, not to tell the
  // landmark's wall from an obstacle a metre or more in front of it. 0 = never taken back.
  double gated_confirm_sigma_m = 0.5;
  template <class B>
  void bind(B& b) {
    b("bearing_sigma_deg", bearing_sigma_deg);
    b("min_spread_deg", min_spread_deg);
    b("max_along_sigma_m", max_along_sigma_m);
    b("range_sigma_m", range_sigma_m);
    b("range_gate_m", range_gate_m);
    b("height_ranging", height_ranging);
    b("height_min_sightings", height_min_sightings);
    b("height_min_elevation_deg", height_min_elevation_deg);
    b("height_elevation_sigma_deg", height_elevation_sigma_deg);
    b("height_max_sigma_m", height_max_sigma_m);
    b("height_min_sigma_m", height_min_sigma_m);
    b("height_agree_m", height_agree_m);
    b("gated_confirm_sigma_m", gated_confirm_sigma_m);
  }
  void validate() const;  // InputError "nav.locate.<field> = ...: ..."
};

struct LandmarkFix {
  bool ok = false;
  Eigen::Vector2d position{0, 0};                         // [m] odometry frame
  Eigen::Matrix2d information = Eigen::Matrix2d::Zero();  // [1/m^2] inverse covariance
  bool triangulated = false;  // the bearings cross well (see LocateParams)
  // Neither crossing bearings nor a range that agrees: the landmark is somewhere along its
  // rays. `information` is then (nearly) rank one, across the view only, and `position` a
  // nominal point on the rays (its place along them means nothing): the refit can still use
  // it, but nothing may shift the route towards that point.
  bool bearing_only = false;
  int rays = 0;  // sightings used
  int ranges_used = 0, ranges_dropped = 0;
  int height_ranges = 0;      // sightings ranged by height (replacing the laser's or none)
  double height_sigma_m = 0;  // their range error (from the fit)
  int gated_ranges = 0;       // laser ranges the sketch's gate refused, taken back (height
                              // ranges agree with them; LocateParams::gated_confirm_sigma_m)
};

/// Height ranging alone (see LocateParams): per sighting the range it gives (0: none) and
/// its error; empty when the sightings do not range the landmark.
struct HeightRanges {
  std::vector<double> range_m;
  double sigma_m = 0;
};
HeightRanges heightRanges(const std::vector<Sighting>& sightings, const LocateParams& p);

/// The landmark's position from its sightings (see LocateParams). Not ok when there is no
/// sighting. With no range and bearings that do not cross well enough, ok and bearing_only.
LandmarkFix locateLandmark(const std::vector<Sighting>& sightings, const LocateParams& p);

}  // namespace sketchnav::nav
