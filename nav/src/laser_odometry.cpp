#include "sketchnav/nav/laser_odometry.h"

#include <mrpt/maps/CSimplePointsMap.h>
#include <mrpt/poses/CPose2D.h>
#include <mrpt/poses/CPosePDF.h>
#include <mrpt/slam/CICP.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <chrono>
#include <cmath>

#include "sketchnav/core/config.h"
#include "sketchnav/nav/sections.h"

namespace sketchnav::nav {

using mrpt::poses::CPose2D;

void LaserOdometryParams::validate() const {
  require(keyframe_dist_m > 0, "nav.laser_odometry.keyframe_dist_m", "must be > 0");
  require(keyframe_deg > 0 && keyframe_deg <= 90, "nav.laser_odometry.keyframe_deg",
          "must be in (0, 90]");
  require(max_range_m > 0, "nav.laser_odometry.max_range_m", "must be > 0");
  require(submap_keyframes >= 1 && submap_keyframes <= 20, "nav.laser_odometry.submap_keyframes",
          "must be in [1, 20]");
  require(min_points >= 5, "nav.laser_odometry.min_points", "must be >= 5");
  require(min_spread_m >= 0, "nav.laser_odometry.min_spread_m", "must be >= 0");
  require(min_goodness >= 0 && min_goodness <= 1, "nav.laser_odometry.min_goodness",
          "must be in [0, 1]");
  require(max_correction_m > 0, "nav.laser_odometry.max_correction_m", "must be > 0");
  require(max_correction_deg > 0, "nav.laser_odometry.max_correction_deg", "must be > 0");
  require(match_dist_m > 0, "nav.laser_odometry.match_dist_m", "must be > 0");
  require(match_deg >= 0, "nav.laser_odometry.match_deg", "must be >= 0");
  require(constrained_points >= 0, "nav.laser_odometry.constrained_points", "must be >= 0");
  require(normal_radius_m > 0, "nav.laser_odometry.normal_radius_m", "must be > 0");
  require(moving_baseline_s >= 0 && moving_baseline_s <= 5, "nav.laser_odometry.moving_baseline_s",
          "must be in [0, 5]");
  require(wheel_agree_m >= 0, "nav.laser_odometry.wheel_agree_m", "must be >= 0");
  require(wheel_agree_rel >= 0 && wheel_agree_rel <= 1, "nav.laser_odometry.wheel_agree_rel",
          "must be in [0, 1]");
}

namespace {
CPose2D toMrpt(const hw::Pose2D& p) {
  return CPose2D(p.x, p.y, p.theta);
}
hw::Pose2D fromMrpt(const CPose2D& p) {
  return {p.x(), p.y(), p.phi()};
}

// How well the scan's surfaces pin a translation down, direction by direction: the sum over
// the points of n n^T, n the unit normal of the surface through the point (a line fitted to
// its beam neighbours within `radius` m). It is the translation block of the point-to-line
// alignment's Hessian: along a unit direction e, e^T H e counts the points whose surface
// faces e (cos^2 weighted). Two parallel walls leave it near zero along them. Points with no
// line through them (too few neighbours, a corner, clutter) add nothing.
Eigen::Matrix2d surfaceInformation(const mrpt::aligned_std_vector<float>& xs,
                                   const mrpt::aligned_std_vector<float>& ys, double radius) {
  Eigen::Matrix2d H = Eigen::Matrix2d::Zero();
  const int n = static_cast<int>(xs.size());
  const int window = 10;  // beam neighbours looked at on each side
  const double r2 = radius * radius;
  for (int i = 0; i < n; ++i) {
    double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
    int m = 0;
    for (int j = std::max(0, i - window); j <= std::min(n - 1, i + window); ++j) {
      const double dx = xs[j] - xs[i], dy = ys[j] - ys[i];
      if (dx * dx + dy * dy > r2) continue;
      sx += dx, sy += dy, sxx += dx * dx, syy += dy * dy, sxy += dx * dy;
      ++m;
    }
    if (m < 5) continue;
    const double mx = sx / m, my = sy / m;
    Eigen::Matrix2d C;
    C << sxx / m - mx * mx, sxy / m - mx * my, sxy / m - mx * my, syy / m - my * my;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(C);
    // A line: the spread across it well under the spread along it (std. dev. ratio < 0.3).
    if (es.eigenvalues()(0) > 0.09 * es.eigenvalues()(1)) continue;
    const Eigen::Vector2d nrm = es.eigenvectors().col(0);
    H += nrm * nrm.transpose();
  }
  return H;
}

// Range of `scan`'s beam towards robot-frame bearing `bearing` (from the mount): NaN outside
// its field of view, +inf where it saw nothing within `rmax`.
double rangeToward(const hw::RangeScan& scan, double bearing, double rmax) {
  const size_t n = std::min(scan.angles.size(), scan.ranges.size());
  if (n < 2) return std::nan("");
  const double a0 = scan.angles.front(), step = (scan.angles.back() - a0) / (n - 1);
  if (!(step > 0)) return std::nan("");  // beams are ordered counter-clockwise
  double d = wrapAngle(bearing - a0);
  if (d < 0) d += 2 * M_PI;  // a field of view may span more than half a turn
  const double k = std::round(d / step);
  if (!(k >= 0 && k <= static_cast<double>(n - 1))) return std::nan("");
  const double r = scan.ranges[static_cast<size_t>(k)];
  return std::isfinite(r) && r < rmax && r >= scan.min_range ? r : INFINITY;
}

// The points of `cur` (from scan `cs`) left once what moved since scan `rs` (points `ref`) is
// taken out; `rel` is the current pose in the reference scan's frame. A point is explained
// when the reference has a point, or a segment between two beam neighbours, within
// dist + ang x range (segments because a wall seen at a grazing angle is sampled metres apart;
// a segment longer than a fifth of its range joins two surfaces, not one). An unexplained
// point has moved when the reference looked through the place (its beam there reached
// further), or when what hid it then has gone (the current beam reaches past it): a person
// walking away hides their own new place. Otherwise it has just come into view from behind
// something still there, or into the field of view, and is kept. Runs of fewer than min_run
// such beams are kept too: an edge sampled differently, or noise, and edges are what pin a
// pose down.
mrpt::maps::CSimplePointsMap movedPointsLeftOut(const mrpt::maps::CSimplePointsMap& cur,
                                                const hw::RangeScan& cs,
                                                const mrpt::maps::CSimplePointsMap& ref,
                                                const hw::RangeScan& rs, const CPose2D& rel,
                                                double dist, double ang, int min_run, double rmax) {
  mrpt::maps::CSimplePointsMap out;
  const auto& cx = cur.getPointsBufferRef_x();
  const auto& cy = cur.getPointsBufferRef_y();
  if (ref.size() == 0) return cur;
  const auto& rx = ref.getPointsBufferRef_x();
  const auto& ry = ref.getPointsBufferRef_y();
  const double c = std::cos(rel.phi()), sn = std::sin(rel.phi());
  const auto toSegment = [&](double px, double py, size_t a, size_t b) {
    const double ax = rx[a], ay = ry[a], ex = rx[b] - ax, ey = ry[b] - ay;
    const double len2 = ex * ex + ey * ey;
    if (len2 > 0.04 * (ax * ax + ay * ay)) return 1e9;
    const double u = len2 > 0 ? std::clamp(((px - ax) * ex + (py - ay) * ey) / len2, 0.0, 1.0) : 0;
    return std::hypot(px - ax - u * ex, py - ay - u * ey);
  };
  const double mx = cs.mount.x, my = cs.mount.y;
  std::vector<char> moved(cx.size(), 0);
  for (size_t i = 0; i < cx.size(); ++i) {
    const double px = rel.x() + c * cx[i] - sn * cy[i], py = rel.y() + sn * cx[i] + c * cy[i];
    const double range = std::hypot(cx[i] - mx, cy[i] - my);
    const double tol = dist + ang * range;
    float d2 = 0;
    const size_t j = ref.kdTreeClosestPoint2D(static_cast<float>(px), static_cast<float>(py), d2);
    double best = std::sqrt(d2);
    if (j > 0) best = std::min(best, toSegment(px, py, j - 1, j));
    if (j + 1 < rx.size()) best = std::min(best, toSegment(px, py, j, j + 1));
    if (best <= tol) continue;
    // Seen from the reference pose: the point's range and that beam's.
    const double rr = std::hypot(px - mx, py - my);
    const double rref = rangeToward(rs, std::atan2(py - my, px - mx), rmax);
    if (std::isnan(rref)) continue;  // outside the reference's field of view
    if (rref > rr + tol) {
      moved[i] = 1;  // the reference saw through this place
      continue;
    }
    if (rref < rr - tol) {
      // Hidden then, by a surface at rref along that beam: is it still there?
      const double b = std::atan2(py - my, px - mx);
      const double ox = mx + rref * std::cos(b), oy = my + rref * std::sin(b);
      // ...that surface point in the current frame (inverse of rel)
      const double dx = ox - rel.x(), dy = oy - rel.y();
      const double qx = c * dx + sn * dy, qy = -sn * dx + c * dy;
      const double rq = std::hypot(qx - mx, qy - my);
      const double rcur = rangeToward(cs, std::atan2(qy - my, qx - mx), rmax);
      if (!std::isnan(rcur) && rcur > rq + dist + ang * rq) moved[i] = 1;  // gone
    }
  }
  for (size_t i = 0; i < cx.size();) {
    size_t e = i;
    while (e < cx.size() && moved[e] == moved[i]) ++e;
    if (!moved[i] || e - i < static_cast<size_t>(min_run))
      for (size_t k = i; k < e; ++k) out.insertPoint(cx[k], cy[k], 0.f);
    i = e;
  }
  return out;
}
}  // namespace

struct LaserOdometry::Impl {
  mrpt::slam::CICP icp;
  struct Stamped {
    double t;
    CPose2D wheel;
  };
  std::deque<Stamped> history;  // recent wheel poses, to place a scan at its own time
  bool have_anchor = false;
  CPose2D anchor_wheel, anchor_pose;  // a wheel pose and the corrected pose at that moment
  bool have_kf = false;
  CPose2D kf_pose;                      // the newest keyframe's pose
  CPose2D kf_wheel;                     // the wheel pose at that moment
  mrpt::maps::CSimplePointsMap kf_map;  // the last keyframes' points, in the newest's frame
  struct Keyframe {
    CPose2D pose;
    std::vector<float> xs, ys;  // scan points in the robot frame at `pose`
  };
  std::deque<Keyframe> keyframes;  // the submap, oldest first
  // Recent scans, every point (robot frame, beam order), with the wheel pose at each: what
  // moved is judged against them.
  struct Past {
    double t;
    CPose2D wheel;
    mrpt::maps::CSimplePointsMap map;
    hw::RangeScan scan;
  };
  std::deque<Past> past;
  double moving_sum = 0;
  int moving_n = 0;
  double last_scan_stamp = -1e300;
  double ms_sum = 0;

