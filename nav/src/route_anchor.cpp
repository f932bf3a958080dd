#include "sketchnav/nav/route_anchor.h"

#include <algorithm>
#include <cmath>

#include "sketchnav/core/config.h"

namespace sketchnav::nav {

void RouteAnchorParams::validate() const {
  require(reanchor_gain >= 0 && reanchor_gain <= 1, "nav.reanchor_gain", "must be in [0, 1]");
  require(realign_gain >= 0 && realign_gain <= 1, "nav.realign_gain", "must be in [0, 1]");
  require(realign_baseline_m >= 0, "nav.realign_baseline_m", "must be >= 0");
  require(same_class_gate_m >= 0, "nav.same_class_gate_m", "must be >= 0 (0 = off)");
  require(fit_fixes == 0 || fit_fixes >= 3, "nav.fit_fixes", "must be 0 (off) or >= 3");
  require(fit_min_span_m >= 0, "nav.fit_min_span_m", "must be >= 0");
  require(fit_max_scale_change >= 0 && fit_max_scale_change < 1, "nav.fit_max_scale_change",
          "must be in [0, 1)");
  require(fit_local_gain >= 0 && fit_local_gain <= 1, "nav.fit_local_gain", "must be in [0, 1]");
  require(fit_outlier_m >= 0, "nav.fit_outlier_m", "must be >= 0 (0 = keep every fix)");
}

void RouteAnchor::start(const SectionTracker& route) {
  last_route_ = route.route().start_m;
  last_odom_ = route.toOdom(last_route_);
  Fix f;
  f.route = last_route_;
  f.odom = last_odom_;
  f.information = Eigen::Matrix2d::Identity() / (0.05 * 0.05);  // the start: where it is put
  fixes_ = {f};
}

bool RouteAnchor::atEarlierFix(const std::string& cls, const Eigen::Vector2d& o, double direction,
                               double range, double ranged_within_m) const {
  const Eigen::Vector2d dir(std::cos(direction), std::sin(direction));
  for (size_t j = 1; j < fixes_.size(); ++j) {
    const Fix& f = fixes_[j];
    if (f.class_name != cls || f.bearingOnly()) continue;
    const Eigen::Vector2d v = f.odom - o;
    if (range > 0 && range <= ranged_within_m) {
      if ((o + range * dir - f.odom).norm() < p_.same_class_gate_m) return true;
    } else if (v.dot(dir) > 0 &&
               std::abs(dir.x() * v.y() - dir.y() * v.x()) < 0.5 * p_.same_class_gate_m) {
      return true;
    }
  }
  return false;
}

RouteAnchor::Correction RouteAnchor::correct(SectionTracker& tracker,
                                             const Eigen::Vector2d& route_pt,
                                             const std::string& cls,
                                             const std::vector<Sighting>& sightings,
                                             const LocateParams& locate) {
  Correction out;
  // Where the landmark really is (odometry frame: its bearings crossed, and the ranges that
  // agree) vs where the sketch puts it: refit or rotate the route, then shift it, each by its
  // gain.
  LandmarkFix lf = locateLandmark(sightings, locate);
  if (lf.ok && lf.bearing_only && !(p_.fit_bearing_only && p_.fit_weighted))
    lf.ok = false;  // (an equal-weight fit would take its nominal point as exact)
  // Across the rays of a bearing-only fix (the newest sighting's).
  Eigen::Vector2d across = Eigen::Vector2d::Zero();
  if (lf.ok && lf.bearing_only) {
    const double a = sightings.back().direction;
    across = {-std::sin(a), std::cos(a)};
  }
  // Located where an earlier landmark of the same class was (a bearing-only one: its rays
  // pass there): the sightings were of that one.
  for (size_t j = 1; lf.ok && j < fixes_.size(); ++j) {
    const Fix& f = fixes_[j];
    if (f.class_name != cls || f.bearingOnly()) continue;
    const Eigen::Vector2d v = f.odom - lf.position;
    if (lf.bearing_only ? std::abs(across.dot(v)) < 0.5 * p_.same_class_gate_m
                        : v.norm() < p_.same_class_gate_m) {
      lf.ok = false;
      out.rejected = "where an earlier " + cls + " was";
    }
  }
  if (!lf.ok) return out;

  const Eigen::Vector2d seen = lf.position;
  auto& fx = out.fix.emplace();
  fx.method = lf.bearing_only ? "bearing only" : lf.triangulated ? "bearings" : "ranges";
  fx.rays = lf.rays;
  fx.ranges_used = lf.ranges_used;
  fx.height_ranges = lf.height_ranges;
  fx.height_sigma_m = lf.height_sigma_m;
  fx.gated_ranges = lf.gated_ranges;
  fx.ranges_dropped = lf.ranges_dropped;
  for (const auto& q : sightings)
    fx.sightings.push_back({q.origin.x(), q.origin.y(), q.direction, q.range_m});
  // A bearing-only fix says nothing along its rays: only the across part shifts anything.
  auto toward = [&](const Eigen::Vector2d& d) -> Eigen::Vector2d {
    return lf.bearing_only ? Eigen::Vector2d(across * across.dot(d)) : d;
  };
  // Shift the route `gain` of the way to the fix, as the route stands then.
  auto reanchorOn = [&](double gain) {
    const Eigen::Vector2d at = tracker.toOdom(route_pt);
    tracker.reanchor(route_pt, at + toward(seen - at), gain);
  };
  const Eigen::Vector2d shift = toward(seen - tracker.toOdom(route_pt));
  Fix nf;
  nf.route = route_pt;
  nf.odom = seen;
  nf.information = lf.information;
  nf.class_name = cls;
  nf.across = across;
  fixes_.push_back(nf);
  // With enough fixes spread far enough: refit rotation, scale and translation to the last
  // fit_fixes of them (the start counts as one) by least squares, then pull the route
  // fit_local_gain of the way to this one (0 by default).
  const size_t n = std::min<size_t>(fixes_.size(), std::max(0, p_.fit_fixes));
  std::vector<size_t> idx;  // the fixes fitted: the last n (and the start, if asked)
  if (p_.fit_keep_start && fixes_.size() > n) idx.push_back(0);
  for (size_t j = fixes_.size() - n; j < fixes_.size(); ++j) idx.push_back(j);
  std::vector<Eigen::Vector2d> fr, fo;
  for (size_t j : idx) fr.push_back(fixes_[j].route), fo.push_back(fixes_[j].odom);
  double span = 0;
  for (const auto& a : fr)
    for (const auto& b : fr) span = std::max(span, (a - b).norm());
  if (n >= 3 && span >= p_.fit_min_span_m) {
    SectionTracker::Fit f;
    if (p_.fit_weighted) {
      WeightedFitParams wp;
      wp.outlier_m = p_.fit_outlier_m;
      wp.max_scale_change = p_.fit_max_scale_change;
      std::vector<WeightedFix> wf;
      for (size_t j : idx)
        wf.push_back({fixes_[j].route, fixes_[j].odom, fixes_[j].information, j == 0});
      f = tracker.fitSimilarityWeighted(wf, wp);
    } else {
      f = tracker.fitSimilarity(fr, fo, p_.fit_max_scale_change, p_.fit_outlier_m);
    }
    // Not towards the newest fix when the fit found it an outlier.
    if (f.used.empty() || f.used.back()) reanchorOn(p_.fit_local_gain);
    fx.fit =
        event::PassedRefit{f.rotation * 180 / M_PI, tracker.scale(), f.rms, idx.size(), f.dropped};
  } else {
    const double rot = lf.bearing_only ? 0.0
                                       : tracker.realign(route_pt, seen, last_route_, last_odom_,
                                                         p_.realign_gain, p_.realign_baseline_m);
    reanchorOn(p_.reanchor_gain);
    fx.realign = event::PassedRealign{rot * 180 / M_PI, shift.norm() * p_.reanchor_gain};
  }
  fx.disagreement_m = shift.norm();
  // Both ends of the fix, for judging the sketch's and the estimator's errors offline.
  fx.route = route_pt;
  fx.odom = seen;
  if (!lf.bearing_only) {  // the anchor of the next realign: a point, not a ray
    last_route_ = route_pt;
    last_odom_ = seen;
  }
  return out;
}

}  // namespace sketchnav::nav
