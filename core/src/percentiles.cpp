#include "sketchnav/core/percentiles.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace sketchnav {

namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
}

void PercentileAccumulator::add(double x) {
  if (!std::isfinite(x)) return;
  samples_.push_back(x);
  sum_ += x;
  max_ = std::max(max_, x);
}

double PercentileAccumulator::mean() const {
  return samples_.empty() ? kNaN : sum_ / static_cast<double>(samples_.size());
}

double PercentileAccumulator::max() const {
  return samples_.empty() ? kNaN : max_;
}

double nearestRankQuantile(const std::vector<double>& sorted, double q) {
  if (!(q >= 0 && q <= 1)) throw std::invalid_argument("quantile: q must be in [0, 1]");
  if (sorted.empty()) return kNaN;
  // Rank ceil(q n), 1-based; the small epsilon keeps q n that is an integer in floating point
  // (0.95 * 100 = 95.00000000000001) from rounding up a rank.
  const double r = std::ceil(q * static_cast<double>(sorted.size()) - 1e-9);
  const std::size_t rank = std::max<std::size_t>(1, static_cast<std::size_t>(r));
  return sorted[std::min(sorted.size(), rank) - 1];
}

PercentileAccumulator::Summary::Summary() : p50(kNaN), p95(kNaN), p99(kNaN), max(kNaN) {}

nlohmann::json PercentileAccumulator::Summary::toJson() const {
  auto num = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
  return {{"n", n}, {"p50", num(p50)}, {"p95", num(p95)}, {"p99", num(p99)}, {"max", num(max)}};
}

PercentileAccumulator::Summary PercentileAccumulator::summary() const {
  Summary s;
  s.n = samples_.size();
  if (samples_.empty()) return s;
  std::vector<double> v = samples_;
  std::sort(v.begin(), v.end());
  s.p50 = nearestRankQuantile(v, 0.50);
  s.p95 = nearestRankQuantile(v, 0.95);
  s.p99 = nearestRankQuantile(v, 0.99);
  s.max = v.back();
  return s;
}

double PercentileAccumulator::quantile(double q) const {
  std::vector<double> v = samples_;
  std::sort(v.begin(), v.end());
  return nearestRankQuantile(v, q);
}

}  // namespace sketchnav
