#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include <opencv2/imgproc.hpp>

#include "sketchnav/core/error.h"
#include "sketchnav/landmarks/landmark_set.h"
#include "sketchnav/landmarks/model.h"
#include "sketchnav/landmarks/recognition.h"
#include "test_data.h"
#include "test_recognition_support.h"

using namespace sketchnav;
using namespace sketchnav::landmarks;
namespace fs = std::filesystem;

namespace {

ModelParams tinyParams() {
  ModelParams p;
  p.vocabulary_size = 64;
  p.features.max_features = 300;
  p.kmeans_iterations = 5;
  return p;
}

std::string readAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void writeAll(const std::string& path, const std::string& data) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << data;
}

// One small model shared by the tests of this file (training takes about a second).
class TinyModel : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    root_ = test::tempDir("recog-tiny");
    test::writeLandmarkSet(root_, 3, 4, 7);
    model_ = new LandmarkModel(trainModel(root_, tinyParams()));
  }
  static void TearDownTestSuite() {
    delete model_;
    model_ = nullptr;
  }
  static std::string root_;
  static LandmarkModel* model_;
};
std::string TinyModel::root_;
LandmarkModel* TinyModel::model_ = nullptr;

// class0's object in the left half of a 640 x 240 frame, class2's in the right half.
cv::Mat twoObjects() {
  cv::Mat frame(240, 640, CV_8UC3, cv::Scalar(128, 128, 128));
  test::randomView(test::texturedImage(240, 180, 1000), 320, 240, 8001, 5)
      .copyTo(frame(cv::Rect(0, 0, 320, 240)));
  test::randomView(test::texturedImage(240, 180, 1002), 320, 240, 8002, 5)
      .copyTo(frame(cv::Rect(320, 0, 320, 240)));
  return frame;
}

}  // namespace

TEST(LandmarkSet, LeafFoldersAreClassesAndJunkIsSkipped) {
  const std::string root = test::tempDir("recog-scan");
  fs::create_directories(root + "/Juice/Bravo-Apple-Juice");
  fs::create_directories(root + "/Milk/Arla");
  fs::create_directories(root + "/Empty");
  cv::imwrite(root + "/Juice/Bravo-Apple-Juice/a.jpg", test::texturedImage(64, 64, 1));
  cv::imwrite(root + "/Milk/Arla/b.PNG", test::texturedImage(64, 64, 2));
  writeAll(root + "/Milk/Arla/notes.txt", "not a photo");
  writeAll(root + "/Milk/stray.jpg", "x");
  const LandmarkSet set = scanLandmarkSet(root);
  ASSERT_EQ(set.classes.size(), 2u);
  EXPECT_EQ(set.classes[0].name, "Arla");
  EXPECT_EQ(set.classes[1].name, "Bravo-Apple-Juice");
  EXPECT_EQ(set.classes[0].photos.size(), 1u);
  EXPECT_EQ(set.skipped.size(), 3u);  // notes.txt, stray.jpg outside a leaf, Empty/
  EXPECT_EQ(classOfImage(root + "/Juice/Bravo-Apple-Juice/a.jpg"), "Bravo-Apple-Juice");
}

TEST(LandmarkSet, MissingOrEmptyFolderIsInputErrorNamingIt) {
  const std::string root = test::tempDir("recog-empty");
  fs::create_directories(root + "/A");
  try {
    scanLandmarkSet(root);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(root), std::string::npos) << e.what();
  }
  EXPECT_THROW(scanLandmarkSet(root + "/nope"), InputError);
}

