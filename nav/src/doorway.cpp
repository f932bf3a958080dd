#include "sketchnav/nav/doorway.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "sketchnav/core/config.h"

namespace sketchnav::nav {

void DoorwayParams::validate(const char* prefix) const {
  const std::string p = prefix;
  require(min_width_m > 0.1 && min_width_m < max_width_m, p + ".min_width_m",
          "must be in (0.1, max_width_m) m");
  require(max_width_m <= 5, p + ".max_width_m", "must be <= 5 m");
  require(depth_m > 0.1, p + ".depth_m", "must be > 0.1 m");
  require(wall_m >= 0, p + ".wall_m", "must be >= 0 m");
  require(wall_tol_m > 0 && wall_tol_m < 0.5, p + ".wall_tol_m", "must be in (0, 0.5) m");
  require(max_range_m > 0, p + ".max_range_m", "must be > 0 m");
}

void GoalDoorParams::validate() const {
  DoorwayParams::validate("nav.goal_door");
  require(look_m > 0, "nav.goal_door.look_m", "must be > 0 m");
  require(search_m > 0, "nav.goal_door.search_m", "must be > 0 m");
  require(min_scans >= 1, "nav.goal_door.min_scans", "must be >= 1");
  require(agree_m > 0, "nav.goal_door.agree_m", "must be > 0 m");
}

std::vector<Doorway> findDoorways(const hw::RangeScan& scan, const hw::Pose2D& pose,
                                  const DoorwayParams& p) {
  std::vector<Doorway> out;
  if (scan.kind != hw::RangeScan::Kind::Laser) return out;
  const size_t n = std::min(scan.angles.size(), scan.ranges.size());
  if (n < 3) return out;
  // Beams in angle order (drivers give them so, but nothing below may assume it).
  std::vector<size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
            [&](size_t a, size_t b) { return scan.angles[a] < scan.angles[b]; });
  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  const Eigen::Vector2d origin(pose.x + c * scan.mount.x - s * scan.mount.y,
                               pose.y + s * scan.mount.x + c * scan.mount.y);
  std::vector<double> r(n), ang(n);
  std::vector<char> hit(n), none(n);  // a return / nothing within the sensor's range
  std::vector<Eigen::Vector2d> pt(n), dir(n);
  for (size_t k = 0; k < n; ++k) {
    const size_t i = order[k];
    r[k] = scan.ranges[i];
    ang[k] = pose.theta + scan.angles[i];
    dir[k] = {std::cos(ang[k]), std::sin(ang[k])};
    // A non-finite reading says nothing either way (a fault, not free space).
    hit[k] = std::isfinite(r[k]) && r[k] >= scan.min_range && r[k] < scan.max_range;
    none[k] = std::isfinite(r[k]) && r[k] >= scan.max_range;
    pt[k] = origin + (hit[k] ? r[k] : 0.0) * dir[k];
  }
  // How far along the ray from the sensor in direction `d` the line through `a` along `e`
  // is met; NaN when they are parallel.
  auto toLine = [&](const Eigen::Vector2d& d, const Eigen::Vector2d& a, const Eigen::Vector2d& e) {
    const double den = d.x() * e.y() - d.y() * e.x();
    if (std::abs(den) < 1e-9) return std::numeric_limits<double>::quiet_NaN();
    const Eigen::Vector2d q = a - origin;
    return (q.x() * e.y() - q.y() * e.x()) / den;
  };
  // Beam k passes the line a-b (a wall with an opening) and reads at least depth_m beyond it.
  auto beyond = [&](size_t k, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
    if (none[k]) return true;
    if (!hit[k]) return false;
    const double t = toLine(dir[k], a, b - a);
    return t > 0 && r[k] >= t + p.depth_m;  // false for NaN
  };
  auto farJump = [&](size_t k, size_t jamb) {
    return none[k] || (hit[k] && r[k] >= r[jamb] + p.depth_m);
  };
  // The returns either side of the opening, walking away from it from jamb `from` by `step`
  // while they form one surface (neighbours within 0.3 m), up to wall_m + 0.5 m from the jamb.
  auto side = [&](long from, long step) {
    std::vector<Eigen::Vector2d> pts{pt[from]};
    for (long k = from + step; k >= 0 && k < static_cast<long>(n); k += step) {
      if (!hit[k] || (pt[k] - pts.back()).norm() > 0.3) break;
      if ((pt[k] - pt[from]).norm() > p.wall_m + 0.5) break;
      pts.push_back(pt[k]);
    }
    return pts;
  };
  for (size_t i = 0; i + 2 < n; ++i) {
    if (!hit[i] || r[i] > p.max_range_m || !farJump(i + 1, i)) continue;
    for (size_t k = i + 2; k < n; ++k) {
      if (!hit[k]) continue;
      const double w = (pt[k] - pt[i]).norm();
      if (w > p.max_width_m || w < p.min_width_m || r[k] > p.max_range_m || !farJump(k - 1, k))
        continue;
      bool open = true;
      for (size_t j = i + 1; j < k && open; ++j) open = beyond(j, pt[i], pt[k]);
      if (!open) continue;
      // The wall: one straight line through the returns on both sides. Walls are thick, and
      // seen at a slant the jambs' end faces (5-15 cm deep) are hit too, off the wall's line:
      // the line is fitted to the returns within wall_tol_m of it (total least squares,
      // started from the line through the two sides' means), and the end faces left out.
      const auto sa = side(static_cast<long>(i), -1), sb = side(static_cast<long>(k), +1);
      auto mean = [](const std::vector<Eigen::Vector2d>& v) {
        Eigen::Vector2d m(0, 0);
        for (const auto& q : v) m += q;
        return Eigen::Vector2d(m / static_cast<double>(v.size()));
      };
      Eigen::Vector2d c = 0.5 * (mean(sa) + mean(sb)), u = mean(sb) - mean(sa);
      if (u.norm() < 1e-6) continue;
      u.normalize();
      auto off = [&](const Eigen::Vector2d& q) {
        const Eigen::Vector2d d = q - c;
        return std::abs(u.x() * d.y() - u.y() * d.x());
      };
      for (int it = 0; it < 3; ++it) {
        Eigen::Vector2d m(0, 0);
        Eigen::Matrix2d C = Eigen::Matrix2d::Zero();
        int cnt = 0;
        for (const auto* v : {&sa, &sb})
          for (const auto& q : *v)
            if (off(q) <= (it == 0 ? 3 : 1) * p.wall_tol_m) m += q, ++cnt;
        if (cnt < 4) break;
        m /= cnt;
        for (const auto* v : {&sa, &sb})
          for (const auto& q : *v)
            if (off(q) <= (it == 0 ? 3 : 1) * p.wall_tol_m) C += (q - m) * (q - m).transpose();
        Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(C);
        Eigen::Vector2d nu = es.eigenvectors().col(1);
        if (nu.dot(u) < 0) nu = -nu;
        c = m, u = nu;
      }
      // Each side: the wall runs on at least wall_m beyond its jamb, on the line.
      const double ja = (pt[i] - c).dot(u), jb = (pt[k] - c).dot(u);
      auto run = [&](const std::vector<Eigen::Vector2d>& v, double j) {
        double best = 0;
        for (const auto& q : v)
          if (off(q) <= p.wall_tol_m) best = std::max(best, std::abs((q - c).dot(u) - j));
        return best;
      };
      if (run(sa, ja) < p.wall_m || run(sb, jb) < p.wall_m) continue;
      // The wall ends somewhere between the last beam on it and the first one through the
      // opening; the last hits alone make every opening look wider by up to a beam spacing
      // (0.1 m and more seen at a slant from a few metres). A jamb hit on the wall's face is
      // put where the ray midway between those two beams meets the wall line; one hit on the
      // jamb's end face is where the wall ends already (its projection on the line).
      auto jamb = [&](size_t on, size_t through) -> Eigen::Vector2d {
        const Eigen::Vector2d proj = c + u * (pt[on] - c).dot(u);
        if (off(pt[on]) > p.wall_tol_m) return proj;
        const double m = 0.5 * (ang[on] + ang[through]);
        const Eigen::Vector2d dm(std::cos(m), std::sin(m));
        const double t = toLine(dm, c, u);
        if (!(t > 0)) return proj;
        const Eigen::Vector2d x = origin + t * dm;
        return (x - proj).norm() < 0.3 ? x : proj;
      };
      Doorway d;
      d.a = jamb(i, i + 1);
      d.b = jamb(k, k - 1);
      d.centre = 0.5 * (d.a + d.b);
      d.width_m = (d.a - d.b).norm();
      if (d.width_m < p.min_width_m || d.width_m > p.max_width_m) continue;
      d.normal = {-u.y(), u.x()};
      if (d.normal.dot(origin - d.centre) < 0) d.normal = -d.normal;
      out.push_back(d);
      i = k - 1;  // the far jamb may start the next opening
      break;
    }
  }
  return out;
}

}  // namespace sketchnav::nav
