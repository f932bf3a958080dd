#pragma once
// The route: what the robot follows. Produced by toRoute(sketch) (pure function).
//
// Route frame: the sketch canvas scaled to metres, origin at the sketch's start point,
// x to the right on the canvas, y UP on the canvas (canvas y is flipped), so angles are CCW
// like REP 103. The navigation executive aligns this frame with odometry by assuming the
// robot starts at `start_m` facing `start_heading_rad` (along the drawn line's first
// stretch, RouteParams::start_tangent_m; usually the first section's direction).
#include <Eigen/Core>

#include <string>
#include <vector>

#include "sketchnav/mapsketch/sketch.h"

namespace sketchnav::mapsketch {

enum class Side { Left, Right, Ahead };

/// A landmark the robot should pass while on a section. toRoute() sets `side` Ahead when the
/// section runs into the landmark's drawn box or the landmark lies beyond the section's end
/// within RouteParams::ahead_angle_deg; `along_m` is the projection on the section, so it can
/// be < 0 or > length_m for a landmark at a corner (doc/sketch-format.md).
struct ExpectedLandmark {
  std::string id;           // sketch landmark id
  std::string class_name;   // class of the landmark set
  int order = 0;            // sequence order along the whole route (0-based)
  Side side = Side::Ahead;  // relative to the direction of travel on the section
  double range_m = 0;       // approximate lateral distance from the section [m]
  double along_m = 0;       // approximate distance from the section's start where it is passed [m]
  Eigen::Vector2d position_m{0, 0};  // approximate position in the route frame [m]
};

/// The part of the path between two consecutive guide points.
struct PathSection {
  int index = 0;
  Eigen::Vector2d start_m{0, 0}, end_m{0, 0};  // guide points in the route frame [m]
  double length_m = 0;                         // approximate length [m]
  double heading_rad = 0;                      // direction of travel in the route frame
  double heading_change_rad = 0;               // turn at the section's start (CCW +)
  std::vector<ExpectedLandmark> landmarks;     // in the order they are passed
};

struct Route {
  std::vector<PathSection> sections;
  std::vector<Eigen::Vector2d> guide_points_m;  // sections.size() + 1 points
  Eigen::Vector2d start_m{0, 0}, goal_m{0, 0};
  GoalPlace goal_place;  // the sketch's: a doorway goal is looked for near goal_m
  double start_heading_rad = 0;
  double scale_m_per_px = 0;  // estimated from the user's distances (least squares)
  double scale_residual = 0;  // relative RMS residual of that fit (0 = consistent distances)
  double total_length_m = 0;
  // Added by the sketch-map work (extra detail; the fields above keep their meaning):
  std::vector<std::string> distance_outliers;  // landmark ids whose distance the fit discounted
  std::vector<int> guide_point_path_index;     // index into Sketch::path of each guide point
                                               // (-1 for a start/goal that is not on the path)
  std::vector<std::string> warnings;           // human-readable doubts about the sketch
};

/// Settings of the sketch -> route conversion.
struct RouteParams {
  double simplify_tolerance = 0.025;  // Douglas-Peucker tolerance [fraction of the canvas
                                      // diagonal]; ~30 px on a 1000 x 700 canvas, above
                                      // hand jitter, below a deliberate bend
  double robust_scale = 0.25;         // Cauchy width of the scale fit [log ratio ~ relative
                                      // distance error]
  double outlier_residual = 0.5;      // a distance whose relative error exceeds this is reported
  double ahead_angle_deg = 20;        // a landmark within this angle of the direction of travel,
                                      // beyond the section's end, is "ahead" rather than left/right
  double start_tangent_m = 1.0;       // [m] the robot is put down facing along the drawn line:
                                      // its direction over this first stretch (a short first
                                      // stroke is simplified away, but still says how the robot
                                      // stands)
  template <class B>
  void bind(B& b) {
    b("simplify_tolerance", simplify_tolerance);
    b("robust_scale", robust_scale);
    b("outlier_residual", outlier_residual);
    b("ahead_angle_deg", ahead_angle_deg);
    b("start_tangent_m", start_tangent_m);
  }
  void validate() const;
};

/// Converts a (validated) sketch into its route. Pure function. Throws InputError when the
/// sketch cannot give a route (see validateSketch(); also when no landmark distance can fix
/// the scale).
Route toRoute(const Sketch& sketch, const RouteParams& params = {});

// ---- the pieces of toRoute, exposed for tests and tools -----------------------------------

/// Douglas-Peucker simplification; returns the indices of the kept points (first and last
/// always kept), increasing.
std::vector<int> simplifyPolyline(const std::vector<Eigen::Vector2d>& pts, double tolerance);

/// The point of a polyline closest to a point: how far it is and its arc length from the
/// polyline's start (the polyline's units). One point: its distance, arc 0; none: infinite.
struct PolylinePoint {
  double distance = 0;
  double arc = 0;
};
PolylinePoint closestOnPolyline(const Eigen::Vector2d& p, const std::vector<Eigen::Vector2d>& poly);

/// Result of fitting metres-per-pixel to the user's distances.
struct ScaleFit {
  double scale = 0;                    // [m / canvas px]
  double rms_relative = 0;             // sqrt(mean(((scale * d_px - d_m) / d_m)^2)) over all pairs
  std::vector<double> relative_error;  // per pair, same order as the input
  std::vector<double> weight;          // final robust weight per pair (0..1)
};

/// Robust least squares of log(d_m) ~ log(scale) + log(d_px): starts at the median ratio,
/// then iteratively reweighted least squares with Cauchy weights (width `robust_width`, in
/// log ratio ~ relative error), so one wildly wrong distance barely moves the scale. Pairs with
/// d_px ~ 0 get weight 0. Throws InputError when no pair is usable.
ScaleFit fitScale(const std::vector<double>& d_px, const std::vector<double>& d_m,
                  double robust_width = 0.25);

const char* sideName(Side s);  // "left", "right", "ahead"

}  // namespace sketchnav::mapsketch
