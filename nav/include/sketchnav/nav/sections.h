#pragma once
// Path-section bookkeeping: the route (mapsketch::Route, in the route frame) placed in the
// odometry frame, the current section, progress along it, and the point to steer to.
//
// Alignment: the odometry frame is the robot's start frame. At start the robot is assumed to
// stand at the route's start facing `start_heading_rad`, so oMr (route -> odometry) is the
// rotation by -start_heading about the start point. Landmarks located where the sketch does
// not put them correct it (RouteAnchor decides which, route_anchor.h): reanchor() shifts oMr
// only; realign() rotates it about an earlier fix (two fixes a baseline apart fix a heading,
// one does not); fitSimilarityWeighted() refits rotation, scale and translation to all the
// fixes at once. The rest of the route is then followed relative to the landmarks seen.
#include <Eigen/Core>

#include <cmath>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "sketchnav/core/angles.h"  // wrapAngle
#include "sketchnav/hw/types.h"
#include "sketchnav/mapsketch/route.h"

namespace sketchnav::nav {

struct SectionParams {
  double reach_radius_m = 0.35;  // [m] a section ends when its end point is this close...
  double end_slack_m = 0.10;     // [m] ...or the robot has crossed the line through its end
                                 // point (perpendicular to it) to within this
  double goal_radius_m = 0.15;   // [m] the last section (the goal) ends only this close to its
                                 // end point (docking drives straight there, so it is reached;
                                 // every cm here is one less for the sketch's own error)...
  double goal_ahead_m = 0.03;    // [m] ...and once the goal is no more than this ahead of the
                                 // robot: it stops on the goal, not on the circle round it
  double lookahead_m = 1.0;      // [m] pure-pursuit look-ahead along the remaining route
  template <class B>
  void bind(B& b) {
    b("reach_radius_m", reach_radius_m);
    b("end_slack_m", end_slack_m);
    b("goal_radius_m", goal_radius_m);
    b("goal_ahead_m", goal_ahead_m);
    b("lookahead_m", lookahead_m);
  }
  void validate() const;  // InputError "nav.sections.<field> = ...: ..."
};

/// One sighting of a landmark: the ray from the camera (odometry frame) along its bearing, and
/// the laser / sonar range along it (<= 0 = none).
struct Sighting {
  Eigen::Vector2d origin{0, 0};  // [m] robot position
  double direction = 0;          // [rad] odometry-frame bearing of the landmark
  double range_m = 0;            // [m] (<= 0: unranged)
  // Unranged because the laser along the bearing read further than a landmark range is
  // trusted (it may hit what stands beyond): that reading [m], as the sighting's distance
  // for the weight of its bearing (the landmark is no further). 0: unknown.
  double beyond_m = 0;
  // The landmark centre's elevation seen from the camera [rad] (NaN: unknown), the camera's
  // distance ahead of `origin` along this bearing [m], and the database photo matched: with
  // the landmark's height unknown but fixed, elevations from different distances range it
  // (locateLandmark, LocateParams::height_ranging).
  double elevation = NAN;
  double camera_along_m = 0;
  int photo = -1;
  // A laser range along the bearing that the sketch's range gate refused (rangeAgrees()): the
  // sketch's distances can be metres off, so locateLandmark() takes it back when the camera's
  // own ranges (height ranging) agree with it. 0: none.
  double gated_range_m = 0;
};

/// One fix for SectionTracker::fitSimilarityWeighted(): where the sketch puts a point (route
/// frame), where it was observed (odometry frame) and how well (information matrix, e.g. from
/// locateLandmark(); the start: exactly).
struct WeightedFix {
  Eigen::Vector2d route_pt{0, 0};
  Eigen::Vector2d odom_pt{0, 0};
  Eigen::Matrix2d information = Eigen::Matrix2d::Identity();  // [1/m^2]
  bool trusted = false;  // never left out as an outlier (the start)
};

struct WeightedFitParams {
  double sketch_sigma_m = 0.3;    // [m] how far off the user draws a landmark (per axis)
  double outlier_m = 0.6;         // [m] a fix further than this off the fit (Mahalanobis
                                  // distance x sketch_sigma_m) is left out
  double max_scale_change = 0.5;  // relative to the drawing's own scale (route metres)
};

struct SectionProgress {
  double along_m = 0;      // distance travelled along the current section (projection)
  double cross_m = 0;      // signed lateral offset from it (left positive)
  double remaining_m = 0;  // to its end point along the section
  double to_end_m = 0;     // straight-line distance to its end point
};

class SectionTracker {
 public:
  /// Throws InputError when the route has no section.
  SectionTracker(mapsketch::Route route, SectionParams params = {});

  const mapsketch::Route& route() const { return route_; }
  int current() const { return current_; }
  int count() const { return static_cast<int>(route_.sections.size()); }
  bool finished() const { return current_ >= count(); }
  /// The current section (precondition: !finished()).
  const mapsketch::PathSection& section() const;

