#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>

#include "../src/matcher_internal.h"
#include "sketchnav/core/error.h"
#include "sketchnav/landmarks/matcher.h"
#include "sketchnav/landmarks/model.h"
#include "sketchnav/landmarks/recognition.h"
#include "test_data.h"
#include "test_recognition_support.h"

using namespace sketchnav;
using namespace sketchnav::landmarks;

namespace {

// A model whose class "class0" has one database photo: the flat object itself (so the true
// database -> frame homography is the one used to warp it into the frame).
class MatchFixture : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = test::tempDir("recog-match");
    std::filesystem::create_directories(root_ + "/class0");
    std::filesystem::create_directories(root_ + "/class1");
    cv::imwrite(root_ + "/class0/flat.png", test::texturedImage(320, 240, 1000));
    cv::imwrite(root_ + "/class1/flat.png", test::texturedImage(320, 240, 1001));
    ModelParams p;
    p.vocabulary_size = 50;
    model_ = new LandmarkModel(trainModel(root_, p));
  }
  static void TearDownTestSuite() { delete model_; }
  static std::string root_;
  static LandmarkModel* model_;

  // Warps the class0 photo into a 640x480 frame with H (photo -> frame).
  static cv::Mat frameWith(const cv::Mat& H) {
    cv::Mat frame(480, 640, CV_8UC3);
    cv::RNG(3).fill(frame, cv::RNG::UNIFORM, 90, 160);
    cv::GaussianBlur(frame, frame, cv::Size(0, 0), 4);
    cv::warpPerspective(test::texturedImage(320, 240, 1000), frame, H, frame.size(),
                        cv::INTER_LINEAR, cv::BORDER_TRANSPARENT);
    return frame;
  }

  static void checkRecovered(const cv::Mat& H, const MatchResult& m) {
    ASSERT_TRUE(m.matched);
    EXPECT_GE(m.inliers, 20);
    EXPECT_GT(m.confidence, 0.3f);
    EXPECT_EQ(m.database_size, cv::Size(320, 240));
    ASSERT_EQ(m.x_t.size(), m.x_d.size());
    // Every inlier pair agrees with the true warp.
    std::vector<cv::Point2f> proj;
    cv::perspectiveTransform(m.x_d, proj, H);
    for (size_t i = 0; i < proj.size(); ++i) EXPECT_LT(cv::norm(proj[i] - m.x_t[i]), 8.0);
    // The servo offset: the column of the matched part's centre in the frame (the centre of
    // the inliers' extent in the photo through the true warp; here the object fills the photo).
    const cv::Rect2f part = cv::boundingRect(m.x_d);
    std::vector<cv::Point2f> c = {{part.x + 0.5f * part.width, part.y + 0.5f * part.height}}, cf;
    EXPECT_LT(cv::norm(c[0] - cv::Point2f(160, 120)), 20.0);
    cv::perspectiveTransform(c, cf, H);
    const ServoOffset o = servoOffset(m, 640);
    ASSERT_TRUE(o.valid);
    EXPECT_NEAR(o.object_u, cf[0].x, 4.0);
    EXPECT_NEAR(o.offset_px, cf[0].x - 320, 4.0);
    EXPECT_NEAR(o.paper_offset_px, cf[0].x - 320, 15.0);
  }
};
std::string MatchFixture::root_;
LandmarkModel* MatchFixture::model_ = nullptr;

cv::Mat similarity(double angle_deg, double scale, double tx, double ty) {
  cv::Mat A = cv::getRotationMatrix2D(cv::Point2f(160, 120), angle_deg, scale);
  A.at<double>(0, 2) += tx;
  A.at<double>(1, 2) += ty;
  cv::Mat H = cv::Mat::eye(3, 3, CV_64F);
  A.copyTo(H.rowRange(0, 2));
  return H;
}

}  // namespace

TEST_F(MatchFixture, RotatedCopyRightOfCentre) {
  const cv::Mat H = similarity(30, 1.0, 300, 100);
  checkRecovered(H, match(*model_, frameWith(H), cv::Rect(), "class0", MatchParams{}));
}

TEST_F(MatchFixture, ScaledCopyLeftOfCentre) {
  const cv::Mat H = similarity(-5, 0.6, 20, 150);
  const MatchResult m = match(*model_, frameWith(H), cv::Rect(), "class0", MatchParams{});
  checkRecovered(H, m);
  EXPECT_LT(servoOffset(m, 640).offset_px, 0.f) << "object left of centre -> negative";
}

