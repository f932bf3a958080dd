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

#include "sketchnav/core/error.h"
#include "sketchnav/core/log.h"
#include "sketchnav/hw/registry.h"
#include "sketchnav/ros/bag.h"

namespace sketchnav::ros {
namespace {

const std::string kImage = "sensor_msgs/Image";
const std::string kCompressed = "sensor_msgs/CompressedImage";

class BagCamera final : public hw::Camera {
 public:
  explicit BagCamera(const Uri& u) : uri_(u.text) {
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
    // The camera_info beside the image topic (".../image_raw" -> ".../camera_info").
    std::string info = u.param("info", "");
    if (info.empty()) {
      const auto slash = topic.rfind('/');
      info =
          (slash == std::string::npos ? std::string() : topic.substr(0, slash + 1)) + "camera_info";
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

  hw::GrabStatus grab(hw::Frame& frame, double) override {
    std::lock_guard<std::mutex> l(m_);
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
      if (!have_t0_) {
        t0_ = stamp.toSec();
        have_t0_ = true;
      }
      if (!have_info_ && !sized_) {
        intr_ = hw::Intrinsics::fromFov(img.cols, img.rows, hfov_);
        sized_ = true;
      }
      frame.image = img;
      frame.stamp = stamp.toSec() - t0_;
      frame.seq = ++seq_;
      frame.source = topic_ + "#" + std::to_string(index_);
      ++st_.received;
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
  mutable std::mutex m_;
  std::string uri_, topic_;
  rosbag::Bag bag_;
  std::unique_ptr<rosbag::View> view_;
  rosbag::View::iterator it_;
  double hfov_ = 0, t0_ = 0;
  bool have_t0_ = false, have_info_ = false, sized_ = false;
  std::uint64_t seq_ = 0, index_ = 0;
  hw::Intrinsics intr_;
  hw::DeviceStats st_;
};

}  // namespace

void registerBagDriver() {
  static std::once_flag once;
  std::call_once(once, [] {
    hw::Registry::instance().addCamera(
        "bag",
        [](const Uri& u, hw::DeviceContext&) -> std::unique_ptr<hw::Camera> {
          return std::make_unique<BagCamera>(u);
        },
        {"topic", "info", "hfov_deg"});
  });
}

}  // namespace sketchnav::ros
