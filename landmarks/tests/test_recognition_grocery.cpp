// Real photos: a small grocery-packages subset (skipped when the shared data is absent).
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include <filesystem>

#include "sketchnav/landmarks/landmark_set.h"
#include "sketchnav/landmarks/model.h"
#include "sketchnav/landmarks/recognition.h"
#include "test_data.h"

using namespace sketchnav;
using namespace sketchnav::landmarks;
namespace fs = std::filesystem;

TEST(GroceryRecognition, HeldOutPhotosOfThreeProductsAreRecognised) {
  SKETCHNAV_REQUIRE_DATA(data, "grocery-packages");
  const std::vector<std::pair<std::string, std::string>> classes = {
      {"Oat-Milk", "Oatly-Oat-Milk"},
      {"Milk", "Garant-Ecological-Medium-Fat-Milk"},
      {"Juice", "God-Morgon-Apple-Juice"}};
  // Landmark set: the first 10 training photos of each product (as a user would take them).
  const std::string root = test::tempDir("recog-grocery");
  for (const auto& [group, name] : classes) {
    const LandmarkSet src = scanLandmarkSet(data + "/train/" + group + "/" + name);
    const std::string dst = root + "/" + group + "/" + name;
    fs::create_directories(dst);
    for (size_t i = 0; i < src.classes[0].photos.size() && i < 10; ++i)
      fs::copy_file(src.classes[0].photos[i],
                    dst + "/" + fs::path(src.classes[0].photos[i]).filename().string());
  }
  ModelParams p;
  p.vocabulary_size = 200;
  const LandmarkModel m = trainModel(root, p);
  ASSERT_EQ(m.classes().size(), 3u);
  int n = 0, correct = 0;
  for (const auto& [group, name] : classes) {
    const LandmarkSet val = scanLandmarkSet(data + "/val/" + group + "/" + name);
    for (const auto& photo : val.classes[0].photos) {
      const auto r = recognise(m, cv::imread(photo), {}, 3);
      ++n;
      correct += !r.empty() && !r[0].rejected && r[0].class_name == name;
    }
  }
  ASSERT_EQ(n, 16);
  EXPECT_GE(correct, 13) << "of " << n << " held-out photos";
}