TEST_F(MatchFixture, PerspectiveWarpedCopyInAWindow) {
  const std::vector<cv::Point2f> src = {{0, 0}, {320, 0}, {320, 240}, {0, 240}};
  const std::vector<cv::Point2f> dst = {{250, 90}, {560, 130}, {540, 360}, {260, 420}};
  const cv::Mat H = cv::getPerspectiveTransform(src, dst);
  const MatchResult m =
      match(*model_, frameWith(H), cv::Rect(220, 60, 380, 400), "class0", MatchParams{});
  checkRecovered(H, m);
  EXPECT_EQ(m.window, cv::Rect(220, 60, 380, 400));
  for (const auto& p : m.x_t) EXPECT_TRUE(cv::Rect2f(220, 60, 380, 400).contains(p));
}

TEST_F(MatchFixture, WrongClassOrEmptyWindowIsNotMatched) {
  const cv::Mat H = similarity(10, 0.9, 150, 120);
  const cv::Mat frame = frameWith(H);
  const MatchResult other = match(*model_, frame, cv::Rect(), "class1", MatchParams{});
  EXPECT_FALSE(other.matched);
  EXPECT_TRUE(other.x_t.empty());
  EXPECT_FALSE(servoOffset(other, 640).valid);
  // A window away from the object holds too few keypoints: not matched, never a guess.
  const MatchResult off = match(*model_, frame, cv::Rect(0, 0, 40, 40), "class0", MatchParams{});
  EXPECT_FALSE(off.matched);
  EXPECT_THROW(match(*model_, frame, cv::Rect(), "no-such-class", MatchParams{}), InputError);
}

TEST_F(MatchFixture, MatchReusesRecognitionsVerificationOfTheSameFrame) {
  const cv::Mat H = similarity(20, 0.9, 40, 10);
  const FrameFeatures f = computeFrameFeatures(*model_, frameWith(H));
  RecognitionParams rp;
  const auto r = recognise(*model_, f, {}, 1, rp);
  ASSERT_FALSE(r.empty());
  ASSERT_FALSE(r[0].rejected);
  ASSERT_EQ(r[0].class_name, "class0");
  ASSERT_EQ(f.photo_cache->verified.size(), 1u);
  const MatchResult fresh =
      match(*model_, FrameFeatures{f.features, f.words, nullptr}, cv::Rect(), "class0", rp.match);
  const MatchResult reused = match(*model_, f, cv::Rect(), "class0", rp.match);
  checkRecovered(H, reused);
  EXPECT_EQ(reused.inliers, r[0].inliers);
  EXPECT_EQ(reused.database_photo, fresh.database_photo);
  EXPECT_EQ(reused.window, cv::Rect(0, 0, 640, 480));
  // It is the cached verification (marked here), not a new search; other verification settings
  // or another class search afresh.
  f.photo_cache->verified[0].result.inliers = 999;
  EXPECT_EQ(match(*model_, f, cv::Rect(), "class0", rp.match).inliers, 999);
  MatchParams other = rp.match;
  other.min_inliers += 1;
  EXPECT_EQ(match(*model_, f, cv::Rect(), "class0", other).inliers, fresh.inliers);
  EXPECT_FALSE(match(*model_, f, cv::Rect(), "class1", rp.match).matched);
}

TEST(ViewSynthesis, MoreInliersOnAStronglyTiltedView) {
  // One flat photo; the frame sees it at ~70 degrees off its normal (compressed 3x along x).
  const std::string root = test::tempDir("recog-synth");
  std::filesystem::create_directories(root + "/class0");
  std::filesystem::create_directories(root + "/class1");
  cv::imwrite(root + "/class0/flat.png", test::texturedImage(320, 240, 1000));
  cv::imwrite(root + "/class1/flat.png", test::texturedImage(320, 240, 1001));
  ModelParams p;
  p.vocabulary_size = 50;
  const LandmarkModel plain = trainModel(root, p);
  p.synth_views = 2;
  p.synth_tilt = 2.0;
  const LandmarkModel synth = trainModel(root, p);
  // Database keypoints of the synthesised views are in the photo's pixels.
  const auto& ph = synth.photos()[synth.photosOfClass(0)[0]];
  EXPECT_GT(ph.keypoints.size(), plain.photos()[plain.photosOfClass(0)[0]].keypoints.size());
  for (const auto& k : ph.keypoints) {
    EXPECT_GE(k.pt.x, 0);
    EXPECT_LT(k.pt.x, 320);
  }
  int plain_sum = 0, synth_sum = 0;
  for (int i = 0; i < 3; ++i) {
    cv::Mat H = (cv::Mat_<double>(3, 3) << 1.0 / 3, 0.05 * i, 260, 0.1, 1.2, 80 + 20 * i, 0, 0, 1);
    if (i == 2) H = (cv::Mat_<double>(3, 3) << 1.2, 0, 140, 0.05, 0.4, 150, 0, 0, 1);  // along y
    cv::Mat frame(480, 640, CV_8UC3);
    cv::RNG(3 + i).fill(frame, cv::RNG::UNIFORM, 90, 160);
    cv::GaussianBlur(frame, frame, cv::Size(0, 0), 4);
    cv::warpPerspective(test::texturedImage(320, 240, 1000), frame, H, frame.size(), cv::INTER_AREA,
                        cv::BORDER_TRANSPARENT);
    MatchParams mp;
    mp.min_inliers = 8;
    const MatchResult a = match(plain, frame, cv::Rect(), "class0", mp);
    const MatchResult b = match(synth, frame, cv::Rect(), "class0", mp);
    plain_sum += a.inliers;
    synth_sum += b.inliers;
    // The synthesised view's correspondences agree with the true warp.
    if (b.matched) {
      std::vector<cv::Point2f> proj;
      cv::perspectiveTransform(b.x_d, proj, H);
      int close = 0;
      for (size_t k = 0; k < proj.size(); ++k) close += cv::norm(proj[k] - b.x_t[k]) < 8.0;
      EXPECT_GE(close, static_cast<int>(0.9 * proj.size()));
    }
  }
  EXPECT_GT(synth_sum, plain_sum + plain_sum / 2 + 10);
  EXPECT_THROW(
      [] {
        ModelParams bad;
        bad.synth_views = 5;
        bad.validate();
      }(),
      InputError);
}

