#include "geometry.h"

#include <cmath>

namespace sketchnav::sim::geom {

std::vector<Vec2> rectangle(const Vec2& c, double hx, double hy, double yaw) {
  const Vec2 ex(std::cos(yaw), std::sin(yaw)), ey(-std::sin(yaw), std::cos(yaw));
  return {c - hx * ex - hy * ey, c + hx * ex - hy * ey, c + hx * ex + hy * ey,
          c - hx * ex + hy * ey};
}

std::vector<Vec2> thickSegment(const Vec2& a, const Vec2& b, double thickness) {
  const Vec2 d = b - a;
  const double len = d.norm();
  return rectangle(0.5 * (a + b), 0.5 * len, 0.5 * thickness, std::atan2(d.y(), d.x()));
}

Solids buildSolids(const World& w) {
  Solids s;
  for (const auto& wall : w.walls)
    s.polys.push_back(
        {wall.name.empty() ? "wall" : wall.name, thickSegment(wall.a, wall.b, wall.thickness)});
  for (const auto& door : w.doors)
    if (!door.open)
      s.polys.push_back(
          {door.name.empty() ? "door" : door.name, thickSegment(door.a, door.b, 0.05)});
  for (const auto& o : w.obstacles) {
    if (o.shape == Obstacle::Shape::Box)
      s.polys.push_back({o.name, rectangle(o.centre, 0.5 * o.size_x, 0.5 * o.size_y, o.yaw)});
    else
      s.circles.push_back({o.name, o.centre, o.radius});
  }
  return s;
}

double pointSegmentDistance(const Vec2& p, const Vec2& a, const Vec2& b) {
  const Vec2 ab = b - a;
  const double l2 = ab.squaredNorm();
  double t = l2 > 0 ? (p - a).dot(ab) / l2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return (a + t * ab - p).norm();
}

bool pointInPolygon(const Vec2& p, const std::vector<Vec2>& poly) {
  bool in = false;
  for (size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const Vec2& a = poly[i];
    const Vec2& b = poly[j];
    if ((a.y() > p.y()) != (b.y() > p.y()) &&
        p.x() < (b.x() - a.x()) * (p.y() - a.y()) / (b.y() - a.y()) + a.x())
      in = !in;
  }
  return in;
}

double signedDistance(const Vec2& p, const Polygon& poly) {
  double d = kInf;
  const size_t n = poly.pts.size();
  for (size_t i = 0; i < n; ++i)
    d = std::min(d, pointSegmentDistance(p, poly.pts[i], poly.pts[(i + 1) % n]));
  return pointInPolygon(p, poly.pts) ? -d : d;
}

double rayPolygon(const Vec2& o, const Vec2& d, const Polygon& poly) {
  double best = kInf;
  const size_t n = poly.pts.size();
  for (size_t i = 0; i < n; ++i) {
    const Vec2& a = poly.pts[i];
    const Vec2 e = poly.pts[(i + 1) % n] - a;
    const double den = cross(d, e);
    if (std::abs(den) < 1e-12) continue;
    const Vec2 ao = a - o;
    const double t = cross(ao, e) / den;
    const double u = cross(ao, d) / den;
    if (t >= 0 && u >= 0 && u <= 1) best = std::min(best, t);
  }
  return best;
}

double rayCircle(const Vec2& o, const Vec2& d, const Vec2& c, double r) {
  const Vec2 oc = o - c;
  const double b = oc.dot(d);
  const double cc = oc.squaredNorm() - r * r;
  const double disc = b * b - cc;
  if (disc < 0) return kInf;
  const double sq = std::sqrt(disc);
  const double t0 = -b - sq;
  if (t0 >= 0) return t0;
  const double t1 = -b + sq;
  return t1 >= 0 ? 0.0 : kInf;  // inside the circle: hit at once
}

}  // namespace sketchnav::sim::geom