TEST(Train, CorruptPhotosAndEmptyClassesAreSkipped) {
  const std::string root = test::tempDir("recog-corrupt");
  test::writeLandmarkSet(root, 2, 2, 3);
  fs::create_directories(root + "/group/onlyjunk");
  writeAll(root + "/group/onlyjunk/broken.jpg", "\xff\xd8\xff\xe0 truncated jpeg");
  writeAll(root + "/group/class0/broken.jpg", "\xff\xd8\xff garbage");
  // A "very large" photo: downscaled before SIFT, keypoints reported in its own pixels.
  const cv::Mat big = test::randomView(test::texturedImage(240, 180, 1000), 3000, 2200, 5, 10);
  cv::imwrite(root + "/group/class0/big.jpg", big);
  const LandmarkModel m = trainModel(root, tinyParams());
  EXPECT_EQ(m.classes(), (std::vector<std::string>{"class0", "class1"}));
  EXPECT_EQ(m.photos().size(), 5u);  // 2 + 2 + big
  bool big_seen = false;
  for (const auto& ph : m.photos()) {
    if (ph.path.find("big.jpg") == std::string::npos) continue;
    big_seen = true;
    EXPECT_EQ(ph.size, cv::Size(3000, 2200));
    float max_x = 0;
    for (const auto& k : ph.keypoints) max_x = std::max(max_x, k.pt.x);
    EXPECT_GT(max_x, 1500.f);
  }
  EXPECT_TRUE(big_seen);
}

TEST(Train, SingleClassWithOnePhotoWorks) {
  const std::string root = test::tempDir("recog-single");
  test::writeLandmarkSet(root, 1, 1, 11);
  const LandmarkModel m = trainModel(root, tinyParams());
  ASSERT_EQ(m.classes().size(), 1u);
  // A new view of the object is recognised (verification decides; the SVM cannot).
  const cv::Mat view = test::randomView(test::texturedImage(240, 180, 1000), 320, 240, 99, 15);
  const auto r = recognise(m, view, {}, 1);
  ASSERT_FALSE(r.empty());
  EXPECT_FALSE(r[0].rejected);
  EXPECT_EQ(r[0].class_name, "class0");
  // An unrelated image is not.
  const auto u = recognise(m, test::texturedImage(320, 240, 4242), {}, 1);
  ASSERT_FALSE(u.empty());
  EXPECT_TRUE(u[0].rejected);
}

TEST(Train, NoUsablePhotoIsInputError) {
  const std::string root = test::tempDir("recog-nophoto");
  fs::create_directories(root + "/A");
  writeAll(root + "/A/x.jpg", "not a jpeg");
  EXPECT_THROW(trainModel(root, tinyParams()), InputError);
}

TEST_F(TinyModel, RecognisesHeldOutViewsAndRejectsUnknownObjects) {
  int correct = 0;
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < 3; ++i) {
      const cv::Mat view = test::randomView(test::texturedImage(240, 180, 1000 + k), 320, 240,
                                            5000 + 10 * k + i, 20);
      const auto r = recognise(*model_, view, {}, 3);
      ASSERT_FALSE(r.empty());
      correct += !r[0].rejected && r[0].class_name == "class" + std::to_string(k);
    }
  EXPECT_GE(correct, 8) << "of 9 held-out views";
  int rejected = 0;
  for (int i = 0; i < 3; ++i) {
    const cv::Mat unknown =
        test::randomView(test::texturedImage(240, 180, 7777 + i), 320, 240, 6000 + i, 20);
    const auto r = recognise(*model_, unknown, {}, 3);
    rejected += r.empty() || r[0].rejected;
  }
  EXPECT_EQ(rejected, 3);
}

TEST_F(TinyModel, CombinedScoreRanksByAllEvidenceAndRejectsBelowTheThreshold) {
  RecognitionParams p;
  p.combined_score = true;
  int correct = 0;
  for (int k = 0; k < 3; ++k)
    for (int i = 0; i < 3; ++i) {
      const cv::Mat view = test::randomView(test::texturedImage(240, 180, 1000 + k), 320, 240,
                                            5000 + 10 * k + i, 20);
      const auto r = recognise(*model_, view, {}, 3, p);
      ASSERT_GE(r.size(), 2u);
      correct += !r[0].rejected && r[0].class_name == "class" + std::to_string(k);
      // Best first by the combined score, which is what the evidence fields give.
      EXPECT_GE(r[0].evidence, r[1].evidence);
      EXPECT_NEAR(
          r[0].evidence,
          p.combinedScore(
              r[0].inliers, r[0].votes,
              r[0].vote_share > 0 ? static_cast<int>(std::lround(r[0].votes / r[0].vote_share)) : 0,
              r[0].bow_probability, r[0].verified),
          1e-3);
      EXPECT_TRUE(r[1].rejected);  // only the best candidate can be the answer
    }
  EXPECT_GE(correct, 8) << "of 9 held-out views";
  // Unknown objects score low; a threshold between them and the known views rejects them all,
  // and a threshold below everything accepts them (so the threshold is what decides).
  RecognitionParams lax = p;
  lax.accept_score = -1e9;
  p.accept_score = 3;  // known views score 7-8 here, unknown objects about 0
  for (int i = 0; i < 3; ++i) {
    const cv::Mat unknown =
        test::randomView(test::texturedImage(240, 180, 7777 + i), 320, 240, 6000 + i, 20);
    const auto r = recognise(*model_, unknown, {}, 3, p);
    ASSERT_FALSE(r.empty());
    EXPECT_TRUE(r[0].rejected) << "evidence " << r[0].evidence;
    EXPECT_FALSE(recognise(*model_, unknown, {}, 3, lax)[0].rejected);
  }
}

