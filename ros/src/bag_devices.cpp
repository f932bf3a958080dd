// Runs as ROS bags (bag.h): `run --record x.bag` writes one, `run --replay x.bag` navigates on
// one's odometry (bag:// base), laser and sonar (bag:// ranges) and camera (bag:// camera, in
// bag_camera.cpp), paced on the run's clock from one common time origin.
#include <geometry_msgs/TransformStamped.h>
#include <geometry_msgs/Twist.h>
#include <nav_msgs/Odometry.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/Range.h>
#include <std_msgs/String.h>
#include <tf2/LinearMath/Matrix3x3.h>
#include <tf2/LinearMath/Quaternion.h>
#include <tf2_msgs/TFMessage.h>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <mutex>
#include <set>

#include "bag_internal.h"
#include "internal.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/json_io.h"
#include "sketchnav/core/log.h"
#include "sketchnav/drivers/rawlog.h"
#include "sketchnav/drivers/recording.h"
#include "sketchnav/hw/registry.h"

namespace sketchnav::ros {
namespace {

const std::string kOdometry = "nav_msgs/Odometry";
const std::string kLaserScan = "sensor_msgs/LaserScan";
const std::string kRange = "sensor_msgs/Range";
const std::string kRunInfoTopic = "/sketchnav/run_info";

// Bag time of a run stamp: rosbag refuses times before ros::TIME_MIN (a simulated run starts at
// 0 s).
::ros::Time bagTime(double stamp) {
  return stamp > 1e-9 ? ::ros::Time(stamp) : ::ros::TIME_MIN;
}
geometry_msgs::Quaternion yawQuaternion(double yaw) {
  geometry_msgs::Quaternion q;
  q.z = std::sin(yaw / 2);
  q.w = std::cos(yaw / 2);
  return q;
}
geometry_msgs::TransformStamped mountTransform(const std::string& child, const hw::Pose2D& m,
                                               ::ros::Time t) {
  geometry_msgs::TransformStamped tf;
  tf.header.stamp = t;
  tf.header.frame_id = "base_link";
  tf.child_frame_id = child;
  tf.transform.translation.x = m.x;
  tf.transform.translation.y = m.y;
  tf.transform.rotation = yawQuaternion(m.theta);
  return tf;
}

// ---------------------------------------------------------------------------------------
// The recording: the topics `ros sim` publishes (image_raw as a lossless PNG
// CompressedImage, camera_info, odom, scan, sonar, tf_static for the sensors' mounts) plus the
// commands on cmd_vel. Readings a device returns again unchanged (the same stamp) are written
// once.
class BagRecorder final : public drivers::Recorder {
 public:
  explicit BagRecorder(const std::string& path) : path_(path) {
    const std::filesystem::path p(path);
    const auto dir = p.parent_path().empty() ? std::filesystem::path(".") : p.parent_path();
    if (!std::filesystem::is_directory(dir))
      throw InputError("--record " + path + ": folder '" + dir.string() + "' does not exist");
    try {
      bag_.open(path, rosbag::bagmode::Write);
    } catch (const std::exception& e) {
      throw InputError("--record " + path + ": cannot be written (" + e.what() + ")");
    }
  }
  ~BagRecorder() override {
    std::lock_guard<std::mutex> l(m_);
    try {
      bag_.close();
    } catch (...) {
    }
  }
  void addFrame(const hw::Frame& frame, const hw::Intrinsics& k) override {
    std::lock_guard<std::mutex> l(m_);
    const ::ros::Time t = bagTime(frame.stamp);
    sensor_msgs::CompressedImage im;
    im.header.stamp = t;
    im.header.frame_id = "camera_optical";
    im.header.seq = static_cast<std::uint32_t>(frame.seq);
    im.format = "bgr8; png compressed bgr8";
    // PNG: lossless, so perception on the replayed frame sees the recorded pixels exactly.
    if (!cv::imencode(".png", frame.image, im.data, {cv::IMWRITE_PNG_COMPRESSION, 1}))
      throw RuntimeError(path_ + ": frame " + std::to_string(frame.seq) + " does not encode");
    write("/image_raw/compressed", t, im);
    sensor_msgs::CameraInfo ci;
    ci.header = im.header;
    ci.width = k.width;
    ci.height = k.height;
    ci.distortion_model = "plumb_bob";
    ci.D = {0, 0, 0, 0, 0};
    ci.K = {k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1};
    ci.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    ci.P = {k.fx, 0, k.cx, 0, 0, k.fy, k.cy, 0, 0, 0, 1, 0};
    write("/camera_info", t, ci);
  }
  void addOdometry(const hw::Odometry& o) override {
    std::lock_guard<std::mutex> l(m_);
    if (o.stamp <= last_odom_) return;
    last_odom_ = o.stamp;
    nav_msgs::Odometry m;
    m.header.stamp = bagTime(o.stamp);
    m.header.frame_id = "odom";
    m.child_frame_id = "base_link";
    m.pose.pose.position.x = o.pose.x;
    m.pose.pose.position.y = o.pose.y;
    m.pose.pose.orientation = yawQuaternion(o.pose.theta);
    m.twist.twist.linear.x = o.v;
    m.twist.twist.angular.z = o.w;
    write("/odom", m.header.stamp, m);
  }
  void addRange(const hw::RangeScan& sc, const std::string& label) override {
    std::lock_guard<std::mutex> l(m_);
    const bool sonar = label == "SONAR";
    double& last = sonar ? last_sonar_ : last_laser_;
    if (sc.stamp <= last || sc.ranges.empty() || sc.angles.size() != sc.ranges.size()) return;
    last = sc.stamp;
    const ::ros::Time t = bagTime(sc.stamp);
    if (!sonar) {
      if (!laser_mount_written_) {
        tf2_msgs::TFMessage tf;
        tf.transforms.push_back(mountTransform("laser", sc.mount, t));
        write("/tf_static", t, tf);
        laser_mount_written_ = true;
      }
      sensor_msgs::LaserScan m;
      m.header.stamp = t;
      m.header.frame_id = "laser";
      m.angle_min = sc.angles.front();
      m.angle_max = sc.angles.back();
      m.angle_increment = sc.angles.size() > 1 ? (sc.angles.back() - sc.angles.front()) /
                                                     static_cast<float>(sc.angles.size() - 1)
                                               : 0.0f;
      m.range_min = sc.min_range;
      m.range_max = sc.max_range;
      m.ranges.resize(sc.ranges.size());
      for (size_t i = 0; i < sc.ranges.size(); ++i)
        m.ranges[i] =
            sc.ranges[i] >= sc.max_range ? std::numeric_limits<float>::infinity() : sc.ranges[i];
      write("/scan", t, m);
      return;
    }
    // A ring of sonars: one Range per beam from a frame on the robot's centre turned to the
    // beam's bearing (the scan's ranges are from the centre), its mount on tf_static.
    if (sonar_beams_written_ != sc.angles.size()) {
      tf2_msgs::TFMessage tf;
      for (size_t i = 0; i < sc.angles.size(); ++i)
        tf.transforms.push_back(
            mountTransform("sonar_" + std::to_string(i), {0, 0, sc.angles[i]}, t));
      write("/tf_static", t, tf);
      sonar_beams_written_ = sc.angles.size();
    }
    for (size_t i = 0; i < sc.ranges.size(); ++i) {
      sensor_msgs::Range m;
      m.header.stamp = t;
      m.header.frame_id = "sonar_" + std::to_string(i);
      m.radiation_type = sensor_msgs::Range::ULTRASOUND;
      m.field_of_view = sc.beam_width;
      m.min_range = sc.min_range;
      m.max_range = sc.max_range;
      m.range =
          sc.ranges[i] >= sc.max_range ? std::numeric_limits<float>::infinity() : sc.ranges[i];
      write("/sonar", t, m);
    }
  }
  void addCommand(double v, double w, double stamp, bool) override {
    std::lock_guard<std::mutex> l(m_);
    geometry_msgs::Twist m;
    m.linear.x = v;
    m.angular.z = w;
    write("/cmd_vel", bagTime(stamp), m);
  }
  void addRunInfo(const Json& settings) override {
    std::lock_guard<std::mutex> l(m_);
    std_msgs::String m;
    m.data = settings.dump();
    write(kRunInfoTopic, ::ros::TIME_MIN, m);
    // The camera's mount on tf_static as `ros sim` publishes it (base_link -> camera_optical,
    // REP 103 optical axes), for ROS tools and a `ros nav` replay reading it from tf.
    const double x = settings.value("robot.camera.x_m", 0.0),
                 z = settings.value("robot.camera.z_m", 0.0),
                 yaw = settings.value("robot.camera.yaw", 0.0),
                 pitch = settings.value("robot.camera.pitch", 0.0);
    // Body axes (x ahead, y left, z up) turned by yaw then tilted up by pitch; the optical
    // frame's x right, y down, z along the view.
    tf2::Matrix3x3 body;
    body.setRPY(0, -pitch, yaw);
    const tf2::Matrix3x3 optical = body * tf2::Matrix3x3(0, 0, 1, -1, 0, 0, 0, -1, 0);
    tf2::Quaternion q;
    optical.getRotation(q);
    tf2_msgs::TFMessage tf;
    geometry_msgs::TransformStamped t;
    t.header.stamp = ::ros::TIME_MIN;
    t.header.frame_id = "base_link";
    t.child_frame_id = "camera_optical";
    t.transform.translation.x = x;
    t.transform.translation.z = z;
    t.transform.rotation.x = q.x();
    t.transform.rotation.y = q.y();
    t.transform.rotation.z = q.z();
    t.transform.rotation.w = q.w();
    tf.transforms.push_back(t);
    write("/tf_static", ::ros::TIME_MIN, tf);
  }
  std::string path() const override { return path_; }

