#pragma once
// The simulator: a World, a simulated clock, and the devices the navigation code reads
// (hw::Camera, hw::Base, two hw::RangeSensor: laser and sonar).
//
// TIME MODEL. The simulator owns a hw::SimClock. The control loop advances it
// (clock()->sleepUntil(t_next) just jumps simulated time) and then reads devices; every device
// call first integrates the world lazily up to clock()->now() in fixed substeps
// (SimParams::substep), so the same executive code drives the real robot (SteadyClock) and
// the simulator. advanceTo(t) does the same explicitly.
//  - camera().grab() delivers frames at SimParams::camera_hz like a real camera: when a new
//    frame period has started since the last delivered frame it renders the view now;
//    otherwise it blocks, i.e. advances the clock to the next frame time, then renders.
//    camera_hz = 0 renders on every call at the current time.
//  - laser()/sonar() read(): the latest scan, recomputed when a new period (the world's
//    laser.rate_hz / sonar.rate_hz) has started since the last one.
//  - base().odometry(): the noisy dead-reckoned pose. The odometry frame is the robot's start
//    frame: odometry starts at (0, 0, 0) at World::start. truePose() is in the world frame.
//  - A collision (the robot's disc touching a wall, closed door, obstacle or pedestrian)
//    stops the base for good: collided() becomes true, base().ok() false, commands are ignored.
// Deterministic: the same world, params (seed) and command sequence at the same simulated
// times give the same trajectory, scans and images. Thread-safe (one internal mutex), so a
// camera thread and a control thread may share one Simulator.
#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "sketchnav/hw/clock.h"
#include "sketchnav/hw/devices.h"
#include "sketchnav/sim/world.h"

namespace sketchnav::sim {

struct SimParams {
  // Time
  double substep = 0.01;    // [s] fixed integration step
  double camera_hz = 10.0;  // [Hz] camera frame rate (0 = a frame on every grab)
  bool realtime = false;    // true: advancing the clock also waits wall time (--realtime)
  // Camera image degradations (on top of World::lighting)
  double image_noise_std = 2.0;    // [grey levels] Gaussian pixel noise (0 = none)
  double blur_sigma = 0.0;         // [px] Gaussian blur (0 = none)
  double brightness_jitter = 0.0;  // relative per-frame random brightness change (0.05 = 5 %)
  // Base limits
  double v_max = 0.5;      // [m/s]
  double w_max = 1.5;      // [rad/s]
  double acc_max = 1.0;    // [m/s^2]
  double alpha_max = 3.0;  // [rad/s^2]
  // Odometry noise (applied to the measured wheel increments; ground truth is exact)
  double odom_slip_std = 0.02;       // relative random error of each distance increment
  double odom_turn_slip_std = 0.03;  // relative random error of each heading increment
  double odom_scale_error = 0.01;    // systematic relative error of the distance (wheel size)
  double odom_drift = 0.01;          // [rad/m] systematic heading drift per metre driven
  // Range sensors
  double range_noise_scale = 1.0;  // multiplies the world's laser/sonar noise_std (0 = exact)
  // Pedestrians follow their paths whatever the robot does, with one exception: someone who
  // comes up behind the robot (it in their way ahead of them, its back towards them, not
  // driving at them) waits pedestrian_keep_behind_m [m] short of it until it moves on, as
  // people do behind someone standing in a corridor. The robot's sensors do not see behind
  // it; coming at it from the front or the side, people walk on (the robot must keep out of
  // their way). 0 = they walk into it from behind too.
  double pedestrian_keep_behind_m = 0.5;
  // Randomness
  std::uint64_t seed = 1;
  // Trajectory recording
  double record_period = 0.1;  // [s] trajectory sample period (0 = none)

