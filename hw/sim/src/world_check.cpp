// World plausibility checks (world_check.h): plain geometry over the world's solids.
#include "sketchnav/sim/world_check.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <queue>

#include "geometry.h"

namespace sketchnav::sim {
namespace {

constexpr double kDeg = M_PI / 180.0;

std::string fmtM(double x) {
  char b[32];
  std::snprintf(b, sizeof b, "%.2f", x);
  return b;
}

// Depths under 1 cm in millimetres ("0.005 m" would print as 0.00 m).
std::string fmtMm(double x) {
  char b[32];
  if (x < 0.01)
    std::snprintf(b, sizeof b, "%.0f mm", x * 1000);
  else
    std::snprintf(b, sizeof b, "%.2f m", x);
  return b;
}

std::string idx(const char* what, size_t i) {
  return std::string(what) + "[" + std::to_string(i) + "]";
}

std::string named(const std::string& field, const std::string& name) {
  return name.empty() || name == field ? field : field + " ('" + name + "')";
}

// The outward normal of the convex polygon's edge nearest to p.
Vec2 nearestEdgeNormal(const Vec2& p, const std::vector<Vec2>& pts) {
  Vec2 centroid(0, 0);
  for (const auto& q : pts) centroid += q;
  centroid /= static_cast<double>(pts.size());
  double best = geom::kInf;
  Vec2 n(1, 0);
  for (size_t i = 0; i < pts.size(); ++i) {
    const Vec2& a = pts[i];
    const Vec2& b = pts[(i + 1) % pts.size()];
    const double d = geom::pointSegmentDistance(p, a, b);
    if (d >= best || (b - a).norm() < 1e-9) continue;
    best = d;
    const Vec2 e = (b - a).normalized();
    n = Vec2(e.y(), -e.x());
    if ((0.5 * (a + b) - centroid).dot(n) < 0) n = -n;
  }
  return n;
}

// Overlap depth of two convex polygons by separating axes (<= 0: apart or touching).
double polygonOverlap(const std::vector<Vec2>& p, const std::vector<Vec2>& q) {
  double depth = geom::kInf;
  for (const auto* poly : {&p, &q})
    for (size_t i = 0; i < poly->size(); ++i) {
      const Vec2 e = (*poly)[(i + 1) % poly->size()] - (*poly)[i];
      if (e.norm() < 1e-12) continue;
      const Vec2 n = Vec2(-e.y(), e.x()).normalized();
      double p0 = geom::kInf, p1 = -geom::kInf, q0 = geom::kInf, q1 = -geom::kInf;
      for (const auto& v : p) p0 = std::min(p0, v.dot(n)), p1 = std::max(p1, v.dot(n));
      for (const auto& v : q) q0 = std::min(q0, v.dot(n)), q1 = std::max(q1, v.dot(n));
      depth = std::min(depth, std::min(p1, q1) - std::max(p0, q0));
    }
  return depth;
}

struct Solid {
  std::string field, name;
  bool circle = false;
  std::vector<Vec2> pts;  // polygon
  Vec2 c{0, 0};           // circle
  double r = 0;
  double top = 0;  // [m] height of its top
  double signedDistance(const Vec2& p) const {
    return circle ? (p - c).norm() - r : geom::signedDistance(p, {name, pts});
  }
  Vec2 outwardNormal(const Vec2& p) const {
    if (!circle) return nearestEdgeNormal(p, pts);
    const Vec2 d = p - c;
    return d.norm() > 1e-9 ? Vec2(d.normalized()) : Vec2(1, 0);
  }
};

double overlap(const Solid& a, const Solid& b) {
  if (a.circle && b.circle) return a.r + b.r - (a.c - b.c).norm();
  if (a.circle) return a.r - b.signedDistance(a.c);
  if (b.circle) return b.r - a.signedDistance(b.c);
  return polygonOverlap(a.pts, b.pts);
}

std::vector<Solid> wallSolids(const World& w) {
  std::vector<Solid> out;
  for (size_t i = 0; i < w.walls.size(); ++i) {
    const auto& x = w.walls[i];
    Solid s;
    s.field = idx("walls", i);
    s.name = x.name;
    s.pts = geom::thickSegment(x.a, x.b, x.thickness);
    s.top = x.height;
    out.push_back(s);
  }
  return out;
}

std::vector<Solid> obstacleSolids(const World& w) {
  std::vector<Solid> out;
  for (size_t i = 0; i < w.obstacles.size(); ++i) {
    const auto& o = w.obstacles[i];
    Solid s;
    s.field = idx("obstacles", i);
    s.name = o.name;
    s.top = o.height;
    if (o.shape == Obstacle::Shape::Cylinder) {
      s.circle = true;
      s.c = o.centre;
      s.r = o.radius;
    } else {
      s.pts = geom::rectangle(o.centre, 0.5 * o.size_x, 0.5 * o.size_y, o.yaw);
    }
    out.push_back(s);
  }
  return out;
}

WorldIssue error(std::string field, std::string msg) {
  return {WorldIssue::Severity::Error, std::move(field), std::move(msg)};
}
WorldIssue warning(std::string field, std::string msg) {
  return {WorldIssue::Severity::Warning, std::move(field), std::move(msg)};
}

}  // namespace

std::string WorldIssue::text(const std::string& origin) const {
  return origin + ": " + (field.empty() ? "" : field + ": ") +
         (severity == Severity::Warning ? "warning: " : "") + message;
}

std::vector<WorldIssue> checkWorldGeometry(const World& w, const WorldCheckParams& p) {
  std::vector<WorldIssue> out;
  const auto walls = wallSolids(w);
  const auto obstacles = obstacleSolids(w);

  // --- landmark photos: on a face, not inside anything ------------------------------------
  for (size_t i = 0; i < w.landmarks.size(); ++i) {
    const Landmark& l = w.landmarks[i];
    const std::string f = idx("landmarks", i);
    const Vec2 facing(std::cos(l.yaw), std::sin(l.yaw));
    const double bottom = l.elevation - 0.5 * l.height;
    bool on_something = false, reported = false;
    double nearest = geom::kInf;
    std::string nearest_name;
    for (const auto* set : {&walls, &obstacles})
      for (const Solid& s : *set) {
        if (reported) break;
        const double d = s.signedDistance(l.position);
        // A photo standing on the top of a piece of furniture (its bottom at or above the
        // top) may have its centre over the footprint.
        const bool above = bottom >= s.top - p.inside_m;
        if (d < -p.inside_m && !above) {
          out.push_back(error(f + ".position", "'" + l.id + "' is " + fmtMm(-d) + " inside " +
                                                   named(s.field, s.name) +
                                                   ": the photo would be hidden"));
          reported = true;
          break;
        }
        if (d <= p.inside_m && above) on_something = true;
        if (std::abs(d) <= p.on_face_m && !above) {
          on_something = true;
          if (facing.dot(s.outwardNormal(l.position)) < -0.2) {
            out.push_back(
                error(f + ".yaw_deg", "'" + l.id + "' faces into " + named(s.field, s.name) +
                                          " (its normal must point away from the face it is on)"));
            reported = true;
            break;
          }
        }
        if (std::abs(d) < nearest) nearest = std::abs(d), nearest_name = named(s.field, s.name);
      }
    if (!reported && !on_something)
      out.push_back(
          warning(f + ".position", "'" + l.id + "' is on no wall or furniture face" +
                                       (nearest_name.empty() ? std::string()
                                                             : " (nearest: " + nearest_name + ", " +
                                                                   fmtM(nearest) + " m away)") +
                                       ": a free-standing board?"));
  }

  // --- furniture against walls and each other ----------------------------------------------
  for (const Solid& o : obstacles) {
    for (const Solid& s : walls) {
      const double d = overlap(o, s);
      if (d > p.overlap_m)
        out.push_back(error(o.field, "'" + o.name + "' overlaps " + named(s.field, s.name) +
                                         " by " + fmtM(d) + " m"));
    }
  }
  for (size_t a = 0; a < obstacles.size(); ++a)
    for (size_t b = a + 1; b < obstacles.size(); ++b) {
      const double d = overlap(obstacles[a], obstacles[b]);
      if (d > p.overlap_m)
        out.push_back(warning(obstacles[b].field, "'" + obstacles[b].name + "' overlaps " +
                                                      named(obstacles[a].field, obstacles[a].name) +
                                                      " by " + fmtM(d) + " m"));
    }
  return out;
}

std::vector<WorldIssue> checkLandmarkClasses(const World& w,
                                             const std::vector<std::string>& classes) {
  std::vector<WorldIssue> out;
  std::string known;
  for (const auto& c : classes) known += (known.empty() ? "" : ", ") + c;
  if (known.size() > 200) known = known.substr(0, 197) + "...";
  for (size_t i = 0; i < w.landmarks.size(); ++i) {
    const auto& l = w.landmarks[i];
    if (std::find(classes.begin(), classes.end(), l.class_name) != classes.end()) continue;
    out.push_back(error(idx("landmarks", i) + ".class",
                        "'" + l.class_name + "' is not in the landmark set (" + known + ")"));
  }
  return out;
}

std::vector<WorldIssue> checkStartHeading(const World& w, const RoutePlacement& route,
                                          const std::string& sketch_name, const WorldCheckParams& p,
                                          double* out_disagreement_rad) {
  if (out_disagreement_rad) *out_disagreement_rad = 0;
  // Route frame -> world frame: the route's start on the world's start, its first stroke
  // along the start heading.
  const double rot = w.start.theta - route.start_heading;
  const double c = std::cos(rot), s = std::sin(rot);
  const Vec2 start(w.start.x, w.start.y);
  double sum_dot = 0, sum_cross = 0;
  int used = 0;
  for (const auto& sl : route.landmarks) {
    const Landmark* l = w.findLandmark(sl.id);
    if (!l) continue;
    const Vec2 d = sl.position - route.start;
    const Vec2 a(c * d.x() - s * d.y(), s * d.x() + c * d.y());  // sketched, world frame
    const Vec2 b = l->position - start;                          // true
    if (a.norm() < 0.5 || b.norm() < 0.5) continue;
    sum_dot += a.dot(b);
    sum_cross += geom::cross(a, b);
    ++used;
  }
  if (used == 0) return {};
  const double delta = std::atan2(sum_cross, sum_dot);  // rotate the sketch by this to fit
  if (out_disagreement_rad) *out_disagreement_rad = delta;
  const double deg = std::abs(delta) / kDeg;
  if (deg <= p.heading_warn_deg) return {};
  char b[400];
  std::snprintf(b, sizeof b,
                "%.0f disagrees with the sketch %s: placed with its first stroke along the start "
                "heading, the sketch's landmarks fit the world's best turned %.0f deg %s (%d "
                "landmark%s); is the robot put down facing along the first stroke?",
                w.start.theta / kDeg, sketch_name.c_str(), deg,
                delta > 0 ? "counter-clockwise" : "clockwise", used, used == 1 ? "" : "s");
  if (deg > p.heading_error_deg) return {error("start.yaw_deg", b)};
  return {warning("start.yaw_deg", b)};
}

double freePathLength(const World& w, double margin_m, double res) {
  if (w.floor.size() < 3 || !(res > 0)) return -1;
  double x0 = geom::kInf, y0 = geom::kInf, x1 = -geom::kInf, y1 = -geom::kInf;
  for (const auto& q : w.floor) {
    x0 = std::min(x0, q.x()), y0 = std::min(y0, q.y());
    x1 = std::max(x1, q.x()), y1 = std::max(y1, q.y());
  }
  const int nx = static_cast<int>(std::ceil((x1 - x0) / res)),
            ny = static_cast<int>(std::ceil((y1 - y0) / res));
  if (nx <= 0 || ny <= 0 || static_cast<double>(nx) * ny > 2e7) return -1;
  const geom::Solids solids = geom::buildSolids(w);
  const double need = w.robot.radius + margin_m;
  auto centre = [&](int i, int j) { return Vec2(x0 + (i + 0.5) * res, y0 + (j + 0.5) * res); };
  std::vector<char> free(static_cast<size_t>(nx) * ny, 0);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const Vec2 c = centre(i, j);
      if (!geom::pointInPolygon(c, w.floor)) continue;
      bool ok = true;
      for (const auto& p : solids.polys)
        if (geom::signedDistance(c, p) < need) {
          ok = false;
          break;
        }
      for (size_t k = 0; ok && k < solids.circles.size(); ++k)
        ok = (c - solids.circles[k].c).norm() - solids.circles[k].r >= need;
      free[static_cast<size_t>(j) * nx + i] = ok;
    }
  auto cellOf = [&](const Vec2& p) {
    const int i = std::clamp(static_cast<int>((p.x() - x0) / res), 0, nx - 1);
    const int j = std::clamp(static_cast<int>((p.y() - y0) / res), 0, ny - 1);
    return j * nx + i;
  };
  const int s = cellOf({w.start.x, w.start.y});
  free[s] = 1;  // the start itself was checked at load with the bare radius
  // Dijkstra over the grid (steps of res and res * sqrt 2).
  std::vector<double> dist(free.size(), geom::kInf);
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  dist[s] = 0;
  queue.push({0.0, s});
  while (!queue.empty()) {
    const auto [d, c] = queue.top();
    queue.pop();
    if (d > dist[c]) continue;
    const int ci = c % nx, cj = c / nx;
    if ((centre(ci, cj) - w.goal.centre).norm() <= w.goal.radius) return d;
    for (int dj = -1; dj <= 1; ++dj)
      for (int di = -1; di <= 1; ++di) {
        const int i = ci + di, j = cj + dj;
        if ((!di && !dj) || i < 0 || j < 0 || i >= nx || j >= ny) continue;
        const int n = j * nx + i;
        // No corner cutting: a diagonal step needs both side cells free.
        if (!free[n] || (di && dj && (!free[cj * nx + i] || !free[j * nx + ci]))) continue;
        const double nd = d + res * ((di && dj) ? M_SQRT2 : 1.0);
        if (nd < dist[n]) {
          dist[n] = nd;
          queue.push({nd, n});
        }
      }
  }
  return -1;
}

}  // namespace sketchnav::sim
