#pragma once
// Small 2-D helpers on canvas polylines (private to mapsketch).
#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

#include "sketchnav/mapsketch/sketch.h"

namespace sketchnav::mapsketch::detail {

inline double polylineLength(const std::vector<Eigen::Vector2d>& p) {
  double L = 0;
  for (size_t i = 1; i < p.size(); ++i) L += (p[i] - p[i - 1]).norm();
  return L;
}

/// Closest point of segment ab to p as the parameter t in [0, 1].
inline double segmentParam(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                           const Eigen::Vector2d& b) {
  const Eigen::Vector2d ab = b - a;
  const double n2 = ab.squaredNorm();
  if (n2 <= 0) return 0;
  return std::clamp((p - a).dot(ab) / n2, 0.0, 1.0);
}

inline double pointSegmentDistance(const Eigen::Vector2d& p, const Eigen::Vector2d& a,
                                   const Eigen::Vector2d& b) {
  return (a + segmentParam(p, a, b) * (b - a) - p).norm();
}

inline double pointRectDistance(const Eigen::Vector2d& p, const CanvasRect& r) {
  const double dx = std::max({r.x - p.x(), 0.0, p.x() - (r.x + r.w)});
  const double dy = std::max({r.y - p.y(), 0.0, p.y() - (r.y + r.h)});
  return std::hypot(dx, dy);
}

/// True when segment ab crosses the rectangle (Liang-Barsky clipping).
inline bool segmentHitsRect(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                            const CanvasRect& r) {
  double t0 = 0, t1 = 1;
  const Eigen::Vector2d d = b - a;
  const double p[4] = {-d.x(), d.x(), -d.y(), d.y()};
  const double q[4] = {a.x() - r.x, r.x + r.w - a.x(), a.y() - r.y, r.y + r.h - a.y()};
  for (int i = 0; i < 4; ++i) {
    if (p[i] == 0) {
      if (q[i] < 0) return false;
    } else {
      const double t = q[i] / p[i];
      if (p[i] < 0)
        t0 = std::max(t0, t);
      else
        t1 = std::min(t1, t);
      if (t0 > t1) return false;
    }
  }
  return true;
}

inline double rectToPolylineDistance(const CanvasRect& r, const std::vector<Eigen::Vector2d>& p) {
  if (p.size() == 1) return pointRectDistance(p[0], r);
  const Eigen::Vector2d corners[4] = {
      {r.x, r.y}, {r.x + r.w, r.y}, {r.x, r.y + r.h}, {r.x + r.w, r.y + r.h}};
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 1; i < p.size(); ++i) {
    if (segmentHitsRect(p[i - 1], p[i], r)) return 0;
    best = std::min({best, pointRectDistance(p[i - 1], r), pointRectDistance(p[i], r)});
    for (const auto& c : corners) best = std::min(best, pointSegmentDistance(c, p[i - 1], p[i]));
  }
  return best;
}

/// How close (canvas px) the path must come to at least one landmark for the sketch to make
/// sense: 15 % of the canvas diagonal.
inline double nearDistancePx(const Sketch& s) {
  return 0.15 * std::hypot(s.canvas_width, s.canvas_height);
}

struct PolylineHit {
  int segment = 0;      // p[segment] .. p[segment + 1]
  double t = 0;         // along that segment
  double arc = 0;       // arc length from p[0] to the hit
  double distance = 0;  // from the query point
};

inline PolylineHit nearestOnPolyline(const Eigen::Vector2d& q,
                                     const std::vector<Eigen::Vector2d>& p) {
  PolylineHit best;
  best.distance = std::numeric_limits<double>::infinity();
  double arc = 0;
  for (size_t i = 1; i < p.size(); ++i) {
    const double t = segmentParam(q, p[i - 1], p[i]);
    const double len = (p[i] - p[i - 1]).norm();
    const double d = (p[i - 1] + t * (p[i] - p[i - 1]) - q).norm();
    if (d < best.distance) best = {static_cast<int>(i - 1), t, arc + t * len, d};
    arc += len;
  }
  return best;
}

}  // namespace sketchnav::mapsketch::detail
