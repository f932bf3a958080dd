// `sketchnav ros sim`: the simulator's devices stepped on simulated time and published
// (sim_bridge.h).
#include <cv_bridge/cv_bridge.h>
#include <geometry_msgs/TransformStamped.h>
#include <geometry_msgs/Twist.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/Range.h>
#include <std_msgs/Float64MultiArray.h>
#include <std_msgs/String.h>
#include <tf2/LinearMath/Quaternion.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>
#include <Eigen/Geometry>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <mutex>
#include <opencv2/imgcodecs.hpp>
#include <thread>

#include "internal.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/log.h"
#include "sketchnav/ros/sim_bridge.h"
#include "sketchnav/sim/register.h"
#include "sketchnav/sim/simulator.h"

namespace sketchnav::ros {
namespace {
namespace fs = std::filesystem;

geometry_msgs::Quaternion yawQuat(double yaw) {
  tf2::Quaternion q;
  q.setRPY(0, 0, yaw);
  geometry_msgs::Quaternion g;
  g.x = q.x(), g.y = q.y(), g.z = q.z(), g.w = q.w();
  return g;
}

geometry_msgs::TransformStamped transform(const std::string& parent, const std::string& child,
                                          double x, double y, double z, const Eigen::Quaterniond& q,
                                          ::ros::Time t) {
  geometry_msgs::TransformStamped m;
  m.header.stamp = t;
  m.header.frame_id = parent;
  m.child_frame_id = child;
  m.transform.translation.x = x;
  m.transform.translation.y = y;
  m.transform.translation.z = z;
  m.transform.rotation.x = q.x();
  m.transform.rotation.y = q.y();
  m.transform.rotation.z = q.z();
  m.transform.rotation.w = q.w();
  return m;
}

// ROS time = simulated time + 1 s: ROS takes time 0 for "not set" (a node under
// use_sim_time waits for a non-zero /clock), and the simulation starts at 0.
constexpr double kRosEpoch = 1.0;
::ros::Time rosTime(double sim_t) {
  return ::ros::Time(sim_t + kRosEpoch);
}

Eigen::Quaterniond yawQ(double yaw) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
}

}  // namespace