 private:
  template <class M>
  void write(const std::string& topic, ::ros::Time t, const M& m) {
    try {
      bag_.write(topic, t, m);
    } catch (const std::exception& e) {
      throw RuntimeError(path_ + ": " + topic + ": " + e.what());
    }
  }
  std::mutex m_;
  std::string path_;
  rosbag::Bag bag_;
  double last_odom_ = -1, last_laser_ = -1, last_sonar_ = -1;
  bool laser_mount_written_ = false;
  size_t sonar_beams_written_ = 0;
};

// ---------------------------------------------------------------------------------------
// Reading a bag's messages of one topic in order, each with its header stamp.
void openBag(rosbag::Bag& bag, const Uri& u) {
  if (u.path.empty() || !std::filesystem::is_regular_file(u.path))
    throw InputError(u.text + ": no such bag file '" + u.path + "'");
  try {
    bag.open(u.path, rosbag::bagmode::Read);
  } catch (const std::exception& e) {
    throw InputError(u.text + ": cannot be read as a ROS bag (" + e.what() + ")");
  }
}

// The topic of `type` to read: `topic` when given (it must have that type), else the bag's
// only such topic, else `preferred` among several.
std::string topicOf(rosbag::Bag& bag, const Uri& u, const std::string& type,
                    const std::string& topic, const std::string& preferred) {
  rosbag::View all(bag);
  std::set<std::string> found;
  for (const auto* c : all.getConnections())
    if (c->datatype == type) found.insert(c->topic);
  if (!topic.empty()) {
    if (!found.count(topic))
      throw InputError(u.text + ": no " + type + " topic '" + topic + "' in the bag");
    return topic;
  }
  if (found.size() == 1) return *found.begin();
  if (found.count(preferred)) return preferred;
  std::string list;
  for (const auto& t : found) list += (list.empty() ? "" : ", ") + t;
  throw InputError(u.text + ": " +
                   (found.empty()
                        ? "no " + type + " topic in the bag"
                        : "several " + type + " topics (" + list + "): choose one with ?topic="));
}

// Opens `path` for reading; InputError naming it when it is no bag.
void openToRead(rosbag::Bag& bag, const std::string& path) {
  try {
    bag.open(path, rosbag::bagmode::Read);
  } catch (const std::exception& e) {
    throw InputError(path + ": cannot be read as a ROS bag (" + e.what() + ")");
  }
}

// The transform base_link (or base_footprint) -> `frame` on the bag's tf_static / tf, one hop;
// false when the bag has none.
bool transformInBag(rosbag::Bag& bag, const std::string& frame, geometry_msgs::Transform& out) {
  rosbag::View v(bag, rosbag::TopicQuery(std::vector<std::string>{"/tf_static", "/tf"}));
  for (const auto& m : v) {
    const auto tf = m.instantiate<tf2_msgs::TFMessage>();
    if (!tf) continue;
    for (const auto& t : tf->transforms)
      if (t.child_frame_id == frame &&
          (t.header.frame_id == "base_link" || t.header.frame_id == "base_footprint")) {
        out = t.transform;
        return true;
      }
  }
  return false;
}

// A sensor's mount in the plane (x, y, yaw) from the bag's tf; false when the bag has none.
bool mountInBag(rosbag::Bag& bag, const std::string& frame, hw::Pose2D& out) {
  geometry_msgs::Transform t;
  if (!transformInBag(bag, frame, t)) return false;
  const auto& q = t.rotation;
  double r, p, yaw;
  tf2::Matrix3x3(tf2::Quaternion(q.x, q.y, q.z, q.w)).getRPY(r, p, yaw);
  out = {t.translation.x, t.translation.y, yaw};
  return std::isfinite(out.x) && std::isfinite(out.y) && std::isfinite(out.theta);
}

// Messages of one topic in bag order, delivered on the run's clock: a message stamped s is due
// at t0_clock + (s - t0_bag), t0_bag the bag's first stamp (bagFirstStamp), so every bag://
// device of one bag keeps the recorded time between them.
template <class Msg>
class PacedTopic {
 public:
  PacedTopic(rosbag::Bag& bag, const std::string& topic, const std::string& path,
             std::shared_ptr<hw::Clock> clock)
      : view_(bag, rosbag::TopicQuery(topic)),
        it_(view_.begin()),
        clock_(clock ? std::move(clock) : std::make_shared<hw::SteadyClock>()) {
    const BagOrigin o = bagOrigin(path, *clock_);
    t0_bag_ = o.t0_bag;
    t0_clock_ = o.t0_clock;
  }
  // Moves to the newest message due now; `take` is called for each message passed (in order).
  template <class F>
  void advance(F&& take) {
    const double now = clock_->now();
    while (true) {
      if (!have_next_ && !fetch()) {
        ended_ = true;
        return;
      }
      if (due(next_stamp_) > now + drivers::kReplaySlack) return;
      take(*next_, due(next_stamp_));
      have_next_ = false;
    }
  }
  bool ended() const { return ended_; }

