#include "sketchnav/servo/turn_law.h"

#include <visp3/core/vpHomogeneousMatrix.h>
#include <visp3/core/vpMatrix.h>
#include <visp3/core/vpRotationMatrix.h>
#include <visp3/core/vpTranslationVector.h>
#include <visp3/core/vpVelocityTwistMatrix.h>
#include <visp3/robot/vpUnicycle.h>
#include <visp3/visual_features/vpFeaturePoint.h>
#include <visp3/vs/vpServo.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "sketchnav/core/config.h"

namespace sketchnav::servo {

const char* toString(Turn t) {
  switch (t) {
    case Turn::Left:
      return "Left";
    case Turn::Right:
      return "Right";
    default:
      return "Straight";
  }
}

void TurnLawParams::validate() const {
  require(std::isfinite(lambda) && lambda > 0, "servo.lambda", "must be > 0");
  require(std::isfinite(v_forward) && v_forward >= 0, "servo.v_forward", "must be >= 0");
  require(std::isfinite(max_w) && max_w > 0, "servo.max_w", "must be > 0");
  require(std::isfinite(dead_band) && dead_band >= 0 && dead_band < 1, "servo.dead_band",
          "must be in [0, 1)");
  require(std::isfinite(camera_x_m) && std::abs(camera_x_m) < 5, "robot.camera.x_m",
          "must be a finite offset below 5 m");
  require(std::isfinite(camera_z_m) && std::abs(camera_z_m) < 5, "robot.camera.z_m",
          "must be a finite offset below 5 m");
  require(std::isfinite(default_depth_m) && default_depth_m > 0.05, "servo.default_depth_m",
          "must be > 0.05 m");
}

namespace {
// The unicycle of ViSP (vpUnicycle, as vpPioneer sets it up) with the camera mounted
// looking forward at (camera_x_m, 0, camera_z_m) in the robot frame (x forward, y left, z up).
class MountedUnicycle : public vpUnicycle {
 public:
  MountedUnicycle(double cam_x, double cam_z) {
    // Robot axes seen from the camera optical frame (z forward, x right, y down):
    // robot x = camera z, robot y = camera -x, robot z = camera -y.
    vpRotationMatrix cRe;
    cRe[0][0] = 0;
    cRe[0][1] = -1;
    cRe[0][2] = 0;
    cRe[1][0] = 0;
    cRe[1][1] = 0;
    cRe[1][2] = -1;
    cRe[2][0] = 1;
    cRe[2][1] = 0;
    cRe[2][2] = 0;
    // The robot origin expressed in the camera frame.
    const vpTranslationVector cte(0, cam_z, -cam_x);
    set_cMe(vpHomogeneousMatrix(cte, cRe));
    // Velocity twist at the wheel-axis midpoint: q = (v_x, w_z) -> (v, omega) in e.
    vpMatrix eJe(6, 2, 0.0);
    eJe[0][0] = 1;
    eJe[5][1] = 1;
    set_eJe(eJe);
  }
};
}  // namespace

struct TurnLaw::Impl {
  MountedUnicycle robot;
  vpServo task;
  vpFeaturePoint s, sd;
  vpMatrix eJe_w;  // the yaw-rate column only: the forward speed is not servoed

