// Proposal-evaluation metrics (voc.h).
#include <algorithm>
#include <map>

#include "sketchnav/landmarks/boxes.h"
#include "sketchnav/landmarks/voc.h"

namespace sketchnav::landmarks {

double bestOverlap(const cv::Rect& gt, const std::vector<cv::Rect>& proposals, int budget) {
  const int n = budget < 0 ? static_cast<int>(proposals.size())
                           : std::min<int>(budget, static_cast<int>(proposals.size()));
  double best = 0.0;
  for (int i = 0; i < n; ++i) best = std::max(best, iou(gt, proposals[i]));
  return best;
}

void ProposalEval::add(const std::vector<VocObject>& gt, const std::vector<cv::Rect>& proposals,
                       int budget) {
  for (const auto& o : gt) {
    if (o.difficult) continue;
    best_.push_back(bestOverlap(o.box, proposals, budget));
    cls_.push_back(o.name);
  }
}

double ProposalEval::recall(double t) const {
  if (best_.empty()) return 0.0;
  const auto hit = std::count_if(best_.begin(), best_.end(), [&](double b) { return b >= t; });
  return static_cast<double>(hit) / static_cast<double>(best_.size());
}

double ProposalEval::averageRecall() const {
  if (best_.empty()) return 0.0;
  double s = 0.0;
  for (double b : best_) s += std::max(b - 0.5, 0.0);
  return 2.0 * s / static_cast<double>(best_.size());
}

double ProposalEval::abo() const {
  if (best_.empty()) return 0.0;
  double s = 0.0;
  for (double b : best_) s += b;
  return s / static_cast<double>(best_.size());
}

double ProposalEval::mabo() const {
  std::map<std::string, std::pair<double, int>> per;
  for (size_t i = 0; i < best_.size(); ++i) {
    per[cls_[i]].first += best_[i];
    per[cls_[i]].second += 1;
  }
  if (per.empty()) return 0.0;
  double s = 0.0;
  for (const auto& [c, v] : per) s += v.first / v.second;
  return s / static_cast<double>(per.size());
}

}  // namespace sketchnav::landmarks