TEST_F(TinyModel, InlierEvidenceIsReportedBelowMinInliers) {
  // An unknown object: candidates are not verified, but the inliers found are still reported
  // (the combined score uses them), and 'verified' is what says they are too few.
  const cv::Mat unknown = test::randomView(test::texturedImage(240, 180, 7777), 320, 240, 6000, 20);
  RecognitionParams p;
  p.max_verified_photos = 0;
  const auto r = recognise(*model_, unknown, {}, 3, p);
  ASSERT_FALSE(r.empty());
  for (const auto& c : r) {
    EXPECT_FALSE(c.verified);
    EXPECT_LT(c.inliers, p.match.min_inliers);
  }
  // A known view: the answer is verified with at least min_inliers.
  const cv::Mat view = test::randomView(test::texturedImage(240, 180, 1001), 320, 240, 5011, 20);
  const auto k = recognise(*model_, view, {}, 3, p);
  ASSERT_FALSE(k.empty());
  EXPECT_TRUE(k[0].verified);
  EXPECT_GE(k[0].inliers, p.match.min_inliers);
}

TEST_F(TinyModel, WindowsRestrictTheSearch) {
  // Two objects side by side; each window recognises its own.
  const FrameFeatures f = computeFrameFeatures(*model_, twoObjects());
  const auto per = recogniseWindows(
      *model_, f, {cv::Rect(0, 0, 320, 240), cv::Rect(320, 0, 320, 240)}, 1, RecognitionParams{});
  ASSERT_EQ(per.size(), 2u);
  ASSERT_FALSE(per[0].empty());
  ASSERT_FALSE(per[1].empty());
  EXPECT_EQ(per[0][0].class_name, "class0");
  EXPECT_EQ(per[1][0].class_name, "class2");
  EXPECT_FALSE(per[0][0].rejected);
  EXPECT_EQ(per[1][0].window, cv::Rect(320, 0, 320, 240));
}

// Per keypoint, the class it votes for: over each object's half of the frame mostly that
// object's class and hardly ever the other's, and the same counts as recogniseWindows' votes.
TEST_F(TinyModel, KeypointVotesSayWhichObjectEachKeypointBelongsTo) {
  const FrameFeatures f = computeFrameFeatures(*model_, twoObjects());
  const RecognitionParams p;
  const std::vector<int> votes = keypointVotes(*model_, f, p);
  ASSERT_EQ(votes.size(), f.features.keypoints.size());
  const int c0 = model_->classId("class0"), c2 = model_->classId("class2");
  int left[2] = {0, 0}, right[2] = {0, 0};  // votes for class0, class2
  for (size_t i = 0; i < votes.size(); ++i) {
    int* side = f.features.keypoints[i].pt.x < 320 ? left : right;
    side[0] += votes[i] == c0;
    side[1] += votes[i] == c2;
  }
  EXPECT_GE(left[0], 10);
  EXPECT_GE(right[1], 10);
  EXPECT_LE(left[1], left[0] / 5);
  EXPECT_LE(right[0], right[1] / 5);
  // The whole frame's recognition counts the same votes.
  const auto whole = recogniseWindows(*model_, f, {}, 3, p);
  ASSERT_FALSE(whole.empty());
  for (const auto& r : whole[0]) {
    const int c = model_->classId(r.class_name);
    EXPECT_EQ(r.votes, static_cast<int>(std::count(votes.begin(), votes.end(), c))) << r.class_name;
  }
}