  Impl(const TurnLawParams& p) : robot(p.camera_x_m, p.camera_z_m), eJe_w(6, 1, 0.0) {
    eJe_w[5][0] = 1;
    task.setServo(vpServo::EYEINHAND_L_cVe_eJe);
    task.setInteractionMatrixType(vpServo::CURRENT, vpServo::PSEUDO_INVERSE);
    task.setLambda(p.lambda);
    task.set_cVe(robot.get_cVe());
    task.set_eJe(eJe_w);
    s.buildFrom(0, 0, p.default_depth_m);
    sd.buildFrom(0, 0, p.default_depth_m);
    task.addFeature(s, sd, vpFeaturePoint::selectX());
  }
};

TurnLaw::TurnLaw(TurnLawParams params) : params_(params) {
  params_.validate();
  impl_ = std::make_unique<Impl>(params_);
}
TurnLaw::~TurnLaw() = default;
TurnLaw::TurnLaw(TurnLaw&&) noexcept = default;
TurnLaw& TurnLaw::operator=(TurnLaw&&) noexcept = default;

std::array<double, 2> TurnLaw::featureJacobian(double x, double y, double depth_m) const {
  vpFeaturePoint p;
  p.buildFrom(x, y, depth_m);
  const vpMatrix J = p.interaction(vpFeaturePoint::selectX()) * vpMatrix(impl_->robot.get_cVe()) *
                     impl_->robot.get_eJe();
  return {J[0][0], J[0][1]};
}

TurnCommand TurnLaw::compute(double x_t, double x_d, double depth_m) const {
  if (!std::isfinite(x_t) || !std::isfinite(x_d))
    throw std::invalid_argument("TurnLaw::compute: non-finite feature");
  const double Z = (std::isfinite(depth_m) && depth_m > 0.05) ? depth_m : params_.default_depth_m;
  TurnCommand c;
  c.v = params_.v_forward;
  c.error = x_t - x_d;
  if (std::abs(c.error) <= params_.dead_band) return c;  // Straight: keep heading

  impl_->s.buildFrom(x_t, 0, Z);
  impl_->sd.buildFrom(x_d, 0, Z);
  double w = impl_->task.computeControlLaw()[0];  // -lambda J_w^+ e (ViSP)
  if (params_.feed_forward) {
    // e_dot = J_v v + J_w w: remove what the forward motion alone would do to x.
    const auto J = featureJacobian(x_t, 0, Z);
    if (std::abs(J[1]) > 1e-9) w -= J[0] * c.v / J[1];
  }
  if (std::abs(w) > params_.max_w) {
    w = std::copysign(params_.max_w, w);
    c.saturated = true;
  }
  c.w = w;
  if (w > 0) c.state = Turn::Left;
  if (w < 0) c.state = Turn::Right;
  c.radius_m = (w == 0) ? std::numeric_limits<double>::infinity() : c.v / std::abs(w);
  return c;
}

namespace {
double median(std::vector<double> v) {
  const size_t n = v.size();
  std::nth_element(v.begin(), v.begin() + n / 2, v.end());
  double m = v[n / 2];
  if (n % 2 == 0) m = 0.5 * (m + *std::max_element(v.begin(), v.begin() + n / 2));
  return m;
}
}  // namespace

Offset robustOffset(const std::vector<double>& x_t, const std::vector<double>& x_d) {
  Offset o;
  if (x_t.empty() || x_t.size() != x_d.size()) return o;
  std::vector<double> d(x_t.size());
  for (size_t i = 0; i < d.size(); ++i) d[i] = x_t[i] - x_d[i];
  o.x_t = median(x_t);
  o.x_d = o.x_t - median(d);
  return o;
}

namespace {
// The robot's cruise speed, "nav.v_cruise" (bound again in nav::DriveParams, which validates it
// the same way): servoing keeps it.
struct Cruise {
  double v_cruise = 0.30;  // [m/s]
  template <class B>
  void bind(B& b) {
    b("v_cruise", v_cruise);
  }
  void validate() const {
    require(v_cruise > 0 && v_cruise <= 2, "nav.v_cruise", "must be in (0, 2] m/s");
  }
};
}  // namespace

TurnLawParams turnLawParamsFrom(const Config& config) {
  rejectRenamed(config, "servo.v_forward", "nav.v_cruise",
                "servoing keeps the robot's cruise speed");
  TurnLawParams p;
  applyConfig(p, config, "servo");
  p.setCamera(cameraMountFrom(config));
  Cruise cruise;
  applyConfig(cruise, config, "nav");
  p.v_forward = cruise.v_cruise;
  p.validate();
  return p;
}

}  // namespace sketchnav::servo
