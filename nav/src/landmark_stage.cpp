#include "sketchnav/nav/landmark_stage.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

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
  require(bearing_only_gate_deg >= 0 && bearing_only_gate_deg <= bearing_gate_deg,
          "nav.select.bearing_only_gate_deg", "must be in [0, bearing_gate_deg]");
}

namespace {
// The range gate's half-width around a predicted range [m].
double rangeGate(double predicted_m, const SelectParams& p) {
  return std::max(p.range_gate_min_m, p.range_gate_rel * predicted_m);
}
}  // namespace

bool rangeAgrees(double measured_m, double predicted_m, const SelectParams& p) {
  if (measured_m <= 0 || predicted_m <= 0) return true;
  return std::abs(measured_m - predicted_m) <= rangeGate(predicted_m, p);
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
      const double gate = rangeGate(pr, p);
      const double dr = std::abs(c.range_m - pr);
      if (dr <= gate) {
        cost += dr / p.range_sigma_m;
      } else if (db <= p.bearing_only_gate_deg * deg) {
        cost += gate / p.range_sigma_m;  // its bearing only (see SelectParams)
      } else {
        continue;
      }
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

Polar expectedFromTrack(const hw::Pose2D& robot, const Eigen::Vector2d& origin,
                        double world_bearing, double range) {
  if (range <= 0) return {wrapAngle(world_bearing - robot.theta), 0.0};
  return polarFrom(
      robot, origin + range * Eigen::Vector2d(std::cos(world_bearing), std::sin(world_bearing)));
}

bool claimedByTracked(const Candidate& c, size_t self, const std::vector<Expected>& expected) {
  if (!c.detection) return false;
  for (size_t m = 0; m < expected.size(); ++m) {
    const auto& e = expected[m];
    if (m == self || !e.tracked || e.class_name != c.detection->class_name) continue;
    const double db = std::abs(wrapAngle(c.detection->bearing - e.where.bearing));
    const bool range_ok =
        c.range_m <= 0 || e.where.range <= 0 || std::abs(c.range_m - e.where.range) < 0.75;
    if (db < 10 * M_PI / 180 && range_ok) return true;
  }
  return false;
}

void LocateParams::validate() const {
  require(bearing_sigma_deg > 0 && bearing_sigma_deg < 30, "nav.locate.bearing_sigma_deg",
          "must be in (0, 30)");
  require(min_spread_deg >= 0 && min_spread_deg < 90, "nav.locate.min_spread_deg",
          "must be in [0, 90)");
  require(max_along_sigma_m > 0, "nav.locate.max_along_sigma_m", "must be > 0");
  require(range_sigma_m > 0, "nav.locate.range_sigma_m", "must be > 0");
  require(range_gate_m > 0, "nav.locate.range_gate_m", "must be > 0");
  require(height_min_sightings >= 3, "nav.locate.height_min_sightings", "must be >= 3");
  require(height_min_elevation_deg > 0 && height_min_elevation_deg < 80,
          "nav.locate.height_min_elevation_deg", "must be in (0, 80)");
  require(height_elevation_sigma_deg > 0 && height_elevation_sigma_deg < 10,
          "nav.locate.height_elevation_sigma_deg", "must be in (0, 10)");
  require(height_max_sigma_m > 0, "nav.locate.height_max_sigma_m", "must be > 0");
  require(height_min_sigma_m > 0, "nav.locate.height_min_sigma_m", "must be > 0");
  require(height_agree_m > 0, "nav.locate.height_agree_m", "must be > 0");
  require(gated_confirm_sigma_m >= 0, "nav.locate.gated_confirm_sigma_m", "must be >= 0");
}

HeightRanges heightRanges(const std::vector<Sighting>& ss, const LocateParams& p) {
  HeightRanges out;
  if (!p.height_ranging) return out;
  const double emin = p.height_min_elevation_deg * M_PI / 180;
  std::map<int, std::vector<int>> by_photo;
  for (size_t i = 0; i < ss.size(); ++i)
    if (std::isfinite(ss[i].elevation) && std::abs(ss[i].elevation) >= emin)
      by_photo[ss[i].photo].push_back(static_cast<int>(i));
  std::vector<std::vector<int>> groups;
  for (auto& [photo, idx] : by_photo)
    if (static_cast<int>(idx.size()) >= p.height_min_sightings) groups.push_back(idx);
  if (groups.empty()) return out;
  // Unknowns: the landmark point q (2) and one height difference per photo. Sighting i says
  // q = o_i + (camera_along_i + dh_g cot e_i) u_i. Weighted least squares: along its ray a
  // sighting is worth (r^2 / dh) x elevation noise, across it r x bearing noise, so the far
  // ones (small elevations, noisy cotangents that would pull dh towards 0) count little. The
  // weights need r and dh: a first pass with equal weights gives them.
  const int G = static_cast<int>(groups.size()), n_par = 2 + G;
  const double sigma = p.bearing_sigma_deg * M_PI / 180;
  const double sigma_e = p.height_elevation_sigma_deg * M_PI / 180;
  auto unit = [](double a) { return Eigen::Vector2d(std::cos(a), std::sin(a)); };
  Eigen::MatrixXd AtA;
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n_par);
  double sse = 0;
  int rows = 0;
  // A sighting's noise [m] along and across its ray at the current estimate x.
  auto noise = [&](int g, const Sighting& s) {
    const double dh = std::abs(x(2 + g)) + 0.05;
    const double r = std::max(0.5, (x.head<2>() - s.origin).norm());
    return std::pair(r * r / dh * sigma_e + 0.02, r * sigma + 0.02);
  };
  for (int pass = 0; pass < 2; ++pass) {
    AtA = Eigen::MatrixXd::Zero(n_par, n_par);
    Eigen::VectorXd Atb = Eigen::VectorXd::Zero(n_par);
    rows = 0;
    for (int g = 0; g < G; ++g)
      for (int i : groups[g]) {
        const Sighting& s = ss[i];
        const Eigen::Vector2d u = unit(s.direction), nn(-u.y(), u.x());
        const Eigen::Vector2d a = u / std::tan(s.elevation);
        const Eigen::Vector2d o = s.origin + s.camera_along_m * u;
        Eigen::Matrix2d W = Eigen::Matrix2d::Identity();
        if (pass == 1) {
          const auto [s_along, s_across] = noise(g, s);
          W = u * u.transpose() / (s_along * s_along) + nn * nn.transpose() / (s_across * s_across);
        }
        Eigen::MatrixXd J = Eigen::MatrixXd::Zero(2, n_par);  // q - dh_g a = o
        J(0, 0) = 1, J(1, 1) = 1;
        J.col(2 + g) = -a;
        AtA += J.transpose() * W * J;
        Atb += J.transpose() * W * o;
        rows += 2;
      }
    if (rows <= n_par) return out;
    AtA += 1e-9 * Eigen::MatrixXd::Identity(n_par, n_par);
    x = AtA.ldlt().solve(Atb);
  }
  // Weighted residuals: their scale says how far the assumed noise is off.
  for (int g = 0; g < G; ++g)
    for (int i : groups[g]) {
      const Sighting& s = ss[i];
      const Eigen::Vector2d u = unit(s.direction), nn(-u.y(), u.x());
      const Eigen::Vector2d res =
          x.head<2>() - s.origin - (s.camera_along_m + x(2 + g) / std::tan(s.elevation)) * u;
      const auto [s_along, s_across] = noise(g, s);
      sse += std::pow(u.dot(res) / s_along, 2) + std::pow(nn.dot(res) / s_across, 2);
    }
  // At least the assumed noise: a perfect fit (simulation) must not claim perfect ranges.
  const double s2 = std::max(sse / (rows - n_par), 1.0);
  const Eigen::MatrixXd cov = s2 * AtA.inverse();
  out.range_m.assign(ss.size(), 0.0);
  out.sigma_m = 1e300;
  bool any = false;
  for (int g = 0; g < G; ++g) {
    const double dh = x(2 + g), sd = std::sqrt(std::max(0.0, cov(2 + g, 2 + g)));
    for (int i : groups[g]) {
      const Sighting& s = ss[i];
      const double cot = 1 / std::tan(s.elevation);
      const double r = s.camera_along_m + dh * cot, sr = sd * std::abs(cot);
      // A negative range is the wrong root (the fit found no height, only noise).
      if (r <= 0.3 || sr > p.height_max_sigma_m) continue;
      out.range_m[i] = r;
      out.sigma_m = std::min(out.sigma_m, sr);
      any = true;
    }
  }
  if (!any) return {};
  out.sigma_m = std::max(out.sigma_m, p.height_min_sigma_m);
  return out;
}

