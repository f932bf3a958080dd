#include "sketchnav/nav/safety.h"

#include <algorithm>
#include <cstdio>

#include "sketchnav/core/config.h"

namespace sketchnav::nav {

void SafetyParams::validate() const {
  require(camera_timeout_s > 0 && camera_timeout_s <= 5, "nav.safety.camera_timeout_s",
          "must be in (0, 5] s");
  require(range_timeout_s > 0 && range_timeout_s <= 5, "nav.safety.range_timeout_s",
          "must be in (0, 5] s");
  require(odom_timeout_s > 0 && odom_timeout_s <= 5, "nav.safety.odom_timeout_s",
          "must be in (0, 5] s");
}

const char* toString(Fault f) {
  switch (f) {
    case Fault::CameraStale:
      return "camera_stale";
    case Fault::RangeStale:
      return "range_stale";
    case Fault::OdometryStale:
      return "odometry_stale";
    case Fault::BaseLinkLost:
      return "base_link_lost";
    case Fault::Exception:
      return "exception";
    default:
      return "none";
  }
}

SafetySupervisor::SafetySupervisor(SafetyParams params) : params_(params) {
  params_.validate();
}

void SafetySupervisor::start(double now) {
  start_ = now;
}
void SafetySupervisor::cameraFrame(double s) {
  camera_ = std::max(camera_, s);
}
void SafetySupervisor::rangeScan(double s) {
  range_ = std::max(range_, s);
}
void SafetySupervisor::odometry(double s) {
  odom_ = std::max(odom_, s);
}

SafetyStatus SafetySupervisor::check(double now, bool base_ok) const {
  auto age = [&](double last) { return now - std::max(last, start_); };
  auto fmt = [](const char* what, double a) {
    char buf[96];
    std::snprintf(buf, sizeof buf, "%s: no data for %.0f ms", what, 1000 * a);
    return std::string(buf);
  };
  if (!base_ok) return {Fault::BaseLinkLost, "base link lost"};
  if (age(odom_) > params_.odom_timeout_s)
    return {Fault::OdometryStale, fmt("odometry stale", age(odom_))};
  if (params_.require_range && age(range_) > params_.range_timeout_s)
    return {Fault::RangeStale, fmt("range data stale", age(range_))};
  if (params_.require_camera && age(camera_) > params_.camera_timeout_s)
    return {Fault::CameraStale, fmt("camera stale", age(camera_))};
  return {};
}

}  // namespace sketchnav::nav
