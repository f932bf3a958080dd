// DBSCAN restricted to an adjacency graph (scs.h). Superpixels are few (hundreds), so the
// neighbour test is a plain loop over each point's adjacency list.
#include <deque>

#include "sketchnav/landmarks/scs.h"

namespace sketchnav::landmarks {

std::vector<int> dbscan(const cv::Mat& features, const std::vector<std::vector<int>>& adjacency,
                        double eps, int min_pts) {
  const int n = features.rows;
  CV_Assert(n == 0 || features.type() == CV_32F);
  CV_Assert(static_cast<int>(adjacency.size()) == n);
  const double eps2 = eps * eps;
  auto near = [&](int i) {
    std::vector<int> out{i};
    const float* a = features.ptr<float>(i);
    for (int j : adjacency[i]) {
      const float* b = features.ptr<float>(j);
      double d2 = 0;
      for (int c = 0; c < features.cols; ++c) d2 += double(a[c] - b[c]) * (a[c] - b[c]);
      if (d2 <= eps2) out.push_back(j);
    }
    return out;
  };
  std::vector<int> label(n, -1);  // -1 unvisited, -2 noise
  int next = 0;
  for (int i = 0; i < n; ++i) {
    if (label[i] != -1) continue;
    const auto nb = near(i);
    if (static_cast<int>(nb.size()) < min_pts) {
      label[i] = -2;
      continue;
    }
    const int c = next++;
    label[i] = c;
    std::deque<int> queue(nb.begin() + 1, nb.end());
    while (!queue.empty()) {
      const int j = queue.front();
      queue.pop_front();
      if (label[j] == -2) label[j] = c;  // border point
      if (label[j] != -1) continue;
      label[j] = c;
      const auto nj = near(j);
      if (static_cast<int>(nj.size()) >= min_pts)
        queue.insert(queue.end(), nj.begin() + 1, nj.end());
    }
  }
  for (int i = 0; i < n; ++i)
    if (label[i] < 0) label[i] = next++;  // noise: a cluster of its own
  return label;
}

}  // namespace sketchnav::landmarks
