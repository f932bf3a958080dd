#pragma once
// A top-down map of a world, reused to draw trajectories (like the paper's Figures 7-9):
// walls, doors, obstacles, regions, landmarks as stars with labels, start as a dot, goal as a
// double circle; callers add the sketched path (solid) and the actual trajectory (dashed).
#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <string>
#include <vector>

#include "sketchnav/hw/types.h"
#include "sketchnav/sim/world.h"

namespace sketchnav::sim {

class MapCanvas {
 public:
  /// Draws the static world at `px_per_m` pixels per metre, with a `margin_m` border.
  /// `labels`: write landmark ids/classes and region names.
  explicit MapCanvas(const World& world, double px_per_m = 40.0, double margin_m = 0.5,
                     bool labels = true);

  cv::Mat& image() { return image_; }
  const cv::Mat& image() const { return image_; }
  /// World (x right, y up) -> pixel (u right, v down).
  cv::Point toPixel(const Eigen::Vector2d& world_xy) const;
  cv::Point2d toPixelF(const Eigen::Vector2d& world_xy) const;
  double pxPerMetre() const { return scale_; }

  void drawPolyline(const std::vector<Eigen::Vector2d>& pts, cv::Scalar color, bool dashed = false,
                    int thickness = 2);
  void drawPoses(const std::vector<hw::Pose2D>& poses, cv::Scalar color, bool dashed = true,
                 int thickness = 2);
  void drawStart(const Eigen::Vector2d& p, cv::Scalar color = {0, 0, 0});  // filled dot •
  void drawGoal(const Eigen::Vector2d& p, double radius_m,
                cv::Scalar color = {0, 0, 0});                                 // double circle ◎
  void drawStar(const Eigen::Vector2d& p, cv::Scalar color, int size_px = 9);  // ★
  void drawRobot(const hw::Pose2D& pose, double radius_m, cv::Scalar color);
  void drawText(const Eigen::Vector2d& p, const std::string& text, cv::Scalar color,
                double scale = 0.4);
  void drawLegend(const std::vector<std::pair<std::string, cv::Scalar>>& entries);
  /// Writes a PNG (or any format OpenCV knows by extension); RuntimeError when it fails.
  void save(const std::string& path) const;

 private:
  double scale_;
  Eigen::Vector2d origin_;  // world coordinates of the top-left corner
  cv::Mat image_;
};

}  // namespace sketchnav::sim
