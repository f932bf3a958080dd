#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <random>

#include "sketchnav/landmarks/bow.h"
#include "sketchnav/landmarks/rootsift.h"
#include "sketchnav/landmarks/vocabulary.h"
#include "test_recognition_support.h"

using namespace sketchnav::landmarks;

namespace {
cv::Mat randomSift(int rows, unsigned seed) {
  cv::Mat d(rows, 128, CV_32F);
  cv::RNG rng(seed);
  rng.fill(d, cv::RNG::UNIFORM, 0, 255);
  return d;
}
}  // namespace

TEST(RootSift, NonNegativeAndUnitL2) {
  cv::Mat d = rootSift(randomSift(50, 3));
  for (int r = 0; r < d.rows; ++r) {
    double mn, mx;
    cv::minMaxLoc(d.row(r), &mn, &mx);
    EXPECT_GE(mn, 0.0);
    EXPECT_NEAR(cv::norm(d.row(r), cv::NORM_L2), 1.0, 1e-5);
  }
}

TEST(RootSift, ZeroRowStaysZero) {
  cv::Mat d = cv::Mat::zeros(1, 128, CV_32F);
  rootSiftInPlace(d);
  EXPECT_EQ(cv::countNonZero(d), 0);
}

// Euclidean distance of RootSIFT equals the Hellinger distance of the L1-normalised SIFT:
// |√p − √q|² = 2 − 2 Σ √(p q).
TEST(RootSift, HellingerEquivalence) {
  cv::Mat a = randomSift(20, 5), b = randomSift(20, 6);
  cv::Mat ra = rootSift(a), rb = rootSift(b);
  for (int r = 0; r < a.rows; ++r) {
    const double l1a = cv::norm(a.row(r), cv::NORM_L1), l1b = cv::norm(b.row(r), cv::NORM_L1);
    double bc = 0;
    for (int c = 0; c < 128; ++c)
      bc += std::sqrt(a.at<float>(r, c) / l1a * b.at<float>(r, c) / l1b);
    const double e2 = std::pow(cv::norm(ra.row(r), rb.row(r), cv::NORM_L2), 2);
    EXPECT_NEAR(e2, 2.0 - 2.0 * bc, 1e-5);
  }
}

TEST(RootSift, ExtractedFeaturesAreRootSiftAndInImagePixels) {
  const cv::Mat img = sketchnav::test::texturedImage(800, 600, 11);
  FeatureParams p;
  p.max_image_side = 400;  // forces a ×0.5 downscale inside
  Features f = extractFeatures(img, p);
  ASSERT_GT(f.keypoints.size(), 50u);
  EXPECT_EQ(f.descriptors.rows, static_cast<int>(f.keypoints.size()));
  EXPECT_LE(static_cast<int>(f.keypoints.size()), p.max_features + 10);
  float max_x = 0;
  for (const auto& k : f.keypoints) max_x = std::max(max_x, k.pt.x);
  EXPECT_GT(max_x, 450.f) << "keypoints must be reported in input pixels";
  for (int r = 0; r < f.descriptors.rows; ++r)
    EXPECT_NEAR(cv::norm(f.descriptors.row(r)), 1.0, 1e-4);
  p.root_sift = false;
  Features g = extractFeatures(img, p);
  ASSERT_FALSE(g.descriptors.empty());
  EXPECT_GT(cv::norm(g.descriptors.row(0)), 10.0) << "plain SIFT is not normalised to 1";
}

