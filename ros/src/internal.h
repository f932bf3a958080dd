#pragma once
// State shared by the ros:// devices, the watchdog and the node helpers (one node a process).
#include <ros/ros.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <atomic>
#include <condition_variable>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <geometry_msgs/Transform.h>

#include "sketchnav/core/camera_mount.h"
#include "sketchnav/ros/node.h"

namespace sketchnav::ros::detail {

/// What a subscribed stream carries (the lock-step step message lists a stamp per kind).
enum class InputKind { Camera, Odometry, Laser, Sonar };

/// One subscribed stream the watchdog judges.
struct Input {
  InputKind kind = InputKind::Camera;
  std::string what;                     // "camera", "odometry", "laser scan", "sonar"
  std::string topic;                    // resolved name
  std::atomic<double> wall_last{-1.0};  // [s] wallNow() of the last message, -1 before the first
  std::atomic<bool> had_publisher{false};
  std::atomic<bool> active{true};  // false once its device is closing
  // [s, ROS time] header stamp of the last message delivered to its device (lock-step: the
  // node's time moves to a step once every input has what the simulator sent up to it)
  std::atomic<double> stamp_last{-1e300};
  std::function<std::uint32_t()> publishers;  // number of connected publishers
};

/// Image-to-command latency samples (node.h latencySummary()).
struct Latency {
  struct FrameTimes {
    double recv = -1, ready = -1, grab = -1;  // [s, wallNow()] callback, converted, grabbed
    double transport = -1;                    // [s] stamp -> callback (wall-time robots only)
  };
  std::map<std::uint64_t, FrameTimes> frames;  // by camera seq, the last ~50
  bool pending = false;
  std::uint64_t pending_seq = 0;
  std::vector<double> transport, convert, wait, grab_to_cmd, total;  // [s]
};

struct State {
  std::mutex mutex;
  bool initialised = false;
  std::unique_ptr<::ros::NodeHandle> nh;
  std::unique_ptr<::ros::AsyncSpinner> spinner;
  std::shared_ptr<tf2_ros::Buffer> tf;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener;
  std::vector<std::shared_ptr<Input>> inputs;
  ::ros::Publisher cmd_vel;  // set by the ros:// base: what the watchdog zeroes
  bool have_cmd_vel = false;
  RosParams params;
  std::string fault;
  std::atomic<bool> tripped{false};
  // hold(): commands are zero until release(). command_m orders a hold or a trip against a
  // command being published, so no command of the route can follow their zero. Lock order:
  // command_m before mutex.
  std::atomic<bool> held{false};
  std::mutex command_m;
  std::thread watchdog, liveness;
  std::atomic<bool> watchdog_stop{false};
  std::mutex latency_mutex;
  Latency latency;
  // Wake on frame (RosParams::wake_on_frame): the camera counts frames the executive will
  // grab (stamped at least wake_gap_s after the last one it took); the clock's sleepUntil()
  // returns as soon as one arrives.
  std::atomic<double> wake_gap_s{-1.0};  // [s] < 0: off
  std::mutex wake_m;
  std::condition_variable wake_cv;
  std::uint64_t frames_due = 0;               // guarded by wake_m
  std::atomic<std::uint64_t> frame_wakes{0};  // sleeps a frame ended early (this camera's)
  // Lock-step with `ros sim --lockstep` (RosParams::lockstep, doc/ros.md "Lock-step").
  std::atomic<bool> lockstep{false};
  ::ros::Subscriber lockstep_step;
  ::ros::Publisher lockstep_ack;
  std::vector<double> step;  // the simulator's last step: t and the stamps it had sent (wake_m)
  double lockstep_now = -1;  // [s, ROS time] the node's time: the last step all inputs reached
                             // (wake_m); < 0 before the first
  // [s, wall] when the control loop began waiting for the simulator; < 0 while it works (the
  // simulator waits for it then, so its inputs are not stale)
  std::atomic<double> lockstep_wait_since{-1.0};
  std::atomic<double> last_v{0.0}, last_w{0.0};  // the last command the base published
};

State& state();
double wallNow();
/// Publishes a zero Twist on the base's cmd_vel (no-op without a base). Never throws.
void publishZero() noexcept;
/// A stream delivered garbage: log it and trip the watchdog.
void garbage(const std::string& reason);
void addInput(const std::shared_ptr<Input>& in);
void removeInput(const std::shared_ptr<Input>& in);
/// Throws RuntimeError when init() has not run.
::ros::NodeHandle& nodeHandle();
/// The camera mount of an image's optical frame (REP 103: z forward, x right, y down) given
/// the transform base frame -> that frame: position, and the optical axis's yaw and pitch.
CameraMount opticalMount(const geometry_msgs::Transform& t);

}  // namespace sketchnav::ros::detail
