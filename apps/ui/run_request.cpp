// The run page's request bodies (run_request.h), apart from run_api.cpp so they build without
// the navigation stack (the fuzzer, fuzz/entry_webui.cpp, links only these).
#include "run_request.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <regex>
#include <vector>

#include "sketchnav/core/error.h"
#include "sketchnav/core/input_file.h"

namespace sketchnav::ui {

// ---- request -------------------------------------------------------------------------------

namespace {
// A field the request does not take is an error like an unknown setting: a misspelt "sede"
// ran with seed 1 without a word.
void requireKnownFields(const Json& j, const std::string& what,
                        const std::vector<std::string>& known) {
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (std::find(known.begin(), known.end(), it.key()) != known.end()) continue;
    throw InputError(what + ": unknown field '" + clipForMessage(it.key()) + "' (did you mean '" +
                     closestKey(it.key(), known) + "'?)");
  }
}
}  // namespace

RunRequest RunRequest::fromJson(const Json& j) {
  if (!j.is_object()) throw InputError("run request: expected a JSON object");
  requireKnownFields(j, "run request",
                     {"world", "sketch", "seed", "max_time_s", "mode", "robot", "camera", "laser",
                      "sonar", "camera_only"});
  RunRequest r;
  auto str = [&](const char* key, std::string& out) {
    if (!j.contains(key) || j[key].is_null()) return;
    if (!j[key].is_string())
      throw InputError(std::string("run request: '") + key + "' must be a string");
    out = j[key].get<std::string>();
    if (out.size() > 500) throw InputError(std::string("run request: '") + key + "' is too long");
  };
  str("world", r.world);
  str("sketch", r.sketch);
  str("robot", r.robot);
  str("camera", r.camera);
  str("laser", r.laser);
  str("sonar", r.sonar);
  if (j.contains("seed")) {
    // Range-checked as a 64-bit value: get<int>() would wrap 4294967297 to seed 1.
    const Json& v = j["seed"];
    const bool ok = v.is_number_unsigned() ? v.get<std::uint64_t>() <= INT_MAX
                    : v.is_number_integer()
                        ? v.get<std::int64_t>() >= 0 && v.get<std::int64_t>() <= INT_MAX
                        : false;
    if (!ok) throw InputError("run request: 'seed' must be an integer 0..2147483647");
    r.seed = v.get<int>();
  }
  if (j.contains("max_time_s")) {
    if (!j["max_time_s"].is_number() || !(j["max_time_s"].get<double>() >= 0))
      throw InputError("run request: 'max_time_s' must be a number >= 0");
    r.max_time_s = j["max_time_s"].get<double>();
  }
  if (j.contains("camera_only")) {
    if (!j["camera_only"].is_boolean())
      throw InputError("run request: 'camera_only' must be true or false");
    r.camera_only = j["camera_only"].get<bool>();
  }
  std::string mode;
  str("mode", mode);
  if (!mode.empty() && mode != "sim" && mode != "hardware" && mode != "camera")
    throw InputError("run request: 'mode' must be \"sim\", \"hardware\" or \"camera\"");
  if (r.camera_only || mode == "camera") {
    if (r.camera.empty()) throw InputError("run request: 'camera' URI is required for camera only");
    r.camera_only = true;
    return r;
  }
  // Any device field present (even empty) asks for the real robot: never fall back to a
  // simulated run because the fields were left blank.
  bool asks_robot = mode == "hardware";
  for (const char* k : {"robot", "camera", "laser", "sonar"})
    if (j.contains(k) && !j[k].is_null()) asks_robot = true;
  if (mode == "sim" && r.hardware())
    throw InputError("run request: device URIs given for a simulated run ('mode': \"sim\")");
  if (asks_robot && r.robot.empty())
    throw InputError("run request: 'robot' URI is required for a run on the robot");
  if (!r.hardware() && r.world.empty())
    throw InputError("run request: 'world' is required for a simulated run");
  if (r.hardware() && r.robot.empty())
    throw InputError("run request: 'robot' URI is required with hardware devices");
  return r;
}

Json RunRequest::toJson() const {
  Json j = {{"seed", seed}, {"max_time_s", max_time_s}};
  if (camera_only) {
    j["mode"] = "camera";
    j["camera"] = camera;
  } else if (hardware()) {
    j["mode"] = "hardware";
    j["robot"] = robot;
    j["camera"] = camera;
    j["laser"] = laser;
    j["sonar"] = sonar;
  } else {
    j["mode"] = "sim";
    j["world"] = world;
  }
  j["sketch"] = sketch;
  return j;
}

CaptureRequest CaptureRequest::fromJson(const Json& j) {
  if (!j.is_object()) throw InputError("capture: expected a JSON object");
  requireKnownFields(j, "capture", {"class", "box"});
  if (!j.contains("class") || !j["class"].is_string())
    throw InputError("capture: 'class' (a landmark class name) is required");
  std::optional<cv::Rect> box;
  if (j.contains("box") && !j["box"].is_null()) {
    const Json& b = j["box"];
    if (!b.is_array() || b.size() != 4)
      throw InputError("capture: 'box' must be [x, y, width, height] in frame pixels");
    // Bounded before lround() / int: 1e300 would come back as an unspecified pixel.
    for (const auto& v : b)
      if (!v.is_number() || !(std::abs(v.get<double>()) <= 1e6))
        throw InputError("capture: 'box' values must be numbers of pixels (|v| <= 1000000)");
    box = cv::Rect(static_cast<int>(std::lround(b[0].get<double>())),
                   static_cast<int>(std::lround(b[1].get<double>())),
                   static_cast<int>(std::lround(b[2].get<double>())),
                   static_cast<int>(std::lround(b[3].get<double>())));
  }
  return {j["class"].get<std::string>(), box};
}

std::string safeClassName(const std::string& name) {
  static const std::regex ok(R"([A-Za-z0-9_][A-Za-z0-9_. -]{0,79})");
  if (!std::regex_match(name, ok) || name.find("..") != std::string::npos || name.back() == ' ' ||
      name.back() == '.')
    throw InputError("capture: class name '" + name.substr(0, 100) +
                     "' is not allowed (letters, digits, '_', '-', '.', spaces; at most 80)");
  return name;
}

}  // namespace sketchnav::ui
