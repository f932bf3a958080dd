#pragma once
// Ways round static obstacles, planned on an occupancy grid of what the laser has seen.
//
// The reactive avoider (avoidance.h) sees only the current scan. Round a box standing on the
// path it picks a side from the landmark's side and a bias, and round a long bench or along a
// wall it can loop: in the experiments, 3 of 4 robots dodged the static obstacle into a loop
// beside the lab bench, two circled the bench their landmark stood on, and two could not
// reach a goal in a doorway because the straight line to it grazed the door frame. The
// planner remembers what the laser saw and finds the open side and the way back to the route.
//
// Grid: MRPT's COccupancyGridMap2D in the odometry frame; each laser scan is inserted at the
// robot's pose, and the beams clear the cells they cross, so a pedestrian's trace is erased
// once the laser sees through it again. Planning: A* over the cells of a window round the
// start and goal, costed by clearance from OpenCV's distance transform so that the path keeps
// to the middle of gaps. (mrpt::nav::PlannerSimple2D's wavefront gives shortest paths, which
// graze every corner at exactly the robot radius.)
#include <Eigen/Core>

#include <memory>
#include <vector>

#include "sketchnav/hw/types.h"

namespace sketchnav::nav {

struct PlannerParams {
  double cell_m = 0.1;           // [m] grid resolution
  double robot_radius_m = 0.2;   // [m] cells closer than this (+ 2 cm) to an obstacle are
                                 // impassable
  double clearance_m = 0.32;     // [m] cells closer than this cost clearance_cost per metre more
  double clearance_cost = 20;    // so the path goes there only when nothing else gets through
  double comfort_m = 0.7;        // [m] below this clearance a cell costs up to comfort_cost
  double comfort_cost = 2;       // per metre more (paths keep to the middle of gaps)
  double occupied_p = 0.65;      // occupancy probability above which a cell is an obstacle
  double max_insert_m = 6.0;     // [m] laser readings further than this do not mark the grid
  double window_margin_m = 3.0;  // [m] planning window: box round start and goal plus this
  double max_window_margin_m = 3.0;  // [m] with no way found and the search stopped by the
                                     // window's edge, the margin doubles up to this (12 m:
                                     // see doc/navigation.md "Evidence for the defaults")
  double goal_snap_m = 1.0;          // [m] a goal within an obstacle's clearance moves to the
                                     // nearest clear cell at most this far
  double carrot_m = 0.7;             // [m] path-following look-ahead
  template <class B>
  void bind(B& b) {
    b("cell_m", cell_m);
    b("robot_radius_m", robot_radius_m);
    b("clearance_m", clearance_m);
    b("clearance_cost", clearance_cost);
    b("comfort_m", comfort_m);
    b("comfort_cost", comfort_cost);
    b("occupied_p", occupied_p);
    b("max_insert_m", max_insert_m);
    b("window_margin_m", window_margin_m);
    b("max_window_margin_m", max_window_margin_m);
    b("goal_snap_m", goal_snap_m);
    b("carrot_m", carrot_m);
  }
  void validate() const;  // InputError "nav.planner.<field> = ...: ..."
};

struct PlannedPath {
  bool found = false;
  std::vector<Eigen::Vector2d> points;  // odometry frame, start first, goal last
  double length_m = 0;
  Eigen::Vector2d goal{0, 0};  // where the path ends (the goal, or where it was moved to)
  bool goal_moved = false;     // the goal was within an obstacle's clearance
  double min_clearance_m = 0;  // smallest obstacle clearance along the path
  double window_margin_m = 0;  // [m] margin of the window the search ended in
  bool enclosed = false;       // not found, and provably so: the search ran out of cells
                               // inside the window without reaching its edge (walled in)
};

class LocalPlanner {
 public:
  explicit LocalPlanner(PlannerParams params = {});
  ~LocalPlanner();
  LocalPlanner(LocalPlanner&&) noexcept;
  LocalPlanner& operator=(LocalPlanner&&) noexcept;

  /// Adds a scan taken at `robot` (odometry frame). Laser scans only: a sonar cone says that
  /// something is somewhere across it, too vague to mark cells.
  void insert(const hw::Pose2D& robot, const hw::RangeScan& scan);
  /// Plans from `from` to `goal` (odometry frame) in a window round both, widening it (the
  /// margin doubles from window_margin_m to max_window_margin_m) while the search is stopped
  /// by the window's edge. Not found: no clear cell lies within goal_snap_m of the goal, the
  /// robot or the goal is walled in (`enclosed`), or the way lies beyond the widest window.
  PlannedPath plan(const Eigen::Vector2d& from, const Eigen::Vector2d& goal) const;
  /// The straight segment keeps `clearance` [m] from every obstacle cell.
  bool segmentClear(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double clearance) const;
  /// Whether the cell at `p` is an obstacle.
  bool occupied(const Eigen::Vector2d& p) const;
  /// Whether the cell at `p` has been seen as free floor (a laser point there now is
  /// something that moved in: movers.h).
  bool seenFree(const Eigen::Vector2d& p) const;
  /// Whether the cell at `p` and the 8 round it have all been seen free: a point there stands
  /// on open floor (a static surface's laser point often falls in the free cell just in front
  /// of the surface's own cells, which seenFree() alone would take for floor).
  bool seenFreeAround(const Eigen::Vector2d& p) const;
  /// The point `dist` along `path` beyond the path point nearest to `at`.
  static Eigen::Vector2d carrot(const PlannedPath& path, const Eigen::Vector2d& at, double dist);

  /// A deep copy (the mover tracker judges "seen free" against the grid of a few seconds ago,
  /// before a walking person's own trace was marked).
  LocalPlanner snapshot() const;

  int scansInserted() const { return inserted_; }
  const PlannerParams& params() const { return params_; }

 private:
  PlannedPath planInWindow(const Eigen::Vector2d& from, const Eigen::Vector2d& goal,
                           double margin_m, bool& hit_edge, bool& searched) const;
  struct Impl;
  PlannerParams params_;
  std::unique_ptr<Impl> impl_;
  int inserted_ = 0;
};

}  // namespace sketchnav::nav
