// IoU, NMS and the proposal-evaluation metrics on hand-made boxes with known answers.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "sketchnav/core/error.h"
#include "sketchnav/landmarks/boxes.h"
#include "sketchnav/landmarks/voc.h"
#include "test_data.h"

using namespace sketchnav::landmarks;

TEST(ObjectnessBoxes, IouKnownValues) {
  EXPECT_DOUBLE_EQ(iou({0, 0, 10, 10}, {0, 0, 10, 10}), 1.0);
  EXPECT_DOUBLE_EQ(iou({0, 0, 10, 10}, {10, 0, 10, 10}), 0.0);  // touching, no overlap
  EXPECT_DOUBLE_EQ(iou({0, 0, 10, 10}, {5, 0, 10, 10}), 50.0 / 150.0);
  EXPECT_DOUBLE_EQ(iou({0, 0, 10, 10}, {2, 2, 5, 5}), 25.0 / 100.0);  // contained
  EXPECT_DOUBLE_EQ(iou({0, 0, 0, 10}, {0, 0, 10, 10}), 0.0);          // empty box
}

TEST(ObjectnessBoxes, NmsKeepsBestAndSuppressesOverlaps) {
  const std::vector<ScoredBox> b = {{{0, 0, 10, 10}, 0.5f},
                                    {{1, 0, 10, 10}, 0.9f},    // IoU with #0 = 90/110
                                    {{50, 50, 10, 10}, 0.7f},  // far away
                                    {{0, 0, 0, 0}, 1.0f}};     // empty: dropped
  EXPECT_EQ(nms(b, 0.5, 0), (std::vector<int>{1, 2}));
  EXPECT_EQ(nms(b, 0.95, 0), (std::vector<int>{1, 2, 0}));
  EXPECT_EQ(nms(b, 0.95, 2), (std::vector<int>{1, 2}));
}

TEST(ObjectnessBoxes, RecallAboAndAverageRecall) {
  // Two objects of class a, one of class b; one difficult object that must be ignored.
  const std::vector<VocObject> gt = {{"a", {0, 0, 10, 10}, false},
                                     {"a", {100, 100, 10, 10}, false},
                                     {"b", {50, 0, 20, 10}, false},
                                     {"a", {200, 200, 5, 5}, true}};
  const std::vector<cv::Rect> props = {
      {0, 0, 10, 10},      // exact hit on object 0 (IoU 1)
      {50, 0, 10, 10},     // half of object 2 (IoU 0.5)
      {100, 100, 8, 10}};  // object 1 at IoU 0.8, but only counted with budget >= 3
  ProposalEval e2, e3;
  e2.add(gt, props, 2);
  e3.add(gt, props, 3);
  EXPECT_EQ(e2.objects(), 3);
  EXPECT_NEAR(e2.recall(0.5), 2.0 / 3.0, 1e-12);
  EXPECT_NEAR(e2.recall(0.7), 1.0 / 3.0, 1e-12);
  EXPECT_NEAR(e3.recall(0.7), 2.0 / 3.0, 1e-12);
  EXPECT_NEAR(e2.abo(), (1.0 + 0.0 + 0.5) / 3.0, 1e-12);
  // MABO: class a = (1 + 0.8)/2, class b = 0.5 → mean 0.7.
  EXPECT_NEAR(e3.mabo(), 0.7, 1e-12);
  // AR = 2·mean(max(best − 0.5, 0)) = 2·(0.5 + 0.3 + 0)/3.
  EXPECT_NEAR(e3.averageRecall(), 2.0 * 0.8 / 3.0, 1e-12);
  ProposalEval none;
  EXPECT_EQ(none.recall(0.5), 0.0);
  EXPECT_EQ(none.mabo(), 0.0);
}

namespace {
std::string writeFile(const std::string& dir, const std::string& name, const std::string& text) {
  const std::string p = dir + "/" + name;
  std::ofstream(p) << text;
  return p;
}
}  // namespace

