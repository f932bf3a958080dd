#pragma once
// The expected landmarks' tracks: for each landmark of the route, whether it is still looked
// for (pending), being tracked, passed or missed, what was seen of it (its sightings, for the
// route anchor), and the rules that move it between those states — which detection is which
// landmark (association), when a tracked one is lost from view, when one is passed or missed,
// and how many were missed in a row.
//
// A LandmarkTracker never ends the run and emits nothing: each call returns its outcome (the
// event to report, the "lost" verdict with its reason) and the executive acts on it.
#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

#include "sketchnav/mapsketch/route.h"
#include "sketchnav/nav/events.h"
#include "sketchnav/nav/landmark_stage.h"
#include "sketchnav/nav/route_anchor.h"
#include "sketchnav/nav/sections.h"

namespace sketchnav::nav {

/// The tracker's settings. Their keys sit directly under "nav." (ExecutiveParams derives from
/// this struct): `nav.approach_m`, `nav.lost_after_s`, ...
struct LandmarkTrackerParams {
  double approach_m = 1.4;         // [m] a servoed landmark is passed at max(this, its range_m)
                                   // (more than avoid.trigger_m + radius: pass before dodging)
  double max_approach_m = 2.5;     // [m] cap on the sketch's range_m for that test
  double lost_after_s = 2.0;       // [s] a tracked landmark unseen this long: back to searching
  double miss_slack_m = 2.0;       // [m] past a landmark's along position without seeing it: missed
  double attend_bearing_deg = 75;  // [deg] look for the landmark only when the sketch puts it
  double attend_range_m = 12;      // [m]  within this bearing and range
  int max_missed_in_row = 2;       // more consecutive missed landmarks than this: lost, fail
  template <class B>
  void bind(B& b) {
    b("approach_m", approach_m);
    b("max_approach_m", max_approach_m);
    b("lost_after_s", lost_after_s);
    b("miss_slack_m", miss_slack_m);
    b("attend_bearing_deg", attend_bearing_deg);
    b("attend_range_m", attend_range_m);
    b("max_missed_in_row", max_missed_in_row);
  }
  void validate() const;  // InputError "nav.<field> = ...: ..."
};

enum class LandmarkState { Pending, Tracking, Passed, Missed };
/// "pending", "tracking", "passed", "missed" (summary.json landmarks[].state).
const char* toString(LandmarkState s);

/// What is known of one expected landmark.
struct LandmarkTrack {
  LandmarkState state = LandmarkState::Pending;
  int frames_seen = 0, max_inliers = 0;
  double last_seen = -1e300;  // [s] run clock
  double last_range = 0;      // [m] last measured range (0 = none usable)
  double last_bearing = 0;    // [rad] robot frame
  // Where it was last seen (odometry frame): the ray's origin and direction, and its point when
  // it had a range. While it is being tracked, detections are matched against this, not
  // against where the sketch puts it.
  Eigen::Vector2d last_origin{0, 0};
  double last_world_bearing = 0, last_point_range = 0;
  std::vector<Sighting> sightings;  // within fix range, for RouteAnchor::correct()
};

/// A landmark attended this tick: section k's landmark i, where the sketch (or its track)
/// puts it, and whether frames are searched for it.
struct AttendedLandmark {
  int k = 0, i = 0;
  Polar pred;  // from the robot, by odometry and the (re-anchored) sketch
  bool attend = false;
};

class LandmarkTracker {
 public:
  /// `route` must outlive the tracker (SectionTracker::route()).
  LandmarkTracker(const mapsketch::Route& route, LandmarkTrackerParams p);
  const LandmarkTrackerParams& params() const { return p_; }

  const mapsketch::ExpectedLandmark& landmark(int k, int i) const;
  LandmarkTrack& track(int k, int i) { return tracks_[k][i]; }
  const LandmarkTrack& track(int k, int i) const { return tracks_[k][i]; }
  /// Per section, per expected landmark.
  const std::vector<std::vector<LandmarkTrack>>& tracks() const { return tracks_; }
  /// How many landmarks of the sketch have class `cls`.
  int classCount(const std::string& cls) const;

