// The proposal benchmark loop (voc.h).
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <ctime>

#include "sketchnav/core/error.h"
#include "sketchnav/core/image_file.h"
#include "sketchnav/core/log.h"
#include "sketchnav/landmarks/voc.h"

namespace sketchnav::landmarks {

namespace {
double mean(const std::vector<double>& v) {
  if (v.empty()) return 0.0;
  double s = 0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}
double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}
// CPU time of the whole process (all threads), ms: unlike wall time it does not grow when
// other processes compete for the cores.
double cpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return 1000.0 * static_cast<double>(ts.tv_sec) + static_cast<double>(ts.tv_nsec) / 1e6;
}
}  // namespace

double MethodResult::msMean() const {
  return mean(ms);
}
double MethodResult::msMedian() const {
  return median(ms);
}
double MethodResult::cpuMsMean() const {
  return mean(cpu_ms);
}
double MethodResult::cpuMsMedian() const {
  return median(cpu_ms);
}

EvalResult evaluateProposals(const std::vector<VocImage>& images,
                             const std::vector<ProposalMethod*>& methods,
                             const std::vector<int>& budgets,
                             const std::function<void(int, int, const std::string&)>& progress) {
  EvalResult r;
  const int max_budget = budgets.empty() ? 0 : *std::max_element(budgets.begin(), budgets.end());
  for (auto* m : methods) {
    r.methods.emplace_back();
    r.methods.back().name = m->name();
    for (int b : budgets) r.methods.back().at[b];
  }
  for (size_t i = 0; i < images.size(); ++i) {
    const VocImage& im = images[i];
    if (progress) progress(static_cast<int>(i), static_cast<int>(images.size()), im.id);
    for (const auto& w : im.warnings) log::warn("propose", im.id + ": " + w);
    cv::Mat bgr;
    try {
      bgr = readImageFile(im.image_path, "image");
    } catch (const InputError& e) {
      log::warn("propose", "image unreadable or corrupt, skipped",
                {{"file", im.image_path}, {"why", e.what()}});
      r.skipped.push_back(im.image_path);
      continue;
    }
    std::vector<VocObject> gt;
    for (const auto& o : im.objects)
      if (!o.difficult) gt.push_back(o);
    ++r.images;
    r.objects += static_cast<int>(gt.size());
    for (size_t m = 0; m < methods.size(); ++m) {
      const int64 t0 = cv::getTickCount();
      const double c0 = cpuMs();
      const auto boxes = methods[m]->propose(bgr, max_budget);
      r.methods[m].cpu_ms.push_back(cpuMs() - c0);
      r.methods[m].ms.push_back(1000.0 * static_cast<double>(cv::getTickCount() - t0) /
                                cv::getTickFrequency());
      for (int b : budgets) r.methods[m].at[b].add(gt, boxes, b);
    }
  }
  return r;
}

}  // namespace sketchnav::landmarks
