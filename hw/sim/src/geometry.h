#pragma once
// 2-D geometry of the world's solid things, shared by the range sensors, the collision check
// and world validation. Everything solid is either a convex polygon (walls as thin
// rectangles, boxes, closed doors) or a circle (cylinders, pedestrians).
#include <Eigen/Core>

#include <limits>
#include <string>
#include <vector>

#include "sketchnav/sim/world.h"

namespace sketchnav::sim::geom {

constexpr double kInf = std::numeric_limits<double>::infinity();

struct Polygon {
  std::string name;
  std::vector<Vec2> pts;  // convex, either orientation
};

struct Circle {
  std::string name;
  Vec2 c{0, 0};
  double r = 0.0;
};

/// The static solids of a world (walls, closed doors, obstacles).
struct Solids {
  std::vector<Polygon> polys;
  std::vector<Circle> circles;
};

inline double cross(const Vec2& a, const Vec2& b) {
  return a.x() * b.y() - a.y() * b.x();
}

/// A rectangle centred at c, half extents hx, hy, rotated by yaw.
std::vector<Vec2> rectangle(const Vec2& c, double hx, double hy, double yaw);
/// The rectangle around segment ab with the given total thickness.
std::vector<Vec2> thickSegment(const Vec2& a, const Vec2& b, double thickness);

Solids buildSolids(const World& w);

double pointSegmentDistance(const Vec2& p, const Vec2& a, const Vec2& b);
/// Signed distance from p to a convex polygon's boundary (negative inside).
double signedDistance(const Vec2& p, const Polygon& poly);
/// Distance along the ray o + t d (|d| = 1) to the first hit, kInf when none.
double rayPolygon(const Vec2& o, const Vec2& d, const Polygon& poly);
double rayCircle(const Vec2& o, const Vec2& d, const Vec2& c, double r);
bool pointInPolygon(const Vec2& p, const std::vector<Vec2>& poly);

}  // namespace sketchnav::sim::geom
