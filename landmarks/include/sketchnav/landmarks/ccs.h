#pragma once
// CCS — colour contrast and saliency (paper, "Colour contrast and saliency").
//
// Pipeline, on an already down-scaled BGR image:
//  1. L0-norm smoothing (cv::ximgproc::l0Smooth) flattens texture, keeps strong edges.
//  2. Per-channel Sobel gradient magnitude, combined by the per-pixel maximum.
//  3. Morphological reconstruction (h-minima transform, geodesic erosion) so that only
//     marked pixels are regional minima of the gradient; the marked minima are the
//     foreground/background markers of a marker-controlled watershed (cv::watershed).
//  4. Single skeleton refinement: cv::ximgproc::thinning of the watershed regions' interior
//     gives a one-pixel skeleton per region — the subset of n ≪ N pixels that is clustered.
//  5. Fuzzy c-means of the skeleton pixels' Lab colours (fcm()); each watershed region takes
//     the cluster with the highest mean membership over its skeleton; adjacent regions of the
//     same cluster merge; regions under `small_region_frac` of the image merge into the
//     neighbour with the closest mean membership vector ("improved FCM merge").
//  6. A centre–surround contrast saliency map (multi-scale difference of Gaussians in Lab).
//     Windows: bounding boxes of segments, of adjacent segment pairs, and of connected
//     components of the saliency map thresholded at several levels; each scored by the
//     saliency contrast between the window and a ring around it.
#include <opencv2/core.hpp>

#include <vector>

#include "sketchnav/landmarks/boxes.h"

namespace sketchnav::landmarks {

struct CcsParams {
  int work_long_side = 160;  // px: CCS runs at this long side (l0Smooth is the cost)
  int l0_long_side = 100;    // px: L0 smoothing runs at this long side, result upsampled
  double l0_lambda = 0.003;  // l0Smooth smoothing weight
  double l0_kappa = 4.0;     // l0Smooth step factor (2 = reference, larger = faster)
  double h_min = 6.0;        // h-minima depth, gradient units (0..255)
  std::vector<int> fcm_clusters = {4, 8};  // FCM cluster counts (one segmentation each)
  double fcm_m = 2.0;                      // FCM fuzzifier (> 1)
  int fcm_iterations = 30;                 // FCM max iterations
  double small_region_frac = 0.05;         // regions under this area fraction are merged away
  std::vector<double> saliency_levels = {0.3, 0.5, 0.7};  // thresholds, fraction of max
  unsigned seed = 7;                                      // FCM initialisation

  template <class B>
  void bind(B& b) {
    b("work_long_side", work_long_side);
    b("l0_long_side", l0_long_side);
    b("l0_lambda", l0_lambda);
    b("l0_kappa", l0_kappa);
    b("h_min", h_min);
    b("fcm_clusters", fcm_clusters);
    b("fcm_m", fcm_m);
    b("fcm_iterations", fcm_iterations);
    b("small_region_frac", small_region_frac);
    b("saliency_levels", saliency_levels);
    b("seed", seed);
  }
  void validate() const;  // throws InputError "ccs.<field> = ..."
};

/// Result of fuzzy c-means.
struct FcmResult {
  cv::Mat centers;          // CV_32F, c x d
  cv::Mat membership;       // CV_32F, n x c, rows sum to 1
  std::vector<int> labels;  // argmax membership per point
  int iterations = 0;
};

/// Fuzzy c-means of the rows of `points` (CV_32F, n x d) into `c` clusters with fuzzifier `m`,
/// seeded (k-means++-style initial centres from `seed`). Stops when centres move < 1e-4 or
/// after `max_iter`. c is clamped to n. Empty input → empty result.
FcmResult fcm(const cv::Mat& points, int c, double m, int max_iter, unsigned seed);

/// Centre–surround contrast saliency of a BGR image: CV_32F in [0, 1], same size.
cv::Mat centreSurroundSaliency(const cv::Mat& bgr);

/// CCS segmentation (label map CV_32S, labels 0..k-1) for one FCM cluster count.
/// Exposed for tests and debugging.
cv::Mat ccsSegment(const cv::Mat& bgr, const CcsParams& p, int clusters);

/// CCS windows for a BGR image (any size: it is scaled to p.work_long_side inside), in that
/// image's coordinates.
std::vector<ScoredBox> proposeCcs(const cv::Mat& bgr, const CcsParams& p);

}  // namespace sketchnav::landmarks
