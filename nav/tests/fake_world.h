#pragma once
// Test doubles for the executive: a unicycle base on a SimClock, a laser over circular
// obstacles, a camera that delivers blank frames (optionally dropping out), and a perception
// that "sees" landmarks from the true geometry (test-only; `sketchnav run` never does this).
#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "sketchnav/hw/clock.h"
#include "sketchnav/hw/devices.h"
#include "sketchnav/nav/perception.h"

namespace sketchnav::nav::test {

struct Circle {
  Eigen::Vector2d c;
  double r;
};

/// Distance along the ray o + t d (d unit) to the segment a-b; infinity when it misses.
inline double rayToSegment(const Eigen::Vector2d& o, const Eigen::Vector2d& d,
                           const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d e = b - a, q = a - o;
  const double den = d.x() * e.y() - d.y() * e.x();
  if (std::abs(den) < 1e-12) return INFINITY;
  const double t = (q.x() * e.y() - q.y() * e.x()) / den;
  const double u = (q.x() * d.y() - q.y() * d.x()) / den;
  return t > 0 && u >= 0 && u <= 1 ? t : INFINITY;
}

struct Wall {
  Eigen::Vector2d a, b;  // a thin wall from a to b
};

struct FakeWorld {
  std::shared_ptr<hw::SimClock> clock = std::make_shared<hw::SimClock>();
  hw::Pose2D truth;  // world frame; odometry = truth (start frame = world frame here)
  double v = 0, w = 0, t = 0;
  std::vector<Circle> obstacles;
  std::vector<Wall> walls;
  bool stopped_called = false;
  double last_stop_t = -1, last_motion_cmd_t = -1;
  bool link_ok = true;

  void integrate() {
    const double now = clock->now();
    while (t + 1e-12 < now) {
      const double dt = std::min(0.01, now - t);
      truth.x += v * dt * std::cos(truth.theta);
      truth.y += v * dt * std::sin(truth.theta);
      truth.theta += w * dt;
      t += dt;
    }
  }
  double clearance() const {
    double m = 1e9;
    for (const auto& o : obstacles)
      m = std::min(m, (o.c - Eigen::Vector2d(truth.x, truth.y)).norm() - o.r - 0.2);
    const Eigen::Vector2d p(truth.x, truth.y);
    for (const auto& w : walls) {
      const Eigen::Vector2d e = w.b - w.a;
      const double u = std::clamp((p - w.a).dot(e) / e.squaredNorm(), 0.0, 1.0);
      m = std::min(m, (w.a + u * e - p).norm() - 0.2);
    }
    return m;
  }
};

class FakeBase final : public hw::Base {
 public:
  explicit FakeBase(FakeWorld& w) : w_(w) {}
  void command(double v, double w) override {
    w_.integrate();
    w_.v = v;
    w_.w = w;
    if (v != 0 || w != 0) w_.last_motion_cmd_t = w_.clock->now();
  }
  void stop() noexcept override {
    w_.integrate();
    w_.v = w_.w = 0;
    w_.stopped_called = true;
    w_.last_stop_t = w_.clock->now();
  }
  bool odometry(hw::Odometry& o) override {
    w_.integrate();
    o.pose = w_.truth;
    o.stamp = w_.clock->now();
    return true;
  }
  bool ok() const override { return w_.link_ok; }
  hw::DeviceStats stats() const override { return {}; }
  std::string uri() const override { return "fake://base"; }

 private:
  FakeWorld& w_;
};

class FakeLaser final : public hw::RangeSensor {
 public:
  explicit FakeLaser(FakeWorld& w) : w_(w) {}
  bool read(hw::RangeScan& s) override {
    w_.integrate();
    s = {};
    s.kind = hw::RangeScan::Kind::Laser;
    s.min_range = 0.05f;
    s.max_range = 8.0f;
    s.stamp = w_.clock->now();
    for (int i = -120; i <= 120; ++i) {
      const double a = i * M_PI / 180;
      const double ga = w_.truth.theta + a;
      const Eigen::Vector2d o(w_.truth.x, w_.truth.y), d(std::cos(ga), std::sin(ga));
      double best = 8.0;
      for (const auto& c : w_.obstacles) {
        const Eigen::Vector2d oc = c.c - o;
        const double b = oc.dot(d), disc = b * b - (oc.squaredNorm() - c.r * c.r);
        if (disc < 0) continue;
        const double tt = b - std::sqrt(disc);
        if (tt > 0) best = std::min(best, tt);
      }
      for (const auto& wl : w_.walls) best = std::min(best, rayToSegment(o, d, wl.a, wl.b));
      s.angles.push_back(static_cast<float>(a));
      s.ranges.push_back(static_cast<float>(best));
    }
    return true;
  }
  hw::DeviceStats stats() const override { return {}; }
  std::string uri() const override { return "fake://laser"; }

 private:
  FakeWorld& w_;
};

class FakeCamera final : public hw::Camera {
 public:
  FakeCamera(FakeWorld& w, double drop_after = 1e9) : w_(w), drop_after_(drop_after) {}
  hw::GrabStatus grab(hw::Frame& f, double) override {
    if (w_.clock->now() >= drop_after_) return hw::GrabStatus::Timeout;
    f.image = cv::Mat(48, 64, CV_8UC3, cv::Scalar::all(0));
    f.stamp = w_.clock->now();
    f.seq = seq_++;
    return hw::GrabStatus::Ok;
  }
  hw::Intrinsics intrinsics() const override { return hw::Intrinsics{}; }
  hw::DeviceStats stats() const override { return {}; }
  std::string uri() const override { return "fake://camera"; }

 private:
  FakeWorld& w_;
  double drop_after_;
  std::uint64_t seq_ = 0;
};

/// Sees the landmarks in `marks` (true world positions) within 60 deg FOV and 6 m.
struct TrueMark {
  std::string class_name;
  Eigen::Vector2d p;
};
class GeometricPerception final : public Perception {
 public:
  GeometricPerception(FakeWorld& w, std::vector<TrueMark> marks) : w_(w), marks_(marks) {}
  bool throw_now = false;
  Observation observe(const hw::Frame&, const hw::Intrinsics&,
                      const std::vector<std::string>& classes) override {
    if (throw_now) throw std::runtime_error("perception blew up");
    Observation o;
    for (const auto& m : marks_) {
      if (std::find(classes.begin(), classes.end(), m.class_name) == classes.end()) continue;
      const Eigen::Vector2d d = m.p - Eigen::Vector2d(w_.truth.x, w_.truth.y);
      double b = std::atan2(d.y(), d.x()) - w_.truth.theta;
      b = std::atan2(std::sin(b), std::cos(b));
      if (std::abs(b) > 30 * M_PI / 180 || d.norm() > 6) continue;
      Detection det;
      det.class_name = m.class_name;
      det.inliers = 30;
      det.x_t = -std::tan(b);
      det.x_d = 0;
      det.bearing = b;
      o.detections.push_back(det);
    }
    o.timing.total_ms = 1;
    return o;
  }

 private:
  FakeWorld& w_;
  std::vector<TrueMark> marks_;
};

}  // namespace sketchnav::nav::test