Json runSimBridge(const SimBridgeOptions& o, const std::function<bool()>& stop) {
  ::ros::NodeHandle& nh = detail::nodeHandle();
  if (o.rate < 0) throw InputError("--rate must be >= 0 (0 = as fast as possible)");
  if (!(o.step_s > 0 && o.step_s <= 0.1)) throw InputError("--step must be in (0, 0.1] s");
  sim::registerDrivers();
  hw::DeviceContext ctx;
  ctx.config = o.config;
  std::string uri;
  const bool path = o.world.find('/') != std::string::npos ||
                    (o.world.size() > 5 && o.world.substr(o.world.size() - 5) == ".json");
  if (path) {
    if (!fs::exists(o.world)) throw InputError("--world " + o.world + ": no such file");
    uri = "sim://" + fs::absolute(o.world).string();
  } else {
    uri = "sim://" + o.world;
  }
  auto simr = sim::simulatorFor(uri + "?seed=" + std::to_string(o.seed), ctx);
  o.config.requireAllUsed();
  const sim::World& w = simr->world();
  auto clk = simr->clock();

  // /use_sim_time before anything is published: nodes started after this run on /clock.
  ::ros::param::set("/use_sim_time", true);
  auto pub_clock = nh.advertise<rosgraph_msgs::Clock>("/clock", 10);
  auto pub_img = nh.advertise<sensor_msgs::Image>("image_raw", 2);
  // image_transport's compressed topic (jpeg, compressed_image_transport's format string),
  // encoded only while something subscribes to it.
  auto pub_jpeg = nh.advertise<sensor_msgs::CompressedImage>("image_raw/compressed", 2);
  auto pub_info = nh.advertise<sensor_msgs::CameraInfo>("camera_info", 2);
  auto pub_odom = nh.advertise<nav_msgs::Odometry>("odom", 20);
  auto pub_truth = nh.advertise<nav_msgs::Odometry>("ground_truth", 20);
  auto pub_scan = nh.advertise<sensor_msgs::LaserScan>("scan", 5);
  auto pub_sonar = nh.advertise<sensor_msgs::Range>("sonar", 50);
  ::ros::NodeHandle pnh("~");
  auto pub_state = pnh.advertise<std_msgs::String>("state", 5, true);
  tf2_ros::TransformBroadcaster tfb;
  tf2_ros::StaticTransformBroadcaster stfb;

  std::mutex cmd_m;
  double cmd_v = 0, cmd_w = 0, cmd_t = -1e300;
  std::uint64_t cmds = 0;
  boost::function<void(const geometry_msgs::TwistConstPtr&)> on_cmd =
      [&](const geometry_msgs::TwistConstPtr& m) {
        std::lock_guard<std::mutex> l(cmd_m);
        const bool finite = std::isfinite(m->linear.x) && std::isfinite(m->angular.z);
        cmd_v = finite ? m->linear.x : 0.0;
        cmd_w = finite ? m->angular.z : 0.0;
        cmd_t = clk->now();
        ++cmds;
      };
  auto sub_cmd = nh.subscribe<geometry_msgs::Twist>("cmd_vel", 10, on_cmd);
  // Lock-step (SimBridgeOptions::lockstep): the node's answers, [until (ROS time), v, w].
  double ack_until = -1e300, ack_v = 0, ack_w = 0;  // guarded by cmd_m
  std::uint64_t acks = 0;
  ::ros::Publisher pub_step;
  ::ros::Subscriber sub_ack;
  if (o.lockstep) {
    // Latched: a node that subscribes late still learns the step it must reach.
    pub_step = nh.advertise<std_msgs::Float64MultiArray>("lockstep/step", 10, true);
    boost::function<void(const std_msgs::Float64MultiArrayConstPtr&)> on_ack =
        [&](const std_msgs::Float64MultiArrayConstPtr& m) {
          if (m->data.size() < 3 || !std::isfinite(m->data[0]) || !std::isfinite(m->data[1]) ||
              !std::isfinite(m->data[2])) {
            log::warn("ros-sim", "lockstep/ack: ignored (expected 3 finite values: until, v, w)");
            return;
          }
          std::lock_guard<std::mutex> l(cmd_m);
          ack_until = std::max(ack_until, m->data[0] - kRosEpoch);
          ack_v = m->data[1];
          ack_w = m->data[2];
          ++acks;
        };
    sub_ack = nh.subscribe<std_msgs::Float64MultiArray>("lockstep/ack", 10, on_ack);
  }

  // Static frames: the camera's optical frame, the laser, one frame per sonar transducer.
  const ::ros::Time t0 = rosTime(0.0);
  std::vector<geometry_msgs::TransformStamped> statics;
  {
    const Eigen::Isometry3d rMc = w.camera.rMc();
    const Eigen::Vector3d p = rMc.translation();
    statics.push_back(transform("base_link", "camera_optical", p.x(), p.y(), p.z(),
                                Eigen::Quaterniond(rMc.linear()), t0));
  }
  if (w.laser.enabled)
    statics.push_back(
        transform("base_link", "laser", w.laser.x, w.laser.y, w.laser.z, yawQ(w.laser.yaw), t0));
  if (w.sonar.enabled)
    for (size_t i = 0; i < w.sonar.beams.size(); ++i) {
      const auto& b = w.sonar.beams[i];
      statics.push_back(transform("base_link", "sonar_" + std::to_string(i), b.x, b.y, w.sonar.z,
                                  yawQ(b.yaw), t0));
    }
  stfb.sendTransform(statics);

  auto clockAt = [&](double t) {
    rosgraph_msgs::Clock c;
    c.clock = rosTime(t);
    pub_clock.publish(c);
  };
  clockAt(clk->now());

  const hw::Intrinsics K = simr->camera().intrinsics();
  const double cam_period = simr->params().camera_hz > 0 ? 1.0 / simr->params().camera_hz : 0;
  double last_frame_t = -1e300, last_laser = -1e300, last_sonar = -1e300;
  std::uint64_t frames = 0, scans = 0, steps = 0;
  auto publishState = [&](double t) {
    const auto tp = simr->truePose();
    Json s = {
        {"t", t},
        {"collided", simr->collided()},
        {"collision_with", simr->collisionWith()},
        {"at_goal", simr->atGoal()},
        {"distance_to_goal_m", std::hypot(tp.x - w.goal.centre.x(), tp.y - w.goal.centre.y())},
        {"min_clearance_m", simr->minClearance()},
        {"path_length_m", simr->stats().distance},
        {"true_pose", {tp.x, tp.y, tp.theta}},
        {"frames_published", frames},
        {"commands_received", cmds}};
    std_msgs::String m;
    m.data = s.dump();
    pub_state.publish(m);
    return s;
  };
  // The last message of each stream, re-sent while time is held at 0.
  nav_msgs::Odometry odom_msg, truth_msg;
  sensor_msgs::LaserScan scan_msg;
  std::vector<sensor_msgs::Range> sonar_msgs;
  sensor_msgs::ImagePtr img_msg;
  sensor_msgs::CompressedImagePtr jpeg_msg;
  sensor_msgs::CameraInfo info_msg;

  bool collision_logged = false;
  // [s, ROS time] stamps of the last odometry, scan, sonar ring and frame published (-1: none):
  // what a lock-step node must have received before its time may move to a step.
  double sent_odom = -1, sent_scan = -1, sent_sonar = -1, sent_frame = -1;
  auto publishLockstep = [&](double t) {
    if (!o.lockstep) return;
    std_msgs::Float64MultiArray m;
    m.data = {t + kRosEpoch, sent_odom, sent_scan, sent_sonar, sent_frame};
    pub_step.publish(m);
  };
  // Reads every device at the clock's time t and publishes what is new.
  auto publishStep = [&](double t) {
    const ::ros::Time rt = rosTime(t);
    clockAt(t);
    // A collision stops the simulated base for good (its ok() turns false in-process); as a
    // ROS robot its odometry stops, which the navigation takes for a lost base.
    if (simr->collided() && !collision_logged) {
      collision_logged = true;
      log::error("ros-sim", "collision with " + simr->collisionWith() +
                                ": the base has stopped; odometry and tf odom -> base_link are "
                                "no longer published");
    }
    hw::Odometry od;
    if (!simr->collided() && simr->base().odometry(od)) {
      nav_msgs::Odometry& m = odom_msg;
      m.header.stamp = rt;
      m.header.frame_id = "odom";
      m.child_frame_id = "base_link";
      m.pose.pose.position.x = od.pose.x;
      m.pose.pose.position.y = od.pose.y;
      m.pose.pose.orientation = yawQuat(od.pose.theta);
      m.twist.twist.linear.x = od.v;
      m.twist.twist.angular.z = od.w;
      pub_odom.publish(m);
      sent_odom = rt.toSec();
      tfb.sendTransform(
          transform("odom", "base_link", od.pose.x, od.pose.y, 0, yawQ(od.pose.theta), rt));
    }
    {
      const auto tp = simr->truePose();
      nav_msgs::Odometry& m = truth_msg;
      m.header.stamp = rt;
      m.header.frame_id = "map";
      m.child_frame_id = "base_link_truth";
      m.pose.pose.position.x = tp.x;
      m.pose.pose.position.y = tp.y;
      m.pose.pose.orientation = yawQuat(tp.theta);
      pub_truth.publish(m);
    }
    // Scans: the sensors' latest, published when new.
    hw::RangeScan sc;
    if (w.laser.enabled && simr->laser().read(sc) && sc.stamp > last_laser && !sc.angles.empty()) {
      last_laser = sc.stamp;
      sensor_msgs::LaserScan& m = scan_msg;
      m.header.stamp = rosTime(sc.stamp);
      m.header.frame_id = "laser";
      m.angle_min = sc.angles.front();
      m.angle_max = sc.angles.back();
      m.angle_increment = sc.angles.size() > 1
                              ? (sc.angles.back() - sc.angles.front()) / (sc.angles.size() - 1)
                              : 0;
      m.scan_time = w.laser.rate_hz > 0 ? 1.0 / w.laser.rate_hz : 0;
      m.range_min = sc.min_range;
      m.range_max = sc.max_range;
      m.ranges.resize(sc.ranges.size());
      for (size_t i = 0; i < sc.ranges.size(); ++i)
        m.ranges[i] =
            sc.ranges[i] >= sc.max_range ? std::numeric_limits<float>::infinity() : sc.ranges[i];
      pub_scan.publish(m);
      sent_scan = m.header.stamp.toSec();
      ++scans;
    }
    if (w.sonar.enabled && simr->sonar().read(sc) && sc.stamp > last_sonar) {
      last_sonar = sc.stamp;
      sonar_msgs.clear();
      for (size_t i = 0; i < sc.ranges.size() && i < w.sonar.beams.size(); ++i) {
        const auto& b = w.sonar.beams[i];
        // The scan reports ranges from the robot's centre; a transducer's from itself.
        const double off = b.x * std::cos(b.yaw) + b.y * std::sin(b.yaw);
        sensor_msgs::Range m;
        m.header.stamp = rosTime(sc.stamp);
        m.header.frame_id = "sonar_" + std::to_string(i);
        m.radiation_type = sensor_msgs::Range::ULTRASOUND;
        m.field_of_view = sc.beam_width;
        m.min_range = sc.min_range;
        m.max_range = sc.max_range;
        m.range = sc.ranges[i] >= sc.max_range ? std::numeric_limits<float>::infinity()
                                               : static_cast<float>(sc.ranges[i] - off);
        pub_sonar.publish(m);
        sonar_msgs.push_back(m);
        sent_sonar = m.header.stamp.toSec();
      }
    }
    // Camera: a frame whenever a frame period has begun (grab() would otherwise wait for one,
    // i.e. advance the clock).
    if (t + 1e-9 >= last_frame_t + cam_period) {
      hw::Frame f;
      if (simr->camera().grab(f, 0.0) == hw::GrabStatus::Ok && !f.image.empty()) {
        last_frame_t = f.stamp;
        std_msgs::Header h;
        h.stamp = rosTime(f.stamp);
        h.frame_id = "camera_optical";
        h.seq = static_cast<std::uint32_t>(f.seq);
        img_msg = cv_bridge::CvImage(h, "bgr8", f.image).toImageMsg();
        pub_img.publish(img_msg);
        jpeg_msg.reset();
        if (pub_jpeg.getNumSubscribers() > 0) {
          auto c = boost::make_shared<sensor_msgs::CompressedImage>();
          c->header = h;
          c->format = "bgr8; jpeg compressed bgr8";
          cv::imencode(".jpg", f.image, c->data, {cv::IMWRITE_JPEG_QUALITY, 90});
          jpeg_msg = c;
          pub_jpeg.publish(jpeg_msg);
        }
        sensor_msgs::CameraInfo& ci = info_msg;
        ci.header = h;
        ci.width = K.width;
        ci.height = K.height;
        ci.distortion_model = "plumb_bob";
        ci.D = {0, 0, 0, 0, 0};
        ci.K = {K.fx, 0, K.cx, 0, K.fy, K.cy, 0, 0, 1};
        ci.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
        ci.P = {K.fx, 0, K.cx, 0, 0, K.fy, K.cy, 0, 0, 0, 1, 0};
        pub_info.publish(ci);
        sent_frame = h.stamp.toSec();
        ++frames;
      }
    }
  };

  log::info("ros-sim", "running", {{"world", w.name}, {"seed", std::to_string(o.seed)}});
  publishStep(clk->now());
  publishLockstep(clk->now());
  if (o.hold_until_cmd || o.lockstep) {
    // Time held at 0 until the navigation's first command (lock-step: its first answer): it
    // starts on the same simulated instant as an in-process `sketchnav run`, however long it
    // took to load its model. The t = 0 data is sent again meanwhile, for a node that joins.
    log::info("ros-sim", o.lockstep ? "lock-step: simulated time moves when the navigation answers"
                                    : "simulated time held at 0 until the first cmd_vel");
    while (ok() && !(stop && stop())) {
      {
        std::lock_guard<std::mutex> l(cmd_m);
        if (o.lockstep ? acks > 0 : cmds > 0) break;
      }
      clockAt(clk->now());
      pub_odom.publish(odom_msg);
      {  // odom -> base_link again too: a node taking odometry from tf may join late
        const auto& p = odom_msg.pose.pose;
        geometry_msgs::TransformStamped t;
        t.header = odom_msg.header;
        t.child_frame_id = odom_msg.child_frame_id;
        t.transform.translation.x = p.position.x;
        t.transform.translation.y = p.position.y;
        t.transform.rotation = p.orientation;
        if (!t.header.frame_id.empty()) tfb.sendTransform(t);
      }
      pub_truth.publish(truth_msg);
      if (!scan_msg.ranges.empty()) pub_scan.publish(scan_msg);
      for (const auto& m : sonar_msgs) pub_sonar.publish(m);
      if (img_msg) {
        pub_img.publish(img_msg);
        if (!jpeg_msg && pub_jpeg.getNumSubscribers() > 0) {  // a subscriber that joined late
          auto c = boost::make_shared<sensor_msgs::CompressedImage>();
          c->header = img_msg->header;
          c->format = "bgr8; jpeg compressed bgr8";
          cv::imencode(".jpg", cv_bridge::toCvShare(img_msg)->image, c->data,
                       {cv::IMWRITE_JPEG_QUALITY, 90});
          jpeg_msg = c;
        }
        if (jpeg_msg) pub_jpeg.publish(jpeg_msg);
        pub_info.publish(info_msg);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  }
  const auto wall0 = std::chrono::steady_clock::now();
  const double sim0 = clk->now();
  double next_state = 0;
  Json last;
  std::uint64_t lockstep_waits = 0;
  double lockstep_wait_s = 0;  // [s, wall] spent waiting for the navigation
  while (ok() && !(stop && stop())) {
    double t = clk->now();
    if (o.max_time_s > 0 && t >= o.max_time_s) break;
    double next = t + o.step_s;
    if (o.lockstep) {
      // The node is done with time t once it waits for a later time: until then, no step.
      const double w0 = detail::wallNow();
      bool told = false;
      for (;;) {
        {
          std::lock_guard<std::mutex> l(cmd_m);
          if (ack_until > t + 1e-9) {
            simr->base().command(ack_v, ack_w);
            // Exactly to the node's wake-up time when it falls within the step, so it sees
            // the data of that instant (as `sketchnav run` and a replay do).
            next = std::min(next, ack_until);
            break;
          }
        }
        if (!ok() || (stop && stop())) break;
        if (!told && detail::wallNow() - w0 > 5.0) {
          told = true;
          log::warn("ros-sim", "lock-step: no answer from the navigation for 5 s; still waiting",
                    {{"t", std::to_string(t)}});
        }
        std::this_thread::sleep_for(std::chrono::microseconds(200));
      }
      if (!ok() || (stop && stop())) break;
      ++lockstep_waits;
      lockstep_wait_s += detail::wallNow() - w0;
    } else {
      // The latest command holds until it is cmd_timeout_s old (a base's watchdog).
      std::lock_guard<std::mutex> l(cmd_m);
      if (t - cmd_t > o.cmd_timeout_s)
        simr->base().command(0, 0);
      else
        simr->base().command(cmd_v, cmd_w);
    }
    t = next;
    clk->sleepUntil(t);
    simr->sync();
    ++steps;
    publishStep(t);
    publishLockstep(t);
    if (t >= next_state) {
      last = publishState(t);
      next_state = t + 0.5;
    }
    // Pace: `rate` simulated seconds per wall second (0 = no waiting).
    if (o.rate > 0) {
      const auto due = wall0 + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                   std::chrono::duration<double>((t - sim0) / o.rate));
      std::this_thread::sleep_until(due);
    }
  }
  simr->base().command(0, 0);
  last = publishState(clk->now());
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  last["wall_time_s"] = wall;
  last["real_time_factor"] = wall > 0 ? (clk->now() - sim0) / wall : 0.0;
  last["scans_published"] = scans;
  if (o.lockstep) last["lockstep"] = {{"steps", lockstep_waits}, {"wait_wall_s", lockstep_wait_s}};
  last["world"] = w.name;
  last["seed"] = o.seed;
  return last;
}

}  // namespace sketchnav::ros
