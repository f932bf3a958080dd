#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

#include "sketchnav/landmarks/rootsift.h"

namespace sketchnav::landmarks {

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
    cv::resize(grey, grey, cv::Size(), scale, scale, cv::INTER_AREA);
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

Features extractFeatures(const cv::Mat& image, const FeatureParams& p) {
  Features f;
  f.image_size = image.size();
  cv::Mat u8;
  detectSift(image, p, f.keypoints, u8);
  f.descriptors = workingDescriptors(u8, p.root_sift);
  return f;
}

}  // namespace sketchnav::landmarks
