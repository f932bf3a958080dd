#include "sketchnav/nav/sections.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

#include "sketchnav/core/config.h"
#include "sketchnav/core/error.h"

namespace sketchnav::nav {

void SectionParams::validate() const {
  require(reach_radius_m > 0 && reach_radius_m < 5, "nav.sections.reach_radius_m",
          "must be in (0, 5) m");
  require(end_slack_m >= 0 && end_slack_m < 5, "nav.sections.end_slack_m", "must be in [0, 5) m");
  require(goal_radius_m > 0 && goal_radius_m <= 5, "nav.sections.goal_radius_m",
          "must be in (0, 5] m");
  require(goal_ahead_m >= 0 && goal_ahead_m <= goal_radius_m, "nav.sections.goal_ahead_m",
          "must be in [0, goal_radius_m]");
  require(lookahead_m > 0.1 && lookahead_m < 10, "nav.sections.lookahead_m",
          "must be in (0.1, 10) m");
}

namespace {
Eigen::Vector2d rot(double a, const Eigen::Vector2d& v) {
  const double c = std::cos(a), s = std::sin(a);
  return {c * v.x() - s * v.y(), s * v.x() + c * v.y()};
}
}  // namespace

SectionTracker::SectionTracker(mapsketch::Route route, SectionParams params)
    : route_(std::move(route)), params_(params) {
  params_.validate();
  if (route_.sections.empty()) throw InputError("route: no path section to follow");
  rot_ = -route_.start_heading_rad;
}

const mapsketch::PathSection& SectionTracker::section() const {
  if (finished()) throw std::logic_error("SectionTracker::section() after the last section");
  return route_.sections[current_];
}

Eigen::Vector2d SectionTracker::toOdom(const Eigen::Vector2d& p) const {
  return scale_ * rot(rot_, p - route_.start_m) + trans_;
}
Eigen::Vector2d SectionTracker::toRoute(const Eigen::Vector2d& p) const {
  return rot(-rot_, p - trans_) / scale_ + route_.start_m;
}
double SectionTracker::headingToOdom(double h) const {
  return wrapAngle(h + rot_);
}

void SectionTracker::reanchor(const Eigen::Vector2d& route_pt, const Eigen::Vector2d& odom_pt,
                              double gain) {
  trans_ += gain * (odom_pt - toOdom(route_pt));
}

double SectionTracker::realign(const Eigen::Vector2d& route_pt, const Eigen::Vector2d& odom_pt,
                               const Eigen::Vector2d& anchor_route,
                               const Eigen::Vector2d& anchor_odom, double gain,
                               double min_baseline_m) {
  const Eigen::Vector2d predicted = toOdom(route_pt) - toOdom(anchor_route);
  const Eigen::Vector2d seen = odom_pt - anchor_odom;
  if (predicted.norm() < min_baseline_m || seen.norm() < min_baseline_m) return 0;
  const double delta =
      gain * wrapAngle(std::atan2(seen.y(), seen.x()) - std::atan2(predicted.y(), predicted.x()));
  // Rotate about the anchor: it must map to anchor_odom before and after.
  rot_ += delta;
  trans_ = anchor_odom - scale_ * rot(rot_, anchor_route - route_.start_m);
  return delta;
}

SectionTracker::Fit SectionTracker::fitSimilarity(const std::vector<Eigen::Vector2d>& route_pts,
                                                  const std::vector<Eigen::Vector2d>& odom_pts,
                                                  double max_scale_change, double outlier_m) {
  // The weighted fit with every fix an exact point: each then weighs 1 / sketch_sigma^2, the
  // least squares is the plain (Umeyama) similarity, and the Mahalanobis residual times
  // sketch_sigma is the distance in metres.
  WeightedFitParams p;
  p.outlier_m = outlier_m;
  p.max_scale_change = max_scale_change;
  std::vector<WeightedFix> fixes;
  for (size_t i = 0; i < std::min(route_pts.size(), odom_pts.size()); ++i)
    fixes.push_back({route_pts[i], odom_pts[i], 1e12 * Eigen::Matrix2d::Identity(), false});
  return fitSimilarityWeighted(fixes, p);
}

SectionTracker::Fit SectionTracker::fitSimilarityWeighted(const std::vector<WeightedFix>& fixes,
                                                          const WeightedFitParams& p) {
  Fit f;
  const size_t n = fixes.size();
  std::vector<bool> use(n, true);
  // Each fix's weight: the inverse of its observation covariance plus the sketch's error (a
  // trusted fix, the start, has no sketch error of its own).
  std::vector<Eigen::Matrix2d> W(n);
  const Eigen::Matrix2d S = p.sketch_sigma_m * p.sketch_sigma_m * Eigen::Matrix2d::Identity();
  for (size_t i = 0; i < n; ++i) {
    const Eigen::Matrix2d& I = fixes[i].information;
    if (std::abs(I.determinant()) < 1e-12) {
      use[i] = false;
      continue;
    }
    W[i] = fixes[i].trusted ? I : Eigen::Matrix2d((I.inverse() + S).inverse());
  }
  // d(M r + t)/dq for q = (s cos a, s sin a, tx, ty), r relative to the route's start.
  auto jac = [&](size_t i) {
    const Eigen::Vector2d r = fixes[i].route_pt - route_.start_m;
    Eigen::Matrix<double, 2, 4> J;
    J << r.x(), -r.y(), 1, 0, r.y(), r.x(), 0, 1;
    return J;
  };
  auto residual = [&](size_t i, const Eigen::Vector4d& q) {
    const Eigen::Vector2d d = jac(i) * q - fixes[i].odom_pt;
    return std::sqrt(std::max(0.0, d.dot(W[i] * d))) * p.sketch_sigma_m;
  };
  Eigen::Vector4d q;
  for (;;) {
    size_t m = 0;
    Eigen::Matrix4d A = Eigen::Matrix4d::Zero();
    Eigen::Vector4d b = Eigen::Vector4d::Zero();
    for (size_t i = 0; i < n; ++i)
      if (use[i]) {
        const auto J = jac(i);
        A += J.transpose() * W[i] * J;
        b += J.transpose() * W[i] * fixes[i].odom_pt;
        ++m;
      }
    if (m < 2) return f;
    Eigen::FullPivLU<Eigen::Matrix4d> lu(A);
    if (lu.rank() < 4) return f;
    q = lu.solve(b);
    // The scale stays within max_scale_change of the drawing's own (every fit is over all the
    // fixes, so a bound per fit would only slow down a scale the fixes agree on: with one
    // fit, distances said 30 % short stayed 15 % short); clamped, the translation is refitted.
    const double sc = std::hypot(q[0], q[1]);
    if (sc < 1e-9) return f;
    const double lo = 1 - p.max_scale_change, hi = 1 + p.max_scale_change;
    if (sc < lo || sc > hi) {
      const double k = std::clamp(sc, lo, hi) / sc;
      q[0] *= k, q[1] *= k;
      q[2] = q[3] = 0;
      Eigen::Matrix2d At = Eigen::Matrix2d::Zero();
      Eigen::Vector2d bt = Eigen::Vector2d::Zero();
      for (size_t i = 0; i < n; ++i)
        if (use[i]) At += W[i], bt += W[i] * (fixes[i].odom_pt - jac(i) * q);
      q.tail<2>() = At.ldlt().solve(bt);
    }
    if (p.outlier_m <= 0 || m <= 3) break;
    size_t worst = n;
    double worst_r = p.outlier_m;
    for (size_t i = 0; i < n; ++i)
      if (use[i] && !fixes[i].trusted) {
        const double r = residual(i, q);
        if (r > worst_r) worst_r = r, worst = i;
      }
    if (worst == n) break;
    use[worst] = false;
    ++f.dropped;
  }
  const double sc = std::hypot(q[0], q[1]), th = std::atan2(q[1], q[0]);
  f.rotation = wrapAngle(th - rot_);
  f.scale = sc / scale_;
  rot_ = th;
  scale_ = sc;
  trans_ = q.tail<2>();
  size_t m = 0;
  for (size_t i = 0; i < n; ++i)
    if (use[i]) f.rms += (jac(i) * q - fixes[i].odom_pt).squaredNorm(), ++m;
  f.rms = std::sqrt(f.rms / m);
  f.used = use;
  f.ok = true;
  return f;
}

SectionProgress SectionTracker::progress(const hw::Pose2D& o) const {
  SectionProgress p;
  if (finished()) return p;
  const auto& s = section();
  const Eigen::Vector2d a = toOdom(s.start_m), b = endOdom(current_), r(o.x, o.y);
  Eigen::Vector2d d = b - a;
  const double len = d.norm();
  if (len > 1e-9) d /= len;
  p.along_m = (r - a).dot(d);
  p.cross_m = d.x() * (r - a).y() - d.y() * (r - a).x();
  p.remaining_m = len - p.along_m;
  p.to_end_m = (b - r).norm();
  return p;
}

int SectionTracker::update(const hw::Pose2D& o) {
  int n = 0;
  while (!finished()) {
    const auto p = progress(o);
    // Reached its end point, or crossed the line through the end point (perpendicular to the
    // section): a robot pushed sideways by a dodge must not circle back to the exact point.
    // The last section ends at the goal, which is a place, not a line: crossing the line there
    // does not count (an overshoot turns back to the goal point).
    const bool last = current_ + 1 == count();
    const double reach = last ? params_.goal_radius_m : params_.reach_radius_m;
    const bool crossed = !last && p.remaining_m <= params_.end_slack_m;
    if (p.to_end_m > reach && !crossed) break;
    // At the goal, the robot drives on while the goal is still ahead of it: ending at the edge
    // of goal_radius_m left every robot 0.15 m short of its own goal estimate (median over 84
    // experiment trials), along the way it came, a bias on top of the sketch's error.
    if (last) {
      const Eigen::Vector2d to_goal = endOdom(current_) - Eigen::Vector2d(o.x, o.y);
      if (to_goal.dot(Eigen::Vector2d(std::cos(o.theta), std::sin(o.theta))) > params_.goal_ahead_m)
        break;
    }
    ++current_;
    ++n;
  }
  return n;
}

void SectionTracker::advance() {
  if (!finished()) ++current_;
}

std::vector<Eigen::Vector2d> SectionTracker::guidePointsOdom() const {
  std::vector<Eigen::Vector2d> out;
  for (const auto& g : route_.guide_points_m) out.push_back(toOdom(g));
  if (goal_odom_ && !out.empty()) out.back() = *goal_odom_;
  return out;
}

Eigen::Vector2d SectionTracker::endOdom(int k) const {
  if (k + 1 == count() && goal_odom_) return *goal_odom_;
  return toOdom(route_.sections.at(k).end_m);
}

Eigen::Vector2d SectionTracker::lookahead(const hw::Pose2D& o) const {
  return lookahead(o, params_.lookahead_m);
}

Eigen::Vector2d SectionTracker::lookahead(const hw::Pose2D& o, double distance_m) const {
  const auto pts = guidePointsOdom();
  if (finished()) return pts.back();
  const int k = current_;
  const Eigen::Vector2d a = pts[k], b = pts[k + 1], r(o.x, o.y);
  const Eigen::Vector2d d = b - a;
  const double len = d.norm();
  const double t = len > 1e-9 ? std::clamp((r - a).dot(d) / len, 0.0, len) : 0.0;
  // Pure pursuit: the first point of the remaining route, from the robot's projection on,
  // that is at least `lookahead` away from the robot (so the target never sits on top of a
  // robot that is off the line, e.g. after a dodge).
  Eigen::Vector2d p = len > 1e-9 ? Eigen::Vector2d(a + d / len * t) : a;
  const double step = 0.05;
  for (int i = k; i + 1 < static_cast<int>(pts.size()); ++i) {
    const Eigen::Vector2d seg_end = pts[i + 1];
    while ((seg_end - p).norm() > 1e-9) {
      if ((p - r).norm() >= distance_m) return p;
      const Eigen::Vector2d dir = seg_end - p;
      p = dir.norm() <= step ? seg_end : Eigen::Vector2d(p + dir.normalized() * step);
    }
  }
  return pts.back();
}

Polar polarFrom(const hw::Pose2D& pose, const Eigen::Vector2d& pt) {
  const Eigen::Vector2d d = pt - Eigen::Vector2d(pose.x, pose.y);
  return {wrapAngle(std::atan2(d.y(), d.x()) - pose.theta), d.norm()};
}

std::optional<Eigen::Vector2d> goalFromExactFixes(
    const mapsketch::Route& route, const std::map<std::string, Eigen::Vector2d>& truth,
    const WeightedFitParams& p) {
  if (route.sections.empty()) return std::nullopt;
  // An exact observation: the fit's weight is then the sketch's error alone, the same for
  // every landmark, as in the navigation's refit of well-located fixes.
  const Eigen::Matrix2d exact = 1e12 * Eigen::Matrix2d::Identity();
  std::vector<WeightedFix> fixes{{route.start_m, {0, 0}, exact, true}};
  std::vector<std::string> seen;
  for (const auto& sec : route.sections)
    for (const auto& lm : sec.landmarks) {
      const auto it = truth.find(lm.id);
      if (it == truth.end() || std::find(seen.begin(), seen.end(), lm.id) != seen.end()) continue;
      seen.push_back(lm.id);
      fixes.push_back({lm.position_m, it->second, exact, false});
    }
  if (seen.size() < 2) return std::nullopt;
  SectionTracker t(route);
  if (!t.fitSimilarityWeighted(fixes, p).ok) return std::nullopt;
  return t.toOdom(route.goal_m);
}

}  // namespace sketchnav::nav
