// Superpixel straddling score (scs.h).
#include <opencv2/imgproc.hpp>

#include <algorithm>

#include "sketchnav/landmarks/scs.h"

namespace sketchnav::landmarks {

StraddlingScorer::StraddlingScorer(const cv::Mat& labels) : size_(labels.size()) {
  CV_Assert(labels.empty() || labels.type() == CV_32S);
  if (labels.empty()) return;
  int n = 0;
  for (int y = 0; y < labels.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    for (int x = 0; x < labels.cols; ++x) n = std::max(n, l[x] + 1);
  }
  std::vector<cv::Point> lo(n, cv::Point(labels.cols, labels.rows)), hi(n, cv::Point(-1, -1));
  for (int y = 0; y < labels.rows; ++y) {
    const int* l = labels.ptr<int>(y);
    for (int x = 0; x < labels.cols; ++x) {
      const int k = l[x];
      if (k < 0) continue;
      lo[k].x = std::min(lo[k].x, x);
      lo[k].y = std::min(lo[k].y, y);
      hi[k].x = std::max(hi[k].x, x);
      hi[k].y = std::max(hi[k].y, y);
    }
  }
  sp_.resize(n);
  for (int k = 0; k < n; ++k) {
    if (hi[k].x < 0) continue;
    Sp& s = sp_[k];
    s.box = cv::Rect(lo[k], hi[k] + cv::Point(1, 1));
    cv::Mat mask = (labels(s.box) == k) / 255;  // 0/1
    cv::integral(mask, s.integral, CV_32S);
    s.area = s.integral.at<int>(s.box.height, s.box.width);
  }
}

double StraddlingScorer::score(const cv::Rect& w0) const {
  const cv::Rect w = w0 & cv::Rect(0, 0, size_.width, size_.height);
  if (w.area() <= 0) return 0.0;
  double straddle = 0.0;
  for (const Sp& s : sp_) {
    if (s.area == 0) continue;
    const cv::Rect r = s.box & w;
    if (r.area() <= 0) continue;  // |s∩w| = 0 contributes min(|s|, 0) = 0
    const int x0 = r.x - s.box.x, y0 = r.y - s.box.y;
    const int x1 = x0 + r.width, y1 = y0 + r.height;
    const cv::Mat& I = s.integral;
    const int in = I.at<int>(y1, x1) - I.at<int>(y0, x1) - I.at<int>(y1, x0) + I.at<int>(y0, x0);
    straddle += std::min(in, s.area - in);
  }
  return 1.0 - straddle / static_cast<double>(w.area());
}

}  // namespace sketchnav::landmarks