  Eigen::Vector2d toOdom(const Eigen::Vector2d& route_pt) const;
  /// The goal (the last section's end) as observed, odometry frame: the goal doorway the laser
  /// found (doorway.h). It replaces where the alignment puts the goal for progress(),
  /// update(), lookahead() and endOdom(); later refits no longer move it. nullopt: the
  /// alignment's goal again.
  void setGoalOdom(std::optional<Eigen::Vector2d> goal) { goal_odom_ = goal; }
  const std::optional<Eigen::Vector2d>& goalOdom() const { return goal_odom_; }
  /// Section k's end point, odometry frame (the observed goal for the last section).
  Eigen::Vector2d endOdom(int k) const;
  Eigen::Vector2d toRoute(const Eigen::Vector2d& odom_pt) const;
  double headingToOdom(double route_heading) const;
  /// Shifts the alignment by `gain` (0..1) of the way so that `route_pt` maps to `odom_pt`.
  void reanchor(const Eigen::Vector2d& route_pt, const Eigen::Vector2d& odom_pt, double gain);
  /// Rotates the alignment about a trusted fix (`anchor_route` seen at `anchor_odom`: the
  /// start, or the previous landmark) by `gain` of the angle between where the sketch puts
  /// `route_pt` and where it was seen (`odom_pt`), when both are at least `min_baseline_m`
  /// from the anchor. This is what corrects a start heading that differs from the first
  /// section's direction. Returns the rotation applied [rad].
  double realign(const Eigen::Vector2d& route_pt, const Eigen::Vector2d& odom_pt,
                 const Eigen::Vector2d& anchor_route, const Eigen::Vector2d& anchor_odom,
                 double gain, double min_baseline_m = 1.5);

  /// Refits the whole alignment (rotation, scale, translation) to trusted fixes by least
  /// squares: `route_pts[i]` (sketch) was seen at `odom_pts[i]`. A hand-drawn map's scale comes
  /// from the user's distance guesses (10-25 % off each); several fixes a few metres apart pin
  /// scale and heading down far better, and the error of each sketched position averages out
  /// instead of being copied by a shift. The scale stays within `max_scale_change` (relative)
  /// of the drawing's own. Needs two or more fixes. With `outlier_m` > 0, the fix furthest off the
  /// fit is left out and the rest refitted while it is more than `outlier_m` off and more than
  /// three fixes remain.
  struct Fit {
    bool ok = false;
    double rotation = 0;     // [rad] change
    double scale = 1;        // relative change
    double rms = 0;          // [m] residual over the fixes used
    int dropped = 0;         // fixes left out as outliers
    std::vector<bool> used;  // per fix: kept in the fit
  };
  Fit fitSimilarity(const std::vector<Eigen::Vector2d>& route_pts,
                    const std::vector<Eigen::Vector2d>& odom_pts, double max_scale_change = 0.5,
                    double outlier_m = 0);
  /// The same refit with each fix weighted by how well it was observed plus the sketch's own
  /// error (sketch_sigma_m, once per landmark): a landmark located only across its rays (the
  /// robot heading towards it, a laser range that may be the furniture behind) pulls the fit
  /// across them and hardly along. A fix whose Mahalanobis residual (x sketch_sigma_m) exceeds
  /// `outlier_m` is left out, down to three fixes. Linear least squares in
  /// (s cos a, s sin a, t).
  Fit fitSimilarityWeighted(const std::vector<WeightedFix>& fixes, const WeightedFitParams& p);
  double scale() const { return scale_; }

  SectionProgress progress(const hw::Pose2D& odom) const;
  /// Advances past every section whose end has been reached; returns how many it advanced.
  int update(const hw::Pose2D& odom);
  /// Moves to the next section unconditionally (e.g. its landmark was passed at its end).
  void advance();
  /// The point (odometry frame) `lookahead_m` ahead of the robot's projection on the
  /// remaining route (continuing into the following sections, clamped at the goal).
  Eigen::Vector2d lookahead(const hw::Pose2D& odom) const;
  /// The same with its own distance (the planner's detour goal lies further on).
  Eigen::Vector2d lookahead(const hw::Pose2D& odom, double distance_m) const;
  /// The sketched route (guide points) in the odometry frame.
  std::vector<Eigen::Vector2d> guidePointsOdom() const;

 private:
  mapsketch::Route route_;
  SectionParams params_;
  int current_ = 0;
  double rot_ = 0;               // odom heading = route heading + rot_
  double scale_ = 1;             // odom metres per route metre
  Eigen::Vector2d trans_{0, 0};  // odom = scale_ R(rot_) (route - start) + trans_
  std::optional<Eigen::Vector2d> goal_odom_;
};

/// Bearing [rad, CCW, robot frame] and range [m] of an odometry-frame point from a pose.
struct Polar {
  double bearing = 0, range = 0;
};
Polar polarFrom(const hw::Pose2D& pose, const Eigen::Vector2d& pt);

/// Where the route puts its goal (odometry frame) when every sketched landmark is fixed
/// exactly where it truly is: the navigation's refit (fitSimilarityWeighted, the start
/// trusted at the odometry origin) to `truth` (landmark id -> true place, odometry frame);
/// landmarks without a truth are left out. No perception or odometry can do better with
/// this refit, so its distance to the true goal is the part of a goal error that the drawing
/// alone makes (the experiments report it per trial). Empty with fewer than two landmarks
/// known or a degenerate fit. `p.max_scale_change` bounds the scale against the route's own.
std::optional<Eigen::Vector2d> goalFromExactFixes(
    const mapsketch::Route& route, const std::map<std::string, Eigen::Vector2d>& truth,
    const WeightedFitParams& p);

}  // namespace sketchnav::nav
