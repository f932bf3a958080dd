#include "sketchnav/core/camera_mount.h"

#include <cmath>

#include "sketchnav/core/error.h"

namespace sketchnav {

void CameraMount::validate() const {
  require(std::isfinite(x_m) && std::abs(x_m) < 5, "robot.camera.x_m", "must be within 5 m");
  require(std::isfinite(z_m) && std::abs(z_m) < 5, "robot.camera.z_m", "must be within 5 m");
  require(std::isfinite(yaw) && std::abs(yaw) <= M_PI, "robot.camera.yaw",
          "must be in [-pi, pi] rad");
  require(std::isfinite(pitch) && std::abs(pitch) < M_PI / 2, "robot.camera.pitch",
          "must be in (-pi/2, pi/2) rad");
}

const std::vector<std::pair<std::string, std::string>>& cameraMountRenames() {
  static const std::vector<std::pair<std::string, std::string>> r{
      {"servo.camera_x_m", "robot.camera.x_m"},
      {"servo.camera_z_m", "robot.camera.z_m"},
      {"nav.perception.camera_yaw", "robot.camera.yaw"},
      {"nav.perception.camera_pitch", "robot.camera.pitch"}};
  return r;
}

CameraMount cameraMountFrom(const Config& config) {
  for (const auto& [old_key, new_key] : cameraMountRenames())
    rejectRenamed(config, old_key, new_key,
                  "the camera mount is one setting group, robot.camera.*");
  CameraMount m;
  applyConfig(m, config, cameraMountPrefix());
  return m;
}

}  // namespace sketchnav
