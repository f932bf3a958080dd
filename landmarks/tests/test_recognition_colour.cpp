// Colour-layout descriptor and its use as recognition evidence (colour_layout.h,
// RecognitionParams::score_colour / colour_rescue).
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "sketchnav/core/error.h"
#include "sketchnav/landmarks/colour_layout.h"
#include "sketchnav/landmarks/model.h"
#include "sketchnav/landmarks/recognition.h"
#include "test_data.h"
#include "test_recognition_support.h"

using namespace sketchnav;
using namespace sketchnav::landmarks;
namespace fs = std::filesystem;

namespace {

cv::Mat describe(const cv::Mat& bgr) {
  return colourLayoutDescriptor(colourThumbnail(bgr), bgr.size(), cv::Rect());
}

ModelParams tinyParams() {
  ModelParams p;
  p.vocabulary_size = 64;
  p.features.max_features = 300;
  p.kmeans_iterations = 5;
  return p;
}

// A grey-level texture tinted with one colour: the same SIFT keypoints and descriptors for
// every tint, other hues.
cv::Mat tinted(const cv::Mat& grey_texture, const cv::Scalar& tint) {
  cv::Mat g, out;
  cv::cvtColor(grey_texture, g, cv::COLOR_BGR2GRAY);
  cv::Mat g3;
  cv::cvtColor(g, g3, cv::COLOR_GRAY2BGR);
  g3.convertTo(g3, CV_32FC3, 1.0 / 255);
  cv::multiply(g3, cv::Scalar(tint[0], tint[1], tint[2]), out);
  out.convertTo(out, CV_8UC3);
  return out;
}

}  // namespace

TEST(ColourLayout, UnitNormNonNegativeAndOfTheDocumentedSize) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const cv::Mat d = describe(test::texturedImage(300, 200, seed));
    ASSERT_EQ(d.rows, 1);
    ASSERT_EQ(d.cols, kColourLayoutDims);
    ASSERT_EQ(d.type(), CV_32F);
    EXPECT_NEAR(cv::norm(d), 1.0, 1e-4);
    double lo = 0;
    cv::minMaxLoc(d, &lo);
    EXPECT_GE(lo, 0.0);
  }
  // No colour (empty thumbnail, as for a grey frame): all zero, not a made-up histogram.
  EXPECT_EQ(cv::countNonZero(colourLayoutDescriptor(cv::Mat(), cv::Size(10, 10), cv::Rect())), 0);
}

TEST(ColourLayout, InvariantToScalingTheLightButNotToTheHue) {
  const cv::Mat img = test::texturedImage(320, 240, 11);
  cv::Mat dim, shifted;
  img.convertTo(dim, CV_8UC3, 0.6);  // the same scene under 60 % of the light
  cv::Mat hsv;
  cv::cvtColor(img, hsv, cv::COLOR_BGR2HSV);
  for (auto it = hsv.begin<cv::Vec3b>(); it != hsv.end<cv::Vec3b>(); ++it)
    (*it)[0] = static_cast<uchar>(((*it)[0] + 60) % 180);  // every hue turned by 120°
  cv::cvtColor(hsv, shifted, cv::COLOR_HSV2BGR);
  const cv::Mat d = describe(img);
  const double to_dim = cv::norm(d - describe(dim));
  const double to_shifted = cv::norm(d - describe(shifted));
  EXPECT_LT(to_dim, 0.15);
  EXPECT_GT(to_shifted, 0.8);
}

TEST(ColourLayout, TheGridSeesWhereTheColoursAre) {
  // Red left / blue right against its mirror image: the same colours (whole-region part
  // equal), other layout (grid parts differ).
  cv::Mat a(120, 160, CV_8UC3, cv::Scalar(0, 0, 220));
  a(cv::Rect(80, 0, 80, 120)).setTo(cv::Scalar(220, 0, 0));
  cv::Mat b;
  cv::flip(a, b, 1);
  const cv::Mat da = describe(a), db = describe(b);
  EXPECT_NEAR(cv::norm(da.colRange(0, kColourLayoutBins) - db.colRange(0, kColourLayoutBins)), 0.0,
              1e-3);
  EXPECT_GT(cv::norm(da - db), 0.5);
}

