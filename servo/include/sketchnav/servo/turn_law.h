#pragma once
// The image-based servo law of the paper: the robot keeps its forward speed and turns so that
// the matched landmark keypoints come back to where they sit in the landmark's database photo.
//
// Feature: the horizontal normalised coordinate x (doc/conventions.md: x = (u - cx) / fx,
// x > 0 right of the image centre). Current value x_t and desired value x_d are robust
// aggregates (median) over the matched keypoints' inliers. The law is ViSP's eye-in-hand
// law e_dot = -lambda e with the task Jacobian J = L_x cVe eJe of a unicycle (Pioneer-style
// twist and Jacobian); only the yaw rate is servoed, the forward speed is a fixed input whose
// effect on x is fed forward. The continuous yaw rate is discretised into Left / Straight /
// Right with a dead band, as the paper's three action states.
//
// Sign convention (REP 103): w > 0 turns left (CCW). Keypoints right of their database
// position (x_t > x_d) give w < 0: the robot turns right, towards the landmark.
// No ViSP type appears here (pimpl).
#include <array>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "sketchnav/core/camera_mount.h"
#include "sketchnav/core/config.h"

namespace sketchnav::servo {

enum class Turn { Left, Straight, Right };
const char* toString(Turn t);

struct TurnLawParams {
  double lambda = 0.8;  // [1/s] turn-radius gain: larger = sharper turns for an offset
  // [m/s] forward speed kept while servoing: the robot's cruise speed (the "nav.v_cruise"
  // setting, turnLawParamsFrom), not a setting of its own.
  double v_forward = 0.30;
  double max_w = 0.6;       // [rad/s] yaw-rate saturation (also bounds the turn radius)
  double dead_band = 0.02;  // [normalised] |x_t - x_d| below this -> Straight, w = 0
  // The camera's position, from the camera mount (the "robot.camera.*" settings, CameraMount
  // in core/camera_mount.h): not settings of their own.
  double camera_x_m = 0.13;      // [m] camera optical centre ahead of the wheel axis
  double camera_z_m = 0.30;      // [m] camera height above the wheel axis
  double default_depth_m = 2.0;  // [m] landmark depth when no range measurement is given
  bool feed_forward = true;      // compensate the forward motion's effect on x
  template <class B>
  void bind(B& b) {
    b("lambda", lambda);
    b("max_w", max_w);
    b("dead_band", dead_band);
    b("default_depth_m", default_depth_m);
    b("feed_forward", feed_forward);
  }
  /// Throws InputError naming the field ("servo.lambda = -1: must be > 0").
  void validate() const;
  /// Takes the camera's position from the mount.
  void setCamera(const CameraMount& m) {
    camera_x_m = m.x_m;
    camera_z_m = m.z_m;
  }
};

/// The "servo.*" settings of `config`, the camera's position from its mount (robot.camera.*,
/// cameraMountFrom) and the forward speed from nav.v_cruise, validated (InputError naming the
/// field). The old key servo.v_forward is an InputError naming nav.v_cruise.
TurnLawParams turnLawParamsFrom(const Config& config);

struct TurnCommand {
  double v = 0;                                               // [m/s] forward speed
  double w = 0;                                               // [rad/s] yaw rate, CCW positive
  double radius_m = std::numeric_limits<double>::infinity();  // v / |w|; inf when straight
  double error = 0;                                           // x_t - x_d [normalised]
  Turn state = Turn::Straight;
  bool saturated = false;  // |w| was clipped to max_w
};

/// The servo law. One object per run (it keeps the ViSP task); not thread-safe.
class TurnLaw {
 public:
  explicit TurnLaw(TurnLawParams params = {});
  ~TurnLaw();
  TurnLaw(TurnLaw&&) noexcept;
  TurnLaw& operator=(TurnLaw&&) noexcept;

  /// One control step. x_t, x_d: current and desired normalised horizontal coordinate;
  /// depth_m: the landmark's distance along the optical axis if a range sensor gives it
  /// (<= 0 or NaN: params.default_depth_m). Throws std::invalid_argument for non-finite x.
  TurnCommand compute(double x_t, double x_d, double depth_m = 0) const;

  /// The task Jacobian d x / d(v, w) for an image point at normalised (x, y) and depth Z [m]
  /// (L_x cVe eJe, computed by ViSP). Exposed so tests check it against finite differences.
  std::array<double, 2> featureJacobian(double x, double y, double depth_m) const;

  const TurnLawParams& params() const { return params_; }

 private:
  struct Impl;
  TurnLawParams params_;
  std::unique_ptr<Impl> impl_;
};

/// Robust aggregate of x_t - x_d over matched inliers: x_t is the median of the current
/// coordinates and the error the median of the per-match differences (an outlier pair moves
/// neither), x_d = x_t - error. Empty or mismatched input -> NaNs. Normalised coordinates.
struct Offset {
  double x_t = std::numeric_limits<double>::quiet_NaN();
  double x_d = std::numeric_limits<double>::quiet_NaN();
  double error() const { return x_t - x_d; }
};
Offset robustOffset(const std::vector<double>& x_t, const std::vector<double>& x_d);

}  // namespace sketchnav::servo
