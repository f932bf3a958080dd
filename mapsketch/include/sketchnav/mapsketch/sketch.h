#pragma once
// The hand-drawn map as the user drew it (canvas pixels, y down), and its file format
// `.sketch.json` (doc/sketch-format.md). Nothing here is metric yet: toRoute() (route.h)
// turns it into what the robot follows.
#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

namespace sketchnav::mapsketch {

struct CanvasRect {
  double x = 0, y = 0, w = 0, h = 0;  // [canvas px] top-left corner and size
  Eigen::Vector2d centre() const { return {x + 0.5 * w, y + 0.5 * h}; }
};

struct SketchLandmark {
  std::string id;          // unique within the sketch
  std::string class_name;  // a class (leaf folder name) of the landmark set
  CanvasRect rect;         // where the user put it
  double distance_m = 0;   // user's approximate distance [m] from the previous landmark in
                           // route order (from the start for the first one)
};

/// What the goal is, beyond a point on the canvas. A doorway is a place the robot recognises
/// by itself (the laser sees the opening), so the drawn goal only has to be near it: the robot
/// stops `standoff_m` in front of the doorway it finds there (doc/sketch-format.md).
struct GoalPlace {
  enum class Kind { Point, Doorway };
  Kind kind = Kind::Point;
  double standoff_m = 0.5;  // [m] doorway: stop this far in front of the opening (0 = in it)
};

/// A floor-plan image the sketch was traced over (the editor's *Floor plan…*), kept with the
/// sketch for people; the robot never uses it. doc/sketch-format.md, "floor_plan".
struct FloorPlan {
  std::string image;    // a data URL: data:image/(png|jpeg|gif|webp|svg+xml);base64,...
  CanvasRect rect;      // [canvas px] where the image is drawn (fitted inside, aspect kept)
  double m_per_px = 0;  // [m per canvas px] the scale the user set on it; 0 = none
  std::vector<Eigen::Vector2d> scale_points;  // the two points it was measured between, or none
};

struct Sketch {
  int format = 1;
  double canvas_width = 1000, canvas_height = 700;  // [canvas px]
  std::vector<SketchLandmark> landmarks;
  std::vector<Eigen::Vector2d> path;  // the guide path as drawn, many jittery points [px]
  Eigen::Vector2d start{0, 0};        // [px]
  Eigen::Vector2d goal{0, 0};         // [px]
  GoalPlace goal_place;               // optional in the file ("goal_place")
  std::string name;                   // free text
  std::string notes;                  // free text for people (e.g. how it was drawn); optional
  std::optional<FloorPlan> floor_plan;  // optional in the file ("floor_plan")
};

}  // namespace sketchnav::mapsketch
