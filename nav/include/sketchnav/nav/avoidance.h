#pragma once
// Reactive obstacle avoidance over laser + sonar, on MRPT's holonomic ND method
// (mrpt::nav::CHolonomicND) fed with a configuration-space polar obstacle diagram.
//
// Following the paper: when an obstacle blocks the way, the avoider first records the original
// heading and the side on which the next landmark lies, and dodges towards that side (the
// target handed to ND is biased towards it, so ND picks the gap on that side when the obstacle
// is dead ahead); if that side is closed it takes the other. It keeps dodging (a pedestrian
// walking the way the robot dodges means several manoeuvres) until the corridor towards the
// route is clear again. A minimum clearance is never given up on purpose: when anything is
// closer than `min_clearance_m` in the direction of motion the forward speed is zero.
#include <Eigen/Core>

#include <deque>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "sketchnav/hw/types.h"

namespace sketchnav::nav {

enum class DodgeSide { None, Left, Right };
const char* toString(DodgeSide s);

struct AvoidParams {
  double robot_radius_m = 0.20;      // [m] body radius (the diagram is in configuration space)
  double trigger_m = 0.9;            // [m] free corridor length ahead below which avoidance starts
  double release_m = 1.4;            // [m] corridor towards the route this free -> avoidance ends
  double corridor_margin_m = 0.12;   // [m] added to the radius for the corridor checks
  double min_clearance_m = 0.12;     // [m] never move forward closer than this to anything
  double slow_m = 0.8;               // [m] forward speed scales down below this clearance ahead
  double max_range_m = 3.0;          // [m] obstacles beyond this are ignored (ND normalisation)
  double side_bias_deg = 35;         // [deg] target rotation towards the chosen side while dodging
  double moving_side_bias_deg = 65;  // [deg] the same for an obstacle coming towards the robot:
                                     // a pedestrian closes at ~0.7 m/s, so step out of its
                                     // lane rather than edge round it
  double moving_away_m = 0.15;       // [m] an obstacle coming towards the robot this far or
                                     // more to one side of its heading: dodge to the other
                                     // side, not the landmark's (0 = always the landmark's)
  double route_cone_deg = 90;        // [deg] a direction further than this from the route's is
                                     // taken only when none within it is open: the chosen side
                                     // is kept round an obstacle, not all the way back
  double min_active_s = 1.0;         // [s] hold a manoeuvre at least this long (no chattering)
  double same_side_s = 3.0;          // [s] a manoeuvre starting this soon after the last one
                                     // ended dodges to the same side
  double k_heading = 1.5;            // [1/s] yaw rate per rad of direction error
  double approach_horizon_s = 3.0;   // [s] an obstacle coming towards the robot (a pedestrian)
                                     // triggers this much earlier (its speed x horizon)
  double reverse_speed = 0.12;       // [m/s] back-off speed when something keeps coming closer
  // In the executive: the approach estimate counts only points on floor the occupancy grid
  // had seen free 1.5-3 s before (ObstacleAvoider::setMovedInTest); false = every point.
  // Off by default: doc/navigation.md "Evidence for the defaults".
  bool approach_needs_free_floor = false;
  // Someone walking towards the robot is followed from scan to scan (a person-sized group of
  // laser points, with its velocity) for as long as it is in view, not only while it closes
  // the corridor ahead. While its lane (its straight path over lane_horizon_s, as wide as
  // both bodies plus lane_margin_m) covers the robot, the manoeuvre is held and every
  // direction taken leaves the lane at lane_escape_deg or more to its axis.
  double lane_horizon_s = 6.0;   // [s]
  double person_radius_m = 0.3;  // [m]
  double lane_margin_m = 0.35;   // [m] gap kept between the two bodies (out of the lane)
  double lane_escape_deg = 60;   // [deg] from the lane's axis (90 = straight out sideways)
  double max_turn_rate = 0.8;    // [rad/s] how fast the base turns (nav.max_w), to choose the
                                 // side out of a lane
  // [s] > 0: a walker the dodge follows itself has a lane only while its trail over this long
  // bears its filtered speed out (at least half the distance, along it, once the trail spans
  // 0.3 s): a person standing still, whose laser centre jumps a few centimetres while the robot
  // turns, has none. 0 = off: the filtered speed alone (0.2 m/s) makes a lane, a few tenths of
  // a second sooner for someone who starts walking. Off by default: doc/navigation.md
  // "Evidence for the defaults".
  double lane_trail_s = 0.0;
  // Backing out of a walker's lane: where the way out lies behind the robot, reversing along
  // it (at lane_reverse_speed) is also a way out, taken when it gets out sooner than turning
  // round to drive forwards. The laser does not see behind the robot, so a way back is taken
  // only over floor a laser scan of the last rear_memory_s saw free (the robot usually came
  // that way; the newest scan that covers a spot decides, so someone seen walking into it
  // since counts). lane_reverse_speed 0 = only forward ways out.
  double lane_reverse_speed = 0.25;  // [m/s]
  double rear_memory_s = 10.0;       // [s] laser scans kept to judge the floor behind
  // A dodge direction outside every range sensor's view now counts as open only where a laser
  // scan of the last rear_memory_s saw its floor free (sweptSeenFree), and a direction once
  // chosen is kept until the current scan shows less than half of trigger_m free along it (a
  // turn on the spot is not reversed from one scan to the next). false = nothing seen there
  // counts as open, and the kept direction needs the full trigger_m. Evidence for the default:
  // doc/navigation.md "Evidence for the defaults".
  bool unseen_not_open = false;
  int sectors = 144;  // polar diagram resolution over 360 deg
  template <class B>
  void bind(B& b) {
    b("robot_radius_m", robot_radius_m);
    b("trigger_m", trigger_m);
    b("release_m", release_m);
    b("corridor_margin_m", corridor_margin_m);
    b("min_clearance_m", min_clearance_m);
    b("slow_m", slow_m);
    b("max_range_m", max_range_m);
    b("side_bias_deg", side_bias_deg);
    b("moving_side_bias_deg", moving_side_bias_deg);
    b("moving_away_m", moving_away_m);
    b("route_cone_deg", route_cone_deg);
    b("min_active_s", min_active_s);
    b("same_side_s", same_side_s);
    b("k_heading", k_heading);
    b("approach_horizon_s", approach_horizon_s);
    b("reverse_speed", reverse_speed);
    b("approach_needs_free_floor", approach_needs_free_floor);
    b("lane_horizon_s", lane_horizon_s);
    b("person_radius_m", person_radius_m);
    b("lane_margin_m", lane_margin_m);
    b("lane_escape_deg", lane_escape_deg);
    b("max_turn_rate", max_turn_rate);
    b("lane_trail_s", lane_trail_s);
    b("lane_reverse_speed", lane_reverse_speed);
    b("rear_memory_s", rear_memory_s);
    b("unseen_not_open", unseen_not_open);
    b("sectors", sectors);
  }
  void validate() const;  // InputError "nav.avoid.<field> = ...: ..."
};

/// Obstacle points in the robot frame [m] from laser / sonar scans (readings at or beyond
/// max_range dropped; a sonar reading becomes three points across its cone, conservatively).
/// `lasers_only`: sonar scans skipped (where in its cone a sonar echo lies is unknown).
std::vector<std::pair<double, double>> scanPoints(const std::vector<hw::RangeScan>& scans,
                                                  bool lasers_only = false);

/// Free length [m] of a straight corridor of half-width `half_width` from the robot along
/// `direction` [rad, robot frame] (max_len when nothing is in it).
double corridorFree(const std::vector<std::pair<double, double>>& pts, double direction,
                    double half_width, double max_len);

struct AvoidOutput {
  bool active = false;   // a manoeuvre is under way (v, w below replace the nominal command)
  bool started = false;  // this step started it (log the event)
  bool ended = false;    // this step ended it
  double v = 0, w = 0;   // [m/s], [rad/s]
  double direction = 0;  // [rad] chosen direction of motion, robot frame
  DodgeSide side = DodgeSide::None;
  double original_heading = 0;  // [rad] odometry heading recorded at the start
  double front_free_m = 0;      // free corridor ahead [m]
  double clearance_m = 0;       // nearest obstacle to the body [m]
  bool blocked = false;         // forward motion refused by the minimum clearance
  double approach_speed = 0;    // [m/s] estimated speed of the obstacle ahead towards the robot
  bool in_lane = false;         // a walker's lane covers the robot (held, stepping out)
  Eigen::Vector2d walker_pos{0, 0}, walker_vel{0, 0};  // that walker (odometry frame)
};

class ObstacleAvoider {
 public:
  explicit ObstacleAvoider(AvoidParams params = {});
  ~ObstacleAvoider();
  ObstacleAvoider(ObstacleAvoider&&) noexcept;
  ObstacleAvoider& operator=(ObstacleAvoider&&) noexcept;

