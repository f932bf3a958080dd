#pragma once
// The camera renderer: a small software rasteriser with a depth buffer.
//
// Why not vpImageSimulator for everything: it costs ~2 ms per visible plane at 640x480 here
// (bench/sim), and a room shows 20-40 planes (walls split in panels, box sides, landmarks).
// Here each planar convex face is clipped against the near plane, projected, scan-converted
// row by row, and shaded per pixel from its local (s, t) coordinates, which are exact
// perspective-correct functions of the pixel (1/z is affine in u, v on a plane). The floor
// and ceiling are ray-cast analytically. A depth buffer makes occlusion exact, which a
// painter's order is not for long walls between rooms.
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include <memory>
#include <random>
#include <vector>

#include "sketchnav/sim/simulator.h"
#include "sketchnav/sim/world.h"

namespace sketchnav::sim {

struct Face {
  enum class Kind { Wall, Box, Texture, Person, Plain };
  Kind kind = Kind::Plain;
  std::vector<Eigen::Vector3d> poly;  // convex, planar, world frame
  Eigen::Vector3d normal{0, 0, 1};    // the visible side
  Eigen::Vector3d origin{0, 0, 0};    // local frame: point(s, t) = origin + s * es + t * et
  Eigen::Vector3d es{1, 0, 0}, et{0, 0, 1};
  double width = 1.0, height = 1.0;  // extents along es, et [m]
  cv::Vec3f color{150, 150, 150};    // BGR base colour
  int texture = -1;                  // index in the renderer's textures (Kind::Texture)
  Eigen::Vector3d centre{0, 0, 0};   // bounding sphere for culling
  double radius = 0.0;
  float shade = 1.0f;  // Lambert factor from the fixed light direction
};

class Renderer {
 public:
  Renderer(const World& world, const SimParams& params);
  /// Renders the view from a robot at wMr (world frame) at time t into `out` (CV_8UC3,
  /// reallocated if needed). `rng` draws noise/jitter when `degrade`.
  void render(const hw::Pose2D& wMr, double t, const std::vector<PedestrianState>& peds,
              bool degrade, std::mt19937_64& rng, cv::Mat& out);
  size_t staticFaceCount() const { return faces_.size(); }
  /// Faces drawn by the last render (after culling), for the benchmark.
  size_t lastDrawnFaces() const { return last_drawn_; }

 private:
  void drawFloorCeiling(const Eigen::Matrix3d& wRc, const Eigen::Vector3d& C, cv::Mat& img);
  void drawFace(const Face& f, const Eigen::Matrix3d& cRw, const Eigen::Vector3d& C, cv::Mat& img);

  const World& world_;
  SimParams params_;
  hw::Intrinsics K_;
  double near_, far_, ceiling_;
  std::vector<Face> faces_;
  std::vector<cv::Mat> textures_;
  std::vector<float> zbuf_;
  std::vector<cv::Mat> noise_bank_;  // pre-drawn pixel noise (drawing fresh noise costs ~3 ms)
  size_t last_drawn_ = 0;
  double frustum_tan_x_, frustum_tan_y_;
};

}  // namespace sketchnav::sim
