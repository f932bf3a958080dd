#pragma once
// The ROS 1 side of sketchnav (doc/ros.md). One process is one ROS node: init() connects it
// to the master (ROS_MASTER_URI, ROS_IP as usual), and the ros:// devices registered by
// registerDrivers() subscribe / publish through it:
//   ros://camera?topic=image_raw&info=camera_info   sensor_msgs/Image (+ CameraInfo)
//   ros://camera?topic=image_raw&transport=compressed  sensor_msgs/CompressedImage on
//                                                      image_raw/compressed (+ CameraInfo)
//   ros://base?cmd_vel=cmd_vel&odom=odom            geometry_msgs/Twist out, nav_msgs/Odometry in
//   ros://base?cmd_vel=cmd_vel&tf=odom              ... odometry from tf odom -> base_link
//   ros://laser?topic=scan                          sensor_msgs/LaserScan
//   ros://sonar?topic=sonar                         sensor_msgs/Range, one frame per transducer
// so `sketchnav ros nav` runs the unchanged executive (nav/) on a ROS robot. Topic names are
// relative (resolved in the node's namespace; `from:=to` remappings apply).
//
// SAFETY. A watchdog thread (wall clock, 100 Hz) latches a fault, publishes a zero Twist at
// once and keeps every later command at zero when: any input is older than
// RosParams::stale_timeout_s, an input delivered garbage (empty image, an encoding that is not
// a colour / grey image, NaN odometry, a scan whose length does not match its angles), its
// publisher went away, the master cannot be reached, or SIGINT / SIGTERM arrived. The ros://
// base then reports ok() == false, so the executive stops and fails the run with that reason.
// Nothing the node publishes moves the robot after a fault (the process ends with the route).
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "sketchnav/core/camera_mount.h"
#include "sketchnav/core/config.h"
#include "sketchnav/hw/clock.h"

