#pragma once
// Local features for landmark recognition and matching: SIFT keypoints (OpenCV features2d)
// with RootSIFT descriptors (Arandjelović & Zisserman 2012): each SIFT descriptor is
// L1-normalised and square-rooted element-wise, so the Euclidean distance between two
// RootSIFT vectors equals the Hellinger distance between the original SIFT histograms, which
// matches and clusters better than L2 on raw SIFT.
#include <opencv2/core.hpp>

#include <string>
#include <vector>

#include "sketchnav/core/config.h"

namespace sketchnav::landmarks {

/// Feature extraction settings (stored in the model: a model is used with the same settings).
struct FeatureParams {
  int max_features = 500;            // keypoints kept per image (strongest); 0 = all
  int max_image_side = 400;          // [px] longer side above this is downscaled before SIFT
                                     //   (OpenCV SIFT upsamples ×2 internally, so this bounds
                                     //   the cost; keypoints are reported in input pixels)
  double contrast_threshold = 0.04;  // SIFT DoG contrast threshold (OpenCV default)
  bool root_sift = true;             // false = plain SIFT (for comparisons)

  template <class B>
  void bind(B& b) {
    b("max_features", max_features);
    b("max_image_side", max_image_side);
    b("contrast_threshold", contrast_threshold);
    b("root_sift", root_sift);
  }
  void validate() const;
};

/// Keypoints (in the input image's pixels) and their descriptors, one CV_32F row each.
struct Features {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;  // N x 128 CV_32F: RootSIFT or SIFT per FeatureParams::root_sift
  cv::Mat colours;      // N x 3 CV_8U keypointColours(); empty for a grey image
  cv::Size image_size;
};

/// In-place RootSIFT of SIFT descriptors (N x 128 CV_32F): L1-normalise each row, then take
/// the element-wise square root. All-zero rows stay zero. Result rows are non-negative with
/// unit L2 norm.
void rootSiftInPlace(cv::Mat& descriptors);
cv::Mat rootSift(const cv::Mat& sift_descriptors);

/// Raw SIFT (CV_8U, 0..255 per bin) on `image` (BGR or grey, any size): the form stored in
/// model files. Empty image -> no features.
void detectSift(const cv::Mat& image, const FeatureParams& p, std::vector<cv::KeyPoint>& kps,
                cv::Mat& sift_u8);

/// Converts stored CV_8U SIFT to the working descriptor (RootSIFT or SIFT as CV_32F).
cv::Mat workingDescriptors(const cv::Mat& sift_u8, bool root_sift);

/// Mean colour around each keypoint (a square of the keypoint's size, at least a few pixels),
/// N x 3 CV_8U: intensity (0..255), then two opponent chromaticities divided by the intensity
/// (red−green and yellow−blue, 128 = neutral, ~100 units for the full range), so the chroma
/// does not change when the same surface is lit more or less brightly. SIFT sees only grey
/// levels, so sibling products (the same artwork printed on an orange or a green carton) give
/// the same descriptors; the colour around a matched keypoint tells them apart
/// (chromaDistance2()). Empty for a grey (1-channel) image: no colour evidence, colour checks
/// are skipped.
cv::Mat keypointColours(const cv::Mat& image, const std::vector<cv::KeyPoint>& keypoints);

/// Squared chroma distance (intensity ignored) between rows of two keypointColours() matrices.
inline float chromaDistance2(const unsigned char* a, const unsigned char* b) {
  const float da = static_cast<float>(a[1]) - b[1], db = static_cast<float>(a[2]) - b[2];
  return da * da + db * db;
}

/// detectSift + workingDescriptors + keypointColours.
Features extractFeatures(const cv::Mat& image, const FeatureParams& p);

}  // namespace sketchnav::landmarks