  CPose2D corrected(const CPose2D& wheel) const {
    if (!have_anchor) return wheel;
    return anchor_pose + (wheel - anchor_wheel);
  }
  // Wheel pose at time t, linearly interpolated (scans and odometry are not read together).
  bool wheelAt(double t, CPose2D& out) const {
    if (history.empty()) return false;
    if (t <= history.front().t) {
      out = history.front().wheel;
      return true;
    }
    for (size_t i = 1; i < history.size(); ++i)
      if (history[i].t >= t) {
        const auto& a = history[i - 1];
        const auto& b = history[i];
        const double f = b.t > a.t ? (t - a.t) / (b.t - a.t) : 1.0;
        const CPose2D d = b.wheel - a.wheel;
        out = a.wheel + CPose2D(f * d.x(), f * d.y(), f * d.phi());
        return true;
      }
    out = history.back().wheel;
    return true;
  }
};

LaserOdometry::LaserOdometry(LaserOdometryParams params) : params_(params) {
  params_.validate();
  impl_ = std::make_unique<Impl>();
  auto& o = impl_->icp.options;
  o.ICP_algorithm = mrpt::slam::icpClassic;
  o.maxIterations = 60;
  // Start with a wide association distance (the wheel guess can be a few cm and degrees off)
  // and let ICP shrink it as it converges.
  o.thresholdDist = 0.3;
  o.thresholdAng = 2.0 * M_PI / 180;
  o.ALFA = 0.5;
  o.smallestThresholdDist = 0.03;
  // Pair every scan point in every iteration: MRPT's default pairs one in five (~45 of 240
  // beams), and the heading found from so few pairs jitters by up to a degree from one scan to
  // the next, which each keyframe inherits (replaying exp3-4-uneven #2's scans: final heading
  // error 4.1 -> 1.2 degrees with this alone).
  o.corresponding_points_decimation = 1;
  o.onlyUniqueRobust = false;
  o.doRANSAC = false;
  o.skip_cov_calculation = true;
  o.skip_quality_calculation = true;
  impl_->icp.setMinLoggingLevel(mrpt::system::LVL_ERROR);
}
LaserOdometry::~LaserOdometry() = default;
LaserOdometry::LaserOdometry(LaserOdometry&&) noexcept = default;
LaserOdometry& LaserOdometry::operator=(LaserOdometry&&) noexcept = default;

hw::Pose2D LaserOdometry::wheel(const hw::Pose2D& wheel_pose, double stamp) {
  auto& I = *impl_;
  if (I.history.empty() || stamp > I.history.back().t)
    I.history.push_back({stamp, toMrpt(wheel_pose)});
  while (I.history.size() > 2 && I.history.front().t < stamp - 3.0) I.history.pop_front();
  if (!I.have_anchor) {
    I.anchor_wheel = I.anchor_pose = toMrpt(wheel_pose);
    I.have_anchor = true;
  }
  return fromMrpt(I.corrected(toMrpt(wheel_pose)));
}

hw::Pose2D LaserOdometry::pose() const {
  const auto& I = *impl_;
  if (I.history.empty()) return {};
  return fromMrpt(I.corrected(I.history.back().wheel));
}

void LaserOdometry::scan(const hw::RangeScan& sc) {
  auto& I = *impl_;
  if (!params_.enabled || sc.kind != hw::RangeScan::Kind::Laser) return;
  if (sc.stamp <= I.last_scan_stamp || I.history.empty()) return;
  I.last_scan_stamp = sc.stamp;
  ++stats_.scans;
  mrpt::maps::CSimplePointsMap cur;
  const size_t n = std::min(sc.angles.size(), sc.ranges.size());
  const double rmax = std::min<double>(params_.max_range_m, sc.max_range);
  for (size_t i = 0; i < n; ++i) {
    const double r = sc.ranges[i];
    if (!std::isfinite(r) || r >= rmax || r < sc.min_range) continue;
    const double a = sc.angles[i];  // a robot-frame bearing: the mount's yaw is in it already
    cur.insertPoint(static_cast<float>(sc.mount.x + r * std::cos(a)),
                    static_cast<float>(sc.mount.y + r * std::sin(a)), 0.f);
  }
  CPose2D wheel_s;
  I.wheelAt(sc.stamp, wheel_s);
  // `all` keeps every point for the keyframes (a point that has just come into view is what
  // the next scans will see more of); `cur`, aligned, leaves out what moved.
  mrpt::maps::CSimplePointsMap all;
  if (params_.moving_baseline_s > 0 && cur.size() > 0) {
    const Impl::Past* ref = nullptr;
    for (auto it = I.past.rbegin(); it != I.past.rend(); ++it)
      if (it->t <= sc.stamp - params_.moving_baseline_s) {
        ref = &*it;
        break;
      }
    Impl::Past now{sc.stamp, wheel_s, cur, sc};
    all = cur;
    if (ref) {
      cur = movedPointsLeftOut(cur, sc, ref->map, ref->scan, wheel_s - ref->wheel,
                               params_.match_dist_m, params_.match_deg * M_PI / 180, 3, rmax);
      I.moving_sum += 1.0 - static_cast<double>(cur.size()) / now.map.size();
      stats_.moving_share = I.moving_sum / ++I.moving_n;
    }
    I.past.push_back(std::move(now));
    // Keep the newest scan at least moving_baseline_s old, and what is newer.
    while (I.past.size() > 1 && I.past[1].t <= sc.stamp - params_.moving_baseline_s)
      I.past.pop_front();
  }
  if (all.size() == 0) all = cur;
  if (static_cast<int>(cur.size()) < params_.min_points) return;
  {
    // Spread of the points across their main axis (smaller eigenvalue of their covariance).
    const auto& xs = cur.getPointsBufferRef_x();
    const auto& ys = cur.getPointsBufferRef_y();
    double mx = 0, my = 0;
    for (size_t i = 0; i < xs.size(); ++i) mx += xs[i], my += ys[i];
    mx /= xs.size(), my /= xs.size();
    double sxx = 0, syy = 0, sxy = 0;
    for (size_t i = 0; i < xs.size(); ++i) {
      const double dx = xs[i] - mx, dy = ys[i] - my;
      sxx += dx * dx, syy += dy * dy, sxy += dx * dy;
    }
    sxx /= xs.size(), syy /= xs.size(), sxy /= xs.size();
    const double lmin = 0.5 * (sxx + syy) - std::sqrt(0.25 * (sxx - syy) * (sxx - syy) + sxy * sxy);
    if (lmin < params_.min_spread_m * params_.min_spread_m) {
      ++stats_.rejected;
      return;
    }
  }

  const CPose2D predicted = I.corrected(wheel_s);
  // The reference is the union of the last submap_keyframes keyframes, expressed in the newest
  // one's frame: a new keyframe is then placed against points seen from several earlier poses
  // rather than one, so its error is not simply added to the previous keyframe's.
  auto newKeyframe = [&](const CPose2D& at) {
    I.kf_wheel = wheel_s;
    Impl::Keyframe k;
    k.pose = at;
    k.xs.assign(all.getPointsBufferRef_x().begin(), all.getPointsBufferRef_x().end());
    k.ys.assign(all.getPointsBufferRef_y().begin(), all.getPointsBufferRef_y().end());
    I.keyframes.push_back(std::move(k));
    while (static_cast<int>(I.keyframes.size()) > params_.submap_keyframes) I.keyframes.pop_front();
    I.kf_pose = at;
    I.kf_map.clear();
    for (const auto& kf : I.keyframes) {
      const CPose2D rel = kf.pose - at;  // that keyframe in the newest one's frame
      const double c = std::cos(rel.phi()), sn = std::sin(rel.phi());
      for (size_t i = 0; i < kf.xs.size(); ++i)
        I.kf_map.insertPoint(static_cast<float>(rel.x() + c * kf.xs[i] - sn * kf.ys[i]),
                             static_cast<float>(rel.y() + sn * kf.xs[i] + c * kf.ys[i]), 0.f);
    }
    I.have_kf = true;
    ++stats_.keyframes;
  };
  if (!I.have_kf) {
    newKeyframe(predicted);
    return;
  }
  const CPose2D guess = predicted - I.kf_pose;  // current robot in the keyframe's frame
  const auto t0 = std::chrono::steady_clock::now();
  mrpt::slam::CICP::TReturnInfo info;
  const auto pdf = I.icp.Align(&I.kf_map, &cur, guess, info);
  I.ms_sum +=
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  CPose2D est = pdf->getMeanVal();
  // Along a direction the scan's surfaces do not pin down (a corridor's axis between two
  // plain walls), ICP's translation is whatever its point pairs happen to settle on: it stalls
  // or slides. There the wheels' increment is kept (the guess's component), and ICP's only
  // across it and in heading; in between the two are blended by how constrained it is.
  bool degenerate = false;
  if (params_.constrained_points > 0) {
    const Eigen::Matrix2d Hr = surfaceInformation(
        cur.getPointsBufferRef_x(), cur.getPointsBufferRef_y(), params_.normal_radius_m);
    const double c = std::cos(est.phi()), sn = std::sin(est.phi());
    Eigen::Matrix2d R;
    R << c, -sn, sn, c;
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(R * Hr * R.transpose());
    Eigen::Vector2d t(est.x(), est.y());
    const Eigen::Vector2d to_guess = Eigen::Vector2d(guess.x(), guess.y()) - t;
    for (int k = 0; k < 2; ++k) {
      const double lam = es.eigenvalues()(k);
      // Share of ICP's translation kept along this direction: 0 below constrained_points, 1
      // from twice that.
      const double keep = std::clamp(lam / params_.constrained_points - 1.0, 0.0, 1.0);
      if (keep >= 1.0) continue;
      degenerate = true;
      const Eigen::Vector2d e = es.eigenvectors().col(k);
      t += (1.0 - keep) * e * e.dot(to_guess);
    }
    est = CPose2D(t.x(), t.y(), est.phi());
  }
  // The wheels' motion since the keyframe, in the robot's frame at the keyframe (as est is).
  bool wheel_translation = false;
  if (params_.wheel_agree_rel > 0) {
    const CPose2D wrel = wheel_s - I.kf_wheel;
    const double tol =
        params_.wheel_agree_m + params_.wheel_agree_rel * std::hypot(wrel.x(), wrel.y());
    if (std::hypot(est.x() - wrel.x(), est.y() - wrel.y()) > tol) {
      wheel_translation = true;
      est = CPose2D(wrel.x(), wrel.y(), est.phi());
    }
  }
  const CPose2D diff = est - guess;
  // How much of the scan the reference explains at the result: the share of its points with a
  // reference point within match_dist_m + match_deg * range. Not ICP's own goodness, which is
  // that share at its final, shrunk threshold (2-4 cm): beyond 2-4 m that is less than the gap
  // between 1-degree beams, so as the robot moves away from the keyframe fewer beams land on
  // reference points and correct alignments fell under min_goodness after 1-1.5 m. Refused,
  // the robot then ran on its wheels until twice keyframe_dist_m from the keyframe: in
  // exp4-static-obstacle #2 81 scans in a row (8 s, the detour round a box) were refused whose
  // headings were 0.1 degrees off the truth on average, while the wheels lost 3.2 degrees.
  double overlap = 0;
  {
    mrpt::maps::TMatchingParams mp;
    mp.maxDistForCorrespondence = static_cast<float>(params_.match_dist_m);
    mp.maxAngularDistForCorrespondence = static_cast<float>(params_.match_deg * M_PI / 180);
    mp.angularDistPivotPoint = mrpt::math::TPoint3D(est.x(), est.y(), 0);
    mrpt::tfest::TMatchingPairList pairs;
    mrpt::maps::TMatchingExtraResults extra;
    I.kf_map.determineMatching2D(&cur, est, pairs, mp, extra);
    overlap = extra.correspondencesRatio;
  }
  const bool ok = overlap >= params_.min_goodness &&
                  std::hypot(diff.x(), diff.y()) <= params_.max_correction_m &&
                  std::abs(diff.phi()) <= params_.max_correction_deg * M_PI / 180;
  CPose2D now_pose = predicted;
  if (ok) {
    ++stats_.aligned;
    if (degenerate) ++stats_.degenerate;
    if (wheel_translation) ++stats_.wheel_disagree;
    now_pose = I.kf_pose + est;
    I.anchor_wheel = wheel_s;
    I.anchor_pose = now_pose;
  } else {
    ++stats_.rejected;
  }
  ++stats_.attempts;
  stats_.ms_mean = I.ms_sum / stats_.attempts;
  const CPose2D rel = now_pose - I.kf_pose;
  // A refused alignment also starts a new keyframe once the robot is well away from the old
  // one: aligning ever larger displacements only gets worse. And at once when the reference
  // explains too little of the scan: the view has moved on (turning among obstacles, into a
  // new room) and will only move further, while the wheels since the last alignment, 0.1 s
  // ago, are still good. Waiting for twice keyframe_dist_m instead left exp2-redrawn-d #2's
  // robot on its wheels for 6 s (64 scans) in a weave round obstacles: 1.8 degrees lost
  // (replayed: final odometry error 0.47 m / 3.3 degrees -> 0.22 m / 1.0).
  const double k = ok ? 1.0 : 2.0;
  if (overlap < params_.min_goodness ||
      std::hypot(rel.x(), rel.y()) >= k * params_.keyframe_dist_m ||
      std::abs(rel.phi()) >= k * params_.keyframe_deg * M_PI / 180)
    newKeyframe(now_pose);
}

}  // namespace sketchnav::nav