TEST(KeypointColours, ChromaOfTheNeighbourhoodAndNothingForGrey) {
  // Left half red, right half green, same texture (grey levels) on both.
  cv::Mat img(200, 400, CV_8UC3);
  img(cv::Rect(0, 0, 200, 200)).setTo(cv::Scalar(40, 40, 200));
  img(cv::Rect(200, 0, 200, 200)).setTo(cv::Scalar(40, 160, 40));
  std::vector<cv::KeyPoint> kps = {{cv::Point2f(100, 100), 20.f},
                                   {cv::Point2f(300, 100), 20.f},
                                   {cv::Point2f(0, 0), 4.f},
                                   {cv::Point2f(399, 199), 60.f}};
  const cv::Mat c = keypointColours(img, kps);
  ASSERT_EQ(c.rows, 4);
  ASSERT_EQ(c.cols, 3);
  ASSERT_EQ(c.type(), CV_8U);
  EXPECT_GT(c.at<unsigned char>(0, 1), 128 + 40) << "red: a* > 0";
  EXPECT_LT(c.at<unsigned char>(1, 1), 128 - 40) << "green: a* < 0";
  EXPECT_GT(chromaDistance2(c.ptr<unsigned char>(0), c.ptr<unsigned char>(1)), 80.f * 80.f);
  EXPECT_EQ(chromaDistance2(c.ptr<unsigned char>(0), c.ptr<unsigned char>(2)), 0.f)
      << "a keypoint at the image corner is clamped, not out of bounds";
  // Lightness does not count: a darker red is the same chroma class.
  cv::Mat dark;
  img.convertTo(dark, -1, 0.6);
  const cv::Mat d = keypointColours(dark, kps);
  EXPECT_LT(chromaDistance2(c.ptr<unsigned char>(0), d.ptr<unsigned char>(0)), 20.f * 20.f);
  EXPECT_NE(c.at<unsigned char>(0, 0), d.at<unsigned char>(0, 0)) << "L differs";
  cv::Mat grey;
  cv::cvtColor(img, grey, cv::COLOR_BGR2GRAY);
  EXPECT_TRUE(keypointColours(grey, kps).empty());
  EXPECT_TRUE(keypointColours(img, {}).empty());
  // extractFeatures fills one colour per keypoint.
  const Features f = extractFeatures(sketchnav::test::texturedImage(320, 240, 5), FeatureParams{});
  EXPECT_EQ(f.colours.rows, static_cast<int>(f.keypoints.size()));
}

TEST(Vocabulary, SameSeedSameWords) {
  cv::Mat d = rootSift(randomSift(3000, 9));
  VocabularyParams p;
  p.size = 40;
  p.sample = 2000;
  p.iterations = 5;
  p.seed = 7;
  Vocabulary a = Vocabulary::train(d, p), b = Vocabulary::train(d, p);
  ASSERT_EQ(a.size(), 40);
  EXPECT_EQ(cv::norm(a.centres(), b.centres(), cv::NORM_INF), 0.0);
  EXPECT_EQ(a.assign(d), b.assign(d));
  p.seed = 8;
  Vocabulary c = Vocabulary::train(d, p);
  EXPECT_GT(cv::norm(a.centres(), c.centres(), cv::NORM_INF), 0.0);
}

TEST(Vocabulary, AssignsToNearestCentre) {
  cv::Mat d = rootSift(randomSift(2000, 10));
  VocabularyParams p;
  p.size = 30;
  Vocabulary v = Vocabulary::train(d, p);
  // The centres themselves map to their own word.
  const auto w = v.assign(v.centres());
  for (int i = 0; i < v.size(); ++i) EXPECT_EQ(w[i], i);
}

TEST(Vocabulary, TooFewDescriptorsIsInputError) {
  cv::Mat d = rootSift(randomSift(10, 1));
  EXPECT_THROW(Vocabulary::train(d, VocabularyParams{}), sketchnav::InputError);
}

TEST(Bow, HistogramIsUnitL2AndIdfWeighted) {
  std::vector<float> idf = {0.f, 1.f, 2.f, 1.f};
  cv::Mat h = bowHistogram({0, 0, 0, 1, 2, 2}, idf);
  EXPECT_NEAR(cv::norm(h), 1.0, 1e-6);
  EXPECT_EQ(h.at<float>(0), 0.f) << "a word in every image carries no information";
  EXPECT_GT(h.at<float>(2), h.at<float>(1));
  EXPECT_EQ(h.at<float>(3), 0.f);
}
