#pragma once
// A 241-beam laser (+-120 deg, 1 deg) over axis-aligned boxes and discs, for the planner's and
// the mover tracker's tests.
#include <cmath>
#include <vector>

#include "sketchnav/hw/types.h"

namespace sketchnav::nav::test {

struct Box {
  double cx, cy, hx, hy;  // centre and half sizes [m], axis-aligned, world frame
};
struct Disc {
  double cx, cy, r;
};

inline hw::RangeScan scanAt(const hw::Pose2D& pose, const std::vector<Box>& boxes,
                            const std::vector<Disc>& discs = {}, double stamp = 0) {
  hw::RangeScan s;
  s.kind = hw::RangeScan::Kind::Laser;
  s.min_range = 0.05f;
  s.max_range = 8.0f;
  s.stamp = stamp;
  for (int i = -120; i <= 120; ++i) {
    const double a = i * M_PI / 180, wa = pose.theta + a;
    const double dx = std::cos(wa), dy = std::sin(wa);
    double best = 8.0;
    for (const auto& b : boxes) {  // slab test
      double t0 = -1e9, t1 = 1e9;
      const double o[2] = {pose.x - b.cx, pose.y - b.cy}, d[2] = {dx, dy}, h[2] = {b.hx, b.hy};
      bool miss = false;
      for (int k = 0; k < 2 && !miss; ++k) {
        if (std::abs(d[k]) < 1e-12) {
          miss = std::abs(o[k]) > h[k];
          continue;
        }
        double ta = (-h[k] - o[k]) / d[k], tb = (h[k] - o[k]) / d[k];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
      }
      if (!miss && t0 <= t1 && t0 > 0) best = std::min(best, t0);
    }
    for (const auto& c : discs) {
      const double ox = pose.x - c.cx, oy = pose.y - c.cy;
      const double b = ox * dx + oy * dy, q = ox * ox + oy * oy - c.r * c.r;
      const double disc = b * b - q;
      if (disc >= 0 && -b - std::sqrt(disc) > 0) best = std::min(best, -b - std::sqrt(disc));
    }
    s.angles.push_back(static_cast<float>(a));
    s.ranges.push_back(static_cast<float>(best));
  }
  return s;
}

// Room 10 x 6 m (walls 0.1 m thick) round x in [-2, 8], y in [-3, 3].
inline std::vector<Box> room() {
  return {{3, -3, 5, 0.05}, {3, 3, 5, 0.05}, {-2, 0, 0.05, 3}, {8, 0, 0.05, 3}};
}

}  // namespace sketchnav::nav::test