namespace sketchnav::ros {

/// The node's own settings ("ros.*", as --set ros.x=... or the ROS parameter ~ros/x).
struct RosParams {
  double stale_timeout_s = 0.5;  // [s, wall] an input older than this stops the robot
  double wait_s = 30.0;          // [s, wall] how long opening a device waits for its first message
  // [s, wall] how often the master's presence is checked (one loopback or LAN XML-RPC call):
  // a lost master stops the robot within this period plus that call, under the 200 ms a
  // killed input may take.
  double master_check_s = 0.1;
  std::string image_topic = "image_raw";
  std::string image_transport = "raw";  // "raw": sensor_msgs/Image on image_topic;
                                        // "compressed": sensor_msgs/CompressedImage (jpeg, png)
                                        // on image_topic + "/compressed", decoded with OpenCV
                                        // (image_transport's topic layout; also ~image_transport)
  bool wake_on_frame = true;  // a new camera frame wakes the control loop at once instead of
                              // waiting for its next tick (cuts the image -> command latency)
  std::string camera_info_topic = "camera_info";
  std::string odom_topic = "odom";
  std::string scan_topic = "scan";    // "" = no laser
  std::string sonar_topic = "sonar";  // "" = no sonar
  std::string cmd_vel_topic = "cmd_vel";
  std::string base_frame = "base_link";
  std::string odom_source = "topic";  // "topic": nav_msgs/Odometry on odom_topic; "tf": the
                                      // transform odom_frame -> base_frame (REP 105)
  std::string odom_frame = "odom";    // the odometry frame (tf source; pose, route, markers)
  bool camera_mount_from_tf = true;   // robot.camera.* (the camera mount) from tf
                                      // base_frame -> the image's frame, unless set
  // Lock-step with `ros sim --lockstep`: the node's time moves only to the simulator's steps
  // whose data every input has received, and each time the control loop waits it tells the
  // simulator until when (lockstep/ack, with its last command), so the simulator steps only
  // when the node has answered. Simulated time stands while a frame is perceived, as in
  // `sketchnav run`: the run is the same however loaded the machine is, and a bag recorded
  // of it replays to its commands. Turns wake_on_frame off. Only with that simulator.
  bool lockstep = false;
  template <class B>
  void bind(B& b) {
    b("stale_timeout_s", stale_timeout_s);
    b("wait_s", wait_s);
    b("master_check_s", master_check_s);
    b("image_topic", image_topic);
    b("image_transport", image_transport);
    b("wake_on_frame", wake_on_frame);
    b("camera_info_topic", camera_info_topic);
    b("odom_topic", odom_topic);
    b("scan_topic", scan_topic);
    b("sonar_topic", sonar_topic);
    b("cmd_vel_topic", cmd_vel_topic);
    b("base_frame", base_frame);
    b("odom_source", odom_source);
    b("odom_frame", odom_frame);
    b("camera_mount_from_tf", camera_mount_from_tf);
    b("lockstep", lockstep);
  }
  void validate() const;  // InputError "ros.<field> = ...: ..."
};

/// Connects this process to the ROS master as node `name`. `args` are passed to ros::init (ROS
/// remappings `from:=to`, `__name:=`, `__ns:=`...). Installs SIGINT / SIGTERM handlers that
/// trip the watchdog (robot stopped) and make ok() false. Throws RuntimeError when the master
/// cannot be reached within `wait_master_s` (wall).
void init(const std::string& name, const std::vector<std::string>& args, double wait_master_s);
/// False after a signal, ros::shutdown() or a lost master.
bool ok();
/// The signal that ended the node ("SIGINT", "SIGTERM") or "".
std::string signalReceived();
/// Sends what is queued and leaves the master. Idempotent.
void shutdown();

/// The node's private parameters (~) as settings: ~nav/v_cruise -> "nav.v_cruise". Keys are
/// whatever is on the parameter server; the caller checks them (strict, like --set).
Config privateParams();

/// Starts the watchdog with these limits (once; later calls update the limits).
void startWatchdog(const RosParams& p);
/// The latched fault ("" while healthy), e.g. "odometry on /odom: no usable message for 0.52 s".
std::string fault();
/// Publishes one zero Twist on the ros:// base's cmd_vel (no-op before the base exists): what
/// the navigation sends when its route starts, so `ros sim` (holding time at 0) starts too.
void sendZeroCommand();
/// Trips the watchdog by hand (zero Twist now, every later command zero).
void trip(const std::string& reason);
/// Clears a latched fault (a new goal after a safety stop): commands pass again. A cause
/// still present (master gone, an input stale) trips it again at the next watchdog check.
void resetFault();
/// Holds the robot stopped for a cancelled or preempted goal: a zero Twist now, from the
/// caller's thread (a route server callback), whatever the control loop is doing — a
/// perception pass can take a second on a slow machine, and the loop reads the cancel only
/// between ticks — and every later command of the route zero. Not a fault: fault() and the
/// diagnostics stay as they are. release() (a new goal) ends it.
void hold(const std::string& why);
void release();

/// The ROS clock (simulated when /use_sim_time is set): now() = ros::Time::now();
/// sleepUntil() returns early once the watchdog has tripped, so a frozen /clock cannot hang
/// the executive.
std::shared_ptr<hw::Clock> clock();
/// From now on the clock's sleepUntil() also returns as soon as the ros:// camera delivers a
/// frame stamped at least `min_gap_s` after the last frame grabbed (the executive grabs one
/// when nav.camera_period_s - tick_s / 2 has passed): the control loop runs that frame at
/// once. A negative gap turns it off (frames wait for the next tick).
void wakeOnFrames(double min_gap_s);
/// Waits (wall) until ROS time is valid (a first /clock under use_sim_time). False on timeout.
bool waitForTime(double timeout_s);

/// Image-to-command latency (doc/ros.md "Latency"). The perception tap calls this with the
/// seq of each frame it examined; the ros:// base's next command closes the measurement.
void noteObservation(std::uint64_t frame_seq);
/// The measurements so far: frames, and mean / p95 [ms] of transport (image stamp -> the
/// node's callback; null under simulated time, where stamps are not wall time), convert
/// (the callback's checks and cv_bridge copy), wait (converted -> the executive's grab),
/// grab_to_cmd (the in-process path: grab -> the command sent), total (stamp, or callback
/// under simulated time, -> command) and ros_overhead (total - grab_to_cmd); frame_wakes:
/// how many times a frame woke the control loop early (wakeOnFrames()).
Json latencySummary();

/// Registers the ros:// camera, base and range drivers with hw::Registry. Idempotent.
void registerDrivers();

/// Looks up tf base_frame -> camera_frame (waiting up to timeout_s wall) as the camera mount
/// (the optical axis's pan and tilt, the optical centre ahead of and above the base frame's
/// origin; a sideways offset is not part of the mount). False when absent.
bool lookupCameraMount(const std::string& base_frame, const std::string& camera_frame,
                       double timeout_s, sketchnav::CameraMount& out);
/// The frame_id of the next image on `topic` (waiting up to timeout_s wall); "" on timeout.
/// `transport` "compressed" reads sensor_msgs/CompressedImage on `topic`/compressed.
std::string imageFrame(const std::string& topic, double timeout_s,
                       const std::string& transport = "raw");

/// A std_msgs/String topic carrying one JSON object per message (state, events, result).
class JsonPublisher {
 public:
  JsonPublisher(const std::string& topic, bool latch, int queue = 50);
  ~JsonPublisher();
  void publish(const Json& j);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace sketchnav::ros