  /// Range [m] at which a servoed landmark counts as passed: its lateral distance from the
  /// path, or, for a landmark ahead beyond its section's end (on the wall the route turns at),
  /// its sketched distance from that end — re-anchoring on it then puts the end where the robot
  /// is — clamped to [approach_m, max_approach_m].
  double passDistance(int k, int i) const;
  /// Whether a measured range says the robot is at the landmark (within a metre of the pass
  /// distance): one that slid out of view there was passed, and the furniture being dodged
  /// there is its own.
  bool atLandmark(int k, int i, double range_m) const;
  /// Sightings further than this [m] are not ranged fixes (the laser along the bearing may hit
  /// something else that far out).
  double fixRange() const { return p_.max_approach_m + 1.5; }

  /// A landmark marked missed: the event to report, and — when more than max_missed_in_row in
  /// a row have now been missed — the "lost" verdict's reason.
  struct Miss {
    event::LandmarkMissed event;
    std::optional<std::string> lost;
  };
  /// Marks landmark (k, i) missed. `counts`: towards "lost: N in a row" (a landmark left behind
  /// one that was passed after it does not count: the robot knows where it is).
  Miss miss(int k, int i, bool counts = true);
  /// Marks landmark (k, i) passed, and every earlier landmark still pending as behind the robot
  /// (passed when it was seen, else missed without counting); the run of misses ends. Returns
  /// those misses, in order. The fix the passed landmark gives is the RouteAnchor's business.
  std::vector<Miss> pass(int k, int i);

  /// Whether a servoed landmark of section k (other than its landmark `except_i`, e.g. the
  /// final look's; -1: none) holds the section open: tracked and seen within `within_s` [s] of
  /// `now`.
  bool holdsSection(int k, double now, double within_s, int except_i = -1) const;

  /// Where each attended landmark is expected in this frame (a tracked one: where it was last
  /// seen; else where the sketch puts it), for handing out detections (claimedByTracked).
  std::vector<Expected> expectations(const std::vector<AttendedLandmark>& att,
                                     const hw::Pose2D& pose) const;

  /// The detection given to an attended landmark in this frame.
  struct Association {
    const Detection* detection = nullptr;
    double range_m = 0;  // its range, 0 when not usable (far, or another object's)
    std::optional<event::LandmarkSeen> seen;  // it was not being tracked: now it is
  };
  /// Hands attended landmark `n` the detection that best matches where it is expected
  /// (selectCandidate over `candidates` not yet `used`, not at an earlier fix of its class
  /// (`anchor`), not a tracked landmark's); marks it used and updates the track at `pose`,
  /// `now` (state, counts, last seen, a sighting for the fix). `camera_x_m` [m]: the camera's
  /// distance ahead of the robot's centre; `far_bearings`: sightings beyond fixRange() are
  /// kept as bearings (RouteAnchorParams::fit_bearing_only). Nothing when no detection fits.
  std::optional<Association> associate(const std::vector<AttendedLandmark>& att, size_t n,
                                       const std::vector<Expected>& expect,
                                       const std::vector<Candidate>& candidates,
                                       std::vector<bool>& used, const RouteAnchor& anchor,
                                       const SelectParams& select, const hw::Pose2D& pose,
                                       double now, double camera_x_m, bool far_bearings);

  /// A tracked landmark unseen for lost_after_s at `now`.
  enum class Unseen {
    No,          // still in view, or not tracked
    AtIt,        // it slid out of view when already close: pass it
    LostToView,  // back to pending (this call has set it so): report event::LandmarkLost
  };
  Unseen checkUnseen(int k, int i, double now);

  /// The landmark to look for at the goal: the nearest to `pose` within `range_m` [m], by the
  /// route as it is placed now (`route`), of any section, never seen and pending or missed.
  std::optional<std::pair<int, int>> finalLookCandidate(const SectionTracker& route,
                                                        const hw::Pose2D& pose, double range_m,
                                                        double& at_range_m) const;

 private:
  const mapsketch::Route& route_;
  LandmarkTrackerParams p_;
  std::vector<std::vector<LandmarkTrack>> tracks_;
  int missed_in_row_ = 0;
  std::vector<std::string> missed_ids_;  // every landmark missed, in order
};

}  // namespace sketchnav::nav
