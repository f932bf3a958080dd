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
  int sectors = 144;                 // polar diagram resolution over 360 deg
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
    b("sectors", sectors);
  }
  void validate() const;  // InputError "nav.avoid.<field> = ...: ..."
};

/// Obstacle points in the robot frame [m] from laser / sonar scans (readings at or beyond
/// max_range dropped; a sonar reading becomes three points across its cone, conservatively).
std::vector<std::pair<double, double>> scanPoints(const std::vector<hw::RangeScan>& scans);

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
  Eigen::Vector2d prev_pt_{0, 0};  // nearest obstacle point ahead at the last scan (odometry)
  double prev_pt_t_ = 0;
  bool have_prev_pt_ = false;
};

}  // namespace sketchnav::nav