TEST_F(TinyModel, SaveLoadRoundTripGivesTheSameAnswers) {
  const std::string path = test::tempDir("recog-io") + "/m.slm";
  model_->save(path);
  const LandmarkModel m = LandmarkModel::load(path);
  EXPECT_EQ(m.classes(), model_->classes());
  EXPECT_EQ(m.photos().size(), model_->photos().size());
  EXPECT_EQ(m.vocabulary().size(), model_->vocabulary().size());
  EXPECT_EQ(m.sourceFingerprint(), model_->sourceFingerprint());
  const cv::Mat view = test::randomView(test::texturedImage(240, 180, 1001), 320, 240, 31, 10);
  const auto a = recognise(*model_, view, {}, 3), b = recognise(m, view, {}, 3);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].class_name, b[i].class_name);
    EXPECT_EQ(a[i].inliers, b[i].inliers);
  }
}

TEST_F(TinyModel, TruncatedCorruptOrForeignFilesAreInputErrorsNamingTheFile) {
  const std::string dir = test::tempDir("recog-bad");
  const std::string good = dir + "/good.slm";
  model_->save(good);
  const std::string data = readAll(good);
  auto expectInputError = [&](const std::string& path, const std::string& what) {
    try {
      LandmarkModel::load(path);
      FAIL() << "expected InputError for " << what;
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(path), std::string::npos) << msg;
      EXPECT_NE(msg.find(what), std::string::npos) << msg;
    }
  };
  writeAll(dir + "/trunc.slm", data.substr(0, data.size() / 2));
  expectInputError(dir + "/trunc.slm", "truncated");
  writeAll(dir + "/short.slm", data.substr(0, 10));
  expectInputError(dir + "/short.slm", "truncated");
  std::string flipped = data;
  flipped[flipped.size() - 7] ^= 0x55;
  writeAll(dir + "/flip.slm", flipped);
  expectInputError(dir + "/flip.slm", "checksum");
  std::string other = data;
  other[8] = static_cast<char>(LandmarkModel::kFormatVersion + 1);
  writeAll(dir + "/v2.slm", other);
  expectInputError(dir + "/v2.slm", "version");
  writeAll(dir + "/text.slm", "hello, I am not a model");
  expectInputError(dir + "/text.slm", "not a sketchnav landmark model");
  expectInputError(dir + "/missing.slm", "not found");
}

TEST_F(TinyModel, LoadOrTrainReusesAFreshCacheAndRetrainsAStaleOne) {
  const std::string cache = test::tempDir("recog-cache") + "/sub/default.slm";
  const LandmarkModel a = loadOrTrainModel(root_, cache, tinyParams());
  ASSERT_TRUE(fs::exists(cache));
  const auto t = fs::last_write_time(cache);
  const LandmarkModel b = loadOrTrainModel(root_, cache, tinyParams());
  EXPECT_EQ(fs::last_write_time(cache), t) << "a fresh cache is not rewritten";
  EXPECT_EQ(b.classes(), a.classes());
  writeAll(cache, "garbage");
  const LandmarkModel c = loadOrTrainModel(root_, cache, tinyParams());
  EXPECT_EQ(c.classes(), a.classes());
  EXPECT_NO_THROW(LandmarkModel::load(cache));
}

TEST_F(TinyModel, AnOlderFormatIsRefusedAndACachedOneRetrained) {
  // Version 1 files (no keypoint colours) must not be read as the current version: it names
  // the version and says to retrain, and the run harness's cache retrains instead of failing.
  ASSERT_GE(LandmarkModel::kFormatVersion, 3u);
  const std::string dir = test::tempDir("recog-v1");
  model_->save(dir + "/m.slm");
  std::string data = readAll(dir + "/m.slm");
  data[8] = 1;
  data[9] = data[10] = data[11] = 0;
  writeAll(dir + "/v1.slm", data);
  try {
    LandmarkModel::load(dir + "/v1.slm");
    FAIL() << "a version 1 model was accepted";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("version 1"), std::string::npos) << msg;
    EXPECT_NE(msg.find("retrain"), std::string::npos) << msg;
  }
  const LandmarkModel m = loadOrTrainModel(root_, dir + "/v1.slm", tinyParams());
  EXPECT_EQ(m.classes(), model_->classes());
  EXPECT_NO_THROW(LandmarkModel::load(dir + "/v1.slm")) << "the cache was rewritten";
}

