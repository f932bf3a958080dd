#pragma once
// SCS — superpixel clustering and straddling (paper, "Superpixel clustering and straddling").
//
// Pipeline, on an already down-scaled BGR image:
//  1. SLIC superpixels (cv::ximgproc::createSuperpixelSLIC, SLICO variant: no compactness
//     tuning needed).
//  2. DBSCAN over the superpixels (feature: mean Lab colour + centroid scaled by
//     `dbscan_pos_weight`; neighbours are restricted to spatially adjacent superpixels so
//     clusters stay connected) refines them into larger, colour-coherent clusters.
//  3. Graph-based segmentation (Felzenszwalb–Huttenlocher criterion) of the cluster adjacency
//     graph into regions, for each threshold in `graph_k` (several granularities).
//  4. Hierarchical grouping: the most similar adjacent pair of regions is merged repeatedly
//     (similarity = colour + small-size + fill, as in selective search); the bounding box of
//     every region that ever exists is a candidate window, screened by area.
//  5. Every candidate is scored by superpixel straddling on the SLIC map (Alexe et al.):
//       SS(w) = 1 − Σ_s min(|s∖w|, |s∩w|) / |w|.
//     A dense multi-scale grid of windows is scored the same way and added (Alexe's original
//     sampling), so a budget is never short of candidates.
#include <opencv2/core.hpp>

#include <vector>

#include "sketchnav/landmarks/boxes.h"

namespace sketchnav::landmarks {

struct ScsParams {
  int slic_region_size = 8;        // px at working resolution: SLIC superpixel side
  int slic_iterations = 4;         // SLIC iterations
  double dbscan_eps = 7.0;         // DBSCAN radius in the (Lab, weighted position) space
  int dbscan_min_pts = 2;          // DBSCAN core-point neighbour count (itself included)
  double dbscan_pos_weight = 0.2;  // Lab units per working px of centroid distance
  std::vector<double> graph_k = {8.0, 20.0, 50.0};  // FH thresholds k (Lab units × superpixels)
  double min_area_frac = 0.0015;  // windows below this fraction of the image are dropped
  double max_area_frac = 1.0;     // windows above this fraction are dropped
  bool add_grid = true;           // add a dense multi-scale grid scored by SS
  int grid_scales = 10;           // grid: window side fractions from 1 down to ~0.1
  bool grid_dense = false;        // grid: 5 aspects and 1/3-window stride instead of 3 and 1/2
  double grid_penalty = 0.3;      // subtracted from grid windows' SS (segments rank first)

  template <class B>
  void bind(B& b) {
    b("slic_region_size", slic_region_size);
    b("slic_iterations", slic_iterations);
    b("dbscan_eps", dbscan_eps);
    b("dbscan_min_pts", dbscan_min_pts);
    b("dbscan_pos_weight", dbscan_pos_weight);
    b("graph_k", graph_k);
    b("min_area_frac", min_area_frac);
    b("max_area_frac", max_area_frac);
    b("add_grid", add_grid);
    b("grid_scales", grid_scales);
    b("grid_dense", grid_dense);
    b("grid_penalty", grid_penalty);
  }
  void validate() const;  // throws InputError "scs.<field> = ..."
};

/// Superpixel straddling on a label map (CV_32S, labels 0..n-1). Precomputes one integral
/// image per superpixel over the superpixel's bounding box, so score() is O(#superpixels
/// whose box meets the window).
class StraddlingScorer {
 public:
  explicit StraddlingScorer(const cv::Mat& labels);
  /// SS(w) in [0, 1]; 0 for an empty window. `w` is clipped to the label map.
  double score(const cv::Rect& w) const;
  int superpixels() const { return static_cast<int>(sp_.size()); }

 private:
  struct Sp {
    cv::Rect box;
    int area = 0;
    cv::Mat integral;  // CV_32S, (box.height+1) x (box.width+1)
  };
  cv::Size size_;
  std::vector<Sp> sp_;
};

/// DBSCAN on points given as rows of `features` (CV_32F, one row per point) where only pairs
/// listed in `adjacency` (adjacency[i] = neighbour indices) may be neighbours. Returns a
/// cluster id per point; noise points get their own singleton cluster. Ids are 0..k-1.
std::vector<int> dbscan(const cv::Mat& features, const std::vector<std::vector<int>>& adjacency,
                        double eps, int min_pts);

/// SLIC labels (CV_32S) of a BGR working image.
cv::Mat slicLabels(const cv::Mat& bgr, const ScsParams& p);

/// SCS windows for a BGR working image, scored by SS on `labels` (from slicLabels()).
std::vector<ScoredBox> proposeScs(const cv::Mat& bgr, const cv::Mat& labels, const ScsParams& p,
                                  const StraddlingScorer& scorer);

}  // namespace sketchnav::landmarks
