#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "sketchnav/landmarks/model.h"
#include "sketchnav/landmarks/photo_hash.h"
#include "test_data.h"
#include "test_recognition_support.h"

using namespace sketchnav;
using namespace sketchnav::landmarks;
namespace fs = std::filesystem;

namespace {

cv::Mat reencoded(const cv::Mat& img, int quality) {
  std::vector<uchar> buf;
  cv::imencode(".jpg", img, buf, {cv::IMWRITE_JPEG_QUALITY, quality});
  return cv::imdecode(buf, cv::IMREAD_COLOR);
}

// Copies a user might make of a photo: re-encoded, resized, brightened, cropped by 1.5 %.
std::vector<cv::Mat> copiesOf(const cv::Mat& img) {
  std::vector<cv::Mat> out;
  out.push_back(reencoded(img, 50));
  cv::Mat m;
  cv::resize(img, m, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
  out.push_back(m);
  cv::resize(img, m, cv::Size(), 1.7, 1.7, cv::INTER_CUBIC);
  out.push_back(m);
  img.convertTo(m, -1, 1.0, 25);
  out.push_back(m);
  const int dx = img.cols / 64, dy = img.rows / 64;
  out.push_back(img(cv::Rect(dx, dy, img.cols - 2 * dx, img.rows - 2 * dy)).clone());
  return out;
}

std::vector<std::string> imagesUnder(const std::string& dir) {
  std::vector<std::string> out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.path().extension() == ".jpg") out.push_back(e.path().string());
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

TEST(PerceptualHash, CopiesStayWithinTheRadiusAndOtherImagesLieBeyondIt) {
  std::vector<std::uint64_t> hashes;
  for (unsigned seed = 1; seed <= 12; ++seed) {
    const cv::Mat img = test::texturedImage(320, 240, seed);
    const std::uint64_t h = perceptualHash(img);
    EXPECT_EQ(hashDistance(h, perceptualHash(img)), 0);
    for (const auto& c : copiesOf(img))
      EXPECT_LE(hashDistance(h, perceptualHash(c)), kNearDuplicateBits) << "seed " << seed;
    hashes.push_back(h);
  }
  for (size_t i = 0; i < hashes.size(); ++i)
    for (size_t j = i + 1; j < hashes.size(); ++j)
      EXPECT_GT(hashDistance(hashes[i], hashes[j]), kNearDuplicateBits) << i << " vs " << j;
}

TEST(PerceptualHash, FindsTheTrainingPhotoAmongTheModelsAndNothingForANewImage) {
  const std::string root = test::tempDir("photohash");
  test::writeLandmarkSet(root, 2, 3, 5);
  ModelParams p;
  p.vocabulary_size = 32;
  p.features.max_features = 200;
  const LandmarkModel model = trainModel(root, p);
  const auto photos = imagesUnder(root);
  ASSERT_FALSE(photos.empty());
  const cv::Mat photo = cv::imread(photos.front());
  const auto hits = findTrainingPhotos(model, reencoded(photo, 60));
  ASSERT_FALSE(hits.empty());
  EXPECT_EQ(fs::path(root) / hits.front().photo, fs::path(photos.front()));
  EXPECT_TRUE(findTrainingPhotos(model, test::texturedImage(320, 240, 999)).empty());
}

// The shipped worlds' landmark textures are photos the demo model is not trained on: the
// simulator must not test recognition on its own training data.
TEST(PerceptualHash, NoShippedWorldTextureIsADemoTrainingPhoto) {
  const std::string share = test::sourceDir() + "/share";
  std::vector<std::uint64_t> demo;
  std::vector<std::string> demo_names;
  for (const auto& f : imagesUnder(share + "/landmarks")) {
    demo.push_back(perceptualHash(cv::imread(f)));
    demo_names.push_back(f);
  }
  ASSERT_GT(demo.size(), 40u);
  int textures = 0;
  for (const auto& e : fs::directory_iterator(share + "/worlds")) {
    std::ifstream in(e.path());
    const auto j = nlohmann::json::parse(in);
    for (const auto& l : j.at("landmarks"))
      for (const char* key : {"texture", "back_texture"}) {
        if (!l.contains(key)) continue;
        const std::string tex = share + "/" + l.at(key).get<std::string>();
        const cv::Mat img = cv::imread(tex);
        ASSERT_FALSE(img.empty()) << tex;
        ++textures;
        const std::uint64_t h = perceptualHash(img);
        for (size_t i = 0; i < demo.size(); ++i)
          EXPECT_GT(hashDistance(h, demo[i]), kNearDuplicateBits)
              << tex << " is a near-duplicate of the training photo " << demo_names[i];
        EXPECT_EQ(tex.find("/landmarks/"), std::string::npos) << tex;
      }
  }
  EXPECT_GE(textures, 9);
}