namespace {
// Whether laser readings (per sighting, <= 0: none) agree with height ranges: the median of
// their differences, over the sightings that have both, within `tolerance_m`. False when no
// sighting has both.
bool laserAgrees(const std::vector<double>& laser_m, const HeightRanges& hr, double tolerance_m) {
  std::vector<double> diff;
  for (size_t i = 0; i < laser_m.size(); ++i)
    if (hr.range_m[i] > 0 && laser_m[i] > 0) diff.push_back(laser_m[i] - hr.range_m[i]);
  if (diff.empty()) return false;
  std::nth_element(diff.begin(), diff.begin() + diff.size() / 2, diff.end());
  return std::abs(diff[diff.size() / 2]) <= tolerance_m;
}

// The sightings with the laser ranges the sketch's gate refused taken back when height
// ranges confirm them (LocateParams::gated_confirm_sigma_m); counted in f.gated_ranges.
std::vector<Sighting> withConfirmedRanges(std::vector<Sighting> ss, const LocateParams& p,
                                          LandmarkFix& f) {
  auto gated = [](const Sighting& s) { return s.range_m <= 0 && s.gated_range_m > 0; };
  if (p.gated_confirm_sigma_m <= 0 || std::none_of(ss.begin(), ss.end(), gated)) return ss;
  LocateParams loose = p;
  loose.height_max_sigma_m = std::max(p.height_max_sigma_m, p.gated_confirm_sigma_m);
  const HeightRanges hc = heightRanges(ss, loose);
  if (hc.range_m.empty()) return ss;
  std::vector<double> refused(ss.size(), 0.0);
  for (size_t i = 0; i < ss.size(); ++i)
    if (gated(ss[i])) refused[i] = ss[i].gated_range_m;
  if (!laserAgrees(refused, hc, std::max(p.height_agree_m, 2 * hc.sigma_m))) return ss;
  for (auto& s : ss)
    if (gated(s)) s.range_m = s.gated_range_m, ++f.gated_ranges;
  return ss;
}
}  // namespace

