#include "sketchnav/nav/local_planner.h"

#include <mrpt/maps/COccupancyGridMap2D.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/poses/CPose3D.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>

#include <opencv2/imgproc.hpp>

#include "sketchnav/core/config.h"

namespace sketchnav::nav {

void PlannerParams::validate() const {
  require(cell_m >= 0.02 && cell_m <= 0.5, "nav.planner.cell_m", "must be in [0.02, 0.5] m");
  require(robot_radius_m > 0 && robot_radius_m < 2, "nav.planner.robot_radius_m",
          "must be in (0, 2) m");
  require(clearance_m >= robot_radius_m, "nav.planner.clearance_m", "must be >= robot_radius_m");
  require(comfort_m >= clearance_m, "nav.planner.comfort_m", "must be >= clearance_m");
  require(clearance_cost >= 0 && comfort_cost >= 0, "nav.planner.clearance_cost",
          "costs must be >= 0");
  require(occupied_p > 0.5 && occupied_p < 1, "nav.planner.occupied_p", "must be in (0.5, 1)");
  require(max_insert_m > 0.5, "nav.planner.max_insert_m", "must be > 0.5 m");
  require(window_margin_m >= 0.5 && window_margin_m <= 20, "nav.planner.window_margin_m",
          "must be in [0.5, 20] m");
  require(max_window_margin_m >= window_margin_m && max_window_margin_m <= 40,
          "nav.planner.max_window_margin_m", "must be in [window_margin_m, 40] m");
  require(goal_snap_m >= 0, "nav.planner.goal_snap_m", "must be >= 0");
  require(carrot_m > 0, "nav.planner.carrot_m", "must be > 0");
}

struct LocalPlanner::Impl {
  mrpt::maps::COccupancyGridMap2D grid;
};

LocalPlanner::LocalPlanner(PlannerParams params)
    : params_(params), impl_(std::make_unique<Impl>()) {
  params_.validate();
  // Grows as scans come in (MRPT resizes the grid to what a scan covers).
  impl_->grid.setSize(-5, 5, -5, 5, static_cast<float>(params_.cell_m), 0.5f);
  auto& io = impl_->grid.insertionOptions;
  io.maxDistanceInsertion = static_cast<float>(params_.max_insert_m);
  // "Nothing seen" beams clear the cells up to the insertion distance: that is what erases
  // the trace a walking person leaves.
  io.considerInvalidRangesAsFreeSpace = true;
}
LocalPlanner::~LocalPlanner() = default;
LocalPlanner::LocalPlanner(LocalPlanner&&) noexcept = default;
LocalPlanner& LocalPlanner::operator=(LocalPlanner&&) noexcept = default;

void LocalPlanner::insert(const hw::Pose2D& robot, const hw::RangeScan& scan) {
  if (scan.kind != hw::RangeScan::Kind::Laser) return;
  const size_t n = std::min(scan.angles.size(), scan.ranges.size());
  if (n < 2) return;
  // MRPT's scan model: n beams evenly spread over `aperture`, centred on the sensor's yaw.
  const double a0 = scan.angles.front(), a1 = scan.angles[n - 1];
  const double step = (a1 - a0) / static_cast<double>(n - 1);
  if (std::abs(step) < 1e-6) return;
  for (size_t i = 0; i < n; ++i)
    if (std::abs(scan.angles[i] - (a0 + step * static_cast<double>(i))) > 0.25 * std::abs(step))
      return;  // not an evenly spread scan (no laser we drive produces one)
  mrpt::obs::CObservation2DRangeScan obs;
  obs.aperture = static_cast<float>(std::abs(a1 - a0));
  obs.rightToLeft = step > 0;
  obs.maxRange = scan.max_range;
  // The angles are robot-frame bearings already; the mount only contributes its position.
  obs.sensorPose = mrpt::poses::CPose3D(scan.mount.x, scan.mount.y, 0, 0.5 * (a0 + a1), 0, 0);
  obs.resizeScan(n);
  for (size_t i = 0; i < n; ++i) {
    const float r = scan.ranges[i];
    const bool valid = r < scan.max_range && r >= scan.min_range && std::isfinite(r);
    obs.setScanRange(i, valid ? r : scan.max_range);
    obs.setScanRangeValidity(i, valid);
  }
  const mrpt::poses::CPose3D pose(robot.x, robot.y, 0, robot.theta, 0, 0);
  impl_->grid.insertObservation(obs, pose);
  ++inserted_;
}

bool LocalPlanner::occupied(const Eigen::Vector2d& p) const {
  // MRPT's cells hold the probability of being free; outside the grid it is 0.5 (unknown).
  return impl_->grid.getPos(static_cast<float>(p.x()), static_cast<float>(p.y())) <
         1.0 - params_.occupied_p;
}

LocalPlanner LocalPlanner::snapshot() const {
  LocalPlanner c(params_);
  c.impl_->grid = impl_->grid;
  c.inserted_ = inserted_;
  return c;
}

bool LocalPlanner::seenFree(const Eigen::Vector2d& p) const {
  return impl_->grid.getPos(static_cast<float>(p.x()), static_cast<float>(p.y())) >
         params_.occupied_p;
}

bool LocalPlanner::seenFreeAround(const Eigen::Vector2d& p) const {
  const double c = params_.cell_m;
  for (int i = -1; i <= 1; ++i)
    for (int j = -1; j <= 1; ++j)
      if (!seenFree(p + Eigen::Vector2d(i * c, j * c))) return false;
  return true;
}

bool LocalPlanner::segmentClear(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                                double clearance) const {
  const double c = params_.cell_m;
  const double len = (b - a).norm();
  const int steps = std::max(1, static_cast<int>(std::ceil(len / (0.5 * c))));
  const int r = static_cast<int>(std::ceil(clearance / c));
  for (int s = 0; s <= steps; ++s) {
    const Eigen::Vector2d p = a + (b - a) * (static_cast<double>(s) / steps);
    for (int i = -r; i <= r; ++i)
      for (int j = -r; j <= r; ++j) {
        const Eigen::Vector2d d(i * c, j * c);
        if (d.norm() <= clearance && occupied(p + d)) return false;
      }
  }
  return true;
}

PlannedPath LocalPlanner::plan(const Eigen::Vector2d& from, const Eigen::Vector2d& goal) const {
  // A small window first: most ways round are short, and the window's cost grows with its
  // area. The way round a long blockage (a route drawn on the wrong side of a desk island)
  // can lie metres outside it; then the search meets the window's edge and only a wider
  // window can say whether there is a way.
  double margin = params_.window_margin_m;
  for (;;) {
    bool hit_edge = false, searched = false;
    PlannedPath out = planInWindow(from, goal, margin, hit_edge, searched);
    out.window_margin_m = margin;
    if (out.found || !hit_edge || margin >= params_.max_window_margin_m) {
      out.enclosed = !out.found && searched && !hit_edge;
      return out;
    }
    margin = std::min(2 * margin, params_.max_window_margin_m);
  }
}

PlannedPath LocalPlanner::planInWindow(const Eigen::Vector2d& from, const Eigen::Vector2d& goal,
                                       double margin_m, bool& hit_edge, bool& searched) const {
  const auto& P = params_;
  const double c = P.cell_m;
  PlannedPath out;
  out.goal = goal;
  const double x0 = std::min(from.x(), goal.x()) - margin_m;
  const double y0 = std::min(from.y(), goal.y()) - margin_m;
  const int W = static_cast<int>(std::ceil((std::max(from.x(), goal.x()) + margin_m - x0) / c));
  const int H = static_cast<int>(std::ceil((std::max(from.y(), goal.y()) + margin_m - y0) / c));
  auto centre = [&](int col, int row) {
    return Eigen::Vector2d(x0 + (col + 0.5) * c, y0 + (row + 0.5) * c);
  };
  cv::Mat freeMask(H, W, CV_8U, cv::Scalar(255));
  bool any = false;
  for (int row = 0; row < H; ++row)
    for (int col = 0; col < W; ++col)
      if (occupied(centre(col, row))) freeMask.at<uchar>(row, col) = 0, any = true;
  cv::Mat dist;
  if (any) {
    cv::distanceTransform(freeMask, dist, cv::DIST_L2, cv::DIST_MASK_5);
    dist *= c;
  } else {
    dist = cv::Mat(H, W, CV_32F, cv::Scalar(1e3f));
  }
  auto cellOf = [&](const Eigen::Vector2d& p) {
    return cv::Point(std::clamp(static_cast<int>((p.x() - x0) / c), 0, W - 1),
                     std::clamp(static_cast<int>((p.y() - y0) / c), 0, H - 1));
  };
  const cv::Point s = cellOf(from);
  const double hard = P.robot_radius_m + 0.02;
  // Cells near the start are passable whatever their clearance: a robot already closer to
  // something than it should be must still be able to plan its way out.
  const double escape = P.clearance_m + c;
  auto passable = [&](int col, int row) {
    if (dist.at<float>(row, col) >= hard) return true;
    return (centre(col, row) - from).norm() <= escape;
  };
  // The goal: itself if clear, else the nearest clear cell within goal_snap_m (a goal drawn
  // against a wall or in a door frame is reached as near as the robot fits).
  cv::Point g = cellOf(goal);
  if (dist.at<float>(g.y, g.x) < P.clearance_m) {
    const int r = static_cast<int>(std::ceil(P.goal_snap_m / c));
    double best = 1e300, best_loose = 1e300;
    cv::Point gb(-1, -1), gl(-1, -1);
    for (int i = -r; i <= r; ++i)
      for (int j = -r; j <= r; ++j) {
        const int col = g.x + j, row = g.y + i;
        if (col < 0 || row < 0 || col >= W || row >= H) continue;
        const double d = (centre(col, row) - goal).norm();
        if (d > P.goal_snap_m) continue;
        const float cl = dist.at<float>(row, col);
        if (cl >= P.clearance_m && d < best) best = d, gb = {col, row};
        if (cl >= hard && d < best_loose) best_loose = d, gl = {col, row};
      }
    if (gb.x < 0) gb = gl;
    if (gb.x < 0) return out;
    g = gb;
    out.goal = centre(g.x, g.y);
    out.goal_moved = true;
  }

  searched = true;
  // A* over 8-connected cells; a step costs its length times the clearance penalty of the
  // cell it enters, and the straight-line distance is an admissible estimate.
  const int N = W * H;
  std::vector<float> gcost(N, std::numeric_limits<float>::infinity());
  std::vector<int> parent(N, -1);
  std::vector<char> closed(N, 0);
  using Item = std::pair<float, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> open;
  const int si = s.y * W + s.x, gi = g.y * W + g.x;
  auto h = [&](int col, int row) {
    return static_cast<float>(std::hypot(col - g.x, row - g.y) * c);
  };
  gcost[si] = 0;
  open.push({h(s.x, s.y), si});
  static const int dc[8] = {1, -1, 0, 0, 1, 1, -1, -1};
  static const int dr[8] = {0, 0, 1, -1, 1, -1, 1, -1};
  bool reached = false;
  while (!open.empty()) {
    const int cur = open.top().second;
    open.pop();
    if (closed[cur]) continue;
    closed[cur] = 1;
    if (cur == gi) {
      reached = true;
      break;
    }
    const int col = cur % W, row = cur / W;
    if (col == 0 || row == 0 || col == W - 1 || row == H - 1) hit_edge = true;
    for (int k = 0; k < 8; ++k) {
      const int nc = col + dc[k], nr = row + dr[k];
      if (nc < 0 || nr < 0 || nc >= W || nr >= H) continue;
      const int ni = nr * W + nc;
      if (closed[ni] || !passable(nc, nr)) continue;
      const double cl = dist.at<float>(nr, nc);
      double mult = 1 + P.comfort_cost * std::max(0.0, P.comfort_m - cl) / P.comfort_m;
      if (cl < P.clearance_m) mult += P.clearance_cost;
      const float ng = gcost[cur] + static_cast<float>((k < 4 ? c : c * M_SQRT2) * mult);
      if (ng < gcost[ni]) {
        gcost[ni] = ng;
        parent[ni] = cur;
        open.push({ng + h(nc, nr), ni});
      }
    }
  }
  if (!reached) {
    // The robot's side met the window's edge; the goal's side may still be walled in (a goal
    // inside a closed pen), and then no wider window helps either.
    if (hit_edge) {
      cv::Mat pass(H, W, CV_8U, cv::Scalar(0));
      for (int row = 0; row < H; ++row)
        for (int col = 0; col < W; ++col)
          if (passable(col, row)) pass.at<uchar>(row, col) = 255;
      cv::Rect r;
      cv::floodFill(pass, g, cv::Scalar(128), &r, cv::Scalar(), cv::Scalar(), 8);
      if (r.x > 0 && r.y > 0 && r.x + r.width < W && r.y + r.height < H) hit_edge = false;
    }
    return out;
  }
  std::vector<Eigen::Vector2d> rev;
  double min_cl = 1e300;
  for (int i = gi; i >= 0; i = parent[i]) {
    rev.push_back(i == si ? from : centre(i % W, i / W));
    min_cl = std::min<double>(min_cl, dist.at<float>(i / W, i % W));
    if (i == si) break;
  }
  out.points.assign(rev.rbegin(), rev.rend());
  if (out.points.size() == 1) out.points.push_back(out.goal);
  out.points.back() = out.goal_moved ? out.goal : goal;
  for (size_t i = 1; i < out.points.size(); ++i)
    out.length_m += (out.points[i] - out.points[i - 1]).norm();
  out.min_clearance_m = min_cl;
  out.found = true;
  return out;
}

Eigen::Vector2d LocalPlanner::carrot(const PlannedPath& path, const Eigen::Vector2d& at,
                                     double dist) {
  if (path.points.empty()) return at;
  size_t best = 0;
  double bd = 1e300;
  for (size_t i = 0; i < path.points.size(); ++i) {
    const double d = (path.points[i] - at).squaredNorm();
    if (d < bd) bd = d, best = i;
  }
  double left = dist;
  for (size_t i = best; i + 1 < path.points.size(); ++i) {
    const double seg = (path.points[i + 1] - path.points[i]).norm();
    if (seg >= left) return path.points[i] + (path.points[i + 1] - path.points[i]) * (left / seg);
    left -= seg;
  }
  return path.points.back();
}

}  // namespace sketchnav::nav
