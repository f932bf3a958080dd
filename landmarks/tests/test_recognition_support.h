#pragma once
// Synthetic and small real fixtures for the recognition tests.
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <string>

namespace sketchnav::test {

/// A deterministic, richly textured image (random rectangles, circles, text): plenty of
/// distinctive SIFT keypoints, different for every seed.
inline cv::Mat texturedImage(int w, int h, unsigned seed) {
  cv::RNG rng(seed);
  cv::Mat img(h, w, CV_8UC3,
              cv::Scalar(rng.uniform(0, 255), rng.uniform(0, 255), rng.uniform(0, 255)));
  for (int i = 0; i < 60; ++i) {
    const cv::Scalar col(rng.uniform(0, 255), rng.uniform(0, 255), rng.uniform(0, 255));
    const cv::Point a(rng.uniform(0, w), rng.uniform(0, h));
    switch (i % 3) {
      case 0:
        cv::rectangle(img, a, a + cv::Point(rng.uniform(5, w / 5), rng.uniform(5, h / 5)), col, -1);
        break;
      case 1:
        cv::circle(img, a, rng.uniform(3, w / 10), col, -1);
        break;
      default:
        cv::putText(img, std::to_string(rng.uniform(100, 99999)), a, cv::FONT_HERSHEY_SIMPLEX,
                    rng.uniform(0.5, 2.0), col, 2);
    }
  }
  return img;
}

}  // namespace sketchnav::test

#include <filesystem>
#include <fstream>
#include <vector>

namespace sketchnav::test {

/// `obj` seen through a random perspective (rotation up to ±max_rot_deg, scale 0.6..1.0,
/// corner jitter) pasted on a random textured background of w x h. Returns the image and,
/// optionally, the homography obj -> image.
inline cv::Mat randomView(const cv::Mat& obj, int w, int h, unsigned seed, double max_rot_deg,
                          cv::Mat* H_out = nullptr) {
  cv::RNG rng(seed);
  cv::Mat bg(h, w, CV_8UC3);
  rng.fill(bg, cv::RNG::UNIFORM, 60, 200);
  cv::GaussianBlur(bg, bg, cv::Size(0, 0), 3);
  const double s = rng.uniform(0.6, 1.0) * std::min(w, h) / std::max(obj.cols, obj.rows);
  const double a = rng.uniform(-max_rot_deg, max_rot_deg) * CV_PI / 180;
  const cv::Point2f c(w * 0.5f + rng.uniform(-0.1f, 0.1f) * w,
                      h * 0.5f + rng.uniform(-0.1f, 0.1f) * h);
  std::vector<cv::Point2f> src = {
      {0, 0}, {float(obj.cols), 0}, {float(obj.cols), float(obj.rows)}, {0, float(obj.rows)}};
  std::vector<cv::Point2f> dst;
  for (const auto& p : src) {
    const double x = (p.x - obj.cols / 2.0) * s, y = (p.y - obj.rows / 2.0) * s;
    const double j = 0.08 * s * obj.cols;
    dst.push_back(
        {static_cast<float>(c.x + std::cos(a) * x - std::sin(a) * y + rng.uniform(-j, j)),
         static_cast<float>(c.y + std::sin(a) * x + std::cos(a) * y + rng.uniform(-j, j))});
  }
  cv::Mat H = cv::getPerspectiveTransform(src, dst);
  cv::Mat out = bg.clone();
  cv::warpPerspective(obj, out, H, bg.size(), cv::INTER_LINEAR, cv::BORDER_TRANSPARENT);
  if (H_out) *H_out = H;
  return out;
}

/// Writes a landmark set: `classes` class folders (nested under a group folder, as in
/// grocery-packages) with `photos` random views each of a distinct textured object.
/// Object k is texturedImage(240, 180, 1000 + k).
inline void writeLandmarkSet(const std::string& root, int classes, int photos, unsigned seed) {
  for (int k = 0; k < classes; ++k) {
    const std::string dir = root + "/group/class" + std::to_string(k);
    std::filesystem::create_directories(dir);
    const cv::Mat obj = texturedImage(240, 180, 1000 + k);
    for (int i = 0; i < photos; ++i)
      cv::imwrite(dir + "/p" + std::to_string(i) + ".jpg",
                  randomView(obj, 320, 240, seed + 100 * k + i, 20));
  }
}

}  // namespace sketchnav::test
