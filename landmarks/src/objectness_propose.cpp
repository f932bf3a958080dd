// The union of CCS and SCS windows (objectness.h).
#include <opencv2/imgproc.hpp>
#include <opencv2/ximgproc.hpp>

#include <algorithm>
#include <cmath>

#include "sketchnav/landmarks/baselines.h"
#include "sketchnav/landmarks/objectness.h"

namespace sketchnav::landmarks {

const char* toString(Window::Source s) {
  switch (s) {
    case Window::CCS:
      return "ccs";
    case Window::SCS:
      return "scs";
    case Window::Both:
      return "both";
    case Window::Edges:
      return "edges";
  }
  return "?";
}

void ObjectnessParams::validate() const {
  require(work_long_side >= 32 && work_long_side <= 2048, "objectness.work_long_side",
          "must be in [32, 2048] px");
  require(use_ccs || use_scs, "objectness.use_ccs", "at least one of use_ccs / use_scs");
  require(nms_iou > 0 && nms_iou <= 1, "objectness.nms_iou", "must be in (0, 1]");
  require(both_iou > 0 && both_iou <= 1, "objectness.both_iou", "must be in (0, 1]");
  require(min_side >= 1, "objectness.min_side", "must be >= 1 px");
  require(edgeboxes_max >= 1 && edgeboxes_max <= 100000, "objectness.edgeboxes_max",
          "must be in [1, 100000]");
  require(edgeboxes_min_area_frac >= 0 && edgeboxes_min_area_frac < 1,
          "objectness.edgeboxes_min_area_frac", "must be in [0, 1)");
  require(edgeboxes_alpha > 0 && edgeboxes_alpha < 1, "objectness.edgeboxes_alpha",
          "must be in (0, 1)");
  require(edgeboxes_long_side >= 16 && edgeboxes_long_side <= 2048,
          "objectness.edgeboxes_long_side", "must be in [16, 2048] px");
  ccs.validate();
  scs.validate();
}

ObjectnessParams objectnessParamsFrom(const Config& config) {
  ObjectnessParams p;
  detail::ConfigApplier a(config, "objectness"), ac(config, "objectness.ccs"),
      as(config, "objectness.scs");
  p.bind(a);
  p.ccs.bind(ac);
  p.scs.bind(as);
  p.validate();
  return p;
}

cv::Mat toBgr8(const cv::Mat& img) {
  if (img.empty()) return {};
  if (img.depth() != CV_8U)
    throw InputError("objectness: image must be 8-bit, got depth " + std::to_string(img.depth()));
  cv::Mat out;
  switch (img.channels()) {
    case 1:
      cv::cvtColor(img, out, cv::COLOR_GRAY2BGR);
      break;
    case 3:
      out = img;
      break;
    case 4:
      cv::cvtColor(img, out, cv::COLOR_BGRA2BGR);
      break;
    default:
      throw InputError("objectness: image must have 1, 3 or 4 channels, got " +
                       std::to_string(img.channels()));
  }
  return out;
}

Objectness::Objectness(ObjectnessParams params) : params_(std::move(params)) {
  params_.validate();
}

std::vector<Window> Objectness::propose(const cv::Mat& input, int max_windows) const {
  std::vector<Window> out;
  const cv::Mat bgr_in = toBgr8(input);
  if (bgr_in.empty() || bgr_in.cols < 2 || bgr_in.rows < 2 || max_windows <= 0) return out;
  const auto& p = params_;
  const double scale =
      std::min(1.0, static_cast<double>(p.work_long_side) / std::max(bgr_in.cols, bgr_in.rows));
  cv::Mat bgr;
  if (scale < 1.0)
    cv::resize(bgr_in, bgr, cv::Size(), scale, scale, cv::INTER_AREA);
  else
    bgr = bgr_in;

  const cv::Mat labels = slicLabels(bgr, p.scs);
  const StraddlingScorer scorer(labels);
  std::vector<ScoredBox> boxes;
  std::vector<Window::Source> src;
  if (p.use_scs) {
    for (const auto& b : proposeScs(bgr, labels, p.scs, scorer)) {
      boxes.push_back(b);
      src.push_back(Window::SCS);
    }
  }
  const size_t n_scs = boxes.size();
  if (p.use_ccs) {
    for (const auto& b : proposeCcs(bgr, p.ccs)) {
      // CCS windows are re-scored by straddling so both methods rank on one scale.
      boxes.push_back({b.box, static_cast<float>(scorer.score(b.box) + p.ccs_bonus)});
      src.push_back(Window::CCS);
    }
    // "Both": a CCS window with an SCS window at IoU >= both_iou. SCS boxes are sorted by
    // area so only those with an area ratio >= both_iou (a necessary condition) are tested.
    std::vector<std::pair<int, int>> by_area;  // (area, index)
    for (size_t j = 0; j < n_scs; ++j)
      by_area.emplace_back(boxes[j].box.area(), static_cast<int>(j));
    std::sort(by_area.begin(), by_area.end());
    for (size_t i = n_scs; i < boxes.size(); ++i) {
      const double a = boxes[i].box.area();
      auto it = std::lower_bound(by_area.begin(), by_area.end(),
                                 std::make_pair(static_cast<int>(std::floor(a * p.both_iou)), -1));
      for (; it != by_area.end() && it->first <= a / p.both_iou; ++it)
        if (iou(boxes[i].box, boxes[it->second].box) >= p.both_iou) {
          boxes[i].score += static_cast<float>(p.both_bonus);
          src[i] = Window::Both;
          break;
        }
    }
  }
  if (p.use_edgeboxes) {
    // EdgeBoxes' cost grows with the pixel count and the candidate count: it may run on a
    // smaller copy of the working image; its boxes are scaled back to working pixels.
    const double es =
        std::min(1.0, static_cast<double>(p.edgeboxes_long_side) / std::max(bgr.cols, bgr.rows));
    cv::Mat small;
    if (es < 1.0)
      cv::resize(bgr, small, cv::Size(), es, es, cv::INTER_AREA);
    else
      small = bgr;
    cv::Mat mag, orient;
    sobelEdges(small, mag, orient);
    auto eb = cv::ximgproc::createEdgeBoxes(static_cast<float>(p.edgeboxes_alpha));
    eb->setMaxBoxes(p.edgeboxes_max);
    eb->setMinBoxArea(static_cast<float>(p.edgeboxes_min_area_frac * small.cols * small.rows));
    std::vector<cv::Rect> eboxes;
    std::vector<float> escores;
    eb->getBoundingBoxes(mag, orient, eboxes, escores);
    const cv::Rect frame(0, 0, bgr.cols, bgr.rows);
    for (const auto& r : eboxes) {
      const cv::Rect c = cv::Rect(cvRound(r.x / es), cvRound(r.y / es), cvRound(r.width / es),
                                  cvRound(r.height / es)) &
                         frame;
      if (c.area() <= 0) continue;
      boxes.push_back({c, static_cast<float>(scorer.score(c) + p.edgeboxes_bonus)});
      src.push_back(Window::Edges);
    }
  }
  // Drop windows too small to be useful at the working resolution.
  std::vector<ScoredBox> keep_boxes;
  std::vector<Window::Source> keep_src;
  for (size_t i = 0; i < boxes.size(); ++i)
    if (boxes[i].box.width >= p.min_side && boxes[i].box.height >= p.min_side) {
      keep_boxes.push_back(boxes[i]);
      keep_src.push_back(src[i]);
    }
  std::vector<int> order = nms(keep_boxes, p.nms_iou, max_windows);
  if (static_cast<int>(order.size()) < max_windows) {
    // Fill the budget with the suppressed windows, best first.
    std::vector<char> used(keep_boxes.size(), 0);
    for (int i : order) used[i] = 1;
    std::vector<int> rest;
    for (int i = 0; i < static_cast<int>(keep_boxes.size()); ++i)
      if (!used[i]) rest.push_back(i);
    std::stable_sort(rest.begin(), rest.end(),
                     [&](int a, int b) { return keep_boxes[a].score > keep_boxes[b].score; });
    for (int i : rest) {
      if (static_cast<int>(order.size()) >= max_windows) break;
      order.push_back(i);
    }
  }
  const cv::Rect img(0, 0, bgr_in.cols, bgr_in.rows);
  for (int i : order) {
    const cv::Rect& r = keep_boxes[i].box;
    const cv::Rect back = cv::Rect(cvRound(r.x / scale), cvRound(r.y / scale),
                                   cvRound(r.width / scale), cvRound(r.height / scale)) &
                          img;
    if (back.area() <= 0) continue;
    out.push_back({back, keep_boxes[i].score, keep_src[i]});
  }
  return out;
}

}  // namespace sketchnav::landmarks
