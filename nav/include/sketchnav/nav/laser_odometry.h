#pragma once
// Laser-aided odometry: wheel odometry corrected by scan matching (MRPT's ICP, mrpt::slam::CICP).
//
// Why: wheel odometry on a small differential base drifts in heading (wheel-radius mismatch,
// slip in turns); over the 20 m between the lab's door and its goal a drift of 0.01 rad/m plus
// slip puts the route 15-25 degrees off by the second room, which is enough to miss every
// landmark there. Walls and furniture seen by the laser pin the heading down. Each new laser scan
// is aligned with the points of the last submap_keyframes keyframe scans, the wheel increment
// since the newest keyframe being the initial guess; a new keyframe is taken every
// keyframe_dist_m / keyframe_deg. What remains is the slow drift of chained keyframes, which the
// landmark fixes take out. Each keyframe adds a small error (point-to-point ICP on 1-degree
// beams slides a little along walls), so keyframes are far apart: on the unit test's 33 m loop,
// 0.4 m / 12 deg keyframes end 0.10 rad off, 1.5 m / 30 deg ones under 0.03 rad (the wheels
// alone: 0.66 rad). A submap of three keyframes places each new one against points seen from
// three poses: in the lab experiment whose corner turn cost 6.6 degrees with one keyframe, the
// heading stayed within 1.4 degrees (the lab run: 3.2 -> 2.7-2.8 degrees at worst).
//
// An alignment is accepted only when it is good (enough of the scan explained by the reference)
// and close to the wheel prediction (a pedestrian filling the view, a long featureless
// corridor): otherwise the wheel increment is used unchanged, so a bad scan can never make
// things worse than wheel odometry. "Explained" allows for the gap between beams (a wall seen
// from 1.5 m further on is sampled at other places): judged by ICP's own goodness, which pairs
// points only within 2-4 cm, correct alignments were refused once the robot was 1-1.5 m from
// the keyframe, and in one experiment trial the robot then crossed a detour on its wheels alone
// and lost 3-4 degrees of heading. A scan the reference explains too little of (the view has
// moved on: a turn among obstacles, a door) starts a new keyframe at once, placed by the
// wheels (usually one scan since the last alignment), rather than leaving the robot on its
// wheels until it is twice keyframe_dist_m from the old one.
//
// Along a direction the scan does not constrain, ICP is not trusted: between two plain corridor
// walls a scan fixes the distance to them and the heading but not the position along them, and
// point-to-point ICP's translation there is wherever its pairs settle (in the unit test's 20 m
// corridor it stalls and ends 13-19 m short). The scan's surface normals (lines fitted to beam
// neighbours) give the translation block of the alignment's Hessian, H = sum n n^T; along its
// eigen-directions with fewer than constrained_points points' worth of normals the wheels'
// increment is kept, ICP's correction across it and in heading (same test: 0.60 m off, the
// wheels' own 0.61). Walls and furniture facing every way (a room) leave ICP's result whole.
//
// What the scan does pin down must also be still: a person walking ahead along a corridor is
// often the only surface facing along it, and aligned to them the robot stands still with
// them (in a simulated corridor run, 0.3 m of 3 m counted). Points that moved since a scan a
// moment ago, the two placed by the wheels, are left out (moving_baseline_s); and since the
// keyframe, the alignment's translation must agree with the wheels' within what an encoder
// gets wrong (wheel_agree_*), or the wheels' translation is kept: a slow walker passes the
// first check but not, over a keyframe's length, the second.
#include <deque>
#include <memory>

#include "sketchnav/hw/types.h"