TEST(ColourLayout, RegionIsTheTrimmedKeypointBoxOrTheFallback) {
  std::vector<cv::Point2f> pts;
  cv::RNG rng(5);
  for (int i = 0; i < 200; ++i)
    pts.emplace_back(rng.uniform(100.f, 200.f), rng.uniform(50.f, 150.f));
  pts.emplace_back(5.f, 5.f);  // a stray keypoint far away is trimmed away
  const cv::Rect r = colourRegion(pts, cv::Size(640, 480));
  EXPECT_GE(r.x, 95);
  EXPECT_LE(r.br().x, 205);
  EXPECT_GE(r.y, 45);
  EXPECT_LE(r.br().y, 155);
  EXPECT_GT(r.area(), 80 * 80);
  const std::vector<cv::Point2f> few(pts.begin(), pts.begin() + 5);
  EXPECT_EQ(colourRegion(few, cv::Size(640, 480), cv::Rect(10, 10, 50, 50)),
            cv::Rect(10, 10, 50, 50));
  EXPECT_EQ(colourRegion(few, cv::Size(640, 480)), cv::Rect(0, 0, 640, 480));
}

namespace {

// Two classes with the same texture in two colours (red, blue), and a third of other texture.
class TwinModel : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = test::tempDir("recog-twins");
    const cv::Mat tex = test::texturedImage(240, 180, 4242);
    auto writeClass = [&](const std::string& name, const cv::Mat& obj, unsigned seed) {
      fs::create_directories(root_ + "/" + name);
      for (int i = 0; i < 5; ++i)
        cv::imwrite(root_ + "/" + name + "/p" + std::to_string(i) + ".png",
                    test::randomView(obj, 320, 240, seed + i, 15));
    };
    writeClass("red", tinted(tex, {40, 40, 255}), 100);
    writeClass("blue", tinted(tex, {255, 80, 30}), 200);
    writeClass("other", test::texturedImage(240, 180, 77), 300);
    model_ = new LandmarkModel(trainModel(root_, tinyParams()));
  }
  static void TearDownTestSuite() {
    delete model_;
    model_ = nullptr;
  }
  static cv::Mat view(const std::string& cls, unsigned seed) {
    const cv::Mat tex = test::texturedImage(240, 180, 4242);
    const cv::Mat obj = cls == "red" ? tinted(tex, {40, 40, 255}) : tinted(tex, {255, 80, 30});
    return test::randomView(obj, 320, 240, seed, 15);
  }
  static std::string root_;
  static LandmarkModel* model_;
};
std::string TwinModel::root_;
LandmarkModel* TwinModel::model_ = nullptr;

}  // namespace

TEST_F(TwinModel, ColourEvidenceSeparatesClassesOfIdenticalTexture) {
  // Keypoint colours off: local features alone cannot tell the twins apart (their descriptors
  // tie, so no vote passes the ratio test between classes and both verify alike). The combined
  // score with the colour weight decides by colour; with it at 0 it cannot.
  RecognitionParams p;
  p.match.colour_tolerance = 0;
  p.combined_score = true;
  p.score_bias = 0;
  p.score_inliers = 1;
  p.score_vote_share = p.score_votes = p.score_bow = p.score_verified = 0;
  p.accept_score = -1e9;
  RecognitionParams no_colour = p;
  p.score_colour = 10;  // dominates the inlier term (ln of ~50 inliers ≈ 4)
  int right = 0, right_without = 0, colour_ranks = 0;
  for (const std::string cls : {"red", "blue"})
    for (unsigned i = 0; i < 3; ++i) {
      const cv::Mat v = view(cls, 900 + 10 * (cls == "red") + i);
      const auto r = recognise(*model_, v, {}, 3, p);
      ASSERT_FALSE(r.empty());
      right += !r[0].rejected && r[0].class_name == cls;
      const auto w = recognise(*model_, v, {}, 3, no_colour);
      ASSERT_FALSE(w.empty());
      right_without += !w[0].rejected && w[0].class_name == cls;
      // The colour classifier's own ranking, independent of the decision rule.
      float p_right = 0, p_twin = 0;
      for (const auto& c : r) {
        if (c.class_name == cls) p_right = c.colour_probability;
        if (c.class_name == (cls == "red" ? "blue" : "red")) p_twin = c.colour_probability;
      }
      colour_ranks += p_right > p_twin;
    }
  EXPECT_EQ(colour_ranks, 6);
  EXPECT_EQ(right, 6);
  EXPECT_LE(right_without, 4) << "without colour the twins tie; one side must lose";
}

