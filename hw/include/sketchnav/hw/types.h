#pragma once
// Plain data exchanged with devices. Units SI; frames per REP 103 (doc/conventions.md):
// robot x forward, y left, z up; camera optical frame z forward, x right, y down.
#include <opencv2/core/mat.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace sketchnav::hw {

/// Pinhole intrinsics in pixels of the delivered image (no distortion: frames are delivered
/// undistorted or the distortion is negligible for the servo's horizontal offset).
struct Intrinsics {
  int width = 640;
  int height = 480;
  double fx = 554.0;  // [px] (60 deg horizontal field of view at 640 px)
  double fy = 554.0;  // [px]
  double cx = 319.5;  // [px]
  double cy = 239.5;  // [px]

  /// Intrinsics for a given image size and horizontal field of view [rad].
  static Intrinsics fromFov(int width, int height, double hfov_rad);
  /// Pixel column u -> normalised x = (u - cx) / fx (what the servo law uses).
  double normalisedX(double u) const { return (u - cx) / fx; }
};

/// One camera image. `image` is 8-bit BGR (CV_8UC3), the pipeline's image type.
struct Frame {
  cv::Mat image;
  double stamp = 0.0;  // [s] on the Clock the device was created with
  std::uint64_t seq = 0;
  std::string source;  // file name, device id... (for logs and CSVs)
};

/// 2-D pose in the odometry frame: x, y [m], theta [rad], counter-clockwise positive.
struct Pose2D {
  double x = 0.0;
  double y = 0.0;
  double theta = 0.0;
};

struct Odometry {
  Pose2D pose;         // dead-reckoned pose since the base started
  double v = 0.0;      // measured forward speed [m/s]
  double w = 0.0;      // measured yaw rate [rad/s]
  double stamp = 0.0;  // [s]
};

/// Ranges from a laser scanner or a ring of sonars, in the robot frame.
struct RangeScan {
  enum class Kind { Laser, Sonar };
  Kind kind = Kind::Laser;
  std::vector<float> angles;  // [rad] bearing of each beam in the robot frame, CCW positive
  std::vector<float> ranges;  // [m]; a value >= max_range means "nothing seen"
  float min_range = 0.0f;     // [m]
  float max_range = 0.0f;     // [m]
  float beam_width = 0.0f;    // [rad] cone of a sonar beam (0 for a laser)
  Pose2D mount;               // sensor pose in the robot frame
  double stamp = 0.0;         // [s]
};

/// Health counters every device keeps, reported by `sketchnav probe`.
struct DeviceStats {
  std::uint64_t received = 0;    // frames / messages delivered
  std::uint64_t dropped = 0;     // lost or skipped (e.g. corrupt file)
  std::uint64_t incomplete = 0;  // partially received
  std::string last_error;        // empty when healthy
};

}  // namespace sketchnav::hw
