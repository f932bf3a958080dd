// The sibling check (RecognitionParams::sibling_check): two products sharing most of their artwork.
#include <gtest/gtest.h>

#include <filesystem>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "sketchnav/core/error.h"
#include "sketchnav/landmarks/model.h"
#include "sketchnav/landmarks/recognition.h"
#include "test_data.h"
#include "test_recognition_support.h"

using namespace sketchnav;
using namespace sketchnav::landmarks;
namespace fs = std::filesystem;

namespace {

// Left two thirds from `shared`, the right third from `own`: sibling products (one brand's
// artwork, another flavour picture).
cv::Mat sibling(const cv::Mat& shared, const cv::Mat& own) {
  cv::Mat out = shared.clone();
  const int x = shared.cols * 2 / 3;
  own(cv::Rect(x, 0, shared.cols - x, shared.rows))
      .copyTo(out(cv::Rect(x, 0, shared.cols - x, shared.rows)));
  return out;
}

}  // namespace

TEST(SiblingCheck, TheProductMatchingEverywhereBeatsTheOneSharingPartOfItsArtwork) {
  const cv::Mat shared = test::texturedImage(240, 180, 2000);
  const cv::Mat a = sibling(shared, test::texturedImage(240, 180, 2001));
  const cv::Mat b = sibling(shared, test::texturedImage(240, 180, 2002));
  const std::string root = test::tempDir("recog-sibling-check");
  // Frames of product b, each seen exactly as in one of a's database photos (same homography,
  // same background): a's shared artwork then matches the frame more closely than b's photos
  // (other views) do, so a gets the votes of the shared part, verifies, and ranks first by
  // votes — the val failure: the wrong sibling verified first, the right one never tried.
  const unsigned frame_seeds[] = {500, 501, 502};
  fs::create_directories(root + "/a");
  fs::create_directories(root + "/b");
  for (unsigned s : frame_seeds)
    cv::imwrite(root + "/a/same_view_" + std::to_string(s) + ".png",
                test::randomView(a, 320, 240, s, 15));
  for (unsigned i = 0; i < 3; ++i) {
    cv::imwrite(root + "/a/p" + std::to_string(i) + ".png",
                test::randomView(a, 320, 240, 100 + i, 15));
    cv::imwrite(root + "/b/p" + std::to_string(i) + ".png",
                test::randomView(b, 320, 240, 200 + i, 15));
  }
  ModelParams mp;
  mp.vocabulary_size = 64;
  mp.features.max_features = 300;
  mp.kmeans_iterations = 5;
  const LandmarkModel model = trainModel(root, mp);
  for (const auto& ph : model.photos()) {
    ASSERT_FALSE(ph.thumbnail.empty()) << ph.path;
    EXPECT_EQ(std::max(ph.thumbnail.cols, ph.thumbnail.rows), kPhotoThumbnailSide) << ph.path;
    EXPECT_EQ(ph.thumbnail.type(), CV_8UC3) << ph.path;
  }

  RecognitionParams on, off;
  on.sibling_check = true;
  on.sibling_vote_ratio = 0.2;  // the synthetic votes are less balanced than real siblings'
  off.sibling_check = false;
  int right_on = 0, wrong_off = 0, displaced_listed = 0;
  for (unsigned s : frame_seeds) {
    const cv::Mat frame = test::randomView(b, 320, 240, s, 15);
    const auto r_off = recognise(model, frame, {}, 3, off);
    const auto r_on = recognise(model, frame, {}, 3, on);
    ASSERT_FALSE(r_off.empty());
    ASSERT_FALSE(r_on.empty());
    wrong_off += !r_off[0].rejected && r_off[0].class_name == "a";
    right_on += !r_on[0].rejected && r_on[0].class_name == "b" && r_on[0].verified;
    if (r_on[0].class_name == "b") {
      EXPECT_GT(r_on[0].appearance, -2) << "compared";
      for (const auto& r : r_on)
        if (r.class_name == "a" && r.verified) {
          EXPECT_TRUE(r.rejected) << "a displaced sibling is listed as refused";
          EXPECT_LT(r.appearance, r_on[0].appearance);
          ++displaced_listed;
        }
    }
  }
  EXPECT_EQ(wrong_off, 3) << "the premise: without the check the sibling sharing the artwork wins";
  EXPECT_EQ(right_on, 3);
  EXPECT_GE(displaced_listed, 1);

  // Frames of product a itself are not taken from it: a matches everywhere, b only on the
  // shared part.
  int a_kept = 0;
  for (unsigned s = 0; s < 3; ++s) {
    const auto r = recognise(model, test::randomView(a, 320, 240, 700 + s, 15), {}, 1, on);
    a_kept += !r.empty() && !r[0].rejected && r[0].class_name == "a";
  }
  EXPECT_EQ(a_kept, 3);

  // A grey frame has no colour thumbnail: the check is skipped, the old answer stands.
  cv::Mat grey;
  cv::cvtColor(test::randomView(b, 320, 240, frame_seeds[0], 15), grey, cv::COLOR_BGR2GRAY);
  const auto g_on = recognise(model, grey, {}, 1, on), g_off = recognise(model, grey, {}, 1, off);
  ASSERT_FALSE(g_on.empty());
  ASSERT_FALSE(g_off.empty());
  EXPECT_EQ(g_on[0].class_name, g_off[0].class_name);
}