TEST_F(TwinModel, ColourRescueAcceptsAVotedClassBelowMinInliersOnlyWhenColourAgrees) {
  // min_inliers out of reach: nothing verifies, so the default rule rejects; the rescue accepts
  // a class with most votes when it has some inliers and colour ranks it first. "other" has
  // its own texture, so it gets votes (the twins' votes tie away). Keypoint colours off, so the
  // votes follow the texture alone whatever the view's colours.
  const cv::Mat v = test::randomView(test::texturedImage(240, 180, 77), 320, 240, 950, 15);
  RecognitionParams p;
  p.match.colour_tolerance = 0;
  p.match.min_inliers = 1000;
  p.match.strong_inliers = 2000;
  p.colour_rescue = false;
  const auto none = recognise(*model_, v, {}, 3, p);
  ASSERT_FALSE(none.empty());
  EXPECT_TRUE(none[0].rejected);
  p.colour_rescue = true;
  p.colour_rescue_inliers = 6;
  const auto rescued = recognise(*model_, v, {}, 3, p);
  ASSERT_FALSE(rescued.empty());
  EXPECT_FALSE(rescued[0].rejected);
  EXPECT_TRUE(rescued[0].colour_rescued);
  EXPECT_FALSE(rescued[0].verified);
  EXPECT_EQ(rescued[0].class_name, "other");
  EXPECT_GE(rescued[0].inliers, p.colour_rescue_inliers);
  // The same view recoloured (red): its colour no longer says "other", so no rescue.
  const cv::Mat red = tinted(v, {40, 40, 255});
  const auto disagree = recognise(*model_, red, {}, 3, p);
  ASSERT_FALSE(disagree.empty());
  EXPECT_TRUE(disagree[0].rejected)
      << disagree[0].class_name << " colour p " << disagree[0].colour_probability;
  EXPECT_EQ(disagree[0].class_name, "other") << "still first by votes";
}

TEST_F(TwinModel, ColourClassifierSurvivesTheRoundTripAndOlderVersionsAreRefused) {
  const std::string dir = test::tempDir("recog-colour-io");
  model_->save(dir + "/m.slm");
  const LandmarkModel m = LandmarkModel::load(dir + "/m.slm");
  const LinearClassifier &a = model_->colourClassifier(), &b = m.colourClassifier();
  ASSERT_EQ(a.weights.size(), b.weights.size());
  ASSERT_EQ(a.weights.cols, kColourLayoutDims);
  ASSERT_EQ(a.classes(), static_cast<int>(m.classes().size()));
  EXPECT_EQ(cv::norm(a.weights, b.weights, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(a.weights), 0.0) << "trained, not left empty";
  EXPECT_EQ(a.rho, b.rho);
  EXPECT_EQ(a.platt_a, b.platt_a);
  EXPECT_EQ(a.platt_b, b.platt_b);
  const cv::Mat v = view("blue", 31);
  const auto ra = recognise(*model_, v, {}, 3), rb = recognise(m, v, {}, 3);
  ASSERT_EQ(ra.size(), rb.size());
  for (size_t i = 0; i < ra.size(); ++i)
    EXPECT_EQ(ra[i].colour_probability, rb[i].colour_probability);
  // A version-3 file (no colour classifier) is refused with the version named.
  ASSERT_GE(LandmarkModel::kFormatVersion, 4u);
  std::ifstream in(dir + "/m.slm", std::ios::binary);
  std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  data[8] = 3;
  std::ofstream(dir + "/v3.slm", std::ios::binary | std::ios::trunc) << data;
  try {
    LandmarkModel::load(dir + "/v3.slm");
    FAIL() << "a version 3 model was accepted";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("version 3, this build reads version " +
                       std::to_string(LandmarkModel::kFormatVersion)),
              std::string::npos)
        << msg;
    EXPECT_NE(msg.find("retrain"), std::string::npos) << msg;
  }
}

