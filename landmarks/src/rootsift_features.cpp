#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

#include "sketchnav/landmarks/rootsift.h"

namespace sketchnav::landmarks {

namespace {
// cv::resize by `scale` (INTER_AREA), but never to 0 px: a 1 x 4000 photo scaled down rounds to
// 0 px wide, which cv::resize refuses with an assertion (issue 28: `recognise` exit 1). Other
// images take exactly the scale-factor call as before (same pixels, same features).
void resizeAtLeastOnePixel(const cv::Mat& src, cv::Mat& dst, double scale) {
  const cv::Size to(cv::saturate_cast<int>(src.cols * scale),
                    cv::saturate_cast<int>(src.rows * scale));
  if (to.width >= 1 && to.height >= 1)
    cv::resize(src, dst, cv::Size(), scale, scale, cv::INTER_AREA);
  else
    cv::resize(src, dst, cv::Size(std::max(1, to.width), std::max(1, to.height)), 0, 0,
               cv::INTER_AREA);
}
}  // namespace

void FeatureParams::validate() const {
  require(max_features >= 0, "features.max_features", "must be >= 0");
  require(max_image_side >= 64, "features.max_image_side", "must be >= 64 px");
  require(contrast_threshold > 0 && contrast_threshold < 1, "features.contrast_threshold",
          "must be in (0, 1)");
}

void rootSiftInPlace(cv::Mat& d) {
  CV_Assert(d.empty() || d.type() == CV_32F);
  for (int r = 0; r < d.rows; ++r) {
    float* row = d.ptr<float>(r);
    double l1 = 0;
    for (int c = 0; c < d.cols; ++c) l1 += std::abs(row[c]);
    if (l1 <= 0) continue;
    const float inv = static_cast<float>(1.0 / l1);
    // SIFT bins are non-negative; the abs only guards against foreign input.
    for (int c = 0; c < d.cols; ++c) row[c] = std::sqrt(std::abs(row[c]) * inv);
  }
}

cv::Mat rootSift(const cv::Mat& sift) {
  cv::Mat d;
  sift.convertTo(d, CV_32F);
  rootSiftInPlace(d);
  return d;
}

void detectSift(const cv::Mat& image, const FeatureParams& p, std::vector<cv::KeyPoint>& kps,
                cv::Mat& sift_u8) {
  kps.clear();
  sift_u8.release();
  if (image.empty()) return;
  cv::Mat grey;
  if (image.channels() == 3)
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  else if (image.channels() == 4)
    cv::cvtColor(image, grey, cv::COLOR_BGRA2GRAY);
  else
    grey = image;
  if (grey.depth() != CV_8U) grey.convertTo(grey, CV_8U);
  const int side = std::max(grey.cols, grey.rows);
  double scale = 1.0;
  if (side > p.max_image_side) {
    scale = static_cast<double>(p.max_image_side) / side;
    resizeAtLeastOnePixel(grey, grey, scale);
  }
  // One detector per thread: cv::SIFT is cheap to create but not documented as re-entrant.
  thread_local cv::Ptr<cv::SIFT> sift;
  thread_local int sift_n = -1;
  thread_local double sift_ct = -1;
  if (!sift || sift_n != p.max_features || sift_ct != p.contrast_threshold) {
    sift = cv::SIFT::create(p.max_features, 3, p.contrast_threshold, 10, 1.6, CV_8U);
    sift_n = p.max_features;
    sift_ct = p.contrast_threshold;
  }
  sift->detectAndCompute(grey, cv::noArray(), kps, sift_u8);
  if (scale != 1.0) {
    const float inv = static_cast<float>(1.0 / scale);
    for (auto& k : kps) {
      k.pt *= inv;
      k.size *= inv;
    }
  }
}

cv::Mat workingDescriptors(const cv::Mat& sift_u8, bool root_sift) {
  cv::Mat d;
  if (sift_u8.empty()) return cv::Mat(0, 128, CV_32F);
  sift_u8.convertTo(d, CV_32F);
  if (root_sift) rootSiftInPlace(d);
  return d;
}

cv::Mat keypointColours(const cv::Mat& image, const std::vector<cv::KeyPoint>& kps) {
  if (image.empty() || kps.empty() || image.channels() < 3) return {};
  cv::Mat bgr = image;
  if (image.channels() == 4) cv::cvtColor(image, bgr, cv::COLOR_BGRA2BGR);
  if (bgr.depth() != CV_8U) bgr.convertTo(bgr, CV_8U);
  // Box means from an integral image of a reduced copy: the colour of a keypoint's
  // neighbourhood, not of single (noisy, specular) pixels, for well under 1 ms per frame.
  constexpr int kSide = 640;
  const double s = std::min(1.0, static_cast<double>(kSide) / std::max(bgr.cols, bgr.rows));
  cv::Mat small;
  if (s < 1)
    resizeAtLeastOnePixel(bgr, small, s);
  else
    small = bgr;
  cv::Mat integ;
  cv::integral(small, integ, CV_32S);
  const int n = static_cast<int>(kps.size());
  cv::Mat out(n, 3, CV_8U);
  for (int i = 0; i < n; ++i) {
    const float r = std::max(1.0f, 0.5f * kps[i].size * static_cast<float>(s));
    const float cx = kps[i].pt.x * static_cast<float>(s), cy = kps[i].pt.y * static_cast<float>(s);
    const int x0 = std::clamp(static_cast<int>(std::floor(cx - r)), 0, small.cols - 1);
    const int y0 = std::clamp(static_cast<int>(std::floor(cy - r)), 0, small.rows - 1);
    const int x1 = std::clamp(static_cast<int>(std::ceil(cx + r)), x0 + 1, small.cols);
    const int y1 = std::clamp(static_cast<int>(std::ceil(cy + r)), y0 + 1, small.rows);
    const auto a = integ.at<cv::Vec3i>(y0, x0), b = integ.at<cv::Vec3i>(y0, x1),
               c = integ.at<cv::Vec3i>(y1, x0), d = integ.at<cv::Vec3i>(y1, x1);
    const float area = static_cast<float>((x1 - x0) * (y1 - y0));
    float m[3];  // mean B, G, R in [0, 255]
    for (int k = 0; k < 3; ++k) m[k] = static_cast<float>(d[k] - b[k] - c[k] + a[k]) / area;
    // Opponent chromaticities divided by the intensity: unchanged when the light gets brighter
    // or dimmer (shading, exposure); the +30 pulls near-black patches, whose hue is noise,
    // towards neutral.
    const float inv = 1.0f / (m[0] + m[1] + m[2] + 30.0f);
    const float c1 = (m[2] - m[1]) * inv;                // red - green, in (-1, 1)
    const float c2 = (m[2] + m[1] - 2.0f * m[0]) * inv;  // yellow - blue, in (-2, 1)
    out.at<unsigned char>(i, 0) = cv::saturate_cast<unsigned char>((m[0] + m[1] + m[2]) / 3.0f);
    out.at<unsigned char>(i, 1) = cv::saturate_cast<unsigned char>(128.0f + 100.0f * c1);
    out.at<unsigned char>(i, 2) = cv::saturate_cast<unsigned char>(128.0f + 60.0f * c2);
  }
  return out;
}

Features extractFeatures(const cv::Mat& image, const FeatureParams& p) {
  Features f;
  f.image_size = image.size();
  cv::Mat u8;
  detectSift(image, p, f.keypoints, u8);
  f.descriptors = workingDescriptors(u8, p.root_sift);
  f.colours = keypointColours(image, f.keypoints);
  return f;
}

}  // namespace sketchnav::landmarks
