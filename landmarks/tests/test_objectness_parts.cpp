// Building blocks of the objectness methods: superpixel straddling on hand-made label maps,
// fuzzy c-means and DBSCAN on synthetic clusters, the sliding-window grid, saliency.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <random>
#include <set>

#include "sketchnav/landmarks/baselines.h"
#include "sketchnav/landmarks/ccs.h"
#include "sketchnav/landmarks/scs.h"

using namespace sketchnav::landmarks;

namespace {
// 20x20 map of four 10x10 quadrant superpixels: 0 TL, 1 TR, 2 BL, 3 BR.
cv::Mat quadrants() {
  cv::Mat l(20, 20, CV_32S);
  for (int y = 0; y < 20; ++y)
    for (int x = 0; x < 20; ++x) l.at<int>(y, x) = (y >= 10) * 2 + (x >= 10);
  return l;
}
}  // namespace

TEST(ObjectnessStraddling, WindowsAlignedWithSuperpixelsScoreOne) {
  const StraddlingScorer s(quadrants());
  EXPECT_EQ(s.superpixels(), 4);
  EXPECT_DOUBLE_EQ(s.score({0, 0, 10, 10}), 1.0);    // exactly superpixel 0
  EXPECT_DOUBLE_EQ(s.score({0, 0, 20, 10}), 1.0);    // 0 and 1
  EXPECT_DOUBLE_EQ(s.score({0, 0, 20, 20}), 1.0);    // everything
  EXPECT_DOUBLE_EQ(s.score({-5, -5, 40, 40}), 1.0);  // clipped to the map
  EXPECT_DOUBLE_EQ(s.score({30, 30, 5, 5}), 0.0);    // outside: empty window
}

TEST(ObjectnessStraddling, StraddlingWindowsKnownValues) {
  const StraddlingScorer s(quadrants());
  // 10x10 window at (5,0): covers half of superpixel 0 (50 px in, 50 out) and half of 1.
  // SS = 1 − (min(50,50) + min(50,50)) / 100 = 0.
  EXPECT_NEAR(s.score({5, 0, 10, 10}), 0.0, 1e-12);
  // 12x10 at (0,0): all of 0 (min(0,100) = 0) and 20 px of 1 (min(80,20) = 20): 1 − 20/120.
  EXPECT_NEAR(s.score({0, 0, 12, 10}), 1.0 - 20.0 / 120.0, 1e-12);
  // 4x4 inside superpixel 3: min(84, 16) = 16 → SS = 1 − 16/16 = 0.
  EXPECT_NEAR(s.score({12, 12, 4, 4}), 0.0, 1e-12);
  // Irregular map: superpixel 1 is a 3x3 blob in a sea of 0 (10x10). Window = the blob.
  cv::Mat l(10, 10, CV_32S, cv::Scalar(0));
  l(cv::Rect(3, 3, 3, 3)).setTo(1);
  const StraddlingScorer s2(l);
  // Window covers blob (9 px of 1) and 0 px... of sp 0 inside: 0 → SS = 1.
  EXPECT_NEAR(s2.score({3, 3, 3, 3}), 1.0, 1e-12);
  // 5x5 around the blob: 16 px of sp 0 inside (min(16, 75) = 16), blob whole → 1 − 16/25.
  EXPECT_NEAR(s2.score({2, 2, 5, 5}), 1.0 - 16.0 / 25.0, 1e-12);
}

