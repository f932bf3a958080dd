#pragma once
// The simulated world: everything a world file (doc/world-format.md) describes.
//
// World frame: metres, x/y on the floor, z up, yaw counter-clockwise from +x (REP 103).
// A World is plain data; loadWorld() is the separate, validating loading step.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core/types.hpp>

#include <string>
#include <vector>

#include "sketchnav/core/config.h"
#include "sketchnav/hw/types.h"

namespace sketchnav::sim {

using Vec2 = Eigen::Vector2d;

/// A straight wall segment from `a` to `b` (its centre line), extruded to `height`.
struct Wall {
  std::string name;         // optional, for messages
  Vec2 a{0, 0}, b{0, 0};    // [m] end points of the centre line
  double thickness = 0.10;  // [m]
  double height = 2.5;      // [m]
};

/// A door: an opening between a and b (drawn on the map). A closed door blocks like a wall.
struct Door {
  std::string name;
  Vec2 a{0, 0}, b{0, 0};  // [m]
  bool open = true;
};

/// A static obstacle standing on the floor: a box (table, cabinet, bench) or a cylinder
/// (bin, humidifier, pillar).
struct Obstacle {
  enum class Shape { Box, Cylinder };
  std::string name;
  Shape shape = Shape::Box;
  Vec2 centre{0, 0};                // [m]
  double yaw = 0.0;                 // [rad] orientation of the box's x side
  double size_x = 1.0;              // [m] box extent along its own x (boxes)
  double size_y = 1.0;              // [m] box extent along its own y (boxes)
  double radius = 0.25;             // [m] (cylinders)
  double height = 0.75;             // [m] (range sensors and collisions treat it as a solid column)
  cv::Scalar color{150, 150, 150};  // BGR, for the camera and the map
};

/// A landmark: a photo (the class's texture) on a plane standing in the world, e.g. stuck on
/// the front of a cabinet. The face normal points along `yaw`: the photo is seen from the
/// side the normal points to, upright, its centre `elevation` metres above the floor.
struct Landmark {
  std::string id;            // unique, e.g. "L1"
  std::string class_name;    // = the product folder name in share/landmarks
  std::string texture;       // absolute path of the photo shown on the front face
  std::string back_texture;  // optional second face (seen from behind); empty = plain back
  Vec2 position{0, 0};       // [m] centre of the face on the floor plane
  double yaw = 0.0;          // [rad] direction the face normal points to (towards viewers)
  double width = 0.4;        // [m]
  double height = 0.4;       // [m]
  double elevation = 1.0;    // [m] height of the face centre above the floor
};

/// A pedestrian walking along a polyline at constant speed (a cylinder for the range
/// sensors and collisions, a shaded box in the camera).
struct Pedestrian {
  std::string name;
  std::vector<Vec2> path;  // [m] at least two points
  double speed = 0.4;      // [m/s]
  bool loop = false;       // true: after the last point go back to the first; false: back and forth
  double phase = 0.0;      // [m] distance along the path at t = 0
  double radius = 0.25;    // [m]
  double height = 1.7;     // [m]
  cv::Scalar color{60, 90, 160};  // BGR
};

/// Lighting: a global brightness and a slow variation (sinusoid over time plus per-frame
/// jitter from SimParams), applied to every rendered frame.
struct Lighting {
  double brightness = 1.0;  // multiplier on every texture/shade
  double variation = 0.0;   // amplitude of the slow sinusoidal change (0.1 = +-10 %)
  double period = 60.0;     // [s] period of that change
};

/// The robot camera: intrinsics and its mounting pose on the robot (rMc).
/// rMc = Trans(x, y, z) * Rz(yaw) * Ry(-pitch) * R0, where R0 maps the optical frame
/// (z forward, x right, y down) to the robot frame (x forward, y left, z up): with yaw = pitch
/// = 0 the optical axis is the robot's +x. pitch > 0 tilts the camera up.
struct CameraSpec {
  int width = 640;
  int height = 480;
  double hfov_deg = 60.0;              // [deg] horizontal field of view (fx = fy from it)
  double x = 0.10, y = 0.0, z = 0.30;  // [m] position in the robot frame
  double yaw = 0.0;                    // [rad] pan, CCW
  double pitch = 0.0;                  // [rad] tilt, up positive
  double near = 0.05;                  // [m] near clipping distance
  double far = 30.0;                   // [m] nothing further is drawn
  hw::Intrinsics intrinsics() const;
  /// Camera (optical frame) pose in the robot frame.
  Eigen::Isometry3d rMc() const;
};

/// A planar laser scanner: beams from -fov/2 to +fov/2 around its mounting yaw.
/// Highest scan rate a world may give its laser or sonar [Hz] (real scanners run at 10-50 Hz,
/// sonar rings at 10-25 Hz). A world file above it is refused: each scan costs a ray cast, and
/// 1e9 Hz made `sim drive` take more than 40 s.
constexpr double kMaxRangeRateHz = 100.0;

struct LaserSpec {
  bool enabled = true;
  double x = 0.15, y = 0.0, z = 0.25, yaw = 0.0;  // [m], [rad] mount in the robot frame
  double fov_deg = 240.0;
  double resolution_deg = 1.0;
  double min_range = 0.05;  // [m]
  double max_range = 8.0;   // [m]
  double noise_std = 0.01;  // [m] Gaussian range noise
  double rate_hz = 10.0;    // [Hz] a new scan every 1/rate_hz; in (0, kMaxRangeRateHz]
};

/// One sonar transducer: position and yaw in the robot frame.
struct SonarBeam {
  double x = 0.0, y = 0.0, yaw = 0.0;  // [m], [rad]
};

/// A ring of ultrasonic range finders. Each beam reports the closest hit inside its cone.
struct SonarSpec {
  bool enabled = true;
  std::vector<SonarBeam> beams;  // default: 8 beams around the front half (see labWorld)
  double z = 0.15;               // [m] height of the transducers
  double beam_width_deg = 25.0;  // [deg] full cone angle
  double min_range = 0.05;       // [m]
  double max_range = 4.0;        // [m]
  double noise_std = 0.02;       // [m]
  double rate_hz = 10.0;         // [Hz] in (0, kMaxRangeRateHz]
};

/// The robot's body for collisions: a disc (DaNI-sized).
struct RobotSpec {
  double radius = 0.20;  // [m]
};

/// A labelled area (room, walkway), drawn on the map; no physical effect.
struct Region {
  std::string name;
  std::vector<Vec2> polygon;
};

struct Goal {
  Vec2 centre{0, 0};    // [m]
  double radius = 0.5;  // [m]
};

struct World {
  std::string name;
  std::string source;       // file it was loaded from ("" when built in code)
  std::vector<Vec2> floor;  // [m] floor polygon (CCW or CW), at least 3 points
  std::vector<Wall> walls;
  std::vector<Door> doors;
  std::vector<Obstacle> obstacles;
  std::vector<Landmark> landmarks;
  std::vector<Pedestrian> pedestrians;
  std::vector<Region> regions;
  hw::Pose2D start;  // robot start pose in the world frame
  Goal goal;
  Lighting lighting;
  CameraSpec camera;
  LaserSpec laser;
  SonarSpec sonar;
  RobotSpec robot;

  const Landmark* findLandmark(const std::string& id) const;  // nullptr when absent
};

/// Loads and validates a world file (JSON). Texture paths are resolved relative to the world
/// file's folder, then to share/ (so "textures/Oatly-Oat-Milk/Oatly-Oat-Milk_Iconic.jpg"
/// works from anywhere). Throws InputError with one line naming the file and the field:
/// unknown keys, wrong types, overlapping walls, a landmark outside the floor, a missing
/// texture, a pedestrian path with fewer than two points...
World loadWorld(const std::string& path);
/// Same, from JSON already in memory (`origin` names it in messages; `base_dir` resolves
/// relative texture paths).
World worldFromJson(const Json& j, const std::string& origin, const std::string& base_dir);
/// The built-in lab world (share/worlds/lab.world.json), modelled on the paper's scene.
World labWorld();
/// "lab" -> labWorld(), a name of a file in share/worlds ("corridor") or a path -> loadWorld().
World loadWorldByName(const std::string& name_or_path);
/// The world as JSON in the world-file format (texture paths absolute).
Json worldToJson(const World& w);

}  // namespace sketchnav::sim
