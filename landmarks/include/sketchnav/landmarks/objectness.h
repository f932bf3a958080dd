#pragma once
// Objectness: candidate object windows for a camera frame, the union of two independent
// methods from the paper —
//   CCS (colour contrast + saliency segmentation, ccs.h) and
//   SCS (superpixel clustering + superpixel-straddling scoring, scs.h) —
// de-duplicated by NMS, ranked by score and capped at a requested count.
//
// Choices where the paper is vague (all exposed in ObjectnessParams):
//  - Both methods run on the frame scaled down to `work_long_side` pixels on its long side
//    (segmentation at full size costs seconds; windows are scaled back up at the end).
//  - Every window of either method is re-scored by the superpixel-straddling measure SS(w)
//    (Alexe et al.) on one shared SLIC map, so CCS and SCS scores are comparable. The final
//    score is SS(w) + `ccs_bonus` for CCS windows (saliency-backed) + `both_bonus` when both
//    methods proposed it (IoU >= `both_iou`).
//  - NMS at `nms_iou`; when fewer than `max_windows` survive, the suppressed windows are
//    appended in score order (a budget is better filled by near-duplicates than left empty).
#include <opencv2/core.hpp>

#include <string>
#include <vector>

#include "sketchnav/core/config.h"
#include "sketchnav/landmarks/ccs.h"
#include "sketchnav/landmarks/scs.h"

namespace sketchnav::landmarks {

/// One candidate window, in the input image's pixel coordinates.
struct Window {
  enum Source { CCS, SCS, Both, Edges };  // Edges: EdgeBoxes on the working image's edges
  cv::Rect box;
  float score = 0.f;  // higher = more object-like; comparable across sources
  Source source = SCS;
};

const char* toString(Window::Source s);

struct ObjectnessParams {
  int work_long_side = 200;    // px: long side of the working image (both methods)
  bool use_ccs = true;         // run the CCS method
  bool use_scs = true;         // run the SCS method
  double nms_iou = 0.85;       // NMS overlap above which the lower-scored window is suppressed
  double both_iou = 0.8;       // CCS and SCS windows this similar count as found by both
  double ccs_bonus = 0.05;     // added to the SS score of CCS windows
  double both_bonus = 0.05;    // added when both methods found the window
  int min_side = 4;            // px at working resolution: smaller windows are dropped
  bool use_edgeboxes = false;  // add EdgeBoxes (cv::ximgproc) windows on the working image's
                               // NMS-thinned Sobel edges (baselines.h sobelEdges)
  int edgeboxes_max = 200;     // EdgeBoxes windows added per frame
  double edgeboxes_bonus =
      -0.1;  // added to the SS score of EdgeBoxes windows (< 0: segment windows rank first)
  double edgeboxes_min_area_frac = 0.01;  // EdgeBoxes' smallest box, fraction of the image
  double edgeboxes_alpha = 0.55;  // EdgeBoxes' search step (IoU of neighbouring candidates);
                                  // lower = coarser and faster
  int edgeboxes_long_side = 120;  // px: EdgeBoxes runs on the working image shrunk to this
  CcsParams ccs;
  ScsParams scs;

  template <class B>
  void bind(B& b) {
    b("work_long_side", work_long_side);
    b("use_ccs", use_ccs);
    b("use_scs", use_scs);
    b("nms_iou", nms_iou);
    b("both_iou", both_iou);
    b("ccs_bonus", ccs_bonus);
    b("both_bonus", both_bonus);
    b("min_side", min_side);
    b("use_edgeboxes", use_edgeboxes);
    b("edgeboxes_max", edgeboxes_max);
    b("edgeboxes_bonus", edgeboxes_bonus);
    b("edgeboxes_min_area_frac", edgeboxes_min_area_frac);
    b("edgeboxes_alpha", edgeboxes_alpha);
    b("edgeboxes_long_side", edgeboxes_long_side);
  }
  /// Checks these fields and the nested ccs / scs params; throws InputError naming the field.
  void validate() const;
};

/// Loads ObjectnessParams from a Config (keys "objectness.*", "objectness.ccs.*",
/// "objectness.scs.*"), then validates.
ObjectnessParams objectnessParamsFrom(const Config& config);

/// Stateless after construction: propose() is const and thread-safe (each call allocates its
/// own buffers; OpenCV algorithms are created per call).
class Objectness {
 public:
  /// Throws InputError when `params` is invalid.
  explicit Objectness(ObjectnessParams params);

  /// Up to `max_windows` windows, best first, in `bgr`'s pixel coordinates. Accepts 8-bit
  /// 1-, 3- or 4-channel images of any size; an empty image (or one with a side < 2 px) gives
  /// no windows. max_windows <= 0 gives no windows.
  std::vector<Window> propose(const cv::Mat& bgr, int max_windows) const;

  const ObjectnessParams& params() const { return params_; }

 private:
  ObjectnessParams params_;
};

/// Converts any 8-bit 1/3/4-channel image to 3-channel BGR (8-bit); throws InputError for other
/// depths / channel counts. Empty in → empty out.
cv::Mat toBgr8(const cv::Mat& img);

}  // namespace sketchnav::landmarks