namespace sketchnav::nav {

struct LaserOdometryParams {
  bool enabled = true;
  double keyframe_dist_m = 1.5;    // [m] travel since the keyframe that starts a new one
  double keyframe_deg = 30;        // [deg] rotation since the keyframe that starts a new one
  int submap_keyframes = 3;        // scans are aligned to the union of this many last keyframes
  double max_range_m = 7.5;        // [m] laser returns beyond this are not used
  int min_points = 30;             // fewer usable returns in a scan: no alignment
  double min_spread_m = 0.3;       // [m] nor when they lie along one line or in one small
                                   // cluster (std. dev. across their main axis): a lone
                                   // wall or post leaves the pose free to slide or turn
  double min_goodness = 0.6;       // share of the scan's points that the aligned reference
                                   // explains (a point within match_dist_m + match_deg *
                                   // range of a reference point) to accept
  double match_dist_m = 0.08;      // [m] and
  double match_deg = 1.0;          // [deg] (x range) for that: about the gap between beams
                                   // of a 1-degree laser plus noise, so that a wall seen
                                   // from another pose still counts as explained
  double max_correction_m = 0.15;  // [m] accepted difference from the wheel prediction
  double max_correction_deg = 6;   // [deg] accepted difference from the wheel prediction
  double constrained_points = 1;   // a direction the scan's surfaces face with fewer points
                                   // than this (sum of cos^2 between their normals and it)
                                   // takes the wheels' increment, not ICP's; from twice this
                                   // ICP's is taken whole, blended in between. 0: always ICP's
  double normal_radius_m = 0.3;    // [m] neighbours a point's surface normal is fitted to
  // The alignment's translation since the keyframe may differ from the wheels' by at most
  // wheel_agree_m + wheel_agree_rel x the wheels' travel since it; beyond that the wheels'
  // translation is kept (ICP's heading still taken). A wheel encoder is off by a few percent
  // of the distance, a scan aligned to something that moves (a person walking along with the
  // robot, or towards it) by the distance itself. Wheels that slip without the robot moving
  // (pushing against an obstacle) would pass this check the other way; the avoider keeps the
  // robot off obstacles. wheel_agree_rel = 0: no check.
  // Points that moved are left out of the alignment and of the keyframes: the current scan is
  // placed in the scan of moving_baseline_s ago by the wheels' motion since (good to a few mm
  // over so short a time) and a point with no surface of that scan within match_dist_m +
  // match_deg x range moved, or has just come into view. Things slower than about
  // (match_dist_m + match_deg x range) / moving_baseline_s pass as still. 0: keep every point.
  double moving_baseline_s = 0.5;  // [s]
  double wheel_agree_m = 0.05;     // [m]
  double wheel_agree_rel = 0.15;   // fraction of the wheels' travel since the keyframe
  template <class B>
  void bind(B& b) {
    b("enabled", enabled);
    b("keyframe_dist_m", keyframe_dist_m);
    b("keyframe_deg", keyframe_deg);
    b("submap_keyframes", submap_keyframes);
    b("max_range_m", max_range_m);
    b("min_points", min_points);
    b("min_spread_m", min_spread_m);
    b("min_goodness", min_goodness);
    b("match_dist_m", match_dist_m);
    b("match_deg", match_deg);
    b("max_correction_m", max_correction_m);
    b("max_correction_deg", max_correction_deg);
    b("constrained_points", constrained_points);
    b("normal_radius_m", normal_radius_m);
    b("moving_baseline_s", moving_baseline_s);
    b("wheel_agree_m", wheel_agree_m);
    b("wheel_agree_rel", wheel_agree_rel);
  }
  void validate() const;  // InputError "nav.laser_odometry.<field> = ...: ..."
};

struct LaserOdometryStats {
  int scans = 0;     // laser scans offered
  int aligned = 0;   // alignments accepted
  int attempts = 0;  // ICP alignments run
  int rejected = 0;  // scans not used (degenerate geometry, poor match, too far from the wheels)
  int keyframes = 0;
  int degenerate = 0;       // accepted alignments that took the wheels' increment along some axis
  double moving_share = 0;  // mean share of a scan's points left out as moved or new
  int wheel_disagree = 0;   // accepted alignments whose translation was the wheels' (see
                            // LaserOdometryParams::wheel_agree_rel)
  double ms_mean = 0;       // [ms] wall time per alignment
};

class LaserOdometry {
 public:
  explicit LaserOdometry(LaserOdometryParams params = {});
  ~LaserOdometry();
  LaserOdometry(LaserOdometry&&) noexcept;
  LaserOdometry& operator=(LaserOdometry&&) noexcept;

  /// A new wheel-odometry reading (stamp = its time). Returns the corrected pose.
  hw::Pose2D wheel(const hw::Pose2D& wheel_pose, double stamp);
  /// A laser scan; aligned against the keyframe when it is new. Sonar scans are ignored.
  void scan(const hw::RangeScan& scan);
  /// The current corrected pose (odometry frame: the wheel odometry's origin).
  hw::Pose2D pose() const;
  const LaserOdometryStats& stats() const { return stats_; }

 private:
  struct Impl;
  LaserOdometryParams params_;
  LaserOdometryStats stats_;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sketchnav::nav
