#pragma once
// Axis-aligned boxes in image pixels (cv::Rect: x, y, width, height; see doc/conventions.md):
// intersection-over-union and greedy non-maximum suppression, shared by the objectness
// methods, the baselines and the VOC evaluation.
#include <opencv2/core.hpp>

#include <vector>

namespace sketchnav::landmarks {

/// A scored box. Higher score = more likely an object.
struct ScoredBox {
  cv::Rect box;
  float score = 0.f;
};

/// |a ∩ b| / |a ∪ b|; 0 when either box is empty.
double iou(const cv::Rect& a, const cv::Rect& b);

/// Greedy NMS: sorts by score (descending, stable), keeps a box unless it overlaps an already
/// kept one with IoU > `max_iou`; stops after `max_keep` boxes (<= 0: no cap). Returns the
/// indices of the kept boxes into `boxes`, best first. Empty boxes are dropped.
std::vector<int> nms(const std::vector<ScoredBox>& boxes, double max_iou, int max_keep);

/// Clips `r` to a `size` image; may return an empty rect.
inline cv::Rect clipRect(const cv::Rect& r, const cv::Size& size) {
  return r & cv::Rect(0, 0, size.width, size.height);
}

}  // namespace sketchnav::landmarks