TEST_F(TinyModel, PhotoThumbnailsRoundTripAndAFormat4FileIsRefused) {
  // Version 5 added a colour thumbnail per photo (the sibling check): stored, read back
  // pixel for pixel, and a version-4 file (no thumbnails) is refused with the retrain hint.
  ASSERT_EQ(LandmarkModel::kFormatVersion, 5u);
  const std::string dir = test::tempDir("recog-thumbs");
  model_->save(dir + "/m.slm");
  const LandmarkModel m = LandmarkModel::load(dir + "/m.slm");
  ASSERT_EQ(m.photos().size(), model_->photos().size());
  for (size_t i = 0; i < m.photos().size(); ++i) {
    const cv::Mat& a = model_->photos()[i].thumbnail;
    const cv::Mat& b = m.photos()[i].thumbnail;
    ASSERT_FALSE(a.empty()) << i;
    EXPECT_EQ(a.type(), CV_8UC3);
    EXPECT_EQ(std::max(a.cols, a.rows), kPhotoThumbnailSide) << "320 x 240 photos are shrunk";
    ASSERT_EQ(a.size(), b.size()) << i;
    ASSERT_EQ(b.type(), CV_8UC3);
    EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0) << i;
  }
  std::string data = readAll(dir + "/m.slm");
  data[8] = 4;
  data[9] = data[10] = data[11] = 0;
  writeAll(dir + "/v4.slm", data);
  try {
    LandmarkModel::load(dir + "/v4.slm");
    FAIL() << "a version 4 model was accepted";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("version 4"), std::string::npos) << msg;
    EXPECT_NE(msg.find("retrain"), std::string::npos) << msg;
    EXPECT_NE(msg.find("v4.slm"), std::string::npos) << msg;
  }
}

TEST_F(TinyModel, KeypointColoursAreStoredPerDatabaseKeypoint) {
  for (const auto& ph : model_->photos()) {
    ASSERT_EQ(ph.colours.rows, static_cast<int>(ph.keypoints.size())) << ph.path;
    ASSERT_EQ(ph.colours.cols, 3);
  }
}

// knn2 computes its distance table as a matrix product (|q|^2 + |t|^2 - 2 q.t): it must find
// the neighbours an exact brute force finds, on working descriptors and on a query that is a
// view into a larger matrix (recognise() passes window rows).
TEST_F(TinyModel, PhotoNearestTwoAreTheBruteForceOnes) {
  const int photo = 1;
  const cv::Mat& train = model_->photos()[photo].descriptors;
  ASSERT_GT(train.rows, 2);
  // Queries: other photos' descriptors (near and far ones), every other row of a wider block.
  cv::Mat all;
  cv::vconcat(model_->photos()[0].descriptors, model_->photos()[2].descriptors, all);
  cv::Mat wide(all.rows, 2 * all.cols, CV_32F, cv::Scalar(7));
  all.copyTo(wide.colRange(0, all.cols));
  const cv::Mat query = wide.colRange(0, all.cols).rowRange(0, all.rows - 1);
  ASSERT_FALSE(query.isContinuous());
  cv::Mat idx, d2, ref_d, ref_nn;
  model_->knn2(photo, query, idx, d2);
  cv::batchDistance(query, train, ref_d, CV_32F, ref_nn, cv::NORM_L2SQR, 2);
  ASSERT_EQ(idx.rows, query.rows);
  int same = 0;
  for (int i = 0; i < query.rows; ++i) {
    // Neighbours may only swap on a near tie, where float rounding decides.
    for (int k = 0; k < 2; ++k) {
      EXPECT_NEAR(d2.at<float>(i, k), ref_d.at<float>(i, k), 1e-4f * (1 + ref_d.at<float>(i, k)))
          << "row " << i << " neighbour " << k;
      const int j = idx.at<int>(i, k);
      ASSERT_GE(j, 0);
      EXPECT_NEAR(cv::norm(query.row(i), train.row(j), cv::NORM_L2SQR), ref_d.at<float>(i, k),
                  1e-4f * (1 + ref_d.at<float>(i, k)));
    }
    same += idx.at<int>(i, 0) == ref_nn.at<int>(i, 0);
  }
  EXPECT_GE(same, query.rows - 2);
}

