#pragma once
// Baseline window-proposal methods for the benchmark, all from OpenCV contrib except the grid:
//  - BING (cv::saliency::ObjectnessBING, trained model folder required),
//  - Selective Search, fast mode (cv::ximgproc::segmentation::SelectiveSearchSegmentation),
//    read in one of three orders (SsOrder; the default baseline reads it reversed),
//  - EdgeBoxes (cv::ximgproc::EdgeBoxes) fed with Sobel edge magnitude and orientation, thinned
//    by non-maximum suppression (sobelEdges; the structured-edge model is not available
//    offline),
//  - a fixed sliding-window grid.
// Each returns ranked boxes in the input image's coordinates. None is thread-safe across one
// instance; create one per thread.
#include <opencv2/core.hpp>

#include <memory>
#include <string>
#include <vector>

namespace sketchnav::landmarks {

class ProposalMethod {
 public:
  virtual ~ProposalMethod() = default;
  virtual std::string name() const = 0;
  /// Up to `max_windows` boxes, best first. `bgr` is 8-bit 3-channel, non-empty.
  virtual std::vector<cv::Rect> propose(const cv::Mat& bgr, int max_windows) = 0;
};

/// `model_dir` holds the ObjNessB2W8*.yml.gz files; `scratch_dir` is where BING insists on
/// writing its results. Throws InputError when the model cannot be loaded.
std::unique_ptr<ProposalMethod> makeBing(const std::string& model_dir,
                                         const std::string& scratch_dir);
/// How Selective Search's output list is read. OpenCV returns its regions sorted by
/// rank = hierarchy level × U(0,1) ascending, so the list begins with the initial small
/// segments; `Reversed` puts the late merges (whole objects) first and ranks best
/// (doc/objectness.md); `Random` is Hosang et al.'s seeded-shuffle control.
enum class SsOrder { AsReturned, Reversed, Random };
/// `rects` re-ordered as `order` says (Random: a fixed-seed shuffle, identical every call).
std::vector<cv::Rect> orderSelectiveSearch(std::vector<cv::Rect> rects, SsOrder order);
/// Named "selective-search" (Reversed), "selective-search-as-returned" or
/// "selective-search-random". Methods made with the same `shared_run`
/// (makeSelectiveSearchRun()) run Selective Search once per image and share its boxes.
std::unique_ptr<ProposalMethod> makeSelectiveSearchFast(SsOrder order = SsOrder::Reversed,
                                                        std::shared_ptr<void> shared_run = {});
std::shared_ptr<void> makeSelectiveSearchRun();

/// EdgeBoxes' input without the structured-edge model: grey image, Gaussian σ = 1, 3×3 Sobel;
/// `magnitude` (CV_32F, max 1) is non-maximum suppressed across the edge (one pixel wide) with
/// responses < 0.05 zeroed; `orientation` (CV_32F) is the gradient direction mod π, radians.
void sobelEdges(const cv::Mat& bgr, cv::Mat& magnitude, cv::Mat& orientation);
std::unique_ptr<ProposalMethod> makeEdgeBoxesSobel();
/// Fixed grid: square-ish windows (aspect 1:1, 2:1, 1:2 relative to the image) at scales
/// 1, 0.8, 0.64 … of the image, stride half a window; largest first, capped at max_windows.
std::unique_ptr<ProposalMethod> makeSlidingWindow();

/// The fixed grid itself (shared with SCS's grid candidates). `dense` adds aspects 1:0.7 and
/// 0.7:1 and spaces positions a third of a window apart (SCS's candidate grid; the baseline
/// uses the plain grid).
std::vector<cv::Rect> slidingWindowGrid(const cv::Size& size, int max_windows, int scales = 12,
                                        bool dense = false);

}  // namespace sketchnav::landmarks
