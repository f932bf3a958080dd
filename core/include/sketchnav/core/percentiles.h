#pragma once
// A sample accumulator for latency and duration statistics: add() values as they come, then
// read nearest-rank percentiles. Used for the control loop's latency budget (the executive's
// grab-to-command latency and perception stage times, summary.json "timing").
#include <nlohmann/json.hpp>

#include <cstddef>
#include <limits>
#include <vector>

namespace sketchnav {

/// Percentiles of the values added so far. Keeps every sample (8 bytes each: a 900 s run at
/// 30 Hz is ~27,000 of them); add() is an amortised O(1) push with no lock, so it may sit in a
/// control loop. Thread-compatible (one writer, no concurrent readers).
class PercentileAccumulator {
 public:
  /// Expected number of samples (optional): avoids reallocations in the loop.
  void reserve(std::size_t n) { samples_.reserve(n); }
  /// A NaN or infinite value is ignored (it has no rank).
  void add(double x);
  std::size_t count() const { return samples_.size(); }
  bool empty() const { return samples_.empty(); }
  void clear() {
    samples_.clear();
    sum_ = 0;
    max_ = -std::numeric_limits<double>::infinity();
  }
  /// Mean and largest of the samples, O(1); NaN when empty.
  double mean() const;
  double max() const;

  /// The percentiles reported: nearest rank over the samples so far; all NaN when n == 0.
  struct Summary {
    std::size_t n = 0;
    double p50, p95, p99, max;
    Summary();
    /// {"n", "p50", "p95", "p99", "max"}; the figures are null when n == 0.
    nlohmann::json toJson() const;
  };
  /// Sorts a copy of the samples: O(n log n), for the end of a run, not every tick.
  Summary summary() const;
  /// Nearest-rank quantile, q in [0, 1]: the smallest sample with at least q * n samples at or
  /// below it (q = 0: the minimum); NaN when empty. Throws std::invalid_argument for q
  /// outside [0, 1].
  double quantile(double q) const;

 private:
  std::vector<double> samples_;
  double sum_ = 0;
  double max_ = -std::numeric_limits<double>::infinity();
};

/// The nearest-rank quantile of `sorted` (ascending), as PercentileAccumulator::quantile.
double nearestRankQuantile(const std::vector<double>& sorted, double q);

}  // namespace sketchnav