TEST(RecognitionParams, ColourRescueMustNotBeNegative) {
  RecognitionParams p;
  p.colour_rescue_inliers = -1;
  try {
    p.validate();
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("colour_rescue_inliers"), std::string::npos);
  }
}

namespace {
// `img` with a sinusoidal displacement (amplitude `amp` px): local patches (and so their SIFT
// descriptors and votes) survive, a single homography does not.
cv::Mat wavy(const cv::Mat& img, float amp, float period) {
  cv::Mat mx(img.size(), CV_32F), my(img.size(), CV_32F);
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x) {
      mx.at<float>(y, x) = x + amp * std::sin(2 * static_cast<float>(CV_PI) * y / period);
      my.at<float>(y, x) = y + amp * std::sin(2 * static_cast<float>(CV_PI) * x / period);
    }
  cv::Mat out;
  cv::remap(img, out, mx, my, cv::INTER_LINEAR, cv::BORDER_REFLECT);
  return out;
}
}  // namespace

TEST_F(TwinModel, AcrossWindowsAVerifiedClassOutranksAColourRescuedOne) {
  // Left window: a small clean view of "red" (verifies, few votes). Right window: a large,
  // wavy view of "other" (many votes, no homography): colour-rescued at best.
  const cv::Mat tex = test::texturedImage(240, 180, 4242);
  cv::Mat frame(240, 640, CV_8UC3, cv::Scalar(128, 128, 128));
  test::randomView(tinted(tex, {40, 40, 255}), 320, 240, 77, 5)
      .copyTo(frame(cv::Rect(0, 0, 320, 240)));
  wavy(test::randomView(test::texturedImage(240, 180, 77), 320, 240, 78, 5), 14, 30)
      .copyTo(frame(cv::Rect(320, 0, 320, 240)));
  const std::vector<cv::Rect> windows = {cv::Rect(0, 0, 320, 240), cv::Rect(320, 0, 320, 240)};
  const RecognitionParams p;  // defaults: colour rescue on
  ASSERT_TRUE(p.colour_rescue);
  const FrameFeatures f = computeFrameFeatures(*model_, frame);
  const auto per = recogniseWindows(*model_, f, windows, 3, p);
  ASSERT_EQ(per.size(), 2u);
  ASSERT_FALSE(per[0].empty());
  ASSERT_FALSE(per[1].empty());
  EXPECT_EQ(per[0][0].class_name, "red");
  EXPECT_TRUE(per[0][0].verified);
  EXPECT_EQ(per[1][0].class_name, "other");
  EXPECT_TRUE(per[1][0].colour_rescued);
  EXPECT_FALSE(per[1][0].rejected);
  ASSERT_GT(per[1][0].votes, per[0][0].votes) << "the rescued class must lead by votes";
  // Merged: by votes alone "other" would come first; the verified class does.
  const auto all = recognise(*model_, f, windows, 3, p);
  ASSERT_GE(all.size(), 2u);
  EXPECT_EQ(all[0].class_name, "red");
  EXPECT_TRUE(all[0].verified);
  EXPECT_EQ(all[1].class_name, "other");
  EXPECT_FALSE(all[1].rejected);
}