  /// One step. `target_bearing`: direction [rad, robot frame] the nominal controller wants;
  /// `landmark_side`: where the next landmark lies relative to the direction of travel
  /// (Left / Right; None = no preference -> the freer side); `heading`: odometry heading;
  /// `v_nominal`: the cruise speed. `now` [s] for the hold time.
  AvoidOutput step(const std::vector<hw::RangeScan>& scans, double target_bearing,
                   DodgeSide landmark_side, double heading, double v_nominal, double now);
  /// Caps a nominal command so the minimum clearance holds even outside a manoeuvre.
  /// Returns the capped forward speed.
  double capSpeed(const std::vector<hw::RangeScan>& scans, double v) const;

  /// The robot's odometry pose for the next step(): obstacle motion (a pedestrian coming
  /// towards the robot) is then judged in the odometry frame, also while turning. Without it,
  /// only from the free corridor ahead shrinking faster than the robot drives, while straight.
  void setPose(const hw::Pose2D& pose) {
    pose_ = pose;
    have_pose_ = true;
  }
  /// People walking tracked elsewhere (movers.h, odometry frame): one coming towards the robot
  /// whose lane covers it is followed from the next scan on, also when it is not ahead (a
  /// walker coming at the robot from the side while it servoes on a landmark beside their
  /// lane). The avoider's own detection sees only what closes the corridor ahead.
  void offerWalker(const Eigen::Vector2d& position, const Eigen::Vector2d& velocity);
  /// Whether a person at `position` walking at `velocity` (odometry frame) towards a robot at
  /// `robot` has a lane (lane_horizon_s long, as wide as both bodies plus lane_margin_m) that
  /// covers it: the test the dodge steps out of lanes by, for behaviours that do not run the
  /// dodge (a recovery gives way to it).
  bool walkerLaneCovers(const Eigen::Vector2d& robot, const Eigen::Vector2d& position,
                        const Eigen::Vector2d& velocity) const;
  /// For the ticks another behaviour drives (a recovery, docking) and step() is not called:
  /// the pose and the laser scans, so that sweptSeenFree() judges from where the robot is
  /// and with what it saw meanwhile (a recovery that turned to look at its back).
  void observe(const std::vector<hw::RangeScan>& scans, const hw::Pose2D& pose);
  /// Whether every part of the band `half_width` [m] to each side (default: the robot's radius
  /// + 2 cm, its disc) swept `len` metres from the robot's pose along `direction` [rad, robot
  /// frame] lies on floor the newest remembered laser scan covering it saw free (the current
  /// scan included; rear_memory_s). Unknown floor is not free. The pose and scans are those of
  /// the last step().
  bool sweptSeenFree(double direction, double len, double half_width = 0) const;
  /// Whether a point (odometry frame) lies where the floor was seen free a few seconds ago
  /// (the occupancy grid's memory, movers.h). Set, the point followed for the approach
  /// estimate counts as coming towards the robot only there: the nearest point of a wall or a
  /// door frame slides along its surface as the robot turns, and on an oblique surface that
  /// sliding reads as an approach (static offices had detours ended "coming towards the
  /// robot" with nobody in them). Unset: every point counts.
  void setMovedInTest(std::function<bool(const Eigen::Vector2d&)> moved_in) {
    moved_in_ = std::move(moved_in);
  }
  bool active() const { return active_; }
  void reset();
  const AvoidParams& params() const { return params_; }