TEST(MatchPhotoOrder, TheSmallObjectsPhotoIsTriedFirstInAClutteredFrame) {
  // A class photographed from several sides (five different faces); the frame shows one face
  // small, in clutter, so the frame's BoW histogram is mostly background. Only one photo is
  // tried: it must be the right one, found by nearest-neighbour votes within the class.
  const std::string root = test::tempDir("recog-order");
  std::filesystem::create_directories(root + "/box");
  std::filesystem::create_directories(root + "/other");
  for (int i = 0; i < 5; ++i)
    cv::imwrite(root + "/box/side" + std::to_string(i) + ".png",
                test::texturedImage(320, 240, 2000 + i));
  cv::imwrite(root + "/other/a.png", test::texturedImage(320, 240, 2100));
  ModelParams mp;
  mp.vocabulary_size = 50;
  const LandmarkModel model = trainModel(root, mp);
  cv::Mat frame = test::texturedImage(640, 480, 2200);  // clutter everywhere
  cv::Mat small;
  cv::resize(test::texturedImage(320, 240, 2003), small, cv::Size(200, 150));
  small.copyTo(frame(cv::Rect(400, 300, 200, 150)));
  const FrameFeatures f = computeFrameFeatures(model, frame);
  const int cls = model.classId("box");
  ASSERT_GE(cls, 0);
  const auto votes = model.classPhotoVotes(cls, f.features.descriptors, 16);
  int best = -1;
  for (int p : model.photosOfClass(cls))
    if (best < 0 || votes[p] > votes[best]) best = p;
  ASSERT_GE(best, 0);
  EXPECT_EQ(model.photos()[best].path, "box/side3.png");
  MatchParams p;
  p.max_photos = 1;
  const MatchResult m = match(model, f, cv::Rect(), "box", p);
  EXPECT_TRUE(m.matched);
  EXPECT_EQ(m.database_image, "box/side3.png");
  EXPECT_EQ(m.photos_tried, 1);
  // The per-frame photo cache (filled by the whole-frame match) gives a window the same
  // answer as features without it.
  const cv::Rect win(360, 260, 260, 210);
  const MatchResult cached = match(model, f, win, "box", p);
  FrameFeatures fresh;
  fresh.features = f.features;
  fresh.words = f.words;
  const MatchResult uncached = match(model, fresh, win, "box", p);
  EXPECT_TRUE(cached.matched);
  EXPECT_EQ(cached.database_image, uncached.database_image);
  EXPECT_EQ(cached.inliers, uncached.inliers);
}

TEST(MatchParamsTest, ValidateNamesTheField) {
  MatchParams p;
  p.min_inliers = 2;
  try {
    p.validate();
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("min_inliers"), std::string::npos);
  }
}