namespace {
// The same artwork in other colours: L* kept, (a*, b*) negated, so SIFT (grey levels) sees
// nearly the same image while every coloured region changes hue, as between sibling products.
cv::Mat oppositeColours(const cv::Mat& bgr) {
  cv::Mat lab;
  cv::cvtColor(bgr, lab, cv::COLOR_BGR2Lab);
  for (auto it = lab.begin<cv::Vec3b>(); it != lab.end<cv::Vec3b>(); ++it) {
    (*it)[1] = cv::saturate_cast<uchar>(256 - (*it)[1]);
    (*it)[2] = cv::saturate_cast<uchar>(256 - (*it)[2]);
  }
  cv::Mat out;
  cv::cvtColor(lab, out, cv::COLOR_Lab2BGR);
  return out;
}
}  // namespace

TEST(ColourCheck, TellsSiblingProductsApartAndRejectsAnUnknownSibling) {
  const cv::Mat artwork = test::texturedImage(240, 180, 1000);
  const cv::Mat sibling = oppositeColours(artwork);
  const std::string root = test::tempDir("recog-siblings");
  auto writeClass = [&](const std::string& name, const cv::Mat& obj, unsigned seed) {
    fs::create_directories(root + "/" + name);
    for (int i = 0; i < 4; ++i)
      cv::imwrite(root + "/" + name + "/p" + std::to_string(i) + ".png",
                  test::randomView(obj, 320, 240, seed + i, 20));
  };
  writeClass("orange", artwork, 100);
  writeClass("other", test::texturedImage(240, 180, 1001), 300);
  // Only "orange" and "other" known: a view of the sibling must be "none of these" — and is
  // accepted as "orange" when the colour check is off (so the check is what rejects it).
  const LandmarkModel known = trainModel(root, tinyParams());
  RecognitionParams on, off;
  off.match.colour_tolerance = 0;
  ASSERT_GT(on.match.colour_tolerance, 0);
  int rejected_on = 0, accepted_off = 0;
  for (int i = 0; i < 3; ++i) {
    const cv::Mat view = test::randomView(sibling, 320, 240, 900 + i, 15);
    const auto a = recognise(known, view, {}, 1, on), b = recognise(known, view, {}, 1, off);
    ASSERT_FALSE(a.empty());
    ASSERT_FALSE(b.empty());
    rejected_on += a[0].rejected;
    accepted_off += !b[0].rejected && b[0].class_name == "orange";
  }
  EXPECT_EQ(rejected_on, 3);
  EXPECT_EQ(accepted_off, 3);
  // Both siblings known: each held-out view goes to its own colour.
  writeClass("green", sibling, 200);
  const LandmarkModel both = trainModel(root, tinyParams());
  int correct = 0;
  for (int i = 0; i < 3; ++i) {
    const auto a = recognise(both, test::randomView(artwork, 320, 240, 700 + i, 15), {}, 1, on);
    const auto b = recognise(both, test::randomView(sibling, 320, 240, 800 + i, 15), {}, 1, on);
    correct += !a.empty() && !a[0].rejected && a[0].class_name == "orange";
    correct += !b.empty() && !b[0].rejected && b[0].class_name == "green";
  }
  EXPECT_GE(correct, 5) << "of 6 sibling views";
}

TEST(RecognitionParams, ValidateNamesTheField) {
  RecognitionParams p;
  p.max_verified_photos = -1;
  EXPECT_THROW(p.validate(), InputError);
  p = RecognitionParams{};
  p.match.colour_tolerance = -1;
  try {
    p.validate();
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("colour_tolerance"), std::string::npos);
  }
}

TEST(ModelParams, ValidateNamesTheField) {
  ModelParams p;
  p.vocabulary_size = 1;
  try {
    p.validate();
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("vocabulary_size"), std::string::npos);
  }
}