 private:
  struct Impl;
  AvoidParams params_;
  std::unique_ptr<Impl> impl_;
  bool active_ = false;
  double since_ = 0;
  DodgeSide side_ = DodgeSide::None;
  double original_heading_ = 0;
  double prev_dir_odom_ = 0;  // last chosen direction, odometry frame
  double prev_free_ = -1, prev_t_ = 0, prev_v_ = 0, prev_heading_ = 0;  // approach speed
  double prev_stamp_ = -1e300;
  double approach_ = 0;  // [m/s] filtered speed of the obstacle ahead towards the robot
  bool have_prev_ = false;
  DodgeSide last_side_ = DodgeSide::None;  // side of the last manoeuvre, and when it ended
  double last_end_t_ = -1e300;
  hw::Pose2D pose_;
  bool have_pose_ = false;
  double seen_stamp_ = -1e300;     // newest scan stamp in the memory sweptSeenFree() reads
  Eigen::Vector2d prev_pt_{0, 0};  // nearest obstacle point ahead at the last scan (odometry)
  double prev_pt_t_ = 0;
  bool have_prev_pt_ = false;
  std::function<bool(const Eigen::Vector2d&)> moved_in_;
  // The walker followed (odometry frame): centre of its laser points, filtered velocity.
  struct Walker {
    bool valid = false;
    Eigen::Vector2d pos{0, 0}, vel{0, 0};
    double t = 0;
    bool handed_over = false;  // offered by the mover tracker, its velocity a line fit
    // Where the follower measured it over the last lane_trail_s (stamp, odometry frame).
    std::deque<std::pair<double, Eigen::Vector2d>> trail;
  } walker_;
  // The side of the walker's axis the robot steps out to, a unit direction in the odometry
  // frame (zero: none chosen).
  Eigen::Vector2d lane_side_{0, 0};
  double lane_t_ = -1e300;  // when a lane last covered the robot
  void rememberScans(const std::vector<hw::RangeScan>& scans);
  void followWalker(const std::vector<hw::RangeScan>& scans, double stamp, bool acquire);
  /// The unit normal from the walker's lane axis towards the robot, and the robot's offset
  /// from the axis [m], when the lane covers the robot; false otherwise.
  bool inLane(Eigen::Vector2d& normal, double& offset) const;
  /// Whether the followed walker's trail bears out its velocity (see avoidance.cpp).
  bool walkerWalks() const;
  /// Forward speed along the heading for direction `dir`: turn first beyond 1 rad, slow as the
  /// corridor ahead closes, none inside the minimum clearance (sets out.blocked).
  double forwardSpeed(double dir, double v, AvoidOutput& out) const;
  void laneEscape(const std::vector<std::pair<double, double>>& pts, double target_bearing,
                  double heading, double v_nominal, const Eigen::Vector2d& lane_n, double lane_off,
                  AvoidOutput& out);
};

}  // namespace sketchnav::nav