TEST(RansacIterations, TheFewestThatFindAMinInliersModelWithTheConfidence) {
  const double conf = 0.995;
  for (int n : {12, 13, 20, 25, 40, 60}) {
    const int it = landmarks::detail::ransacIterations(n, 12, 100000, conf);
    // P(a 4-sample lies among the 12 inliers) = C(12,4) / C(n,4).
    const double q = (12.0 * 11 * 10 * 9) / (double(n) * (n - 1) * (n - 2) * (n - 3));
    EXPECT_LE(std::pow(1 - q, it), 1 - conf + 1e-12) << n;
    if (it > 1) EXPECT_GT(std::pow(1 - q, it - 1), 1 - conf) << n;
  }
  EXPECT_EQ(landmarks::detail::ransacIterations(12, 12, 1000, conf),
            1);  // every sample is an inlier one
  EXPECT_EQ(landmarks::detail::ransacIterations(60, 12, 1000, conf), 1000);  // capped
  // Fewer points than min_inliers: at most the number of distinct 4-point samples.
  EXPECT_EQ(landmarks::detail::ransacIterations(8, 12, 1000, conf), 70);
  EXPECT_EQ(landmarks::detail::ransacIterations(11, 12, 100, conf), 100);
  EXPECT_EQ(landmarks::detail::ransacIterations(3, 12, 1000, conf), 0);
}

TEST(RansacIterations, BoundedRansacStillFindsAPlantedModelOfMinInliers) {
  // 12 correspondences of one homography among 25 (13 random): the bound (133 hypotheses
  // instead of 1000) must still recover all 12 in nearly every seeded trial.
  const int n = 25, m = 12, trials = 200;
  const int it = landmarks::detail::ransacIterations(n, m, 1000, 0.995);
  ASSERT_LT(it, 200);
  const cv::Matx33d H(1.1, 0.1, 30, -0.05, 0.95, 12, 1e-4, 2e-4, 1);
  int found = 0;
  for (int t = 0; t < trials; ++t) {
    cv::RNG rng(100 + t);
    std::vector<cv::Point2f> src, dst;
    for (int i = 0; i < n; ++i) {
      const cv::Point2f a(rng.uniform(0.f, 300.f), rng.uniform(0.f, 300.f));
      src.push_back(a);
      if (i < m) {
        cv::Vec3d b = H * cv::Vec3d(a.x, a.y, 1);
        dst.emplace_back(static_cast<float>(b[0] / b[2] + rng.gaussian(0.5)),
                         static_cast<float>(b[1] / b[2] + rng.gaussian(0.5)));
      } else {
        dst.emplace_back(rng.uniform(0.f, 400.f), rng.uniform(0.f, 400.f));
      }
    }
    cv::theRNG().state = 7 + t;
    std::vector<unsigned char> mask;
    const cv::Mat Hf = cv::findHomography(src, dst, cv::RANSAC, 6, mask, it, 0.995);
    int planted = 0;
    for (int i = 0; i < m && !Hf.empty(); ++i) planted += mask[i] ? 1 : 0;
    found += planted == m ? 1 : 0;
  }
  EXPECT_GE(found, trials * 97 / 100);
}

// A photo that frames its object off-centre (here the left half; the right half is plain): the
// servo's column is the object's, not the photo centre's, which lies 80 photo px to its right.
TEST(ServoOffsetFraming, TheObjectsColumnNotThePhotosCentre) {
  const std::string root = test::tempDir("recog-framing");
  std::filesystem::create_directories(root + "/held");
  std::filesystem::create_directories(root + "/other");
  cv::Mat photo(240, 320, CV_8UC3, cv::Scalar(128, 128, 128));
  test::texturedImage(160, 240, 2000).copyTo(photo(cv::Rect(0, 0, 160, 240)));
  cv::imwrite(root + "/held/photo.png", photo);
  cv::imwrite(root + "/other/photo.png", test::texturedImage(320, 240, 2001));
  ModelParams p;
  p.vocabulary_size = 50;
  const LandmarkModel model = trainModel(root, p);
  // The photo at 1.2x, its left edge at column 150, in a 640 x 480 frame.
  const cv::Mat H = (cv::Mat_<double>(3, 3) << 1.2, 0, 150, 0, 1.2, 100, 0, 0, 1);
  cv::Mat frame(480, 640, CV_8UC3);
  cv::RNG(5).fill(frame, cv::RNG::UNIFORM, 90, 160);
  cv::GaussianBlur(frame, frame, cv::Size(0, 0), 4);
  cv::warpPerspective(photo, frame, H, frame.size(), cv::INTER_LINEAR, cv::BORDER_TRANSPARENT);
  const MatchResult m = match(model, frame, cv::Rect(), "held", MatchParams{});
  ASSERT_TRUE(m.matched);
  const ServoOffset o = servoOffset(m, 640);
  ASSERT_TRUE(o.valid);
  const double object_u = 150 + 1.2 * 80, photo_centre_u = 150 + 1.2 * 160;
  EXPECT_NEAR(o.object_u, object_u, 12.0);
  EXPECT_GT(std::abs(o.object_u - photo_centre_u), 80.0);
  EXPECT_NEAR(o.centre_u, photo_centre_u, 4.0);  // elevations still read at the photo centre
}
