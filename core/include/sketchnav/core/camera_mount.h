#pragma once
// Where the camera sits on the robot: one set of settings ("robot.camera.*") that feeds the
// servo law (its position: the interaction matrix of a camera ahead of the wheel axis),
// perception (its pan and tilt: the bearing and elevation of what it sees) and, through them,
// the executive. Robot frame per REP 103 (x forward, y left, z up), origin on the wheel axis.
#include <string>

#include "sketchnav/core/config.h"

namespace sketchnav {

struct CameraMount {
  double x_m = 0.13;  // [m] optical centre ahead of the wheel axis
  double z_m = 0.30;  // [m] optical centre above the wheel axis
  double yaw = 0;     // [rad] pan, counter-clockwise positive (0 = looking straight ahead)
  double pitch = 0;   // [rad] tilt, up positive
  template <class B>
  void bind(B& b) {
    b("x_m", x_m);
    b("z_m", z_m);
    b("yaw", yaw);
    b("pitch", pitch);
  }
  /// Throws InputError naming the field ("robot.camera.x_m = 9: ...").
  void validate() const;
};

/// The settings prefix of the camera mount.
inline const char* cameraMountPrefix() {
  return "robot.camera";
}

/// The camera mount from `config` ("robot.camera.*") over the defaults, validated. A key of the
/// mount's earlier names (servo.camera_x_m, servo.camera_z_m, nav.perception.camera_yaw,
/// nav.perception.camera_pitch) is an InputError naming the new key: the same quantity has one
/// name.
CameraMount cameraMountFrom(const Config& config);

/// Each earlier name of a mount setting and its name now ("servo.camera_x_m" ->
/// "robot.camera.x_m"), for readers of files written before the rename (recordings' run info).
const std::vector<std::pair<std::string, std::string>>& cameraMountRenames();

}  // namespace sketchnav