TEST(SiblingCheck, ValidateNamesTheField) {
  RecognitionParams p;
  p.sibling_vote_ratio = 1.5;
  try {
    p.validate();
    FAIL() << "accepted sibling_vote_ratio 1.5";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("sibling_vote_ratio"), std::string::npos) << e.what();
  }
  p = RecognitionParams();
  p.sibling_margin = -0.1;
  EXPECT_THROW(p.validate(), InputError);
}

// The distinctiveness check (MatchParams::distinct_min_fraction): a product the model does not
// know, sharing half its artwork with class a (the brand's half), is matched as a by the shared
// half alone; with the check those inliers are not distinct (class b has the same artwork), so
// it is not. Product a itself, whose other half is its own, still matches.
TEST(DistinctMatch, ArtworkSharedWithAnotherClassIsNoEvidence) {
  const cv::Mat brand = test::texturedImage(240, 180, 3000);
  auto half = [&](const cv::Mat& own) {
    cv::Mat out = brand.clone();
    own(cv::Rect(120, 0, 120, 180)).copyTo(out(cv::Rect(120, 0, 120, 180)));
    return out;
  };
  const cv::Mat a = half(test::texturedImage(240, 180, 3001));
  const cv::Mat b = half(test::texturedImage(240, 180, 3002));
  const cv::Mat unknown = half(test::texturedImage(240, 180, 3003));  // not in the model
  const std::string root = test::tempDir("distinct-match");
  fs::create_directories(root + "/a");
  fs::create_directories(root + "/b");
  for (unsigned i = 0; i < 3; ++i) {
    cv::imwrite(root + "/a/p" + std::to_string(i) + ".png",
                test::randomView(a, 320, 240, 300 + i, 10));
    // The same views as a's: the shared half is as close to b's photos as to a's (the check
    // compares each descriptor's nearest neighbour in either class, so a sibling photographed
    // from other distances keeps some of the shared artwork distinct for a).
    cv::imwrite(root + "/b/p" + std::to_string(i) + ".png",
                test::randomView(b, 320, 240, 300 + i, 10));
  }
  ModelParams mp;
  mp.vocabulary_size = 64;
  mp.features.max_features = 300;
  mp.kmeans_iterations = 5;
  const LandmarkModel model = trainModel(root, mp);
  MatchParams off, on;
  off.distinct_min_fraction = 0;
  on.distinct_min_fraction = 0.3;
  int unknown_off = 0, unknown_on = 0, a_on = 0, a_off = 0;
  for (unsigned s = 0; s < 4; ++s) {
    const cv::Mat fu = test::randomView(unknown, 320, 240, 900 + s, 10);
    const cv::Mat fa = test::randomView(a, 320, 240, 950 + s, 10);
    unknown_off += match(model, fu, cv::Rect(), "a", off).matched;
    const MatchResult mu = match(model, fu, cv::Rect(), "a", on);
    unknown_on += mu.matched;
    if (mu.inliers >= on.min_inliers) EXPECT_GE(mu.distinct_inliers, 0) << "checked";
    a_off += match(model, fa, cv::Rect(), "a", off).matched;
    const MatchResult ma = match(model, fa, cv::Rect(), "a", on);
    a_on += ma.matched;
    if (ma.matched) EXPECT_GE(ma.distinct_inliers, 0.3 * ma.inliers);
  }
  EXPECT_GE(unknown_off, 3) << "the premise: the shared half alone verifies without the check";
  EXPECT_EQ(unknown_on, 0);
  EXPECT_EQ(a_off, 4);
  EXPECT_GE(a_on, 3);
}

TEST(DistinctMatch, ValidateNamesTheField) {
  MatchParams p;
  p.distinct_min_fraction = 1.5;
  EXPECT_THROW(p.validate(), InputError);
  p = MatchParams();
  p.distinct_ratio = 0;
  try {
    p.validate();
    FAIL() << "accepted distinct_ratio 0";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("distinct_ratio"), std::string::npos) << e.what();
  }
}
