// PercentileAccumulator: nearest-rank percentiles of known data (1..100 shuffled, a small set
// where the ranks round up, a constant), empty and one-sample cases, and non-finite values
// left out.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

#include "sketchnav/core/percentiles.h"

using sketchnav::PercentileAccumulator;

TEST(Percentiles, NearestRankOfOneToAHundredInAnyOrder) {
  std::vector<double> v;
  for (int i = 1; i <= 100; ++i) v.push_back(i);
  std::mt19937 rng(7);
  std::shuffle(v.begin(), v.end(), rng);
  PercentileAccumulator a;
  for (double x : v) a.add(x);
  const auto s = a.summary();
  EXPECT_EQ(s.n, 100u);
  EXPECT_EQ(s.p50, 50);
  EXPECT_EQ(s.p95, 95);
  EXPECT_EQ(s.p99, 99);
  EXPECT_EQ(s.max, 100);
  EXPECT_EQ(a.quantile(0), 1);
  EXPECT_EQ(a.quantile(0.01), 1);
  EXPECT_EQ(a.quantile(0.011), 2);
  EXPECT_EQ(a.quantile(1), 100);
}

TEST(Percentiles, RanksRoundUpOnASmallSet) {
  // 10 samples: p50 is the 5th, p95 and p99 the 10th (ceil(9.5), ceil(9.9)).
  PercentileAccumulator a;
  for (double x : {9.0, 1.5, 3.0, 7.0, 2.0, 8.0, 4.0, 10.0, 5.0, 6.0}) a.add(x);
  const auto s = a.summary();
  EXPECT_EQ(s.n, 10u);
  EXPECT_EQ(s.p50, 5);
  EXPECT_EQ(s.p95, 10);
  EXPECT_EQ(s.p99, 10);
  EXPECT_EQ(s.max, 10);
  EXPECT_EQ(a.quantile(0.2), 2);   // rank 2
  EXPECT_EQ(a.quantile(0.21), 3);  // rank ceil(2.1) = 3
}

TEST(Percentiles, EmptyGivesNullFiguresAndOneSampleIsEveryPercentile) {
  PercentileAccumulator a;
  const auto e = a.summary();
  EXPECT_EQ(e.n, 0u);
  EXPECT_TRUE(std::isnan(e.p50) && std::isnan(e.max));
  EXPECT_TRUE(std::isnan(a.quantile(0.5)));
  const auto j = e.toJson();
  EXPECT_EQ(j["n"], 0);
  EXPECT_TRUE(j["p50"].is_null() && j["p95"].is_null() && j["p99"].is_null() && j["max"].is_null());

  a.add(42.5);
  const auto s = a.summary();
  EXPECT_EQ(s.n, 1u);
  EXPECT_EQ(s.p50, 42.5);
  EXPECT_EQ(s.p99, 42.5);
  EXPECT_EQ(s.max, 42.5);
  EXPECT_EQ(s.toJson()["p95"], 42.5);
}

TEST(Percentiles, NonFiniteValuesAreLeftOut) {
  PercentileAccumulator a;
  a.add(NAN);
  a.add(INFINITY);
  a.add(3);
  a.add(1);
  a.add(-INFINITY);
  a.add(2);
  EXPECT_EQ(a.count(), 3u);
  EXPECT_EQ(a.summary().p50, 2);
  EXPECT_EQ(a.summary().max, 3);
  EXPECT_EQ(a.mean(), 2);
  EXPECT_EQ(a.max(), 3);
}

TEST(Percentiles, MeanAndMaxAreRunningAndNaNWhenEmpty) {
  PercentileAccumulator a;
  EXPECT_TRUE(std::isnan(a.mean()) && std::isnan(a.max()));
  a.add(-4);
  EXPECT_EQ(a.max(), -4);  // a negative sample is the largest when it is the only one
  a.add(10);
  a.add(0.5);
  EXPECT_DOUBLE_EQ(a.mean(), 6.5 / 3);
  EXPECT_EQ(a.max(), 10);
  a.clear();
  EXPECT_TRUE(std::isnan(a.mean()) && std::isnan(a.max()));
  a.add(1);
  EXPECT_EQ(a.max(), 1);
}

TEST(Percentiles, AQuantileOutsideZeroToOneIsRejected) {
  PercentileAccumulator a;
  a.add(1);
  EXPECT_THROW(a.quantile(-0.1), std::invalid_argument);
  EXPECT_THROW(a.quantile(1.5), std::invalid_argument);
  EXPECT_THROW(a.quantile(NAN), std::invalid_argument);
}

TEST(Percentiles, SummaryDoesNotDisturbLaterAdds) {
  // summary() sorts a copy: samples added after it still count, in any order.
  PercentileAccumulator a;
  for (double x : {5.0, 4.0, 3.0}) a.add(x);
  EXPECT_EQ(a.summary().max, 5);
  a.add(10);
  a.add(0);
  const auto s = a.summary();
  EXPECT_EQ(s.n, 5u);
  EXPECT_EQ(s.p50, 4);  // 0 3 4 5 10: rank ceil(2.5) = 3
  EXPECT_EQ(s.max, 10);
}