 private:
  double due(double stamp) const { return t0_clock_ + (stamp - t0_bag_); }
  bool fetch() {
    while (it_ != view_.end()) {
      const rosbag::MessageInstance m = *it_;
      ++it_;
      if (auto p = m.instantiate<Msg>()) {
        next_ = p;
        next_stamp_ = p->header.stamp.isZero() ? m.getTime().toSec() : p->header.stamp.toSec();
        have_next_ = true;
        return true;
      }
    }
    return false;
  }
  rosbag::View view_;
  rosbag::View::iterator it_;
  std::shared_ptr<hw::Clock> clock_;
  double t0_bag_ = 0, t0_clock_ = 0;
  boost::shared_ptr<Msg> next_;
  double next_stamp_ = 0;
  bool have_next_ = false, ended_ = false;
};

// bag:///FILE[?topic=/odom] as a base: the recorded odometry; commands are counted and
// ignored (the bag already holds what the robot did); ok() turns false at the end.
class BagBase final : public hw::Base {
 public:
  BagBase(const Uri& u, std::shared_ptr<hw::Clock> clock) : uri_(u.text) {
    openBag(bag_, u);
    topic_ = topicOf(bag_, u, kOdometry, u.param("topic", ""), "/odom");
    odo_ = std::make_unique<PacedTopic<nav_msgs::Odometry>>(bag_, topic_, u.path, clock);
  }
  void command(double, double) override {
    std::lock_guard<std::mutex> l(m_);
    ++st_.received;
  }
  void stop() noexcept override {}
  bool odometry(hw::Odometry& out) override {
    std::lock_guard<std::mutex> l(m_);
    odo_->advance([&](const nav_msgs::Odometry& m, double due) {
      const auto& q = m.pose.pose.orientation;
      double r, p, yaw;
      tf2::Matrix3x3(tf2::Quaternion(q.x, q.y, q.z, q.w)).getRPY(r, p, yaw);
      hw::Odometry o;
      o.pose = {m.pose.pose.position.x, m.pose.pose.position.y, yaw};
      o.v = m.twist.twist.linear.x;
      o.w = m.twist.twist.angular.z;
      o.stamp = due;
      if (!std::isfinite(o.pose.x) || !std::isfinite(o.pose.y) || !std::isfinite(yaw) ||
          !std::isfinite(o.v) || !std::isfinite(o.w)) {
        ++st_.dropped;
        st_.last_error = "odometry on " + topic_ + " is not finite";
        log::warn("bag", "odometry skipped: not finite", {{"uri", uri_}});
        return;
      }
      current_ = o;
      have_ = true;
    });
    if (!have_) return false;
    out = current_;
    return true;
  }
  bool ok() const override {
    std::lock_guard<std::mutex> l(m_);
    return !odo_->ended();
  }
  hw::DeviceStats stats() const override {
    std::lock_guard<std::mutex> l(m_);
    return st_;
  }
  std::string uri() const override { return uri_; }

