#pragma once
// Plausibility checks of a world (doc/world-format.md, "Checks"), beyond what loading a file
// validates field by field: where the landmark photos hang, furniture standing in walls,
// landmark classes the model does not know, a start heading that disagrees with the sketch.
//
// Each problem is one issue naming the field ("landmarks[2].position"); errors make the world
// unusable (loadWorld() throws the first one, `sketchnav run` exits 2), warnings are doubts a
// person should look at (logged). All checks are pure functions of plain data.
#include <string>
#include <vector>

#include "sketchnav/sim/world.h"

namespace sketchnav::sim {

struct WorldIssue {
  enum class Severity { Error, Warning };
  Severity severity = Severity::Error;
  std::string field;    // e.g. "landmarks[2].position"
  std::string message;  // one line, without the file and field
  bool isError() const { return severity == Severity::Error; }
  /// "<origin>: <field>: <message>" (the format of every world-file error).
  std::string text(const std::string& origin) const;
};

/// How close to a solid's face a photo counts as stuck on it, and how deep inside a solid a
/// photo's centre may sit before it is hidden (the renderer moves faces 4 mm out).
struct WorldCheckParams {
  double on_face_m = 0.05;        // [m] a photo centre within this of a face is on that face
  double inside_m = 0.004;        // [m] deeper than the renderer's 4 mm offset: hidden
  double overlap_m = 0.03;        // [m] solids overlapping deeper than this overlap (a shelf
                                  // drawn 1-2 cm into the wall it stands against does not)
  double heading_warn_deg = 30;   // [deg] start heading vs sketch disagreement: warning
  double heading_error_deg = 90;  // [deg] ... error (the sketch points another way)
};

/// Geometry: a landmark photo inside a wall or inside furniture (below its top), a photo on a
/// face whose normal points into it (errors); a photo on no wall or furniture face (warning:
/// a free-standing board); an obstacle overlapping a wall (error) or another obstacle
/// (warning: furniture made of several boxes is legitimate).
std::vector<WorldIssue> checkWorldGeometry(const World& w, const WorldCheckParams& p = {});

/// Every landmark's class must be one of `classes` (the landmark set / model): an error per
/// landmark of an unknown class, naming `landmarks[i].class`.
std::vector<WorldIssue> checkLandmarkClasses(const World& w,
                                             const std::vector<std::string>& classes);

/// A sketched landmark in the route frame (metres, the sketch's own frame, mapsketch::Route).
struct SketchedLandmark {
  std::string id;
  Vec2 position{0, 0};  // [m] route frame
};

/// The route as the robot places it: it assumes it starts at `start` facing `start_heading`
/// (the direction of the sketch's first stroke, mapsketch::Route::start_heading_rad).
struct RoutePlacement {
  Vec2 start{0, 0};          // [m] route frame
  double start_heading = 0;  // [rad] route frame
  std::vector<SketchedLandmark> landmarks;
};

/// The sketch placed at the world's start pose (first stroke along start.yaw_deg) against the
/// world's landmarks of the same ids: the rotation about the start that fits them best
/// (least squares, ignoring scale) is how far start.yaw_deg disagrees with the drawing. Above
/// `heading_warn_deg` a warning, above `heading_error_deg` an error, on field
/// "start.yaw_deg". Nothing when no sketched landmark is in the world (or all within 0.5 m of
/// the start). `out_disagreement_rad`, when given, receives the fitted rotation (0 if none).
std::vector<WorldIssue> checkStartHeading(const World& w, const RoutePlacement& route,
                                          const std::string& sketch_name,
                                          const WorldCheckParams& p = {},
                                          double* out_disagreement_rad = nullptr);

/// A free path for the robot's disc from the start to the goal region, ignoring pedestrians:
/// a shortest-path search (Dijkstra) over a `resolution_m` grid of the floor whose cells keep the
/// robot's radius + `margin_m` from every wall, closed door and obstacle (8-connected). Returns the
/// path length [m] (over grid steps), or a negative number when there is none.
double freePathLength(const World& w, double margin_m = 0.05, double resolution_m = 0.1);

}  // namespace sketchnav::sim
