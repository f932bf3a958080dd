#pragma once
// Hand-made sketches for the mapsketch tests: an L-shaped route drawn with seeded hand jitter.
#include <random>

#include "sketchnav/mapsketch/sketch.h"

namespace sketchnav::mapsketch::fixtures {

constexpr double kTrueScale = 0.02;  // [m/px] the "real" scale the distances are taken from

/// Samples the polyline `corners` every `step` px and adds seeded jitter of +-`jitter` px
/// (perpendicular wobble, like a hand on a mouse).
inline std::vector<Eigen::Vector2d> wobbly(const std::vector<Eigen::Vector2d>& corners, double step,
                                           double jitter, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-jitter, jitter);
  std::vector<Eigen::Vector2d> out;
  for (size_t i = 1; i < corners.size(); ++i) {
    const Eigen::Vector2d d = corners[i] - corners[i - 1];
    const int n = std::max(1, static_cast<int>(d.norm() / step));
    for (int k = 0; k < n; ++k)
      out.push_back(corners[i - 1] + d * (double(k) / n) + Eigen::Vector2d(u(rng), u(rng)));
  }
  out.push_back(corners.back());
  return out;
}

inline SketchLandmark lm(const std::string& id, const std::string& cls, double cx, double cy,
                         double w = 60, double h = 40) {
  SketchLandmark l;
  l.id = id;
  l.class_name = cls;
  l.rect = {cx - w / 2, cy - h / 2, w, h};
  return l;
}

/// Right along y = 600 from x = 100 to 800, then up to y = 100 (a left turn in the route
/// frame). A above the first leg (left), B below it (right), C right of the second leg,
/// D beyond the goal (ahead). Distances are exact at kTrueScale.
inline Sketch lSketch(unsigned seed = 7) {
  Sketch s;
  s.name = "L";
  s.canvas_width = 1000;
  s.canvas_height = 700;
  s.start = {100, 600};
  s.goal = {800, 100};
  s.path = wobbly({{100, 600}, {800, 600}, {800, 100}}, 5, 3, seed);
  s.path.front() = s.start;
  s.path.back() = s.goal;
  s.landmarks = {lm("A", "Oatly-Oat-Milk", 300, 520), lm("B", "Arla-Standard-Milk", 600, 680),
                 lm("C", "Oatly-Oat-Milk", 880, 300), lm("D", "Bravo-Orange-Juice", 800, 40)};
  Eigen::Vector2d prev = s.start;
  for (auto& l : s.landmarks) {
    l.distance_m = kTrueScale * (l.rect.centre() - prev).norm();
    prev = l.rect.centre();
  }
  return s;
}

}  // namespace sketchnav::mapsketch::fixtures
