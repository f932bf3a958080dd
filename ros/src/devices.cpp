// The ros:// devices: hw::Camera, hw::Base and hw::RangeSensor on ROS topics (node.h).
#include <cv_bridge/cv_bridge.h>
#include <geometry_msgs/Twist.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/Range.h>
#include <tf2/LinearMath/Matrix3x3.h>
#include <tf2/LinearMath/Quaternion.h>
#include <tf2_msgs/TFMessage.h>

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <initializer_list>
#include <limits>
#include <map>
#include <opencv2/imgcodecs.hpp>

#include "internal.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/log.h"
#include "sketchnav/hw/registry.h"

namespace sketchnav::ros {
namespace {
using detail::Input;
using detail::InputKind;
using detail::State;
using detail::state;
using detail::wallNow;

double stampOf(const ::ros::Time& t) {
  return t.isZero() ? ::ros::Time::now().toSec() : t.toSec();
}

// [s] message stamp -> callback, for a raw or compressed camera frame alike; -1 when unknown
// (no stamp, or stamps in simulated time, which say nothing about the transport).
double transportDelay(const ::ros::Time& stamp) {
  return !::ros::Time::isSimTime() && !stamp.isZero() ? (::ros::Time::now() - stamp).toSec() : -1;
}

// Why a pose from a message cannot be used, the one rule for nav_msgs/Odometry and a tf
// odom -> base transform: a NaN or Inf in its position, its orientation quaternion or the
// values that came with it (`extra`, e.g. the twist), or a zero quaternion (no orientation).
enum class PoseFault { None, NotFinite, ZeroQuaternion };

// PoseFault::None and `yaw` [rad] from the normalised quaternion when the pose is usable.
template <class Point, class Quaternion>
PoseFault poseFault(const Point& p, const Quaternion& q, std::initializer_list<double> extra,
                    double& yaw) {
  bool finite = std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(q.x) &&
                std::isfinite(q.y) && std::isfinite(q.z) && std::isfinite(q.w);
  for (double v : extra) finite = finite && std::isfinite(v);
  if (!finite) return PoseFault::NotFinite;
  const double qn = std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  if (qn < 1e-6) return PoseFault::ZeroQuaternion;
  double roll, pitch;
  tf2::Matrix3x3(tf2::Quaternion(q.x / qn, q.y / qn, q.z / qn, q.w / qn)).getRPY(roll, pitch, yaw);
  return PoseFault::None;
}

// Fills in what the watchdog needs once the subscription exists (before addInput()).
void describe(Input& in, InputKind kind, const std::string& what, const ::ros::Subscriber& sub) {
  in.kind = kind;
  in.what = what;
  in.topic = sub.getTopic();
  ::ros::Subscriber copy = sub;
  in.publishers = [copy]() { return copy.getNumPublishers(); };
}

// Waits (wall) for `have()` up to ros.wait_s; RuntimeError naming the topic otherwise.
template <class F>
void waitFirst(F have, const std::string& what, const std::string& topic) {
  const double limit = state().params.wait_s, t0 = wallNow();
  while (!have()) {
    if (!ok()) throw RuntimeError("interrupted while waiting for " + what + " on " + topic);
    if (state().tripped) throw RuntimeError(what + " on " + topic + ": " + fault());
    if (wallNow() - t0 > limit) {
      char b[64];
      std::snprintf(b, sizeof b, "%.0f", limit);
      throw RuntimeError("no " + what + " message on " + topic + " within " + b +
                         " s (ros.wait_s): is the robot or `sketchnav ros sim` running?");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

// ---------------------------------------------------------------------------------------
class RosCamera final : public hw::Camera {
 public:
  // transport "raw": sensor_msgs/Image on `topic`; "compressed": sensor_msgs/CompressedImage
  // on `topic`/compressed, image_transport's layout (its compressed plugin is not packaged in
  // Debian bookworm, so the frames are decoded here with OpenCV).
  RosCamera(const std::string& topic, const std::string& info_topic, const std::string& transport) {
    auto& nh = detail::nodeHandle();
    {
      std::lock_guard<std::mutex> l(state().latency_mutex);
      state().latency.frames.clear();  // seqs start again with this camera
      state().latency.pending = false;
    }
    state().frame_wakes = 0;
    if (transport == "compressed")
      sub_ = nh.subscribe(topic + "/compressed", 2, &RosCamera::onCompressed, this);
    else
      sub_ = nh.subscribe(topic, 2, &RosCamera::onImage, this);
    if (!info_topic.empty()) info_sub_ = nh.subscribe(info_topic, 2, &RosCamera::onInfo, this);
    describe(*in_, InputKind::Camera, "camera", sub_);
    uri_ = "ros://camera?topic=" + sub_.getTopic();
    waitFirst(
        [this] {
          std::lock_guard<std::mutex> l(m_);
          return seq_ > 0;
        },
        "camera image", sub_.getTopic());
    detail::addInput(in_);
    // camera_info normally comes with the first frames; without it the intrinsics are guessed.
    const double t0 = wallNow();
    while (!info_topic.empty() && wallNow() - t0 < 1.0) {
      {
        std::lock_guard<std::mutex> l(m_);
        if (have_info_) break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    std::lock_guard<std::mutex> l(m_);
    if (!have_info_) {
      intr_ = hw::Intrinsics::fromFov(latest_.cols, latest_.rows, 60.0 * M_PI / 180.0);
      log::warn("ros", "no camera_info: intrinsics assumed from a 60 deg field of view",
                {{"topic", info_topic}});
    }
  }

  ~RosCamera() override {
    // Ends the subscriptions (waiting for a running callback) before the members go.
    detail::removeInput(in_);  // first: a closed subscription has no publisher
    sub_.shutdown();
    info_sub_.shutdown();
  }

  hw::GrabStatus grab(hw::Frame& frame, double timeout_s) override {
    std::unique_lock<std::mutex> l(m_);
    const bool got = cv_.wait_for(l, std::chrono::duration<double>(std::max(0.0, timeout_s)),
                                  [this] { return seq_ > delivered_; });
    if (!got) return hw::GrabStatus::Timeout;
    delivered_ = seq_;
    delivered_stamp_ = stamp_;
    {
      std::lock_guard<std::mutex> ll(state().latency_mutex);
      auto it = state().latency.frames.find(seq_);
      if (it != state().latency.frames.end()) it->second.grab = wallNow();
    }
    frame.image = latest_;  // a new Mat per message: no copy needed
    frame.stamp = stamp_;
    frame.seq = seq_;
    frame.source = sub_.getTopic();
    return hw::GrabStatus::Ok;
  }
  hw::Intrinsics intrinsics() const override {
    std::lock_guard<std::mutex> l(m_);
    return intr_;
  }
  hw::DeviceStats stats() const override {
    std::lock_guard<std::mutex> l(m_);
    return st_;
  }
  std::string uri() const override { return uri_; }

 private:
  void bad(const std::string& why) {
    {
      std::lock_guard<std::mutex> l(m_);
      ++st_.dropped;
      st_.last_error = why;
    }
    detail::garbage("camera on " + sub_.getTopic() + ": " + why);
  }
  void onImage(const sensor_msgs::ImageConstPtr& m) {
    const double recv = wallNow();
    in_->wall_last = recv;
    // Stamp -> callback, when stamps are wall time (not under simulated time).
    const double transport = transportDelay(m->header.stamp);
    if (m->width == 0 || m->height == 0 || m->data.empty()) {
      bad("empty image (" + std::to_string(m->width) + "x" + std::to_string(m->height) + ", " +
          std::to_string(m->data.size()) + " bytes)");
      return;
    }
    if (m->data.size() < static_cast<size_t>(m->step) * m->height) {
      bad("image data too short: " + std::to_string(m->data.size()) + " bytes for " +
          std::to_string(m->height) + " rows of " + std::to_string(m->step));
      return;
    }
    cv::Mat img;
    try {
      img = cv_bridge::toCvCopy(m, "bgr8")->image;
    } catch (const std::exception& e) {
      bad("encoding '" + m->encoding + "' is not a colour or grey image (" + e.what() + ")");
      return;
    }
    deliver(img, m->header.stamp, recv, transport);
  }
  void onCompressed(const sensor_msgs::CompressedImageConstPtr& m) {
    const double recv = wallNow();
    in_->wall_last = recv;
    const double transport = transportDelay(m->header.stamp);
    if (m->data.empty()) {
      bad("empty compressed image (format '" + m->format + "', 0 bytes)");
      return;
    }
    // compressedDepth (16-bit depth in a PNG behind a header) is no camera image.
    if (m->format.find("compressedDepth") != std::string::npos) {
      bad("compressed format '" + m->format + "' is a depth image, not a colour or grey image");
      return;
    }
    cv::Mat img;
    try {
      img = cv::imdecode(m->data, cv::IMREAD_COLOR);  // jpeg / png, grey -> bgr
    } catch (const std::exception&) {
      img.release();
    }
    if (img.empty()) {
      bad("compressed image (format '" + m->format + "', " + std::to_string(m->data.size()) +
          " bytes) does not decode");
      return;
    }
    deliver(img, m->header.stamp, recv, transport);
  }
  // A checked, converted frame: the latest, for grab(); wakes the control loop when it is due.
  void deliver(const cv::Mat& img, const ::ros::Time& stamp, double recv, double transport) {
    bool due = false;
    {
      std::lock_guard<std::mutex> l(m_);
      // A frame stamped like the one before is that frame sent again (a simulator holding its
      // time while a node starts), not a new one: grab() must not hand it out twice.
      if (seq_ > 0 && !stamp.isZero() && stampOf(stamp) == stamp_) return;
      latest_ = img;
      stamp_ = stampOf(stamp);
      ++seq_;
      ++st_.received;
      in_->stamp_last = stamp_;
      due = stamp_ >= delivered_stamp_ + state().wake_gap_s;
      std::lock_guard<std::mutex> ll(state().latency_mutex);
      auto& fr = state().latency.frames;
      fr[seq_] = {recv, wallNow(), -1, transport};
      while (fr.size() > 50) fr.erase(fr.begin());
    }
    cv_.notify_all();
    if (due && state().wake_gap_s >= 0) {
      {
        std::lock_guard<std::mutex> l(state().wake_m);
        ++state().frames_due;
      }
      state().wake_cv.notify_all();
    }
  }
  void onInfo(const sensor_msgs::CameraInfoConstPtr& m) {
    if (m->width == 0 || m->height == 0 || !(m->K[0] > 0) || !(m->K[4] > 0)) return;
    std::lock_guard<std::mutex> l(m_);
    intr_.width = m->width;
    intr_.height = m->height;
    intr_.fx = m->K[0];
    intr_.fy = m->K[4];
    intr_.cx = m->K[2];
    intr_.cy = m->K[5];
    have_info_ = true;
  }

  mutable std::mutex m_;
  std::condition_variable cv_;
  ::ros::Subscriber sub_, info_sub_;
  std::shared_ptr<Input> in_ = std::make_shared<Input>();  // before the subscription
  std::string uri_;
  cv::Mat latest_;
  double stamp_ = 0;
  std::uint64_t seq_ = 0, delivered_ = 0;
  double delivered_stamp_ = -1e300;  // [s] the stamp of the last frame grab() handed out
  hw::Intrinsics intr_;
  bool have_info_ = false;
  hw::DeviceStats st_;
};

// ---------------------------------------------------------------------------------------
class RosBase final : public hw::Base {
 public:
  // odom_topic: nav_msgs/Odometry; or, with odom_topic empty, tf odom_frame -> base frame.
  RosBase(const std::string& cmd_topic, const std::string& odom_topic,
          const std::string& odom_frame) {
    auto& nh = detail::nodeHandle();
    pub_ = nh.advertise<geometry_msgs::Twist>(cmd_topic, 5);
    {
      std::lock_guard<std::mutex> l(state().mutex);
      state().cmd_vel = pub_;
      state().have_cmd_vel = true;
    }
    if (!odom_topic.empty()) {
      sub_ = nh.subscribe(odom_topic, 10, &RosBase::onOdom, this);
      describe(*in_, InputKind::Odometry, "odometry", sub_);
      uri_ = "ros://base?cmd_vel=" + pub_.getTopic() + "&odom=" + sub_.getTopic();
    } else {
      odom_frame_ = strip(odom_frame);
      base_frame_ = strip(state().params.base_frame);
      sub_ = nh.subscribe("/tf", 100, &RosBase::onTf, this);
      describe(*in_, InputKind::Odometry,
               "odometry (tf " + odom_frame_ + " -> " + base_frame_ + ")", sub_);
      uri_ = "ros://base?cmd_vel=" + pub_.getTopic() + "&tf=" + odom_frame_;
    }
    waitFirst(
        [this] {
          std::lock_guard<std::mutex> l(m_);
          return have_;
        },
        in_->what, sub_.getTopic());
    // Stamps on another clock than this node's make every input look stale (or fresh forever).
    double stamp;
    {
      std::lock_guard<std::mutex> l(m_);
      stamp = odom_.stamp;
    }
    const double now = ::ros::Time::now().toSec();
    if (std::abs(now - stamp) > 5.0) {
      char b[320];
      std::snprintf(b, sizeof b,
                    "odometry on %s is stamped %.1f s but this node's ROS time is %.1f s%s",
                    sub_.getTopic().c_str(), stamp, now,
                    ::ros::Time::isSimTime()
                        ? ""
                        : ": the robot runs on simulated time and this node does not (set "
                          "/use_sim_time before starting it, e.g. start `sketchnav ros sim` "
                          "first)");
      throw RuntimeError(b);
    }
    detail::addInput(in_);
  }
  ~RosBase() override {
    stop();
    detail::removeInput(in_);
    sub_.shutdown();
  }

  void command(double v, double w) override {
    std::unique_lock<std::mutex> lock(state().command_m);
    if (state().tripped || state().held || !std::isfinite(v) || !std::isfinite(w)) {
      lock.unlock();
      stop();
      return;
    }
    geometry_msgs::Twist t;
    t.linear.x = v;
    t.angular.z = w;
    pub_.publish(t);
    lock.unlock();
    state().last_v = v;
    state().last_w = w;
    closeLatency();
    std::lock_guard<std::mutex> l(m_);
    ++st_.received;
  }
  void stop() noexcept override {
    try {
      pub_.publish(geometry_msgs::Twist());
    } catch (...) {
    }
    state().last_v = 0.0;
    state().last_w = 0.0;
  }
  bool odometry(hw::Odometry& out) override {
    std::lock_guard<std::mutex> l(m_);
    if (!have_) return false;
    out = odom_;
    return true;
  }
  bool ok() const override { return !state().tripped; }

  // The first command after perception examined a frame: that frame's latency.
  static void closeLatency() {
    const double now = wallNow();
    std::lock_guard<std::mutex> l(state().latency_mutex);
    auto& L = state().latency;
    if (!L.pending) return;
    L.pending = false;
    const auto it = L.frames.find(L.pending_seq);
    if (it == L.frames.end() || it->second.grab < 0) return;
    const auto& f = it->second;
    L.convert.push_back(f.ready - f.recv);
    L.wait.push_back(f.grab - f.ready);
    L.grab_to_cmd.push_back(now - f.grab);
    if (f.transport >= 0) L.transport.push_back(f.transport);
    L.total.push_back(now - f.recv + std::max(0.0, f.transport));
  }
  hw::DeviceStats stats() const override {
    std::lock_guard<std::mutex> l(m_);
    return st_;
  }
  std::string uri() const override { return uri_; }

 private:
  void onOdom(const nav_msgs::OdometryConstPtr& m) {
    in_->wall_last = wallNow();
    const auto& p = m->pose.pose.position;
    double yaw = 0;
    const PoseFault fault = poseFault(p, m->pose.pose.orientation,
                                      {m->twist.twist.linear.x, m->twist.twist.angular.z}, yaw);
    if (fault != PoseFault::None) {
      const bool zero = fault == PoseFault::ZeroQuaternion;
      {
        std::lock_guard<std::mutex> l(m_);
        ++st_.dropped;
        st_.last_error = zero ? "zero quaternion" : "NaN or Inf in pose or twist";
      }
      detail::garbage("odometry on " + sub_.getTopic() + ": " +
                      (zero ? "orientation is a zero quaternion" : "NaN or Inf in pose or twist"));
      return;
    }
    std::lock_guard<std::mutex> l(m_);
    odom_.pose = {p.x, p.y, yaw};
    odom_.v = m->twist.twist.linear.x;
    odom_.w = m->twist.twist.angular.z;
    odom_.stamp = stampOf(m->header.stamp);
    have_ = true;
    in_->stamp_last = odom_.stamp;
  }

  static std::string strip(const std::string& f) {
    return !f.empty() && f[0] == '/' ? f.substr(1) : f;
  }

  // tf: the odom -> base transform of this message (direct), else through the tf buffer when
  // the message moves the odometry frame's tree (odom -> base_footprint -> base_link).
  void onTf(const tf2_msgs::TFMessageConstPtr& m) {
    const geometry_msgs::TransformStamped* direct = nullptr;
    bool touches = false;
    for (const auto& t : m->transforms) {
      const std::string parent = strip(t.header.frame_id), child = strip(t.child_frame_id);
      if (parent == odom_frame_ && child == base_frame_) direct = &t;
      if (parent == odom_frame_ || child == base_frame_) touches = true;
    }
    geometry_msgs::TransformStamped looked;
    if (!direct) {
      if (!touches || !state().tf) return;
      try {
        looked = state().tf->lookupTransform(odom_frame_, base_frame_, ::ros::Time(0));
      } catch (const std::exception&) {
        return;
      }
      direct = &looked;
    }
    const double stamp = stampOf(direct->header.stamp);
    {
      std::lock_guard<std::mutex> l(m_);
      if (have_ && stamp < odom_.stamp) return;  // an older transform (a late message)
    }
    in_->wall_last = wallNow();
    const auto& p = direct->transform.translation;
    double yaw = 0;
    const PoseFault fault = poseFault(p, direct->transform.rotation, {}, yaw);
    if (fault != PoseFault::None) {
      const bool zero = fault == PoseFault::ZeroQuaternion;
      {
        std::lock_guard<std::mutex> l(m_);
        ++st_.dropped;
        st_.last_error = zero ? "zero quaternion" : "NaN or Inf in the transform";
      }
      detail::garbage(in_->what + ": " +
                      (zero ? "rotation is a zero quaternion" : "NaN or Inf in the transform"));
      return;
    }
    std::lock_guard<std::mutex> l(m_);
    // Velocities by differencing (tf carries none), over at least 20 ms.
    if (have_ && stamp - vel_from_.stamp >= 0.02) {
      const double dt = stamp - vel_from_.stamp;
      const double dx = p.x - vel_from_.pose.x, dy = p.y - vel_from_.pose.y;
      odom_.v = (dx * std::cos(yaw) + dy * std::sin(yaw)) / dt;
      odom_.w = std::remainder(yaw - vel_from_.pose.theta, 2 * M_PI) / dt;
      vel_from_.pose = {p.x, p.y, yaw};
      vel_from_.stamp = stamp;
    } else if (!have_) {
      vel_from_.pose = {p.x, p.y, yaw};
      vel_from_.stamp = stamp;
    }
    odom_.pose = {p.x, p.y, yaw};
    odom_.stamp = stamp;
    in_->stamp_last = stamp;
    have_ = true;
    ++st_.received;
  }

  mutable std::mutex m_;
  std::string odom_frame_, base_frame_;
  hw::Odometry vel_from_;  // the tf pose velocities are differenced from
  ::ros::Publisher pub_;
  ::ros::Subscriber sub_;
  std::shared_ptr<Input> in_ = std::make_shared<Input>();  // before the subscription
  std::string uri_;
  hw::Odometry odom_;
  bool have_ = false;
  hw::DeviceStats st_;
};

// Sensor frame -> base frame (static for a scan's lifetime), looked up once per frame.
bool mountOf(const std::string& frame, double timeout_s, double& x, double& y, double& yaw) {
  State& s = state();
  const std::string base = s.params.base_frame;
  if (frame.empty() || frame == base) {
    x = y = yaw = 0;
    return true;
  }
  try {
    const auto t = s.tf->lookupTransform(base, frame, ::ros::Time(0), ::ros::Duration(timeout_s));
    x = t.transform.translation.x;
    y = t.transform.translation.y;
    const auto& q = t.transform.rotation;
    double r, p;
    tf2::Matrix3x3(tf2::Quaternion(q.x, q.y, q.z, q.w)).getRPY(r, p, yaw);
    // tf2 refuses NaN and denormalised rotations when they are published; a mount that is
    // still not finite here would put every beam nowhere: garbage, and a stop.
    if (!std::isfinite(x) || !std::isfinite(y) || !std::isfinite(yaw)) {
      detail::garbage("tf " + base + " -> " + frame + ": the sensor mount is not finite");
      return false;
    }
    return true;
  } catch (const std::exception&) {
    return false;
  }
}

// ---------------------------------------------------------------------------------------
class RosLaser final : public hw::RangeSensor {
 public:
  explicit RosLaser(const std::string& topic) {
    sub_ = detail::nodeHandle().subscribe(topic, 5, &RosLaser::onScan, this);
    describe(*in_, InputKind::Laser, "laser scan", sub_);
    uri_ = "ros://laser?topic=" + sub_.getTopic();
    waitFirst(
        [this] {
          std::lock_guard<std::mutex> l(m_);
          return have_;
        },
        "laser scan", sub_.getTopic());
    detail::addInput(in_);
  }
  ~RosLaser() override {
    detail::removeInput(in_);
    sub_.shutdown();
  }
  bool read(hw::RangeScan& out) override {
    std::lock_guard<std::mutex> l(m_);
    if (!have_) return false;
    out = scan_;
    return true;
  }
  hw::DeviceStats stats() const override {
    std::lock_guard<std::mutex> l(m_);
    return st_;
  }
  std::string uri() const override { return uri_; }

 private:
  void onScan(const sensor_msgs::LaserScanConstPtr& m) {
    // Fresh for the watchdog only once usable: a scan skipped for want of its mount keeps
    // nothing fresh (it goes stale, and the robot stops, within ros.stale_timeout_s).
    const double recv = wallNow();
    const double span = m->angle_max - m->angle_min;
    std::string why;
    if (!std::isfinite(m->angle_min) || !std::isfinite(m->angle_increment) ||
        m->angle_increment == 0 || !std::isfinite(span))
      why = "bad angles (angle_increment " + std::to_string(m->angle_increment) + ")";
    else if (!(m->range_max > 0) || !std::isfinite(m->range_max))
      why = "bad range_max " + std::to_string(m->range_max);
    else {
      const long n = std::lround(span / m->angle_increment) + 1;
      if (n != static_cast<long>(m->ranges.size()) || m->ranges.empty())
        why = "angles " + std::to_string(m->angle_min) + ".." + std::to_string(m->angle_max) +
              " step " + std::to_string(m->angle_increment) + " make " + std::to_string(n) +
              " beams but the scan has " + std::to_string(m->ranges.size()) + " ranges";
    }
    if (!why.empty()) {
      {
        std::lock_guard<std::mutex> l(m_);
        ++st_.dropped;
        st_.last_error = why;
      }
      detail::garbage("laser scan on " + sub_.getTopic() + ": " + why);
      return;
    }
    if (m->header.frame_id != frame_) {
      double x, y, yaw;
      if (!mountOf(m->header.frame_id, 0.2, x, y, yaw)) {
        log::warn("ros", "no tf for the laser frame yet: scan skipped",
                  {{"frame", m->header.frame_id}});
        return;
      }
      frame_ = m->header.frame_id;
      mount_ = {x, y, yaw};
    }
    in_->wall_last = recv;
    hw::RangeScan s;
    s.kind = hw::RangeScan::Kind::Laser;
    s.min_range = m->range_min;
    s.max_range = m->range_max;
    s.mount = mount_;
    s.stamp = stampOf(m->header.stamp);
    s.angles.resize(m->ranges.size());
    s.ranges.resize(m->ranges.size());
    for (size_t i = 0; i < m->ranges.size(); ++i) {
      s.angles[i] = static_cast<float>(m->angle_min + i * m->angle_increment);
      const float r = m->ranges[i];
      // REP 117: +Inf = nothing in range, -Inf = too close, NaN = no measurement.
      s.ranges[i] = std::isnan(r) || r == std::numeric_limits<float>::infinity() || r > m->range_max
                        ? m->range_max
                    : r < m->range_min ? m->range_min
                                       : r;
    }
    std::lock_guard<std::mutex> l(m_);
    in_->stamp_last = s.stamp;
    scan_ = std::move(s);
    have_ = true;
    ++st_.received;
  }

  mutable std::mutex m_;
  ::ros::Subscriber sub_;
  std::shared_ptr<Input> in_ = std::make_shared<Input>();  // before the subscription
  std::string uri_, frame_;
  hw::Pose2D mount_;
  hw::RangeScan scan_;
  bool have_ = false;
  hw::DeviceStats st_;
};

// ---------------------------------------------------------------------------------------
// A ring of sonars, one sensor_msgs/Range frame per transducer, delivered as one scan from the
// robot's centre (the simulator's and the executive's convention): each range gets its
// transducer's offset along its axis added.
class RosSonar final : public hw::RangeSensor {
 public:
  explicit RosSonar(const std::string& topic) {
    sub_ = detail::nodeHandle().subscribe(topic, 50, &RosSonar::onRange, this);
    describe(*in_, InputKind::Sonar, "sonar", sub_);
    uri_ = "ros://sonar?topic=" + sub_.getTopic();
    waitFirst(
        [this] {
          std::lock_guard<std::mutex> l(m_);
          return !beams_.empty();
        },
        "sonar range", sub_.getTopic());
    detail::addInput(in_);
  }
  ~RosSonar() override {
    detail::removeInput(in_);
    sub_.shutdown();
  }
  bool read(hw::RangeScan& out) override {
    std::lock_guard<std::mutex> l(m_);
    if (beams_.empty()) return false;
    hw::RangeScan s;
    s.kind = hw::RangeScan::Kind::Sonar;
    s.stamp = -1e300;
    s.min_range = 1e9f;
    s.max_range = 0;
    for (const auto& [frame, b] : beams_) {
      s.min_range = std::min(s.min_range, b.min_range);
      s.max_range = std::max(s.max_range, b.max_range);
      s.beam_width = std::max(s.beam_width, b.fov);
      s.stamp = std::max(s.stamp, b.stamp);
    }
    for (const auto& [frame, b] : beams_) {
      const double off = b.x * std::cos(b.yaw) + b.y * std::sin(b.yaw);
      s.angles.push_back(static_cast<float>(b.yaw));
      s.ranges.push_back(b.range >= b.max_range ? s.max_range : static_cast<float>(b.range + off));
    }
    out = std::move(s);
    return true;
  }
  hw::DeviceStats stats() const override {
    std::lock_guard<std::mutex> l(m_);
    return st_;
  }
  std::string uri() const override { return uri_; }

 private:
  struct Beam {
    double x = 0, y = 0, yaw = 0, stamp = 0;
    float range = 0, min_range = 0, max_range = 0, fov = 0;
  };
  void onRange(const sensor_msgs::RangeConstPtr& m) {
    const double recv = wallNow();  // fresh for the watchdog once usable (as the laser)
    if (std::isnan(m->range) || !(m->max_range > 0) || !std::isfinite(m->max_range)) {
      {
        std::lock_guard<std::mutex> l(m_);
        ++st_.dropped;
        st_.last_error = "NaN range or bad max_range";
      }
      detail::garbage("sonar on " + sub_.getTopic() + " (frame " + m->header.frame_id +
                      "): NaN range or bad max_range");
      return;
    }
    Beam b;
    {
      std::lock_guard<std::mutex> l(m_);
      auto it = beams_.find(m->header.frame_id);
      if (it != beams_.end()) b = it->second;
    }
    if (b.max_range == 0 && !mountOf(m->header.frame_id, 0.2, b.x, b.y, b.yaw)) {
      log::warn("ros", "no tf for a sonar frame yet: range skipped",
                {{"frame", m->header.frame_id}});
      return;
    }
    in_->wall_last = recv;
    b.range = std::isinf(m->range) ? (m->range > 0 ? m->max_range : m->min_range)
                                   : std::clamp(m->range, m->min_range, m->max_range);
    b.min_range = m->min_range;
    b.max_range = m->max_range;
    b.fov = m->field_of_view;
    b.stamp = stampOf(m->header.stamp);
    std::lock_guard<std::mutex> l(m_);
    beams_[m->header.frame_id] = b;
    ++st_.received;
    // The ring is as new as its oldest transducer (one message each, possibly in flight).
    double oldest = 1e300;
    for (const auto& [frame, beam] : beams_) oldest = std::min(oldest, beam.stamp);
    in_->stamp_last = oldest;
  }

  mutable std::mutex m_;
  ::ros::Subscriber sub_;
  std::shared_ptr<Input> in_ = std::make_shared<Input>();  // before the subscription
  std::string uri_;
  std::map<std::string, Beam> beams_;
  hw::DeviceStats st_;
};

std::string topicParam(const Uri& u, const std::string& key, const std::string& def) {
  const std::string t = u.param(key, def);
  if (t.empty()) throw InputError(u.text + ": '" + key + "' must name a topic");
  return t;
}

double mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? 0 : s / v.size();
}
double p95(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(0.95 * v.size()))];
}

}  // namespace

void noteObservation(std::uint64_t frame_seq) {
  std::lock_guard<std::mutex> l(state().latency_mutex);
  state().latency.pending = true;
  state().latency.pending_seq = frame_seq;
}

Json latencySummary() {
  std::lock_guard<std::mutex> l(state().latency_mutex);
  const auto& L = state().latency;
  auto ms = [](const std::vector<double>& v) -> Json {
    if (v.empty()) return nullptr;
    return {{"mean_ms", mean(v) * 1000}, {"p95_ms", p95(v) * 1000}};
  };
  std::vector<double> over;
  for (size_t i = 0; i < L.total.size(); ++i) over.push_back(L.total[i] - L.grab_to_cmd[i]);
  return {{"frames", L.total.size()},     {"frame_wakes", state().frame_wakes.load()},
          {"transport", ms(L.transport)}, {"convert", ms(L.convert)},
          {"wait", ms(L.wait)},           {"grab_to_cmd", ms(L.grab_to_cmd)},
          {"total", ms(L.total)},         {"ros_overhead", ms(over)}};
}

void registerDrivers() {
  static std::once_flag once;
  std::call_once(once, [] {
    auto& r = hw::Registry::instance();
    r.addCamera("ros",
                [](const Uri& u, hw::DeviceContext& ctx) -> std::unique_ptr<hw::Camera> {
                  ctx.clock = clock();
                  const std::string transport = u.param("transport", "raw");
                  if (transport != "raw" && transport != "compressed")
                    throw InputError(u.text + ": unknown transport '" + transport +
                                     "' (raw or compressed)");
                  return std::make_unique<RosCamera>(topicParam(u, "topic", "image_raw"),
                                                     u.param("info", "camera_info"), transport);
                },
                {"topic", "info", "transport"});
    r.addBase("ros",
              [](const Uri& u, hw::DeviceContext& ctx) -> std::unique_ptr<hw::Base> {
                ctx.clock = clock();
                const std::string tf = u.param("tf", "");
                if (!tf.empty() && !u.param("odom", "").empty())
                  throw InputError(u.text +
                                   ": odometry from 'odom' (a topic) or 'tf' (a frame), "
                                   "not both");
                return std::make_unique<RosBase>(topicParam(u, "cmd_vel", "cmd_vel"),
                                                 tf.empty() ? topicParam(u, "odom", "odom") : "",
                                                 tf);
              },
              {"cmd_vel", "odom", "tf"});
    r.addRange(
        "ros",
        [](const Uri& u, hw::DeviceContext& ctx) -> std::unique_ptr<hw::RangeSensor> {
          ctx.clock = clock();
          const std::string kind = u.param("kind", u.authority.empty() ? "laser" : u.authority);
          if (kind == "laser") return std::make_unique<RosLaser>(topicParam(u, "topic", "scan"));
          if (kind == "sonar") return std::make_unique<RosSonar>(topicParam(u, "topic", "sonar"));
          throw InputError(u.text + ": unknown range sensor kind '" + kind + "' (laser or sonar)");
        },
        {"kind", "topic"});
  });
}

}  // namespace sketchnav::ros
