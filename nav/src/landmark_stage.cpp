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

LandmarkFix locateLandmark(const std::vector<Sighting>& ss, const LocateParams& p) {
  LandmarkFix f;
  if (ss.empty()) return f;
  const double sb = p.bearing_sigma_deg * M_PI / 180;
  auto unit = [](double a) { return Eigen::Vector2d(std::cos(a), std::sin(a)); };
  // Distance of a sighting for its bearing's weight: the range, the reading beyond, or 3 m.
  auto distanceOf = [](const Sighting& s) {
    return s.range_m > 0 ? s.range_m : s.beyond_m > 0 ? s.beyond_m : 3.0;
  };
  // Bearings: each pins the point across its ray to (distance x bearing error), the distance
  // from a first pass. A tiny prior at the rays' nominal points keeps the system solvable
  // when they are all parallel.
  Eigen::Matrix2d I;
  Eigen::Vector2d b, nominal(0, 0), mean_dir(0, 0);
  for (const auto& s : ss) {
    const Eigen::Vector2d u = unit(s.direction);
    nominal += s.origin + distanceOf(s) * u;
    mean_dir += u;
  }
  nominal /= ss.size();
  Eigen::Vector2d x = nominal;
  for (int pass = 0; pass < 2; ++pass) {
    I = 1e-6 * Eigen::Matrix2d::Identity();
    b = 1e-6 * nominal;
    for (const auto& s : ss) {
      const Eigen::Vector2d u = unit(s.direction), nn(-u.y(), u.x());
      const double d = std::max(0.5, pass == 0 ? distanceOf(s) : (x - s.origin).norm());
      const double w = 1.0 / (d * d * sb * sb);
      I += w * nn * nn.transpose(), b += w * nn.dot(s.origin) * nn;
    }
    x = I.ldlt().solve(b);
  }
  const Eigen::Vector2d crossing = x;
  const Eigen::Matrix2d Cb = I.inverse();
  // A landmark seen from one place, without a range (a far one: the laser along its bearing
  // hits whatever is beyond), is still on its rays: across them it is known to range x
  // bearing error, which is what the refit needs to turn the route.
  const Eigen::Matrix2d I_rays = I;
  auto bearingOnly = [&] {
    LandmarkFix o;
    o.ok = true;
    o.bearing_only = true;
    o.rays = static_cast<int>(ss.size());
    o.ranges_dropped = f.ranges_dropped;
    o.position = crossing;
    o.information = I_rays;
    return o;
  };
  mean_dir.normalize();
  double lo = 0, hi = 0;  // spread of the rays' directions
  for (const auto& s : ss) {
    const double d = wrapAngle(s.direction - ss.front().direction);
    lo = std::min(lo, d), hi = std::max(hi, d);
  }
  f.triangulated = hi - lo >= p.min_spread_deg * M_PI / 180 &&
                   std::sqrt(std::max(0.0, mean_dir.dot(Cb * mean_dir))) <= p.max_along_sigma_m;
  // What a range is judged against: the crossing, or (no crossing) the median ranged point.
  Eigen::Vector2d ref = crossing;
  if (!f.triangulated) {
    std::vector<double> xs, ys;
    for (const auto& s : ss)
      if (s.range_m > 0) {
        const Eigen::Vector2d q = s.origin + s.range_m * unit(s.direction);
        xs.push_back(q.x()), ys.push_back(q.y());
      }
    if (xs.empty()) return bearingOnly();  // neither crossing bearings nor a range
    std::nth_element(xs.begin(), xs.begin() + xs.size() / 2, xs.end());
    std::nth_element(ys.begin(), ys.begin() + ys.size() / 2, ys.end());
    ref = {xs[xs.size() / 2], ys[ys.size() / 2]};
  }
  std::vector<const Sighting*> agree;
  for (const auto& s : ss) {
    if (s.range_m <= 0) continue;
    const Eigen::Vector2d u = unit(s.direction);
    const double slack = f.triangulated ? 2 * std::sqrt(std::max(0.0, u.dot(Cb * u))) : 0.0;
    if (std::abs(u.dot(ref - s.origin) - s.range_m) > p.range_gate_m + slack)
      ++f.ranges_dropped;
    else
      agree.push_back(&s);
  }
  // The ranges' error is mostly one bias shared by all of them (the same furniture behind),
  // so together they are worth range_sigma_m, not range_sigma_m / sqrt(n).
  f.ranges_used = static_cast<int>(agree.size());
  for (const Sighting* s : agree) {
    const Eigen::Vector2d u = unit(s->direction);
    const double wr = 1.0 / (agree.size() * p.range_sigma_m * p.range_sigma_m);
    I += wr * u * u.transpose(), b += wr * (u.dot(s->origin) + s->range_m) * u;
  }
  if (!f.triangulated && f.ranges_used == 0) return bearingOnly();
  f.ok = true;
  f.rays = static_cast<int>(ss.size());
  f.position = I.ldlt().solve(b);
  f.information = I;
  return f;
}

}  // namespace sketchnav::nav
