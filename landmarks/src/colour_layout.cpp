#include "sketchnav/landmarks/colour_layout.h"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

namespace sketchnav::landmarks {

cv::Mat colourThumbnail(const cv::Mat& image, int max_side) {
  if (image.empty()) return {};
  cv::Mat bgr = image;
  if (image.channels() == 1) cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
  if (image.channels() == 4) cv::cvtColor(image, bgr, cv::COLOR_BGRA2BGR);
  if (bgr.depth() != CV_8U) bgr.convertTo(bgr, CV_8U);
  const double s = std::min(1.0, static_cast<double>(max_side) / std::max(bgr.cols, bgr.rows));
  if (s >= 1) return bgr.clone();
  cv::Mat small;
  const cv::Size size(std::max(1, static_cast<int>(std::lround(bgr.cols * s))),
                      std::max(1, static_cast<int>(std::lround(bgr.rows * s))));
  cv::resize(bgr, small, size, 0, 0, cv::INTER_AREA);
  return small;
}

cv::Rect colourRegion(const std::vector<cv::Point2f>& keypoints, cv::Size image_size,
                      const cv::Rect& fallback) {
  const cv::Rect image(cv::Point(), image_size);
  if (keypoints.size() < 8) return fallback.area() > 0 ? (fallback & image) : image;
  std::vector<float> xs, ys;
  xs.reserve(keypoints.size());
  ys.reserve(keypoints.size());
  for (const auto& p : keypoints) {
    xs.push_back(p.x);
    ys.push_back(p.y);
  }
  const size_t n = xs.size(), k = static_cast<size_t>(kColourLayoutTrim * static_cast<double>(n));
  auto at = [](std::vector<float>& v, size_t i) {
    std::nth_element(v.begin(), v.begin() + static_cast<long>(i), v.end());
    return v[i];
  };
  const float x0 = at(xs, k), x1 = at(xs, n - 1 - k), y0 = at(ys, k), y1 = at(ys, n - 1 - k);
  const cv::Rect r(
      cv::Point(static_cast<int>(std::floor(x0)), static_cast<int>(std::floor(y0))),
      cv::Point(static_cast<int>(std::ceil(x1)) + 1, static_cast<int>(std::ceil(y1)) + 1));
  const cv::Rect clipped = r & image;
  return clipped.area() > 0 ? clipped : image;
}

cv::Mat colourLayoutDescriptor(const cv::Mat& thumbnail, cv::Size image_size, cv::Rect region) {
  cv::Mat d = cv::Mat::zeros(1, kColourLayoutDims, CV_32F);
  if (thumbnail.empty() || image_size.area() <= 0) return d;
  // The region in thumbnail pixels (at least one pixel).
  const double sx = static_cast<double>(thumbnail.cols) / image_size.width;
  const double sy = static_cast<double>(thumbnail.rows) / image_size.height;
  region &= cv::Rect(cv::Point(), image_size);
  if (region.area() <= 0) region = cv::Rect(cv::Point(), image_size);
  const int tx0 = std::clamp(static_cast<int>(std::floor(region.x * sx)), 0, thumbnail.cols - 1);
  const int ty0 = std::clamp(static_cast<int>(std::floor(region.y * sy)), 0, thumbnail.rows - 1);
  const int tx1 =
      std::clamp(static_cast<int>(std::ceil(region.br().x * sx)), tx0 + 1, thumbnail.cols);
  const int ty1 =
      std::clamp(static_cast<int>(std::ceil(region.br().y * sy)), ty0 + 1, thumbnail.rows);
  // Resized in BGR (interpolating hue would mix reds across the 179/0 wrap), then to HSV.
  cv::Mat sq, hsv;
  cv::resize(thumbnail(cv::Rect(tx0, ty0, tx1 - tx0, ty1 - ty0)), sq,
             cv::Size(kColourLayoutSide, kColourLayoutSide), 0, 0, cv::INTER_LINEAR);
  cv::cvtColor(sq, hsv, cv::COLOR_BGR2HSV);  // H in [0, 180), S, V in [0, 255]
  float* out = d.ptr<float>();
  constexpr int half = kColourLayoutSide / 2;
  for (int y = 0; y < kColourLayoutSide; ++y) {
    const auto* px = hsv.ptr<cv::Vec3b>(y);
    for (int x = 0; x < kColourLayoutSide; ++x) {
      const int h = std::min(px[x][0] * kColourLayoutHueBins / 180, kColourLayoutHueBins - 1);
      const int s = px[x][1] * kColourLayoutSatBins / 256;
      const int v = px[x][2] * kColourLayoutValBins / 256;
      const int bin = (h * kColourLayoutSatBins + s) * kColourLayoutValBins + v;
      const int cell = 1 + (y >= half ? 2 : 0) + (x >= half ? 1 : 0);
      out[bin] += 1.0f;
      out[cell * kColourLayoutBins + bin] += 1.0f;
    }
  }
  // Each part: sum 1, square root (unit L2); the whole scaled to unit L2.
  const float whole = static_cast<float>(kColourLayoutSide * kColourLayoutSide);
  const float cell_n = static_cast<float>(half * half);
  const float k = 1.0f / std::sqrt(5.0f);
  for (int part = 0; part < 5; ++part) {
    const float n = part == 0 ? whole : cell_n;
    float* p = out + part * kColourLayoutBins;
    for (int i = 0; i < kColourLayoutBins; ++i) p[i] = k * std::sqrt(p[i] / n);
  }
  return d;
}

}  // namespace sketchnav::landmarks