  template <class B>
  void bind(B& b) {
    b("substep", substep);
    b("camera_hz", camera_hz);
    b("realtime", realtime);
    b("image_noise_std", image_noise_std);
    b("blur_sigma", blur_sigma);
    b("brightness_jitter", brightness_jitter);
    b("v_max", v_max);
    b("w_max", w_max);
    b("acc_max", acc_max);
    b("alpha_max", alpha_max);
    b("odom_slip_std", odom_slip_std);
    b("odom_turn_slip_std", odom_turn_slip_std);
    b("odom_scale_error", odom_scale_error);
    b("odom_drift", odom_drift);
    b("range_noise_scale", range_noise_scale);
    b("pedestrian_keep_behind_m", pedestrian_keep_behind_m);
    b("seed", seed);
    b("record_period", record_period);
  }
  /// Throws InputError "sim.<field> = <value>: <why>".
  void validate() const;
};

struct PedestrianState {
  std::string name;
  Eigen::Vector2d position{0, 0};  // [m] world frame
  Eigen::Vector2d velocity{0, 0};  // [m/s]
  double radius = 0.25;            // [m]
};

/// Where pedestrian `p` is at simulated time `t` when it has not waited (a function of time
/// only; Simulator::pedestrians() gives where each is, waits included).
PedestrianState pedestrianAt(const Pedestrian& p, double t);

struct TrajectorySample {
  double t = 0.0;           // [s] simulated
  hw::Pose2D truth;         // world frame
  hw::Pose2D odom;          // odometry frame (= start frame)
  double v = 0.0, w = 0.0;  // [m/s], [rad/s] true velocities
};

struct SimStats {
  std::uint64_t frames_rendered = 0;
  std::uint64_t laser_scans = 0;
  std::uint64_t sonar_scans = 0;
  double render_seconds = 0.0;  // [s] CPU time of the rendering thread spent rendering
  double distance = 0.0;        // [m] true distance travelled
};

class Simulator {
 public:
  explicit Simulator(World world, SimParams params = {});
  Simulator(World world, SimParams params, std::uint64_t seed);  // seed overrides params.seed
  ~Simulator();
  Simulator(const Simulator&) = delete;
  Simulator& operator=(const Simulator&) = delete;

  // Devices (owned by the simulator; valid for its lifetime).
  hw::Camera& camera();
  hw::Base& base();
  hw::RangeSensor& laser();
  hw::RangeSensor& sonar();
  std::shared_ptr<hw::SimClock> clock() const;

  /// Integrates the world up to simulated time t (no-op when t <= the current state time)
  /// and moves the clock to t if it is behind.
  void advanceTo(double t);
  /// advanceTo(clock()->now()).
  void sync();

  // Ground truth (after sync()).
  hw::Pose2D truePose();      // world frame
  hw::Pose2D odometryPose();  // what base().odometry() reports
  bool collided();
  std::string collisionWith();  // name of what was hit ("" when none)
  double minClearance();        // [m] closest approach of the body to anything so far
  double minClearancePeople();  // [m] closest approach of the body to a pedestrian's (inf: none)
  double clearance();           // [m] current distance from the body to the nearest thing
  std::vector<PedestrianState> pedestrians();
  const World& world() const { return world_; }
  const SimParams& params() const { return params_; }
  std::vector<TrajectorySample> trajectory();
  SimStats stats();
  /// True when the robot's centre is inside the goal region.
  bool atGoal();

  /// Renders the camera view for a robot at `wMr` (world frame) at simulated time `t`
  /// (pedestrian positions, lighting), without moving the simulation. Noise and blur from
  /// params are applied when `degrade` is true (with this call's own RNG draw).
  cv::Mat renderView(const hw::Pose2D& wMr, double t, bool degrade = false);

  /// Teleports the robot (tests, data generation): sets the true pose, stops the base and
  /// clears the collision flag; odometry is not changed.
  void setTruePose(const hw::Pose2D& wMr);

 private:
  World world_;
  SimParams params_;
  struct Impl;
  std::unique_ptr<Impl> impl_;  // after world_/params_: it refers to them
};

}  // namespace sketchnav::sim
