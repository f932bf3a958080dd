#pragma once
// The bodies of the run page's POST requests (run_api.h): what /api/run/start and
// /api/capture ask for, validated. No navigation types here, so the fuzzer
// (fuzz/entry_webui.cpp) builds them alone.
#include <opencv2/core/types.hpp>

#include <optional>
#include <string>

#include "sketchnav/core/config.h"

namespace sketchnav::ui {

/// What the page asks for. Any of robot/camera/laser/sonar set -> the real robot; otherwise
/// the simulator with `world` (a name in share/worlds or a world file).
struct RunRequest {
  std::string world = "corridor";
  std::string sketch;  // "" = the world's own sketch
  std::string robot, camera, laser, sonar;
  int seed = 1;
  double max_time_s = 0;     // > 0 caps the run
  bool camera_only = false;  // open `camera` only and show its frames (capturing, no driving)
  bool hardware() const {
    return !robot.empty() || !camera.empty() || !laser.empty() || !sonar.empty();
  }
  /// From the POST body; InputError naming the bad field.
  static RunRequest fromJson(const Json& j);
  Json toJson() const;
};

/// What POST /api/capture asks for: {class, box?: [x, y, w, h]}.
struct CaptureRequest {
  std::string class_name;
  std::optional<cv::Rect> box;
  /// From the POST body; InputError naming the bad field.
  static CaptureRequest fromJson(const Json& j);
};

/// A landmark class name a capture may create: letters, digits, '_', '-', '.', ' ', no
/// leading dot or space, at most 80 characters. InputError otherwise.
std::string safeClassName(const std::string& name);

}  // namespace sketchnav::ui
