// IoU and greedy NMS (boxes.h).
#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_map>

#include "sketchnav/landmarks/boxes.h"

namespace sketchnav::landmarks {

double iou(const cv::Rect& a, const cv::Rect& b) {
  if (a.width <= 0 || a.height <= 0 || b.width <= 0 || b.height <= 0) return 0.0;
  const double inter = static_cast<double>((a & b).area());
  const double uni = static_cast<double>(a.area()) + static_cast<double>(b.area()) - inter;
  return uni > 0 ? inter / uni : 0.0;
}

std::vector<int> nms(const std::vector<ScoredBox>& boxes, double max_iou, int max_keep) {
  std::vector<int> order(boxes.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return boxes[a].score > boxes[b].score; });
  // IoU(a, b) > t implies min(|a|,|b|) / max(|a|,|b|) > t, so a box only needs comparing with
  // kept boxes whose log-area lies within log(1/t): kept boxes are bucketed by log-area in
  // buckets of that width and only the three nearest buckets are searched.
  const bool suppress = max_iou < 1.0;
  const double width = suppress ? std::log(1.0 / std::max(max_iou, 1e-9)) : 1.0;
  std::unordered_map<long, std::vector<int>> bucket;
  std::vector<int> kept;
  for (int i : order) {
    const cv::Rect& r = boxes[i].box;
    if (r.width <= 0 || r.height <= 0) continue;
    const long b = static_cast<long>(std::floor(std::log(static_cast<double>(r.area())) / width));
    bool ok = true;
    if (suppress)
      for (long nb = b - 1; nb <= b + 1 && ok; ++nb) {
        const auto it = bucket.find(nb);
        if (it == bucket.end()) continue;
        for (int k : it->second)
          if (iou(r, boxes[k].box) > max_iou) {
            ok = false;
            break;
          }
      }
    if (!ok) continue;
    kept.push_back(i);
    bucket[b].push_back(i);
    if (max_keep > 0 && static_cast<int>(kept.size()) >= max_keep) break;
  }
  return kept;
}

}  // namespace sketchnav::landmarks
