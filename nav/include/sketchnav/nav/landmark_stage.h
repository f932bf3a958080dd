#pragma once
// Landmark bookkeeping: which detection is the expected landmark. When several landmarks
// share a class, the one consistent with the current section's predicted bearing / range
// (from odometry and the sketch) is chosen; detections far from the prediction are rejected
// rather than followed (the sketch is rough, so the gates are wide).
#include <string>
#include <vector>

#include "sketchnav/nav/perception.h"

namespace sketchnav::nav {

struct SelectParams {
  double bearing_gate_deg = 40;   // [deg] |measured - predicted bearing| above this: rejected
  double range_gate_rel = 0.6;    // relative |measured - predicted range| above this: rejected
  double range_gate_min_m = 1.5;  // [m] ...but never tighter than this
  double bearing_sigma_deg = 10;  // [deg] scale of the bearing term in the cost
  double range_sigma_m = 1.0;     // [m] scale of the range term
  template <class B>
  void bind(B& b) {
    b("bearing_gate_deg", bearing_gate_deg);
    b("range_gate_rel", range_gate_rel);
    b("range_gate_min_m", range_gate_min_m);
    b("bearing_sigma_deg", bearing_sigma_deg);
    b("range_sigma_m", range_sigma_m);
  }
  void validate() const;  // InputError "nav.select.<field> = ...: ..."
};

/// A detection with its measured range (laser / sonar along its bearing; <= 0 = unknown).
struct Candidate {
  const Detection* detection = nullptr;
  double range_m = 0;
};

/// Index into `candidates` of the one of class `class_name` best matching the prediction,
/// or -1 when none passes the gates. Ties (equal cost) go to more inliers.
int selectCandidate(const std::vector<Candidate>& candidates, const std::string& class_name,
                    double predicted_bearing, double predicted_range, const SelectParams& p);

}  // namespace sketchnav::nav
