// The bag:// camera (bag.h).
#include <cv_bridge/cv_bridge.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/CompressedImage.h>
#include <sensor_msgs/Image.h>
#include <opencv2/imgcodecs.hpp>

#include <cmath>
#include <filesystem>
#include <memory>
#include <mutex>
#include <set>

#include "bag_internal.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/log.h"
#include "sketchnav/drivers/rawlog.h"
#include "sketchnav/hw/registry.h"
#include "sketchnav/ros/bag.h"

namespace sketchnav::ros {
namespace {

const std::string kImage = "sensor_msgs/Image";
const std::string kCompressed = "sensor_msgs/CompressedImage";

class BagCamera final : public hw::Camera {
 public:
  BagCamera(const Uri& u, std::shared_ptr<hw::Clock> clock) : uri_(u.text) {
    const std::string path = u.path;
    if (path.empty() || !std::filesystem::is_regular_file(path))
      throw InputError(u.text + ": no such bag file '" + path + "'");
    try {
      bag_.open(path, rosbag::bagmode::Read);
    } catch (const std::exception& e) {
      throw InputError(u.text + ": cannot be read as a ROS bag (" + e.what() + ")");
    }
    std::string topic = u.param("topic", "");
    {
      rosbag::View all(bag_);
      std::set<std::string> images;
      for (const auto* c : all.getConnections())
        if (c->datatype == kImage || c->datatype == kCompressed) images.insert(c->topic);
      if (topic.empty()) {
        if (images.size() != 1) {
          std::string list;
          for (const auto& t : images) list += (list.empty() ? "" : ", ") + t;
          throw InputError(u.text + ": " +
                           (images.empty()
                                ? std::string("no image topic in the bag")
                                : "several image topics (" + list + "): choose one with ?topic="));
        }
        topic = *images.begin();
      } else if (!images.count(topic)) {
        throw InputError(u.text + ": no sensor_msgs/Image or CompressedImage topic '" + topic +
                         "' in the bag");
      }
    }
    topic_ = topic;
    const double hfov = u.paramDouble("hfov_deg", 60.0);
    if (!(hfov > 0 && hfov < 180)) throw InputError(u.text + ": hfov_deg must be in (0, 180)");
    hfov_ = hfov * M_PI / 180.0;
    // The camera_info beside the image topic (".../image_raw" -> ".../camera_info"; an
    // image_transport topic ".../image_raw/compressed" is beside ".../image_raw").
    std::string info = u.param("info", "");
    if (info.empty()) {
      std::string image = topic;
      const std::string suffix = "/compressed";
      if (image.size() > suffix.size() &&
          image.compare(image.size() - suffix.size(), suffix.size(), suffix) == 0)
        image.resize(image.size() - suffix.size());
      const auto slash = image.rfind('/');
      info =
          (slash == std::string::npos ? std::string() : image.substr(0, slash + 1)) + "camera_info";
    }
    // realtime=1: frames come out at their recorded pace on the run's clock, from the bag's
    // first stamp, in step with the bag:// base and ranges (run --replay).
    if (u.paramInt("realtime", 0) != 0 && clock) {
      clock_ = std::move(clock);
      const BagOrigin o = bagOrigin(path, *clock_);
      t0_bag_ = o.t0_bag;
      t0_clock_ = o.t0_clock;
    }
    rosbag::View iv(bag_, rosbag::TopicQuery(info));
    for (const auto& m : iv) {
      if (auto ci = m.instantiate<sensor_msgs::CameraInfo>()) {
        if (ci->width > 0 && ci->height > 0 && ci->K[0] > 0 && ci->K[4] > 0) {
          intr_.width = ci->width;
          intr_.height = ci->height;
          intr_.fx = ci->K[0];
          intr_.fy = ci->K[4];
          intr_.cx = ci->K[2];
          intr_.cy = ci->K[5];
          have_info_ = true;
        }
        break;
      }
    }
    view_ = std::make_unique<rosbag::View>(bag_, rosbag::TopicQuery(topic_));
    it_ = view_->begin();
  }

