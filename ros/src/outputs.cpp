// What `sketchnav ros nav` shows of its work (outputs.h).
#include <cv_bridge/cv_bridge.h>
#include <diagnostic_msgs/DiagnosticArray.h>
#include <geometry_msgs/PoseStamped.h>
#include <nav_msgs/Path.h>
#include <ros/ros.h>
#include <sensor_msgs/Image.h>
#include <tf2/LinearMath/Quaternion.h>
#include <visualization_msgs/MarkerArray.h>
#ifdef SKETCHNAV_HAVE_DIAGNOSTIC_UPDATER
#include <diagnostic_updater/diagnostic_updater.h>
#endif
#ifdef SKETCHNAV_HAVE_IMAGE_TRANSPORT
#include <image_transport/image_transport.h>
#endif

#include <cmath>
#include <cstdio>

#include "internal.h"
#include "sketchnav/ros/outputs.h"

namespace sketchnav::ros {
namespace {

geometry_msgs::Quaternion yawQuat(double theta) {
  tf2::Quaternion q;
  q.setRPY(0, 0, theta);
  geometry_msgs::Quaternion g;
  g.x = q.x();
  g.y = q.y();
  g.z = q.z();
  g.w = q.w();
  return g;
}

::ros::Time rosTime(double t) {
  return t > 0 ? ::ros::Time(t) : ::ros::Time::now();
}

// One status per input (age against its limit) and one for the safety stop.
template <class S>
void fillInputs(S& stat, double now) {
  detail::State& s = detail::state();
  std::vector<std::shared_ptr<detail::Input>> inputs;
  double limit;
  {
    std::lock_guard<std::mutex> l(s.mutex);
    inputs = s.inputs;
    limit = s.params.stale_timeout_s;
  }
  bool stale = false;
  char b[64];
  std::snprintf(b, sizeof b, "%.3f", limit);
  stat.add("stale_timeout_s", b);
  for (const auto& in : inputs) {
    const double last = in->wall_last;
    const double age = last < 0 ? -1 : now - last;
    std::snprintf(b, sizeof b, "%.3f", age);
    stat.add(in->what + " (" + in->topic + ") age_s", last < 0 ? "no message yet" : b);
    if (age > limit) stale = true;
  }
  stat.add("inputs", std::to_string(inputs.size()));
  if (stale) stat.level = 1;
}

}  // namespace

struct NavOutputs::Impl {
  std::string frame;
  ::ros::Publisher pose, route, marks, image_plain;
#ifdef SKETCHNAV_HAVE_IMAGE_TRANSPORT
  std::unique_ptr<image_transport::ImageTransport> it;
  image_transport::Publisher image_it;
#endif
  std::mutex m;
  std::string status = "idle";
#ifdef SKETCHNAV_HAVE_DIAGNOSTIC_UPDATER
  std::unique_ptr<diagnostic_updater::Updater> updater;
#else
  ::ros::Publisher diag;
#endif
  std::thread diag_thread;
  std::atomic<bool> stop{false};