 private:
  mutable std::mutex m_;
  std::string uri_, topic_;
  rosbag::Bag bag_;
  std::unique_ptr<PacedTopic<nav_msgs::Odometry>> odo_;
  hw::Odometry current_;
  bool have_ = false;
  hw::DeviceStats st_;
};

// bag:///FILE?kind=laser|sonar[&topic=...] as a range sensor: the newest scan due (LaserScan,
// the sensor's mount from the bag's tf), or a sonar ring assembled from its Range messages (one
// frame per transducer, each mount from tf; ranges from the robot's centre as the executive
// takes them). False until the first is due.
class BagRange final : public hw::RangeSensor {
 public:
  BagRange(const Uri& u, std::shared_ptr<hw::Clock> clock) : uri_(u.text) {
    openBag(bag_, u);
    const std::string kind = u.param("kind", "laser");
    if (kind != "laser" && kind != "sonar")
      throw InputError(u.text + ": kind must be laser or sonar, not '" + kind + "'");
    sonar_ = kind == "sonar";
    topic_ = topicOf(bag_, u, sonar_ ? kRange : kLaserScan, u.param("topic", ""),
                     sonar_ ? "/sonar" : "/scan");
    if (sonar_)
      ranges_ = std::make_unique<PacedTopic<sensor_msgs::Range>>(bag_, topic_, u.path, clock);
    else
      scans_ = std::make_unique<PacedTopic<sensor_msgs::LaserScan>>(bag_, topic_, u.path, clock);
  }
  bool read(hw::RangeScan& out) override {
    std::lock_guard<std::mutex> l(m_);
    if (sonar_)
      ranges_->advance([&](const sensor_msgs::Range& m, double due) { onRange(m, due); });
    else
      scans_->advance([&](const sensor_msgs::LaserScan& m, double due) { onScan(m, due); });
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
  void skip(const std::string& why) {
    ++st_.dropped;
    st_.last_error = why;
    log::warn("bag", "scan skipped: " + why, {{"uri", uri_}});
  }
  hw::Pose2D mount(const std::string& frame) {
    auto it = mounts_.find(frame);
    if (it != mounts_.end()) return it->second;
    hw::Pose2D p;
    if (!mountInBag(bag_, frame, p))
      log::warn("bag", "no base_link -> " + frame + " transform in the bag: mounted at the centre",
                {{"uri", uri_}});
    mounts_[frame] = p;
    return p;
  }
  void onScan(const sensor_msgs::LaserScan& m, double due) {
    const long n = m.angle_increment != 0
                       ? std::lround((m.angle_max - m.angle_min) / m.angle_increment) + 1
                       : 1;
    if (!std::isfinite(m.angle_min) || !std::isfinite(m.angle_increment) || !(m.range_max > 0) ||
        !std::isfinite(m.range_max) || m.ranges.empty() || n != static_cast<long>(m.ranges.size()))
      return skip("laser scan on " + topic_ + ": bad angles, range_max or length");
    hw::RangeScan s;
    s.kind = hw::RangeScan::Kind::Laser;
    s.min_range = m.range_min;
    s.max_range = m.range_max;
    s.mount = mount(m.header.frame_id);
    s.stamp = due;
    s.angles.resize(m.ranges.size());
    s.ranges.resize(m.ranges.size());
    for (size_t i = 0; i < m.ranges.size(); ++i) {
      s.angles[i] = static_cast<float>(m.angle_min + i * m.angle_increment);
      const float r = m.ranges[i];
      s.ranges[i] = std::isnan(r) || r >= m.range_max ? m.range_max : std::max(r, m.range_min);
    }
    scan_ = std::move(s);
    have_ = true;
    ++st_.received;
  }
  void onRange(const sensor_msgs::Range& m, double due) {
    if (std::isnan(m.range) || !(m.max_range > 0) || !std::isfinite(m.max_range))
      return skip("sonar on " + topic_ + " (frame " + m.header.frame_id +
                  "): NaN range or bad max_range");
    auto it = std::find_if(beams_.begin(), beams_.end(),
                           [&](const Beam& b) { return b.frame == m.header.frame_id; });
    if (it == beams_.end()) {
      beams_.push_back({m.header.frame_id, mount(m.header.frame_id)});
      it = beams_.end() - 1;
    }
    it->range = std::isinf(m.range) ? (m.range > 0 ? m.max_range : m.min_range)
                                    : std::clamp(m.range, m.min_range, m.max_range);
    it->min_range = m.min_range;
    it->max_range = m.max_range;
    it->fov = m.field_of_view;
    hw::RangeScan s;
    s.kind = hw::RangeScan::Kind::Sonar;
    s.stamp = due;
    s.min_range = 1e9f;
    for (const auto& b : beams_) {
      s.min_range = std::min(s.min_range, b.min_range);
      s.max_range = std::max(s.max_range, b.max_range);
      s.beam_width = std::max(s.beam_width, b.fov);
    }
    for (const auto& b : beams_) {
      // The transducer's range from itself, from the robot's centre along its axis.
      const double off = b.mount.x * std::cos(b.mount.theta) + b.mount.y * std::sin(b.mount.theta);
      s.angles.push_back(static_cast<float>(b.mount.theta));
      s.ranges.push_back(b.range >= b.max_range ? s.max_range : static_cast<float>(b.range + off));
    }
    scan_ = std::move(s);
    have_ = true;
    ++st_.received;
  }
  struct Beam {
    std::string frame;
    hw::Pose2D mount;
    float range = 0, min_range = 0, max_range = 0, fov = 0;
  };
  mutable std::mutex m_;
  std::string uri_, topic_;
  rosbag::Bag bag_;
  bool sonar_ = false, have_ = false;
  std::unique_ptr<PacedTopic<sensor_msgs::LaserScan>> scans_;
  std::unique_ptr<PacedTopic<sensor_msgs::Range>> ranges_;
  std::map<std::string, hw::Pose2D> mounts_;
  std::vector<Beam> beams_;  // in the order the bag first shows them
  hw::RangeScan scan_;
  hw::DeviceStats st_;
};

// The header stamp of a topic's first message (its bag time when the header has none);
// NaN when the topic has no message of a stamped type this reader knows.
double firstStampOf(rosbag::Bag& bag, const std::string& topic) {
  rosbag::View v(bag, rosbag::TopicQuery(topic));
  for (const auto& m : v) {
    ::ros::Time t;
    if (auto p = m.instantiate<sensor_msgs::Image>())
      t = p->header.stamp;
    else if (auto p = m.instantiate<sensor_msgs::CompressedImage>())
      t = p->header.stamp;
    else if (auto p = m.instantiate<nav_msgs::Odometry>())
      t = p->header.stamp;
    else if (auto p = m.instantiate<sensor_msgs::LaserScan>())
      t = p->header.stamp;
    else if (auto p = m.instantiate<sensor_msgs::Range>())
      t = p->header.stamp;
    else
      return NAN;
    return t.isZero() ? m.getTime().toSec() : t.toSec();
  }
  return NAN;
}

}  // namespace

double bagFirstStamp(const std::string& path) {
  static std::mutex m;
  static std::map<std::string, double> cache;
  std::lock_guard<std::mutex> l(m);
  const auto it = cache.find(path);
  if (it != cache.end()) return it->second;
  rosbag::Bag bag;
  bag.open(path, rosbag::bagmode::Read);
  std::set<std::string> topics;
  {
    rosbag::View all(bag);
    for (const auto* c : all.getConnections()) topics.insert(c->topic);
  }
  double first = NAN;
  for (const auto& t : topics) {
    const double s = firstStampOf(bag, t);
    if (std::isfinite(s) && !(s >= first)) first = s;
  }
  if (!std::isfinite(first)) first = 0;
  cache[path] = first;
  return first;
}

BagOrigin bagOrigin(const std::string& path, hw::Clock& clock) {
  const drivers::ReplayOrigin o =
      drivers::replayOrigin(bagFirstStamp(path), clock, !drivers::readRunInfo(path).empty());
  return {o.t0_rec, o.t0_clock};
}

void registerBagDevices() {
  auto& r = hw::Registry::instance();
  r.addBase("bag",
            [](const Uri& u, hw::DeviceContext& ctx) -> std::unique_ptr<hw::Base> {
              return std::make_unique<BagBase>(u, ctx.clock);
            },
            {"topic"});
  r.addRange("bag",
             [](const Uri& u, hw::DeviceContext& ctx) -> std::unique_ptr<hw::RangeSensor> {
               return std::make_unique<BagRange>(u, ctx.clock);
             },
             {"kind", "topic"});
  drivers::RecordingFormat bag_format;
  bag_format.open = [](const std::string& path) { return std::make_shared<BagRecorder>(path); };
  bag_format.run_info = [](const std::string& path) -> Json {
    rosbag::Bag bag;
    openToRead(bag, path);
    rosbag::View v(bag, rosbag::TopicQuery(kRunInfoTopic));
    for (const auto& m : v)
      if (auto s = m.instantiate<std_msgs::String>()) {
        Json j = parseJsonText(s->data, path + ": " + kRunInfoTopic);
        if (!j.is_object()) throw InputError(path + ": " + kRunInfoTopic + ": not a JSON object");
        return j;
      }
    return Json::object();
  };
  bag_format.robot = [](const std::string& path) -> Json {
    rosbag::Bag bag;
    openToRead(bag, path);
    // The optical frame of the bag's first image, raw or compressed.
    std::string frame;
    for (const auto& m : rosbag::View(bag)) {
      if (auto im = m.instantiate<sensor_msgs::Image>())
        frame = im->header.frame_id;
      else if (auto ci = m.instantiate<sensor_msgs::CompressedImage>())
        frame = ci->header.frame_id;
      if (!frame.empty()) break;
    }
    geometry_msgs::Transform t;
    if (frame.empty() || !transformInBag(bag, frame, t)) return Json::object();
    const CameraMount c = detail::opticalMount(t);
    if (!std::isfinite(c.x_m) || !std::isfinite(c.z_m) || !std::isfinite(c.yaw) ||
        !std::isfinite(c.pitch))
      return Json::object();
    return Json{{"robot.camera.x_m", c.x_m},
                {"robot.camera.z_m", c.z_m},
                {"robot.camera.yaw", c.yaw},
                {"robot.camera.pitch", c.pitch}};
  };
  drivers::registerRecordingFormat(".bag", std::move(bag_format));
}

}  // namespace sketchnav::ros