  hw::GrabStatus grab(hw::Frame& frame, double timeout_s) override {
    std::lock_guard<std::mutex> l(m_);
    if (held_) {
      // A frame that was not yet due at the last call.
      if (!due(held_frame_, timeout_s)) return hw::GrabStatus::Timeout;
      held_ = false;
      frame = std::move(held_frame_);
      return hw::GrabStatus::Ok;
    }
    while (it_ != view_->end()) {
      // A copy: the iterator's own instance changes when it moves on.
      const rosbag::MessageInstance m = *it_;
      ++it_;
      ++index_;
      cv::Mat img;
      ::ros::Time stamp = m.getTime();
      std::string why;
      try {
        if (auto im = m.instantiate<sensor_msgs::Image>()) {
          if (!im->header.stamp.isZero()) stamp = im->header.stamp;
          if (im->width == 0 || im->height == 0 ||
              im->data.size() < static_cast<size_t>(im->step) * im->height)
            why = "empty or truncated image";
          else
            img = cv_bridge::toCvCopy(im, "bgr8")->image;
        } else if (auto ci = m.instantiate<sensor_msgs::CompressedImage>()) {
          if (!ci->header.stamp.isZero()) stamp = ci->header.stamp;
          img = cv::imdecode(ci->data, cv::IMREAD_COLOR);
          if (img.empty()) why = "compressed image '" + ci->format + "' does not decode";
        }
      } catch (const std::exception& e) {
        why = e.what();
      }
      if (img.empty()) {
        ++st_.dropped;
        st_.last_error = "message " + std::to_string(index_) + " on " + topic_ + ": " +
                         (why.empty() ? "not an image" : why);
        log::warn("bag", "frame skipped: " + st_.last_error, {{"uri", uri_}});
        continue;
      }
      // A frame stamped like the one before is that frame sent again (a simulator holding its
      // time while a node starts, recorded by rosbag record): replayed once, as it was seen.
      if (have_t0_ && !stamp.isZero() && stamp == last_stamp_) continue;
      last_stamp_ = stamp;
      if (!have_t0_) {
        t0_ = stamp.toSec();
        have_t0_ = true;
      }
      if (!have_info_ && !sized_) {
        intr_ = hw::Intrinsics::fromFov(img.cols, img.rows, hfov_);
        sized_ = true;
      }
      hw::Frame f;
      f.image = img;
      f.stamp = clock_ ? t0_clock_ + (stamp.toSec() - t0_bag_) : stamp.toSec() - t0_;
      f.seq = ++seq_;
      f.source = topic_ + "#" + std::to_string(index_);
      ++st_.received;
      if (!due(f, timeout_s)) {
        held_frame_ = std::move(f);
        held_ = true;
        return hw::GrabStatus::Timeout;
      }
      frame = std::move(f);
      return hw::GrabStatus::Ok;
    }
    return hw::GrabStatus::EndOfStream;
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
  // Paced: waits (a simulated clock jumps) until `f` is due, or `timeout_s` when it is due
  // later than that (false: the caller gets Timeout and the frame on a later call).
  // A frame due within drivers::kReplaySlack of now is due now, stamped now (a bag keeps
  // nanoseconds: 0.44999999999999996 comes back as 0.45).
  bool due(hw::Frame& f, double timeout_s) {
    if (!clock_) return true;
    const double now = clock_->now();
    if (std::abs(f.stamp - now) <= drivers::kReplaySlack) {
      f.stamp = now;
      return true;
    }
    if (f.stamp - now > timeout_s) {
      clock_->sleepUntil(now + timeout_s);
      return false;
    }
    clock_->sleepUntil(f.stamp);
    return true;
  }
  mutable std::mutex m_;
  std::string uri_, topic_;
  rosbag::Bag bag_;
  std::unique_ptr<rosbag::View> view_;
  rosbag::View::iterator it_;
  double hfov_ = 0, t0_ = 0;
  ::ros::Time last_stamp_;
  bool have_t0_ = false, have_info_ = false, sized_ = false;
  std::uint64_t seq_ = 0, index_ = 0;
  hw::Intrinsics intr_;
  hw::DeviceStats st_;
  std::shared_ptr<hw::Clock> clock_;  // null: not paced
  double t0_bag_ = 0, t0_clock_ = 0;
  bool held_ = false;
  hw::Frame held_frame_;
};

}  // namespace

void registerBagDriver() {
  static std::once_flag once;
  std::call_once(once, [] {
    hw::Registry::instance().addCamera(
        "bag",
        [](const Uri& u, hw::DeviceContext& ctx) -> std::unique_ptr<hw::Camera> {
          return std::make_unique<BagCamera>(u, ctx.clock);
        },
        {"topic", "info", "hfov_deg", "realtime"});
    registerBagDevices();
  });
}

}  // namespace sketchnav::ros
