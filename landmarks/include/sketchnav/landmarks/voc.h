#pragma once
// PASCAL VOC-layout data sets (JPEGImages/, Annotations/*.xml, optional ImageSets/Main/*.txt)
// and the proposal-evaluation metrics: recall at an IoU threshold, average recall (AR, IoU
// 0.5–1, Hosang et al.), average best overlap (ABO) and its mean over classes (MABO).
#include <opencv2/core.hpp>

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "sketchnav/landmarks/baselines.h"

namespace sketchnav::landmarks {

struct VocObject {
  std::string name;  // class
  cv::Rect box;      // pixels, VOC's 1-based inclusive corners converted to cv::Rect
  bool difficult = false;
};

struct VocImage {
  std::string id;                     // file stem
  std::string image_path;             // JPEGImages/<id>.jpg (or the first existing extension)
  cv::Size size;                      // from <size>; (0,0) when absent
  std::vector<VocObject> objects;     // boxes clipped to the image when its size is known
  std::vector<std::string> warnings;  // e.g. a box outside the image (dropped)
};

/// Parses one VOC annotation XML file. Throws InputError naming the file when it cannot be
/// read or a <bndbox> is malformed. Boxes fully outside the image (or empty) are dropped with a
/// warning; partly outside ones are clipped.
VocImage readVocAnnotation(const std::string& xml_path);

/// Reads a VOC-layout folder: the ids from ImageSets/Main/test.txt (else the only / first
/// .txt there, else all Annotations/*.xml, sorted). Throws InputError when the folder or its
/// Annotations/ is missing or holds no annotation.
std::vector<VocImage> readVocDataset(const std::string& dir);

/// Best IoU of `gt` against the first `budget` boxes of `proposals` (all if budget < 0).
double bestOverlap(const cv::Rect& gt, const std::vector<cv::Rect>& proposals, int budget = -1);

/// Accumulates per-object best overlaps for one method at one window budget.
class ProposalEval {
 public:
  /// Adds one image: `gt` ground-truth boxes (non-difficult) with class names, and the
  /// method's ranked proposals; only the first `budget` proposals count.
  void add(const std::vector<VocObject>& gt, const std::vector<cv::Rect>& proposals, int budget);
  int objects() const { return static_cast<int>(best_.size()); }
  /// Fraction of objects whose best overlap >= t. 0 when there are no objects.
  double recall(double t) const;
  /// Average recall over IoU 0.5–1: 2 · mean(max(best − 0.5, 0)), the exact integral
  /// 2∫_{0.5}^{1} recall(t) dt.
  double averageRecall() const;
  /// Mean over objects of the best overlap.
  double abo() const;
  /// Mean over classes of the per-class ABO.
  double mabo() const;

 private:
  std::vector<double> best_;
  std::vector<std::string> cls_;
};

/// One method's figures over a data set.
struct MethodResult {
  std::string name;
  std::map<int, ProposalEval> at;  // per window budget
  std::vector<double> ms;          // per evaluated image: wall time of one propose(max budget)
  std::vector<double> cpu_ms;      // the same call's process CPU time (robust to a busy machine)
  double msMean() const;
  double msMedian() const;
  double cpuMsMean() const;
  double cpuMsMedian() const;
};

struct EvalResult {
  int images = 0;                    // evaluated (readable) images
  int objects = 0;                   // non-difficult objects in them
  std::vector<std::string> skipped;  // unreadable / corrupt image files, skipped with a warning
  std::vector<MethodResult> methods;
};

/// Runs every method once per image with the largest budget (so all budgets and timings come
/// from the same run); smaller budgets take the ranked prefix. Unreadable images are skipped
/// (listed in `skipped`), never fatal. `progress(i, n, id)` is called before image i (0-based).
EvalResult evaluateProposals(
    const std::vector<VocImage>& images, const std::vector<ProposalMethod*>& methods,
    const std::vector<int>& budgets,
    const std::function<void(int, int, const std::string&)>& progress = {});

}  // namespace sketchnav::landmarks