TEST(ObjectnessFcm, RecoversThreeSyntheticClusters) {
  std::mt19937 rng(3);
  std::normal_distribution<float> noise(0.f, 0.5f);
  const cv::Point2f centres[3] = {{0, 0}, {10, 0}, {0, 10}};
  cv::Mat pts(300, 2, CV_32F);
  for (int i = 0; i < 300; ++i) {
    pts.at<float>(i, 0) = centres[i % 3].x + noise(rng);
    pts.at<float>(i, 1) = centres[i % 3].y + noise(rng);
  }
  const FcmResult r = fcm(pts, 3, 2.0, 100, 1);
  ASSERT_EQ(r.centers.rows, 3);
  // Every true centre has an FCM centre within 0.3.
  for (const auto& c : centres) {
    double best = 1e9;
    for (int k = 0; k < 3; ++k)
      best = std::min<double>(
          best, std::hypot(r.centers.at<float>(k, 0) - c.x, r.centers.at<float>(k, 1) - c.y));
    EXPECT_LT(best, 0.3);
  }
  // Points of one true cluster share a label, and the three labels differ.
  std::set<int> labels;
  for (int t = 0; t < 3; ++t) {
    for (int i = t; i < 300; i += 3) EXPECT_EQ(r.labels[i], r.labels[t]);
    labels.insert(r.labels[t]);
  }
  EXPECT_EQ(labels.size(), 3u);
  // Memberships are a partition of unity and confident here.
  for (int i = 0; i < 300; ++i) {
    EXPECT_NEAR(cv::sum(r.membership.row(i))[0], 1.0, 1e-4);
    EXPECT_GT(r.membership.at<float>(i, r.labels[i]), 0.9f);
  }
}

TEST(ObjectnessFcm, DegenerateInputs) {
  EXPECT_TRUE(fcm(cv::Mat(0, 3, CV_32F), 4, 2.0, 10, 1).labels.empty());
  cv::Mat two = (cv::Mat_<float>(2, 1) << 0.f, 1.f);
  const FcmResult r = fcm(two, 5, 2.0, 10, 1);  // c clamped to n
  EXPECT_EQ(r.centers.rows, 2);
  EXPECT_NE(r.labels[0], r.labels[1]);
}

TEST(ObjectnessDbscan, ClustersAlongAdjacencyAndKeepsNoiseApart) {
  // A chain 0-1-2-3-4: 0..2 similar, 3 far, 4 similar to 0..2 but only reachable through 3.
  cv::Mat f = (cv::Mat_<float>(5, 1) << 0.f, 1.f, 2.f, 50.f, 2.5f);
  const std::vector<std::vector<int>> adj = {{1}, {0, 2}, {1, 3}, {2, 4}, {3}};
  const auto l = dbscan(f, adj, 1.5, 2);
  EXPECT_EQ(l[0], l[1]);
  EXPECT_EQ(l[1], l[2]);
  EXPECT_NE(l[3], l[0]);
  EXPECT_NE(l[4], l[0]);  // similar colour, but not connected through similar neighbours
  EXPECT_NE(l[4], l[3]);
}

TEST(ObjectnessGrid, CoversImageLargestFirst) {
  const auto g = slidingWindowGrid({200, 100}, 100);
  ASSERT_EQ(g.size(), 100u);
  EXPECT_EQ(g[0], cv::Rect(0, 0, 200, 100));
  const cv::Rect img(0, 0, 200, 100);
  for (size_t i = 0; i < g.size(); ++i) {
    EXPECT_EQ(g[i] & img, g[i]);
    if (i) EXPECT_LE(g[i].area(), g[0].area());
  }
  EXPECT_TRUE(slidingWindowGrid({0, 0}, 10).empty());
}

TEST(ObjectnessSaliency, PatchOnPlainBackgroundIsSalient) {
  cv::Mat img(120, 160, CV_8UC3, cv::Scalar(200, 200, 200));
  cv::rectangle(img, cv::Rect(60, 40, 30, 30), cv::Scalar(0, 0, 255), cv::FILLED);
  const cv::Mat s = centreSurroundSaliency(img);
  ASSERT_EQ(s.size(), img.size());
  EXPECT_GT(cv::mean(s(cv::Rect(65, 45, 20, 20)))[0], 3 * cv::mean(s(cv::Rect(0, 0, 30, 30)))[0]);
}