  // The node's diagnostics, once a second: the route state, the safety stop and each input.
  template <class S>
  void fill(S& stat) {
    const bool tripped = detail::state().tripped;
    std::string st;
    {
      std::lock_guard<std::mutex> l(m);
      st = status;
    }
    stat.level = tripped ? 2 : 0;
    stat.message = tripped ? "safety stop: " + fault() : st;
    stat.add("route", st);
    stat.add("stopped", tripped ? "true" : "false");
    stat.add("fault", fault());
    fillInputs(stat, detail::wallNow());
    if (stat.level == 1) stat.message = st + " (an input is older than its limit)";
  }
};

namespace {
// The level / message / values of a DiagnosticStatus without diagnostic_updater.
struct PlainStatus {
  int level = 0;
  std::string message;
  std::vector<diagnostic_msgs::KeyValue> values;
  void add(const std::string& k, const std::string& v) {
    diagnostic_msgs::KeyValue kv;
    kv.key = k;
    kv.value = v;
    values.push_back(kv);
  }
};
#ifdef SKETCHNAV_HAVE_DIAGNOSTIC_UPDATER
struct WrapperStatus {
  diagnostic_updater::DiagnosticStatusWrapper& w;
  int level = 0;
  std::string message;
  void add(const std::string& k, const std::string& v) { w.add(k, v); }
};
#endif
}  // namespace

NavOutputs::NavOutputs(const std::string& odom_frame) : impl_(std::make_unique<Impl>()) {
  detail::nodeHandle();
  Impl& I = *impl_;
  I.frame = odom_frame;
  ::ros::NodeHandle pnh("~");
  I.pose = pnh.advertise<geometry_msgs::PoseStamped>("pose", 10);
  I.route = pnh.advertise<nav_msgs::Path>("route", 1, true);
  I.marks = pnh.advertise<visualization_msgs::MarkerArray>("landmarks", 1, true);
#ifdef SKETCHNAV_HAVE_IMAGE_TRANSPORT
  I.it = std::make_unique<image_transport::ImageTransport>(pnh);
  I.image_it = I.it->advertise("image", 1);
#else
  I.image_plain = pnh.advertise<sensor_msgs::Image>("image", 1);
#endif
#ifdef SKETCHNAV_HAVE_DIAGNOSTIC_UPDATER
  I.updater = std::make_unique<diagnostic_updater::Updater>();
  I.updater->setHardwareID("sketchnav");
  I.updater->add("sketchnav navigation", [&I](diagnostic_updater::DiagnosticStatusWrapper& w) {
    WrapperStatus s{w, 0, ""};
    I.fill(s);
    w.summary(static_cast<unsigned char>(s.level), s.message);
  });
  I.diag_thread = std::thread([&I] {
    while (!I.stop) {
      I.updater->update();  // publishes at its period (1 s)
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  });
#else
  I.diag = detail::nodeHandle().advertise<diagnostic_msgs::DiagnosticArray>("/diagnostics", 5);
  I.diag_thread = std::thread([&I] {
    double next = 0;
    while (!I.stop) {
      if (detail::wallNow() >= next) {
        next = detail::wallNow() + 1.0;
        PlainStatus s;
        I.fill(s);
        diagnostic_msgs::DiagnosticArray a;
        a.header.stamp = ::ros::Time::now();
        diagnostic_msgs::DiagnosticStatus st;
        st.level = static_cast<unsigned char>(s.level);
        st.name = ::ros::this_node::getName().substr(1) + ": sketchnav navigation";
        st.message = s.message;
        st.hardware_id = "sketchnav";
        st.values = s.values;
        a.status.push_back(st);
        I.diag.publish(a);
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
  });
#endif
}

NavOutputs::~NavOutputs() {
  impl_->stop = true;
  if (impl_->diag_thread.joinable()) impl_->diag_thread.join();
}

bool NavOutputs::wantImage() const {
#ifdef SKETCHNAV_HAVE_IMAGE_TRANSPORT
  return impl_->image_it.getNumSubscribers() > 0;
#else
  return impl_->image_plain.getNumSubscribers() > 0;
#endif
}

void NavOutputs::image(const cv::Mat& bgr, double stamp, const std::string& frame_id) {
  std_msgs::Header h;
  h.stamp = rosTime(stamp);
  h.frame_id = frame_id;
  const sensor_msgs::ImagePtr m = cv_bridge::CvImage(h, "bgr8", bgr).toImageMsg();
#ifdef SKETCHNAV_HAVE_IMAGE_TRANSPORT
  impl_->image_it.publish(m);
#else
  impl_->image_plain.publish(m);
#endif
}

void NavOutputs::pose(double x, double y, double theta, double stamp) {
  geometry_msgs::PoseStamped p;
  p.header.stamp = rosTime(stamp);
  p.header.frame_id = impl_->frame;
  p.pose.position.x = x;
  p.pose.position.y = y;
  p.pose.orientation = yawQuat(theta);
  impl_->pose.publish(p);
}

void NavOutputs::route(const std::vector<std::pair<double, double>>& pts, double stamp) {
  nav_msgs::Path path;
  path.header.stamp = rosTime(stamp);
  path.header.frame_id = impl_->frame;
  for (size_t i = 0; i < pts.size(); ++i) {
    geometry_msgs::PoseStamped p;
    p.header = path.header;
    p.pose.position.x = pts[i].first;
    p.pose.position.y = pts[i].second;
    const size_t j = i + 1 < pts.size() ? i + 1 : i;
    const size_t k = j == i && i > 0 ? i - 1 : i;
    const double heading =
        j != k ? std::atan2(pts[j].second - pts[k].second, pts[j].first - pts[k].first) : 0.0;
    p.pose.orientation = yawQuat(heading);
    path.poses.push_back(p);
  }
  impl_->route.publish(path);
}

void NavOutputs::landmarks(const std::vector<LandmarkMark>& marks, double stamp) {
  visualization_msgs::MarkerArray a;
  visualization_msgs::Marker clear;
  clear.action = visualization_msgs::Marker::DELETEALL;
  a.markers.push_back(clear);
  int id = 0;
  for (const auto& lm : marks) {
    visualization_msgs::Marker m;
    m.header.stamp = rosTime(stamp);
    m.header.frame_id = impl_->frame;
    m.ns = "landmarks";
    m.id = id++;
    m.type = visualization_msgs::Marker::CYLINDER;
    m.action = visualization_msgs::Marker::ADD;
    m.pose.position.x = lm.x;
    m.pose.position.y = lm.y;
    m.pose.position.z = 0.25;
    m.pose.orientation.w = 1;
    m.scale.x = m.scale.y = 0.2;
    m.scale.z = 0.5;
    // pending grey, tracking yellow, passed green, missed red
    m.color.a = 0.9f;
    m.color.r = lm.state == "missed" || lm.state == "tracking" ? 1.0f : 0.5f;
    m.color.g = lm.state == "passed" || lm.state == "tracking" ? 0.9f : 0.5f;
    m.color.b = lm.state == "pending" ? 0.5f : 0.1f;
    a.markers.push_back(m);
    visualization_msgs::Marker t = m;
    t.ns = "landmark_ids";
    t.type = visualization_msgs::Marker::TEXT_VIEW_FACING;
    t.text = lm.id;
    t.pose.position.z = 0.7;
    t.scale.x = t.scale.y = 0;
    t.scale.z = 0.2;
    t.color.r = t.color.g = t.color.b = 1.0f;
    a.markers.push_back(t);
  }
  impl_->marks.publish(a);
}

void NavOutputs::status(const std::string& s) {
  std::lock_guard<std::mutex> l(impl_->m);
  impl_->status = s;
}

}  // namespace sketchnav::ros
