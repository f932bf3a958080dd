#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>

#include "geometry.h"
#include "sketchnav/core/angles.h"
#include "sketchnav/core/config.h"
#include "sketchnav/core/error.h"
#include "sketchnav/mapsketch/io.h"
#include "sketchnav/mapsketch/route.h"

namespace sketchnav::mapsketch {
namespace {

std::string fmt(double v, int prec = 3) {
  std::ostringstream o;
  o.precision(prec);
  o << v;
  return o.str();
}

}  // namespace

const char* sideName(Side s) {
  switch (s) {
    case Side::Left:
      return "left";
    case Side::Right:
      return "right";
    case Side::Ahead:
      return "ahead";
  }
  return "?";
}

void RouteParams::validate() const {
  require(simplify_tolerance > 0 && simplify_tolerance < 0.5, "route.simplify_tolerance",
          "must be in (0, 0.5)");
  require(robust_scale > 0 && robust_scale <= 10, "route.robust_scale", "must be in (0, 10]");
  require(outlier_residual > 0, "route.outlier_residual", "must be positive");
  require(start_tangent_m > 0 && start_tangent_m <= 10, "route.start_tangent_m",
          "must be in (0, 10] m");
  require(ahead_angle_deg >= 0 && ahead_angle_deg < 90, "route.ahead_angle_deg",
          "must be in [0, 90)");
}

PolylinePoint closestOnPolyline(const Eigen::Vector2d& p,
                                const std::vector<Eigen::Vector2d>& poly) {
  PolylinePoint best{std::numeric_limits<double>::infinity(), 0};
  if (poly.size() == 1) return {(poly[0] - p).norm(), 0};
  double s = 0;
  for (size_t i = 0; i + 1 < poly.size(); ++i) {
    const Eigen::Vector2d a = poly[i], d = poly[i + 1] - a;
    const double L2 = d.squaredNorm(), L = std::sqrt(L2);
    const double t = L2 > 0 ? std::clamp((p - a).dot(d) / L2, 0.0, 1.0) : 0.0;
    const double dist = (a + t * d - p).norm();
    if (dist < best.distance) best = {dist, s + t * L};
    s += L;
  }
  return best;
}

std::vector<int> simplifyPolyline(const std::vector<Eigen::Vector2d>& pts, double tolerance) {
  const int n = static_cast<int>(pts.size());
  if (n <= 2) {
    std::vector<int> all(n);
    std::iota(all.begin(), all.end(), 0);
    return all;
  }
  std::vector<char> keep(n, 0);
  keep[0] = keep[n - 1] = 1;
  // Explicit stack: a path of 100k points would overflow a recursive version.
  std::vector<std::pair<int, int>> stack{{0, n - 1}};
  while (!stack.empty()) {
    auto [a, b] = stack.back();
    stack.pop_back();
    double worst = -1;
    int idx = -1;
    for (int i = a + 1; i < b; ++i) {
      const double d = detail::pointSegmentDistance(pts[i], pts[a], pts[b]);
      if (d > worst) {
        worst = d;
        idx = i;
      }
    }
    if (idx >= 0 && worst > tolerance) {
      keep[idx] = 1;
      stack.push_back({a, idx});
      stack.push_back({idx, b});
    }
  }
  std::vector<int> out;
  for (int i = 0; i < n; ++i)
    if (keep[i]) out.push_back(i);
  return out;
}

ScaleFit fitScale(const std::vector<double>& d_px, const std::vector<double>& d_m, double c) {
  if (d_px.size() != d_m.size()) throw std::logic_error("fitScale: size mismatch");
  const size_t n = d_px.size();
  std::vector<char> usable(n, 0);
  std::vector<double> ratios;
  for (size_t i = 0; i < n; ++i) {
    usable[i] = d_px[i] > 1e-6 && d_m[i] > 0;
    if (usable[i]) ratios.push_back(d_m[i] / d_px[i]);
  }
  if (ratios.empty())
    throw InputError(
        "sketch: no landmark distance can fix the scale (landmarks drawn on top of the start?)");
  std::nth_element(ratios.begin(), ratios.begin() + ratios.size() / 2, ratios.end());
  double s = ratios[ratios.size() / 2];
  ScaleFit f;
  f.weight.assign(n, 0);
  f.relative_error.assign(n, 0);
  // Errors as log ratios, because a person's distance estimate is off by a factor (and "twice
  // too far" should count as much as "half as far"); least squares in log space is a weighted
  // geometric mean, and the Cauchy weight lets one wildly wrong distance be outvoted.
  double log_s = std::log(s);
  for (int it = 0; it < 50; ++it) {
    double num = 0, den = 0;
    for (size_t i = 0; i < n; ++i) {
      if (!usable[i]) continue;
      const double r = std::log(d_m[i] / d_px[i]);
      const double e = log_s - r;
      const double w = 1 / (1 + (e / c) * (e / c));
      f.weight[i] = w;
      num += w * r;
      den += w;
    }
    const double next = num / den;
    const bool done = std::abs(next - log_s) < 1e-12;
    log_s = next;
    if (done) break;
  }
  s = std::exp(log_s);
  f.scale = s;
  double sum2 = 0;
  int m = 0;
  for (size_t i = 0; i < n; ++i) {
    if (!usable[i]) continue;
    f.relative_error[i] = (s * d_px[i] - d_m[i]) / d_m[i];
    sum2 += f.relative_error[i] * f.relative_error[i];
    ++m;
  }
  f.rms_relative = std::sqrt(sum2 / m);
  return f;
}

Route toRoute(const Sketch& sk, const RouteParams& params) {
  params.validate();
  validateSketch(sk, sk.name.empty() ? "<sketch>" : sk.name);
  Route route;

  // The full polyline the robot should follow: start, the drawn path, goal. A path drawn from
  // the goal back to the start is turned round (and said so).
  std::vector<Eigen::Vector2d> path = sk.path;
  std::vector<int> path_index(path.size());
  std::iota(path_index.begin(), path_index.end(), 0);
  const double fwd = (sk.start - path.front()).norm() + (sk.goal - path.back()).norm();
  const double bwd = (sk.start - path.back()).norm() + (sk.goal - path.front()).norm();
  if (bwd < 0.5 * fwd) {
    std::reverse(path.begin(), path.end());
    std::reverse(path_index.begin(), path_index.end());
    route.warnings.push_back("the path was drawn from the goal to the start; it was reversed");
  }
  const double diag = std::hypot(sk.canvas_width, sk.canvas_height);
  const double snap = 0.005 * diag;  // a start/goal this close to the path's end is its end
  if ((sk.start - path.front()).norm() > snap) {
    path.insert(path.begin(), sk.start);
    path_index.insert(path_index.begin(), -1);
  } else {
    path.front() = sk.start;
  }
  if ((sk.goal - path.back()).norm() > snap) {
    path.push_back(sk.goal);
    path_index.push_back(-1);
  } else {
    path.back() = sk.goal;
  }

  const std::vector<int> kept = simplifyPolyline(path, params.simplify_tolerance * diag);
  std::vector<double> arc(path.size(), 0);
  for (size_t i = 1; i < path.size(); ++i) arc[i] = arc[i - 1] + (path[i] - path[i - 1]).norm();

  // Sequence order: where along the drawn path each landmark is passed.
  struct Placed {
    const SketchLandmark* lm;
    double arc;
    double dist_px;
    size_t input_index;
  };
  std::vector<Placed> placed;
  for (size_t i = 0; i < sk.landmarks.size(); ++i) {
    const auto hit = detail::nearestOnPolyline(sk.landmarks[i].rect.centre(), path);
    placed.push_back({&sk.landmarks[i], hit.arc, hit.distance, i});
  }
  std::stable_sort(placed.begin(), placed.end(),
                   [](const Placed& a, const Placed& b) { return a.arc < b.arc; });

  // Scale: the user's distances between consecutive landmarks (start -> first) against the
  // straight canvas distances between their centres.
  std::vector<double> d_px, d_m;
  Eigen::Vector2d prev = sk.start;
  for (const auto& p : placed) {
    const Eigen::Vector2d c = p.lm->rect.centre();
    d_px.push_back((c - prev).norm());
    d_m.push_back(p.lm->distance_m);
    prev = c;
  }
  const ScaleFit fit = fitScale(d_px, d_m, params.robust_scale);
  const double s = fit.scale;
  route.scale_m_per_px = s;
  route.scale_residual = fit.rms_relative;
  for (size_t i = 0; i < placed.size(); ++i)
    if (std::abs(fit.relative_error[i]) > params.outlier_residual) {
      route.distance_outliers.push_back(placed[i].lm->id);
      route.warnings.push_back(
          "landmark '" + placed[i].lm->id + "': distance " + fmt(placed[i].lm->distance_m) +
          " m disagrees with the others (the drawing suggests " + fmt(s * d_px[i]) + " m)");
    }

  auto toM = [&](const Eigen::Vector2d& p) -> Eigen::Vector2d {
    return {s * (p.x() - sk.start.x()), -s * (p.y() - sk.start.y())};
  };
  route.start_m = toM(sk.start);
  route.goal_m = toM(sk.goal);
  route.goal_place = sk.goal_place;
  for (int k : kept) {
    route.guide_points_m.push_back(toM(path[k]));
    route.guide_point_path_index.push_back(path_index[k]);
  }

  const int nsec = static_cast<int>(kept.size()) - 1;
  for (int k = 0; k < nsec; ++k) {
    PathSection sec;
    sec.index = k;
    sec.start_m = route.guide_points_m[k];
    sec.end_m = route.guide_points_m[k + 1];
    const Eigen::Vector2d d = sec.end_m - sec.start_m;
    sec.length_m = d.norm();
    sec.heading_rad = std::atan2(d.y(), d.x());
    sec.heading_change_rad =
        k == 0 ? 0.0 : wrapAngle(sec.heading_rad - route.sections.back().heading_rad);
    route.total_length_m += sec.length_m;
    route.sections.push_back(std::move(sec));
  }
  // The drawn line's own direction at the start, not the first section's: the two differ by
  // 20 degrees and more when a short first stroke bends into a long one (the bend is below
  // the simplification tolerance), and the whole route would be turned by that.
  {
    const double reach_px = params.start_tangent_m / s;
    Eigen::Vector2d acc(0, 0);
    for (size_t i = 1; i < path.size() && (i == 1 || arc[i] <= reach_px); ++i)
      if ((path[i] - path[0]).norm() > 1e-9)
        acc += (path[i] - path[0]).normalized() * std::min(arc[i], reach_px);
    route.start_heading_rad =
        acc.norm() > 1e-9 ? std::atan2(-acc.y(), acc.x()) : route.sections.front().heading_rad;
  }

  const double near = detail::nearDistancePx(sk);
  const double ahead_tan = std::tan(params.ahead_angle_deg * M_PI / 180);
  for (size_t order = 0; order < placed.size(); ++order) {
    const Placed& p = placed[order];
    // The section whose stretch of the drawn path passes the landmark.
    int k = 0;
    while (k + 1 < nsec && arc[kept[k + 1]] <= p.arc) ++k;
    PathSection& sec = route.sections[k];
    ExpectedLandmark e;
    e.id = p.lm->id;
    e.class_name = p.lm->class_name;
    e.order = static_cast<int>(order);
    e.position_m = toM(p.lm->rect.centre());
    const Eigen::Vector2d u =
        sec.length_m > 0 ? Eigen::Vector2d((sec.end_m - sec.start_m) / sec.length_m)
                         : Eigen::Vector2d(std::cos(sec.heading_rad), std::sin(sec.heading_rad));
    const Eigen::Vector2d left(-u.y(), u.x());  // route frame is CCW: left of travel
    const Eigen::Vector2d v = e.position_m - sec.start_m;
    e.along_m = v.dot(u);
    const double lateral = v.dot(left);
    e.range_m = std::abs(lateral);
    // A path running into the landmark's drawn box heads at it ("ahead"). Half the box's
    // smaller side, so a long bench drawn beside the path stays "left"/"right".
    const double half_extent = 0.5 * s * std::min(p.lm->rect.w, p.lm->rect.h);
    const double beyond = e.along_m - sec.length_m;
    if (e.range_m <= half_extent || (beyond > 0 && e.range_m <= ahead_tan * beyond))
      e.side = Side::Ahead;
    else
      e.side = lateral > 0 ? Side::Left : Side::Right;
    if (p.dist_px > near)
      route.warnings.push_back("landmark '" + e.id + "' is far from the path (" +
                               fmt(p.dist_px * s) + " m)");
    sec.landmarks.push_back(std::move(e));
  }
  if (route.scale_residual > 0.3)
    route.warnings.push_back(
        "the distances are inconsistent with the drawing (relative RMS residual " +
        fmt(100 * route.scale_residual, 2) + " %)");
  return route;
}

}  // namespace sketchnav::mapsketch