LandmarkFix locateLandmark(const std::vector<Sighting>& given, const LocateParams& p) {
  LandmarkFix f;
  if (given.empty()) return f;
  const std::vector<Sighting> sightings = withConfirmedRanges(given, p, f);
  // Height ranges in place of laser ranges that disagree with them (the laser hit what stands
  // behind or below the landmark), and for sightings the laser did not range at all.
  std::vector<double> range_sigma(sightings.size(), p.range_sigma_m);
  std::vector<Sighting> hs;
  const HeightRanges hr = heightRanges(sightings, p);
  if (!hr.range_m.empty()) {
    std::vector<double> laser(sightings.size());
    for (size_t i = 0; i < sightings.size(); ++i) laser[i] = sightings[i].range_m;
    const bool laser_agrees = laserAgrees(laser, hr, p.height_agree_m);
    hs = sightings;
    for (size_t i = 0; i < hs.size(); ++i) {
      if (laser_agrees && hs[i].range_m > 0) continue;
      if (hr.range_m[i] > 0) {
        hs[i].range_m = hr.range_m[i];
        hs[i].beyond_m = 0;
        range_sigma[i] = hr.sigma_m;
        ++f.height_ranges;
      } else if (!laser_agrees && hs[i].range_m > 0) {
        hs[i].beyond_m = hs[i].range_m;  // the landmark is no further, that is all
        hs[i].range_m = 0;
      }
    }
    f.height_sigma_m = f.height_ranges > 0 ? hr.sigma_m : 0;
  }
  const std::vector<Sighting>& ss = hs.empty() ? sightings : hs;
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
  std::vector<size_t> agree;
  for (size_t i = 0; i < ss.size(); ++i) {
    const Sighting& s = ss[i];
    if (s.range_m <= 0) continue;
    const Eigen::Vector2d u = unit(s.direction);
    const double slack = f.triangulated ? 2 * std::sqrt(std::max(0.0, u.dot(Cb * u))) : 0.0;
    if (std::abs(u.dot(ref - s.origin) - s.range_m) > p.range_gate_m + slack)
      ++f.ranges_dropped;
    else
      agree.push_back(i);
  }
  // The ranges' error is mostly one bias shared by all of them (the same furniture behind; one
  // height fit), so together they are worth one range's sigma, not sigma / sqrt(n).
  f.ranges_used = static_cast<int>(agree.size());
  for (size_t i : agree) {
    const Sighting& s = ss[i];
    const Eigen::Vector2d u = unit(s.direction);
    const double wr = 1.0 / (agree.size() * range_sigma[i] * range_sigma[i]);
    I += wr * u * u.transpose(), b += wr * (u.dot(s.origin) + s.range_m) * u;
  }
  if (!f.triangulated && f.ranges_used == 0) return bearingOnly();
  f.ok = true;
  f.rays = static_cast<int>(ss.size());
  f.position = I.ldlt().solve(b);
  f.information = I;
  return f;
}

}  // namespace sketchnav::nav
