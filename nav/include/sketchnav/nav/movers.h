#pragma once
// People walking: tracked from the laser, and their lanes kept clear.
//
// The reactive avoider judges motion only from the point closing the corridor ahead, so a
// person crossing from the side, or walking up behind a robot that has stopped for something
// else, is not seen coming; a simulated pedestrian (who, like a distracted one, does not step
// aside) then walks into a robot standing in its lane. Here laser points are grouped into
// person-sized clusters in the odometry frame and tracked from scan to scan; a track whose
// points lie where the occupancy grid of a few seconds ago had seen free floor and that
// moves faster than min_speed is a mover. Its lane is the capsule swept over horizon_s,
// widened by the person's and the robot's radii and a margin. The executive keeps out of
// lanes: it does not drive into one, and when it finds itself in one it steps out of it
// sideways, away from the mover's line, rather than cross in front.
#include <Eigen/Core>

#include <cstdint>
#include <vector>

#include "sketchnav/hw/types.h"

namespace sketchnav::nav {

class LocalPlanner;

struct MoverParams {
  // Keeping out of every mover's lane (advise()) is off by default: the tracker also reports
  // phantom movers (occlusion edges of small furniture while the robot drives), and yielding
  // to them makes closed-loop runs worse. `--set nav.movers.enabled=true`. The tracking
  // itself always runs: the avoider steps out of the lane of a mover coming at the robot
  // (avoidance.h). Evidence: doc/navigation.md "Evidence for the defaults".
  bool enabled = false;
  double cluster_gap_m = 0.15;   // [m] consecutive beams further apart start a new cluster
  double max_width_m = 0.8;      // [m] wider clusters are furniture or walls
  double gate_m = 0.5;           // [m] a cluster this close to a track's prediction is it
  double min_speed = 0.2;        // [m/s] slower tracks are not movers
  int min_updates = 5;           // scans before a track's speed is trusted
  double forget_s = 0.6;         // [s] a track not seen this long is dropped
  double horizon_s = 5.0;        // [s] lane length: where the mover will be by then
  double person_radius_m = 0.3;  // [m]
  double margin_m = 0.15;        // [m] added to the person's and the robot's radii
  double robot_radius_m = 0.2;   // [m]
  double look_ahead_s = 1.5;     // [s] the robot's own motion checked against lanes
  double range_m = 4.0;          // [m] movers further than this are ignored
  // Walking behind someone (followSpeed(), applied whether or not `enabled`): the robot keeps
  // follow_gap_m between the two bodies, closing a larger gap at most at 1 / follow_time_s of
  // the excess. A person who turns round then has seconds, not a metre, to be got out of the
  // way of. 0 = off (the default: doc/navigation.md "Evidence for the defaults"; 1.5 m is
  // the setting measured there).
  double follow_gap_m = 0;     // [m]
  double follow_time_s = 2.0;  // [s]
  template <class B>
  void bind(B& b) {
    b("enabled", enabled);
    b("cluster_gap_m", cluster_gap_m);
    b("max_width_m", max_width_m);
    b("gate_m", gate_m);
    b("min_speed", min_speed);
    b("min_updates", min_updates);
    b("forget_s", forget_s);
    b("horizon_s", horizon_s);
    b("person_radius_m", person_radius_m);
    b("margin_m", margin_m);
    b("robot_radius_m", robot_radius_m);
    b("look_ahead_s", look_ahead_s);
    b("range_m", range_m);
    b("follow_gap_m", follow_gap_m);
    b("follow_time_s", follow_time_s);
  }
  void validate() const;  // InputError "nav.movers.<field> = ...: ..."
};

struct Mover {
  Eigen::Vector2d position{0, 0};  // odometry frame [m]
  Eigen::Vector2d velocity{0, 0};  // [m/s]
  int updates = 0;
};

/// What to do about the movers this tick.
struct YieldAdvice {
  bool active = false;     // a lane is in the way: replace the command with (v, w)
  bool in_lane = false;    // the robot is inside a lane (stepping out)
  double v = 0, w = 0;     // [m/s], [rad/s]
  double clearance_m = 0;  // to the nearest mover's body
  Mover mover;             // the one whose lane it is
};

class MoverTracker {
 public:
  explicit MoverTracker(MoverParams params = {});
  /// Updates the tracks from a laser scan taken at `robot` (odometry frame). `grid`: the
  /// occupancy grid as it was a few seconds ago (LocalPlanner::snapshot), where the floor was
  /// seen free before a walking person's own trace was marked.
  void update(const hw::Pose2D& robot, const hw::RangeScan& laser, const LocalPlanner& grid);
  /// Tracks moving faster than min_speed after min_updates scans.
  std::vector<Mover> movers() const;
  /// People walking, for the avoider (which acts only on one coming at the robot whose lane
  /// covers it): tracks followed for 3 x min_updates scans at 1.5 x min_speed to 1.2 m/s,
  /// three quarters of their last 16 points on floor seen free; unlike movers(), the first
  /// need not be: a person already walking when first in view (the lab's walker, seen first across
  /// the room) is first seen where the grid had not yet seen the floor.
  /// Also, wherever its points lie, a track that has come steadily towards the robot (its
  /// velocity within 45 deg of the line to the robot at the last scan, at min_speed to
  /// 1.2 m/s) over its last 2 x min_updates scans: a person walking back along the line they
  /// came by walks over their own trace, which the grid of a few seconds ago holds occupied.
  /// The things the free-floor test is there for (occlusion edges sliding along a wall as the
  /// robot drives or turns) move with the robot or across its line of sight, not at it.
  std::vector<Mover> walkers() const;
  /// The forward speed at most `v` that keeps follow_gap_m behind a track walking away from
  /// the robot in its way (ahead, within both bodies' width of its heading line, steady over
  /// 2 x min_updates scans at 0.2-1.2 m/s). `v` when there is none.
  double followSpeed(const hw::Pose2D& robot, double v) const;
  /// Advice for a robot at `robot` about to command (v, w): stop rather than enter a lane,
  /// step out of one it is in. `k_heading`, `v_max`: how it turns and how fast it may go.
  YieldAdvice advise(const hw::Pose2D& robot, double v, double w, double k_heading,
                     double v_max) const;
  /// The part of advise() that holds the robot short of a lane, for walkers() only and
  /// whether or not `enabled`: a command (v, w) that would take a robot at `robot` into a
  /// walker's lane within look_ahead_s is to wait (active, v = 0, w kept). Inactive while
  /// the robot is in a walker's lane already: stepping out of it is the avoider's.
  YieldAdvice holdShortOfWalkerLanes(const hw::Pose2D& robot, double v, double w) const;
  const MoverParams& params() const { return p_; }

 private:
  struct Track {
    Eigen::Vector2d pos{0, 0}, vel{0, 0};
    double t = 0;
    int updates = 0;
    int free_hits = 0;            // updates whose points landed where the floor had been seen free
    bool born_free = false;       // the first of them did
    std::uint32_t free_bits = 0;  // the last 16 updates, newest lowest: on seen-free floor
    std::vector<std::pair<double, Eigen::Vector2d>> history;  // (stamp, centre), last 1.2 s
    Eigen::Vector2d fit_vel{0, 0};                            // straight-line fit over the history
    bool steady = false;                                      // and the fit is good (RMS <= 6 cm)
    int coming_in_row = 0;  // consecutive updates steady and coming towards the robot
  };
  YieldAdvice holdShort(const std::vector<Mover>& ms, const hw::Pose2D& robot, double v, double w,
                        YieldAdvice a) const;
  MoverParams p_;
  std::vector<Track> tracks_;
};

}  // namespace sketchnav::nav
