#pragma once
// `sketchnav ros sim`: the built-in simulator as a ROS robot (doc/ros.md). It owns the
// simulated clock and publishes, on ROS time = simulated time (/clock, /use_sim_time set):
//   /clock                   rosgraph_msgs/Clock, every step
//   image_raw, camera_info   sensor_msgs/Image (bgr8) + CameraInfo at sim.camera_hz, frame
//   camera_optical odom                     nav_msgs/Odometry odom -> base_link (noisy dead
//   reckoning), every step tf                       odom -> base_link; static base_link ->
//   camera_optical, laser, sonar_<i> scan                     sensor_msgs/LaserScan at the world's
//   laser rate, frame laser sonar                    sensor_msgs/Range per transducer (frame
//   sonar_<i>), +Inf = no echo ground_truth             nav_msgs/Odometry map -> base_link_truth
//   (exact, world frame) ~state                   std_msgs/String JSON: t, collided, at_goal,
//   distance_to_goal_m...
// and subscribes to cmd_vel (geometry_msgs/Twist). Like a real base it stops when commands
// stop: a command older than cmd_timeout_s (simulated) is replaced by zero. A collision stops
// the base for good and its odometry stops (the navigation sees a lost base).
#include <functional>
#include <string>

#include "sketchnav/core/config.h"

namespace sketchnav::ros {

struct SimBridgeOptions {
  std::string world = "lab";  // a world name in share/worlds or a .world.json file
  int seed = 1;
  double rate = 1.0;           // simulated seconds per wall second (0 = as fast as possible)
  double step_s = 0.02;        // [s, simulated] publishing step (/clock, odom, tf)
  double cmd_timeout_s = 0.5;  // [s, simulated] base watchdog
  double max_time_s = 0;       // [s, simulated] > 0: end after this long
  bool hold_until_cmd = true;  // hold time at 0 (re-sending the t = 0 data) until a cmd_vel
  // Lock-step with a node whose ros.lockstep is on: after each step, the simulator publishes
  // lockstep/step (latched Float64MultiArray: t and the ROS stamps of the last odometry, scan,
  // sonar and frame sent, -1 for none) and steps again only once the node has answered on
  // lockstep/ack ([until (ROS time), v, w]: it waits for a later time, with the command to
  // apply), stepping exactly to `until` when it falls within a step. Time is held at 0 until
  // the first answer. Commands come from the answers (cmd_vel is not needed); rate still paces.
  bool lockstep = false;
  Config config;  // sim.* settings
};

/// Runs until SIGINT / SIGTERM, ros::shutdown, `stop()` true or max_time_s. The ROS node must
/// be initialised (ros::init). Returns the ground-truth summary: t, collided, collision_with,
/// at_goal, distance_to_goal_m, min_clearance_m, path_length_m, true_pose, frames_published.
Json runSimBridge(const SimBridgeOptions& options, const std::function<bool()>& stop = {});

}  // namespace sketchnav::ros