TEST(ObjectnessVoc, ParsesObjectsDifficultAndClipsOrDropsBadBoxes) {
  const auto dir = sketchnav::test::tempDir("voc-parse");
  const auto p = writeFile(dir, "x.xml", R"(<annotation><size><width>100</width>
    <height>50</height><depth>3</depth></size>
    <object><name>dog</name><difficult>0</difficult>
      <bndbox><xmin>11</xmin><ymin>6</ymin><xmax>30</xmax><ymax>25</ymax></bndbox></object>
    <object><name>cat</name><difficult>1</difficult>
      <bndbox><xmin>1</xmin><ymin>1</ymin><xmax>10</xmax><ymax>10</ymax></bndbox></object>
    <object><name>far</name>
      <bndbox><xmin>500</xmin><ymin>500</ymin><xmax>600</xmax><ymax>600</ymax></bndbox></object>
    <object><name>edge</name>
      <bndbox><xmin>90</xmin><ymin>40</ymin><xmax>120</xmax><ymax>70</ymax></bndbox></object>
    </annotation>)");
  const VocImage im = readVocAnnotation(p);
  EXPECT_EQ(im.size, cv::Size(100, 50));
  ASSERT_EQ(im.objects.size(), 3u);
  EXPECT_EQ(im.objects[0].box, cv::Rect(10, 5, 20, 20));  // 1-based inclusive → cv::Rect
  EXPECT_TRUE(im.objects[1].difficult);
  EXPECT_EQ(im.objects[2].box, cv::Rect(89, 39, 11, 11));  // clipped to the image
  EXPECT_EQ(im.warnings.size(), 1u);                       // the box outside: dropped
}

TEST(ObjectnessVoc, NoObjectsAndMalformedFiles) {
  const auto dir = sketchnav::test::tempDir("voc-bad");
  const auto empty = writeFile(dir, "e.xml",
                               "<annotation><size><width>10</width>"
                               "<height>10</height></size></annotation>");
  EXPECT_TRUE(readVocAnnotation(empty).objects.empty());
  const auto bad = writeFile(dir, "b.xml",
                             "<annotation><object><name>x</name><bndbox><xmin>a</xmin>"
                             "<ymin>1</ymin><xmax>2</xmax><ymax>2</ymax></bndbox></object>"
                             "</annotation>");
  EXPECT_THROW(readVocAnnotation(bad), sketchnav::InputError);
  const auto junk = writeFile(dir, "j.xml", "not xml at all");
  EXPECT_THROW(readVocAnnotation(junk), sketchnav::InputError);
  EXPECT_THROW(readVocAnnotation(dir + "/missing.xml"), sketchnav::InputError);
  EXPECT_THROW(readVocDataset(dir + "/nowhere"), sketchnav::InputError);
  EXPECT_THROW(readVocDataset(dir), sketchnav::InputError);  // no Annotations/
}

TEST(ObjectnessVoc, ReadsDatasetWithoutImageSets) {
  const auto dir = sketchnav::test::tempDir("voc-set");
  std::filesystem::create_directories(dir + "/Annotations");
  std::filesystem::create_directories(dir + "/JPEGImages");
  writeFile(dir + "/Annotations", "b.xml", "<annotation></annotation>");
  writeFile(dir + "/Annotations", "a.xml", "<annotation></annotation>");
  const auto set = readVocDataset(dir);
  ASSERT_EQ(set.size(), 2u);
  EXPECT_EQ(set[0].id, "a");
  EXPECT_EQ(set[1].image_path, dir + "/JPEGImages/b.jpg");
}

TEST(ObjectnessVoc, ReadsSharedVoc07Mini) {
  SKETCHNAV_REQUIRE_DATA(dir, "voc07-mini");
  const auto set = readVocDataset(dir);
  EXPECT_EQ(set.size(), 9u);
  int n = 0;
  for (const auto& im : set)
    for (const auto& o : im.objects) n += o.difficult ? 0 : 1;
  EXPECT_EQ(n, 46);  // README: 46 non-difficult objects
}
