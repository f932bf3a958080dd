// The baselines' own parts: the order Selective Search's list is read in, and the Sobel edge
// map EdgeBoxes is fed with.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <filesystem>
#include <numeric>

#include "sketchnav/landmarks/baselines.h"
#include "sketchnav/landmarks/voc.h"
#include "test_data.h"

using namespace sketchnav::landmarks;

namespace {

std::vector<cv::Rect> numbered(int n) {
  std::vector<cv::Rect> r;
  for (int i = 0; i < n; ++i) r.emplace_back(i, 0, 1, 1);
  return r;
}

}  // namespace

TEST(SelectiveSearchOrder, ReversedReadsTheListBackwards) {
  const auto r = orderSelectiveSearch(numbered(5), SsOrder::Reversed);
  ASSERT_EQ(r.size(), 5u);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(r[i].x, 4 - i);
  const auto a = orderSelectiveSearch(numbered(5), SsOrder::AsReturned);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(a[i].x, i);
}

TEST(SelectiveSearchOrder, RandomIsASeededPermutation) {
  const auto r1 = orderSelectiveSearch(numbered(200), SsOrder::Random);
  const auto r2 = orderSelectiveSearch(numbered(200), SsOrder::Random);
  ASSERT_EQ(r1.size(), 200u);
  std::vector<int> xs;
  int moved = 0;
  for (size_t i = 0; i < r1.size(); ++i) {
    xs.push_back(r1[i].x);
    EXPECT_EQ(r1[i], r2[i]);
    moved += r1[i].x != static_cast<int>(i);
  }
  std::sort(xs.begin(), xs.end());
  for (int i = 0; i < 200; ++i) EXPECT_EQ(xs[i], i);
  EXPECT_GT(moved, 150);
}

TEST(SelectiveSearchOrder, DefaultBaselineIsReversedAndSharesOneRun) {
  // Textured blobs on a plain background so Selective Search has something to group.
  cv::Mat img(120, 160, CV_8UC3, cv::Scalar(200, 200, 200));
  cv::rectangle(img, cv::Rect(20, 20, 40, 50), cv::Scalar(20, 40, 200), cv::FILLED);
  cv::circle(img, {115, 70}, 25, cv::Scalar(200, 60, 10), cv::FILLED);
  auto run = makeSelectiveSearchRun();
  auto best = makeSelectiveSearchFast(SsOrder::Reversed, run);
  auto raw = makeSelectiveSearchFast(SsOrder::AsReturned, run);
  EXPECT_EQ(best->name(), "selective-search");
  EXPECT_EQ(makeSelectiveSearchFast()->name(), "selective-search");
  EXPECT_EQ(raw->name(), "selective-search-as-returned");
  const auto a = raw->propose(img, 100000);
  const auto b = best->propose(img, 100000);
  ASSERT_GT(a.size(), 3u);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_TRUE(std::equal(a.begin(), a.end(), b.rbegin()));
}

TEST(SelectiveSearchOrder, ReversedRanksBetterOnRealPhotos) {
  const std::string data = sketchnav::test::dataDir();
  if (data.empty() || !std::filesystem::is_directory(data + "/raccoon"))
    GTEST_SKIP() << "shared data (raccoon) not available";
  auto images = readVocDataset(data + "/raccoon");
  images.resize(std::min<size_t>(images.size(), 2));  // SS costs ~1-2 s per photo
  auto run = makeSelectiveSearchRun();
  auto best = makeSelectiveSearchFast(SsOrder::Reversed, run);
  auto raw = makeSelectiveSearchFast(SsOrder::AsReturned, run);
  const EvalResult r = evaluateProposals(images, {best.get(), raw.get()}, {10}, nullptr);
  ASSERT_EQ(r.methods.size(), 2u);
  EXPECT_GT(r.methods[0].at.at(10).recall(0.5), r.methods[1].at.at(10).recall(0.5));
}

TEST(SobelEdges, AStepGivesAOnePixelEdgeAcrossIt) {
  cv::Mat img(40, 60, CV_8UC3, cv::Scalar(30, 30, 30));
  img(cv::Rect(30, 0, 30, 40)).setTo(cv::Scalar(220, 220, 220));  // vertical step at x = 30
  cv::Mat mag, orient;
  sobelEdges(img, mag, orient);
  ASSERT_EQ(mag.type(), CV_32F);
  ASSERT_EQ(orient.type(), CV_32F);
  ASSERT_EQ(mag.size(), img.size());
  for (int y = 2; y < 38; ++y) {
    int on = 0, at = -1;
    for (int x = 0; x < 60; ++x)
      if (mag.at<float>(y, x) > 0) {
        ++on;
        at = x;
      }
    EXPECT_EQ(on, 1) << "row " << y;
    EXPECT_TRUE(at == 29 || at == 30) << "row " << y << " edge at x = " << at;
    if (at >= 0) {
      EXPECT_NEAR(mag.at<float>(y, at), 1.f, 1e-5);
      // Gradient along +x: orientation 0 (mod π).
      const float a = orient.at<float>(y, at);
      EXPECT_TRUE(a < 0.05f || a > CV_PI - 0.05f) << a;
    }
  }
}

TEST(SobelEdges, FlatImageHasNoEdgesAndOrientationIsModPi) {
  cv::Mat flat(30, 30, CV_8UC3, cv::Scalar(90, 90, 90));
  cv::Mat mag, orient;
  sobelEdges(flat, mag, orient);
  EXPECT_EQ(cv::countNonZero(mag), 0);
  cv::Mat disc(64, 64, CV_8UC3, cv::Scalar(0, 0, 0));
  cv::circle(disc, {32, 32}, 20, cv::Scalar(255, 255, 255), cv::FILLED);
  sobelEdges(disc, mag, orient);
  double lo = 0, hi = 0;
  cv::minMaxLoc(orient, &lo, &hi);
  EXPECT_GE(lo, 0.0);
  EXPECT_LT(hi, CV_PI);
  EXPECT_GT(cv::countNonZero(mag), 60);   // the circle's outline, ~2π·20 px
  EXPECT_LT(cv::countNonZero(mag), 200);  // thin, not a band
}
