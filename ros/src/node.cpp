#include <geometry_msgs/Twist.h>
#include <ros/ros.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <std_msgs/Float64MultiArray.h>
#include <std_msgs/String.h>
#include <tf2/LinearMath/Matrix3x3.h>
#include <tf2/LinearMath/Quaternion.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include <netdb.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <map>

#include "internal.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/log.h"

namespace sketchnav::ros {
namespace detail {

State& state() {
  static State s;
  return s;
}

CameraMount opticalMount(const geometry_msgs::Transform& t) {
  const auto& q = t.rotation;
  const tf2::Matrix3x3 R(tf2::Quaternion(q.x, q.y, q.z, q.w));
  // The optical axis (z of an optical frame, REP 103) in the base frame.
  const tf2::Vector3 d = R * tf2::Vector3(0, 0, 1);
  CameraMount m;
  m.x_m = t.translation.x;
  m.z_m = t.translation.z;
  m.yaw = std::atan2(d.y(), d.x());
  m.pitch = std::atan2(d.z(), std::hypot(d.x(), d.y()));
  return m;
}

double wallNow() {
  using C = std::chrono::steady_clock;
  static const C::time_point t0 = C::now();
  return std::chrono::duration<double>(C::now() - t0).count();
}

void publishZero() noexcept {
  try {
    State& s = state();
    if (!s.have_cmd_vel) return;
    s.cmd_vel.publish(geometry_msgs::Twist());
    s.last_v = 0.0;
    s.last_w = 0.0;
  } catch (...) {
  }
}

void garbage(const std::string& reason) {
  trip(reason);
}

void addInput(const std::shared_ptr<Input>& in) {
  std::lock_guard<std::mutex> l(state().mutex);
  state().inputs.push_back(in);
}

void removeInput(const std::shared_ptr<Input>& in) {
  in->active = false;
  std::lock_guard<std::mutex> l(state().mutex);
  auto& v = state().inputs;
  v.erase(std::remove(v.begin(), v.end(), in), v.end());
}

::ros::NodeHandle& nodeHandle() {
  State& s = state();
  if (!s.initialised || !s.nh)
    throw RuntimeError("ros:// devices need a ROS node: use `sketchnav ros nav`");
  return *s.nh;
}

}  // namespace detail

using detail::State;
using detail::state;

namespace {
volatile std::sig_atomic_t g_signal = 0;
void onSignal(int sig) {
  g_signal = sig;
}

void installSignalHandlers() {
  struct sigaction sa {};
  sa.sa_handler = onSignal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESTART;
  ::sigaction(SIGINT, &sa, nullptr);
  ::sigaction(SIGTERM, &sa, nullptr);
}

// XmlRpc parameter tree -> JSON.
Json toJson(XmlRpc::XmlRpcValue& v) {
  switch (v.getType()) {
    case XmlRpc::XmlRpcValue::TypeBoolean:
      return static_cast<bool>(v);
    case XmlRpc::XmlRpcValue::TypeInt:
      return static_cast<int>(v);
    case XmlRpc::XmlRpcValue::TypeDouble:
      return static_cast<double>(v);
    case XmlRpc::XmlRpcValue::TypeString:
      return static_cast<std::string>(v);
    case XmlRpc::XmlRpcValue::TypeArray: {
      Json a = Json::array();
      for (int i = 0; i < v.size(); ++i) a.push_back(toJson(v[i]));
      return a;
    }
    case XmlRpc::XmlRpcValue::TypeStruct: {
      Json o = Json::object();
      for (auto it = v.begin(); it != v.end(); ++it) o[it->first] = toJson(it->second);
      return o;
    }
    default:
      return nullptr;
  }
}

void watchdogLoop() {
  State& s = state();
  double next_master = 0, next_zero = 0;
  while (!s.watchdog_stop) {
    const double now = detail::wallNow();
    if (g_signal) trip(g_signal == SIGTERM ? "SIGTERM received" : "SIGINT received");
    RosParams p;
    std::vector<std::shared_ptr<detail::Input>> inputs;
    {
      std::lock_guard<std::mutex> l(s.mutex);
      p = s.params;
      inputs = s.inputs;
    }
    // Lock-step: the simulator sends nothing while this node works on a step (it waits for
    // it), so an input is judged only while the control loop waits, from when it began to.
    const double lockstep_since = s.lockstep ? s.lockstep_wait_since.load() : 0.0;
    for (const auto& in : inputs) {
      double last = in->wall_last;
      if (last < 0) continue;  // not judged before its first message (the device waits for it)
      if (!in->active) continue;
      const std::uint32_t n = in->publishers ? in->publishers() : 1;
      if (n > 0) in->had_publisher = true;
      const bool judged = !s.lockstep || lockstep_since >= 0;
      if (s.lockstep) last = std::max(last, lockstep_since);
      char b[256];
      if (judged && now - last > p.stale_timeout_s) {
        std::snprintf(b, sizeof b,
                      "%s on %s: no usable message for %.2f s (limit ros.stale_timeout_s = %.2f s)",
                      in->what.c_str(), in->topic.c_str(), now - last, p.stale_timeout_s);
        trip(b);
      } else if (n == 0 && in->had_publisher && in->active) {
        std::snprintf(b, sizeof b, "%s on %s: its publisher went away", in->what.c_str(),
                      in->topic.c_str());
        trip(b);
      }
    }
    if (now >= next_master) {
      next_master = now + p.master_check_s;
      if (!::ros::master::check())
        trip("the ROS master at " + ::ros::master::getURI() + " cannot be reached");
    }
    // Once tripped, a zero command every 0.1 s: a base that missed one still stops.
    if (s.tripped && now >= next_zero) {
      detail::publishZero();
      next_zero = now + 0.1;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

// True when nothing listens at the host:port of an XML-RPC URI "http://host:port/": the node
// behind it has died (a killed node never unregisters from the master). Connecting waits at
// most 100 ms; a slow answer counts as alive.
bool refusesConnections(const std::string& uri) {
  const std::string pre = "http://";
  if (uri.rfind(pre, 0) != 0) return false;
  const std::string hp = uri.substr(pre.size(), uri.find('/', pre.size()) - pre.size());
  const auto colon = hp.rfind(':');
  if (colon == std::string::npos) return false;
  addrinfo hints{}, *res = nullptr;
  hints.ai_socktype = SOCK_STREAM;
  if (::getaddrinfo(hp.substr(0, colon).c_str(), hp.substr(colon + 1).c_str(), &hints, &res) != 0)
    return false;
  bool refused = false;
  const int fd = ::socket(res->ai_family, SOCK_STREAM | SOCK_NONBLOCK, 0);
  if (fd >= 0) {
    if (::connect(fd, res->ai_addr, res->ai_addrlen) != 0) {
      if (errno == ECONNREFUSED) {
        refused = true;
      } else if (errno == EINPROGRESS) {
        pollfd p{fd, POLLOUT, 0};
        if (::poll(&p, 1, 100) == 1) {
          int err = 0;
          socklen_t n = sizeof err;
          ::getsockopt(fd, SOL_SOCKET, SO_ERROR, &err, &n);
          refused = err == ECONNREFUSED;
        }
      }
    }
    ::close(fd);
  }
  ::freeaddrinfo(res);
  return refused;
}

// Publisher liveness: every 50 ms, is each input's publisher node still there? A driver (or
// `ros sim`) that died stops the robot at once, not when its last message gets stale.
void livenessLoop() {
  State& s = state();
  std::map<std::string, std::vector<std::string>> pubs;  // topic -> publisher nodes
  std::map<std::string, std::string> uris;               // node -> XML-RPC URI
  double next_state = 0;
  const std::string me = ::ros::this_node::getName();
  while (!s.watchdog_stop) {
    const double now = detail::wallNow();
    if (now >= next_state) {
      next_state = now + 1.0;
      XmlRpc::XmlRpcValue args, result, payload;
      args[0] = me;
      if (::ros::master::execute("getSystemState", args, result, payload, false) &&
          payload.getType() == XmlRpc::XmlRpcValue::TypeArray && payload.size() > 0) {
        pubs.clear();
        XmlRpc::XmlRpcValue& p = payload[0];
        for (int i = 0; i < p.size(); ++i) {
          std::vector<std::string> nodes;
          for (int j = 0; j < p[i][1].size(); ++j) nodes.push_back(p[i][1][j]);
          pubs[p[i][0]] = nodes;
        }
      }
    }
    std::vector<std::shared_ptr<detail::Input>> inputs;
    {
      std::lock_guard<std::mutex> l(s.mutex);
      inputs = s.inputs;
    }
    for (const auto& in : inputs) {
      if (!in->active || in->wall_last < 0) continue;
      for (const auto& node : pubs[in->topic]) {
        if (node == me) continue;
        if (!uris.count(node)) {
          XmlRpc::XmlRpcValue args, result, payload;
          args[0] = me;
          args[1] = node;
          if (::ros::master::execute("lookupNode", args, result, payload, false))
            uris[node] = static_cast<std::string>(payload);
          else
            continue;
        }
        if (in->active && refusesConnections(uris[node]))
          trip(in->what + " on " + in->topic + ": its publisher " + node + " is gone (" +
               uris[node] + " refuses connections)");
      }
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

// Lock-step (RosParams::lockstep): which entry of the simulator's step message holds the
// stamp an input must have reached.
int stepIndex(detail::InputKind kind) {
  switch (kind) {
    case detail::InputKind::Odometry:
      return 1;
    case detail::InputKind::Laser:
      return 2;
    case detail::InputKind::Sonar:
      return 3;
    case detail::InputKind::Camera:
      return 4;
  }
  return -1;
}

// The node's time in lock-step: the simulator's latest step once every input has received
// what the simulator had sent up to it (topics travel on separate connections, so /clock or
// the step message may arrive before the data); before the first step, ROS time.
double lockstepNow() {
  State& s = state();
  std::vector<std::shared_ptr<detail::Input>> inputs;
  {
    std::lock_guard<std::mutex> l(s.mutex);
    inputs = s.inputs;
  }
  std::lock_guard<std::mutex> l(s.wake_m);
  if (s.step.size() >= 5 && s.step[0] > s.lockstep_now) {
    bool ready = true;
    for (const auto& in : inputs) {
      const int k = stepIndex(in->kind);
      if (k < 0 || !in->active || s.step[k] < 0) continue;
      // Stamps travel as ROS times (nanoseconds): equal within a microsecond.
      if (in->stamp_last < s.step[k] - 1e-6) ready = false;
    }
    if (ready) s.lockstep_now = s.step[0];
  }
  return s.lockstep_now >= 0 ? s.lockstep_now : ::ros::Time::now().toSec();
}

class RosClock final : public hw::Clock {
 public:
  double now() const override {
    return state().lockstep ? lockstepNow() : ::ros::Time::now().toSec();
  }
  void sleepUntil(double t) override {
    State& s = state();
    if (s.lockstep) {
      lockstepSleepUntil(t);
      return;
    }
    // Returns early on a fault: under simulated time a dead simulator freezes /clock, and the
    // executive must still reach its next tick to stop. Returns early, too, when a camera
    // frame the executive will grab arrives (wakeOnFrames()): the frame need not wait for the
    // next tick (up to a whole tick_s otherwise). Each such frame wakes it once.
    std::unique_lock<std::mutex> l(s.wake_m);
    while (now() < t && !s.tripped && ::ros::ok()) {
      if (s.wake_gap_s >= 0 && s.frames_due > woken_) {
        ++s.frame_wakes;
        break;
      }
      // Polled as well: under simulated time now() moves with /clock, not with a notify.
      s.wake_cv.wait_for(l, std::chrono::microseconds(500));
    }
    woken_ = s.frames_due;
  }

 private:
  // Tells the simulator that this node is done until t (with the command it sent last: one
  // message, so the simulator cannot apply a step's command before it has it), then waits
  // until the simulator has stepped to t and every input has what it sent up to then.
  void lockstepSleepUntil(double t) {
    State& s = state();
    if (lockstepNow() >= t) return;
    std_msgs::Float64MultiArray ack;
    ack.data = {t, s.last_v.load(), s.last_w.load()};
    s.lockstep_ack.publish(ack);
    s.lockstep_wait_since = detail::wallNow();
    while (!s.tripped && ::ros::ok()) {
      // The simulator steps to t exactly; its time may come back a rounding error short.
      if (lockstepNow() >= t - 1e-9) {
        std::lock_guard<std::mutex> l(s.wake_m);
        s.lockstep_now = std::max(s.lockstep_now, t);
        break;
      }
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    s.lockstep_wait_since = -1.0;
  }
  std::uint64_t woken_ = 0;  // frames_due when sleepUntil() last returned (guarded by wake_m)
};

}  // namespace

void RosParams::validate() const {
  require(stale_timeout_s > 0 && stale_timeout_s <= 10, "ros.stale_timeout_s",
          "must be in (0, 10] s");
  require(wait_s > 0, "ros.wait_s", "must be > 0 s");
  require(master_check_s > 0 && master_check_s <= 5, "ros.master_check_s", "must be in (0, 5] s");
  require(!image_topic.empty(), "ros.image_topic", "must not be empty (landmarks need a camera)");
  require(image_transport == "raw" || image_transport == "compressed", "ros.image_transport",
          "must be 'raw' (sensor_msgs/Image) or 'compressed' (sensor_msgs/CompressedImage on "
          "<image_topic>/compressed)");
  require(!odom_topic.empty(), "ros.odom_topic", "must not be empty");
  require(!cmd_vel_topic.empty(), "ros.cmd_vel_topic", "must not be empty");
  require(!base_frame.empty(), "ros.base_frame", "must not be empty");
  require(odom_source == "topic" || odom_source == "tf", "ros.odom_source",
          "must be 'topic' (nav_msgs/Odometry) or 'tf' (odom_frame -> base_frame)");
  require(!odom_frame.empty(), "ros.odom_frame", "must not be empty");
}

void init(const std::string& name, const std::vector<std::string>& args, double wait_master_s) {
  State& s = state();
  if (s.initialised) return;
  std::vector<std::string> a = {"sketchnav"};
  a.insert(a.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& x : a) argv.push_back(x.data());
  int argc = static_cast<int>(argv.size());
  ::ros::init(argc, argv.data(), name,
              ::ros::init_options::NoSigintHandler | ::ros::init_options::NoRosout);
  installSignalHandlers();
  ::ros::master::setRetryTimeout(::ros::WallDuration(0.2));
  const double t0 = detail::wallNow();
  while (!::ros::master::check()) {
    if (g_signal) throw RuntimeError("interrupted while waiting for the ROS master");
    if (detail::wallNow() - t0 > wait_master_s)
      throw RuntimeError("no ROS master at " + ::ros::master::getURI() +
                         " (ROS_MASTER_URI) within " +
                         std::to_string(static_cast<int>(wait_master_s)) + " s: start roscore");
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  s.nh = std::make_unique<::ros::NodeHandle>();
  s.spinner = std::make_unique<::ros::AsyncSpinner>(2);
  s.spinner->start();
  s.tf = std::make_shared<tf2_ros::Buffer>();
  s.tf_listener = std::make_unique<tf2_ros::TransformListener>(*s.tf, *s.nh);
  s.initialised = true;
  // Again once the node is up: starting it may install handlers of its own.
  installSignalHandlers();
  log::info("ros", "node up",
            {{"name", ::ros::this_node::getName()},
             {"master", ::ros::master::getURI()},
             {"sim_time", ::ros::Time::isSimTime() ? "yes" : "no"}});
}

bool ok() {
  return !g_signal && ::ros::ok() && state().initialised;
}

std::string signalReceived() {
  return g_signal == SIGINT ? "SIGINT" : g_signal == SIGTERM ? "SIGTERM" : "";
}

void shutdown() {
  State& s = state();
  if (!s.initialised) return;
  s.watchdog_stop = true;
  if (s.watchdog.joinable()) s.watchdog.join();
  if (s.liveness.joinable()) s.liveness.join();
  detail::publishZero();
  // Let the zero command and latched messages leave before the connections close.
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  if (s.spinner) s.spinner->stop();
  s.tf_listener.reset();
  {
    std::lock_guard<std::mutex> l(s.mutex);
    s.inputs.clear();
  }
  ::ros::shutdown();
  s.initialised = false;
}

Config privateParams() {
  XmlRpc::XmlRpcValue v;
  if (!::ros::param::get("~", v) || v.getType() != XmlRpc::XmlRpcValue::TypeStruct) return Config();
  Json j = toJson(v);
  // image_transport's own convention, `_image_transport:=compressed` (~image_transport),
  // is ros.image_transport.
  if (j.contains("image_transport")) {
    Json& r = j["ros"];
    if (!r.is_object()) r = Json::object();
    if (r.contains("image_transport") && r["image_transport"] != j["image_transport"])
      throw InputError("ROS parameters of " + ::ros::this_node::getName() +
                       ": ~image_transport and ~ros/image_transport disagree");
    r["image_transport"] = j["image_transport"];
    j.erase("image_transport");
  }
  return Config::fromJson(j, "ROS parameters of " + ::ros::this_node::getName());
}

void startWatchdog(const RosParams& p) {
  State& s = state();
  {
    std::lock_guard<std::mutex> l(s.mutex);
    s.params = p;
  }
  if (p.lockstep && !s.lockstep) {
    ::ros::NodeHandle& nh = detail::nodeHandle();
    s.lockstep_ack = nh.advertise<std_msgs::Float64MultiArray>("lockstep/ack", 10);
    boost::function<void(const std_msgs::Float64MultiArrayConstPtr&)> on_step =
        [](const std_msgs::Float64MultiArrayConstPtr& m) {
          for (double x : m->data)
            if (!std::isfinite(x)) return detail::garbage("lockstep/step: a value is not finite");
          if (m->data.size() < 5)
            return detail::garbage("lockstep/step: " + std::to_string(m->data.size()) +
                                   " values, expected 5 (t, odometry, scan, sonar, camera)");
          std::lock_guard<std::mutex> l(state().wake_m);
          state().step = m->data;
        };
    s.lockstep_step = nh.subscribe<std_msgs::Float64MultiArray>("lockstep/step", 10, on_step);
    s.lockstep = true;
    log::info("ros", "lock-step with the simulator: time moves when this node has answered",
              {{"step", s.lockstep_step.getTopic()}, {"ack", s.lockstep_ack.getTopic()}});
  }
  if (!s.watchdog.joinable()) {
    s.watchdog = std::thread(watchdogLoop);
    s.liveness = std::thread(livenessLoop);
  }
}

std::string fault() {
  std::lock_guard<std::mutex> l(state().mutex);
  return state().fault;
}

void sendZeroCommand() {
  detail::publishZero();
}

void trip(const std::string& reason) {
  State& s = state();
  {
    // command_m, as in hold(): a command that read "not tripped" is published before this zero,
    // never after it (the watchdog's repeated zero would otherwise be the only stop for 0.1 s).
    std::lock_guard<std::mutex> c(s.command_m);
    {
      std::lock_guard<std::mutex> l(s.mutex);
      if (s.tripped) return;
      s.fault = reason;
      s.tripped = true;
    }
    detail::publishZero();
  }
  log::error("ros", "safety stop: " + reason + " (zero cmd_vel sent; the robot stays stopped)");
}

void hold(const std::string& why) {
  State& s = state();
  {
    std::lock_guard<std::mutex> l(s.command_m);
    if (s.held.exchange(true)) return;
    detail::publishZero();
  }
  log::info("ros", why + ": zero cmd_vel sent; the robot stays stopped until the next goal");
}

void release() {
  State& s = state();
  std::lock_guard<std::mutex> l(s.command_m);
  s.held = false;
}

void resetFault() {
  State& s = state();
  std::lock_guard<std::mutex> l(s.mutex);
  if (!s.tripped) return;
  log::info("ros", "fault cleared for a new goal", {{"fault", s.fault}});
  s.fault.clear();
  s.tripped = false;
}

void wakeOnFrames(double min_gap_s) {
  state().wake_gap_s = min_gap_s;
}

std::shared_ptr<hw::Clock> clock() {
  static auto c = std::make_shared<RosClock>();
  return c;
}

bool waitForTime(double timeout_s) {
  const double t0 = detail::wallNow();
  while (::ros::Time::now().isZero()) {
    if (detail::wallNow() - t0 > timeout_s || g_signal) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

bool lookupCameraMount(const std::string& base_frame, const std::string& camera_frame,
                       double timeout_s, sketchnav::CameraMount& out) {
  State& s = state();
  if (!s.tf || camera_frame.empty()) return false;
  geometry_msgs::TransformStamped t;
  const double t0 = detail::wallNow();
  for (;;) {
    try {
      t = s.tf->lookupTransform(base_frame, camera_frame, ::ros::Time(0));
      break;
    } catch (const std::exception&) {
      if (detail::wallNow() - t0 > timeout_s || g_signal) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
  out = detail::opticalMount(t.transform);
  return true;
}

namespace {
template <class Msg>
std::string frameOf(const std::string& topic, double timeout_s) {
  auto frame = std::make_shared<std::pair<std::mutex, std::string>>();
  auto got = std::make_shared<std::atomic<bool>>(false);
  boost::function<void(const boost::shared_ptr<const Msg>&)> cb =
      [frame, got](const boost::shared_ptr<const Msg>& m) {
        std::lock_guard<std::mutex> l(frame->first);
        frame->second = m->header.frame_id;
        *got = true;
      };
  auto sub = detail::nodeHandle().subscribe<Msg>(topic, 1, cb);
  const double t0 = detail::wallNow();
  while (!*got && detail::wallNow() - t0 < timeout_s && !g_signal)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  sub.shutdown();
  std::lock_guard<std::mutex> l(frame->first);
  return frame->second;
}
}  // namespace

std::string imageFrame(const std::string& topic, double timeout_s, const std::string& transport) {
  return transport == "compressed"
             ? frameOf<sensor_msgs::CompressedImage>(topic + "/compressed", timeout_s)
             : frameOf<sensor_msgs::Image>(topic, timeout_s);
}

struct JsonPublisher::Impl {
  ::ros::Publisher pub;
};

JsonPublisher::JsonPublisher(const std::string& topic, bool latch, int queue)
    : impl_(std::make_unique<Impl>()) {
  detail::nodeHandle();  // the node is up
  // "~name" is private: NodeHandle methods take it only through a "~" handle.
  ::ros::NodeHandle nh(topic.rfind("~", 0) == 0 ? "~" : "");
  impl_->pub = nh.advertise<std_msgs::String>(topic.rfind("~", 0) == 0 ? topic.substr(1) : topic,
                                              queue, latch);
}
JsonPublisher::~JsonPublisher() = default;

void JsonPublisher::publish(const Json& j) {
  std_msgs::String m;
  m.data = j.dump();
  impl_->pub.publish(m);
}

}  // namespace sketchnav::ros
