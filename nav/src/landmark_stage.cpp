#include "sketchnav/nav/landmark_stage.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

#include "sketchnav/core/config.h"
#include "sketchnav/nav/sections.h"

namespace sketchnav::nav {

void SelectParams::validate() const {
  require(bearing_gate_deg > 0 && bearing_gate_deg <= 180, "nav.select.bearing_gate_deg",
          "must be in (0, 180]");
  require(range_gate_rel > 0, "nav.select.range_gate_rel", "must be > 0");
  require(range_gate_min_m >= 0, "nav.select.range_gate_min_m", "must be >= 0");
  require(bearing_sigma_deg > 0, "nav.select.bearing_sigma_deg", "must be > 0");
  require(range_sigma_m > 0, "nav.select.range_sigma_m", "must be > 0");
}

int selectCandidate(const std::vector<Candidate>& cands, const std::string& class_name, double pb,
                    double pr, const SelectParams& p) {
  const double deg = M_PI / 180;
  int best = -1;
  double best_cost = 0;
  for (size_t i = 0; i < cands.size(); ++i) {
    const auto& c = cands[i];
    if (!c.detection || c.detection->class_name != class_name) continue;
    const double db = std::abs(wrapAngle(c.detection->bearing - pb));
    if (db > p.bearing_gate_deg * deg) continue;
    double cost = db / (p.bearing_sigma_deg * deg);
    if (c.range_m > 0 && pr > 0) {
      const double dr = std::abs(c.range_m - pr);
      if (dr > std::max(p.range_gate_min_m, p.range_gate_rel * pr)) continue;
      cost += dr / p.range_sigma_m;
    }
    if (best < 0 || cost < best_cost - 1e-9 ||
        (std::abs(cost - best_cost) <= 1e-9 &&
         c.detection->inliers > cands[best].detection->inliers)) {
      best = static_cast<int>(i);
      best_cost = cost;
    }
  }
  return best;
}

void LocateParams::validate() const {
  require(bearing_sigma_deg > 0 && bearing_sigma_deg < 30, "nav.locate.bearing_sigma_deg",
          "must be in (0, 30)");
  require(min_spread_deg >= 0 && min_spread_deg < 90, "nav.locate.min_spread_deg",
          "must be in [0, 90)");
  require(max_along_sigma_m > 0, "nav.locate.max_along_sigma_m", "must be > 0");
  require(range_sigma_m > 0, "nav.locate.range_sigma_m", "must be > 0");
  require(range_gate_m > 0, "nav.locate.range_gate_m", "must be > 0");
}

namespace {
// Weighted least squares of a point from line constraints n.p = c (unit n, weight w).
struct Lines {
  Eigen::Matrix2d A = Eigen::Matrix2d::Zero();
  Eigen::Vector2d b = Eigen::Vector2d::Zero();
  void add(const Eigen::Vector2d& n, double c, double w) {
    A += w * n * n.transpose();
    b += w * c * n;
  }
};
Eigen::Vector2d unit(double a) {
  return {std::cos(a), std::sin(a)};
}
Eigen::Vector2d normal(double a) {
  return {-std::sin(a), std::cos(a)};
}
}  // namespace

LandmarkFix locateLandmark(const std::vector<Sighting>& ss, const LocateParams& p) {
  LandmarkFix f;
  if (ss.empty()) return f;
  const double sb = p.bearing_sigma_deg * M_PI / 180;
  // Ranges alone: the median of the ranged points (robust to one stray return).
  std::vector<Eigen::Vector2d> ranged;
  for (const auto& s : ss)
    if (s.range_m > 0) ranged.push_back(s.origin + s.range_m * unit(s.direction));
  auto rangesOnly = [&] {
    LandmarkFix r;
    if (ranged.empty()) return r;
    std::vector<double> xs, ys;
    for (const auto& q : ranged) xs.push_back(q.x()), ys.push_back(q.y());
    std::nth_element(xs.begin(), xs.begin() + xs.size() / 2, xs.end());
    std::nth_element(ys.begin(), ys.begin() + ys.size() / 2, ys.end());
    r.ok = true;
    r.position = {xs[xs.size() / 2], ys[ys.size() / 2]};
    r.rays = static_cast<int>(ss.size());
    r.ranges_used = static_cast<int>(ranged.size());
    return r;
  };

  // Spread of the rays' directions.
  double lo = 1e9, hi = -1e9;
  for (const auto& s : ss) {
    const double d = wrapAngle(s.direction - ss.front().direction);
    lo = std::min(lo, d), hi = std::max(hi, d);
  }
  if ((hi - lo) < p.min_spread_deg * M_PI / 180) return rangesOnly();

  // Bearings only, each weighted by its distance (a bearing error moves the point across the
  // ray by range x error): first with the ranges' (or a nominal) distance, then with the
  // distance to the first solution.
  Eigen::Vector2d x = ranged.empty() ? ss.front().origin : rangesOnly().position;
  Lines L;
  for (int it = 0; it < 2; ++it) {
    L = Lines{};
    for (const auto& s : ss) {
      const double r = std::max(0.5, (x - s.origin).norm());
      const Eigen::Vector2d n = normal(s.direction);
      L.add(n, n.dot(s.origin), 1.0 / (r * r * sb * sb));
    }
    if (std::abs(L.A.determinant()) < 1e-12) return rangesOnly();
    x = L.A.ldlt().solve(L.b);
  }
  // Behind the rays (they diverge): no crossing.
  for (const auto& s : ss)
    if (unit(s.direction).dot(x - s.origin) <= 0) return rangesOnly();
  const Eigen::Matrix2d cov = L.A.inverse();
  // Uncertainty along the mean view direction: what the bearings fail to pin down.
  Eigen::Vector2d mean_dir(0, 0);
  for (const auto& s : ss) mean_dir += unit(s.direction);
  mean_dir.normalize();
  const double along_sigma = std::sqrt(std::max(0.0, mean_dir.dot(cov * mean_dir)));
  if (along_sigma > p.max_along_sigma_m) return rangesOnly();

  // Ranges that agree with the crossing point refine it; the others hit something else.
  f.ok = true;
  f.triangulated = true;
  f.rays = static_cast<int>(ss.size());
  Lines all = L;
  for (const auto& s : ss) {
    if (s.range_m <= 0) continue;
    const Eigen::Vector2d u = unit(s.direction);
    const double predicted = u.dot(x - s.origin);
    if (std::abs(s.range_m - predicted) > p.range_gate_m + 2 * along_sigma) {
      ++f.ranges_dropped;
      continue;
    }
    all.add(u, u.dot(s.origin) + s.range_m, 1.0 / (p.range_sigma_m * p.range_sigma_m));
    ++f.ranges_used;
  }
  f.position = all.A.ldlt().solve(all.b);
  return f;
}

}  // namespace sketchnav::nav
