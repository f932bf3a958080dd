// The CCS ∪ SCS union end to end: finds pasted objects, survives odd inputs; the benchmark
// loop survives a corrupt JPEG and odd annotations.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <filesystem>
#include <fstream>
#include <random>

#include "sketchnav/core/error.h"
#include "sketchnav/landmarks/objectness.h"
#include "sketchnav/landmarks/voc.h"
#include "test_data.h"

using namespace sketchnav::landmarks;

namespace {

// A plain, slightly noisy background with textured, colourful patches pasted at `boxes`.
cv::Mat scene(cv::Size size, const std::vector<cv::Rect>& boxes, unsigned seed) {
  std::mt19937 rng(seed);
  cv::Mat img(size, CV_8UC3, cv::Scalar(190, 195, 200));
  cv::Mat noise(size, CV_8UC3);
  cv::randn(noise, cv::Scalar(0, 0, 0), cv::Scalar(3, 3, 3));
  img += noise;
  std::uniform_int_distribution<int> c(0, 255);
  for (const auto& b : boxes) {
    cv::Mat patch = img(b);
    patch.setTo(cv::Scalar(c(rng) / 3, c(rng) / 3, c(rng) / 3));
    // Texture: random coloured stripes and discs, as on a product photo.
    for (int k = 0; k < 12; ++k) {
      const cv::Scalar col(c(rng), c(rng), c(rng));
      if (k % 2)
        cv::line(patch, {0, c(rng) % b.height}, {b.width, c(rng) % b.height}, col, 2);
      else
        cv::circle(patch, {c(rng) % b.width, c(rng) % b.height}, 2 + c(rng) % 8, col, cv::FILLED);
    }
  }
  return img;
}

double best(const std::vector<Window>& w, const cv::Rect& gt, size_t top) {
  double b = 0;
  for (size_t i = 0; i < std::min(top, w.size()); ++i) b = std::max(b, iou(w[i].box, gt));
  return b;
}

void expectSane(const std::vector<Window>& w, const cv::Size& size, int max_windows) {
  EXPECT_LE(static_cast<int>(w.size()), max_windows);
  const cv::Rect img(0, 0, size.width, size.height);
  for (size_t i = 0; i < w.size(); ++i) {
    EXPECT_GT(w[i].box.area(), 0);
    EXPECT_EQ(w[i].box & img, w[i].box);
    if (i) EXPECT_LE(w[i].score, w[i - 1].score + 1e-6f) << "ranked best first";
  }
}

}  // namespace

TEST(ObjectnessUnion, FindsTexturedObjectOnPlainBackground) {
  const cv::Rect obj(150, 90, 70, 60);
  const cv::Mat img = scene({320, 240}, {obj}, 1);
  const Objectness o{ObjectnessParams{}};
  const auto w = o.propose(img, 100);
  expectSane(w, img.size(), 100);
  EXPECT_GE(best(w, obj, 10), 0.7) << "the object should be among the top 10 windows";
}

TEST(ObjectnessUnion, FindsSmallLandmarksInCameraFrame) {
  // A 640x480 frame of a plain room with three photo-like landmarks 40–120 px wide.
  const std::vector<cv::Rect> objs = {{80, 200, 40, 50}, {300, 150, 120, 90}, {520, 260, 60, 60}};
  const cv::Mat img = scene({640, 480}, objs, 2);
  for (const bool eb : {false, true}) {
    ObjectnessParams p;
    p.use_edgeboxes = eb;
    const auto w = Objectness{p}.propose(img, 100);
    expectSane(w, img.size(), 100);
    for (const auto& g : objs) EXPECT_GE(best(w, g, 100), 0.6) << g << " edgeboxes " << eb;
  }
}

TEST(ObjectnessUnion, SourcesAndSwitches) {
  const cv::Mat img = scene({320, 240}, {{100, 80, 80, 60}}, 3);
  ObjectnessParams p;
  p.use_edgeboxes = true;
  int edges = 0;
  for (const auto& w : Objectness(p).propose(img, 1000)) edges += w.source == Window::Edges;
  EXPECT_GT(edges, 0) << "use_edgeboxes adds EdgeBoxes windows to the union";
  p.use_edgeboxes = false;
  p.use_ccs = false;
  for (const auto& w : Objectness(p).propose(img, 50)) EXPECT_EQ(w.source, Window::SCS);
  p.use_ccs = true;
  p.use_scs = false;
  for (const auto& w : Objectness(p).propose(img, 50)) EXPECT_NE(w.source, Window::SCS);
  p.use_ccs = false;
  EXPECT_THROW(Objectness{p}, sketchnav::InputError);
  ObjectnessParams bad;
  bad.scs.slic_region_size = 1;
  EXPECT_THROW(Objectness{bad}, sketchnav::InputError);
}

TEST(ObjectnessUnion, DeterministicAcrossCalls) {
  const cv::Mat img = scene({320, 240}, {{100, 80, 80, 60}}, 4);
  const Objectness o{ObjectnessParams{}};
  const auto a = o.propose(img, 100), b = o.propose(img, 100);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i].box, b[i].box);
}

TEST(ObjectnessRobustness, OddImages) {
  const Objectness o{ObjectnessParams{}};
  EXPECT_TRUE(o.propose(cv::Mat(), 100).empty());
  EXPECT_TRUE(o.propose(cv::Mat(1, 1, CV_8UC3, cv::Scalar::all(9)), 100).empty());
  EXPECT_TRUE(o.propose(scene({64, 48}, {}, 5), 0).empty());
  const std::vector<cv::Mat> images = {
      scene({16, 16}, {}, 5),                                  // tiny
      cv::Mat(480, 640, CV_8UC3, cv::Scalar::all(0)),          // all black
      cv::Mat(480, 640, CV_8UC3, cv::Scalar::all(255)),        // all white
      cv::Mat(3000, 4000, CV_8UC3, cv::Scalar(90, 120, 150)),  // huge
      cv::Mat(5, 300, CV_8UC3, cv::Scalar::all(60)),           // a sliver
  };
  for (const auto& img : images) {
    SCOPED_TRACE(::testing::Message() << img.cols << "x" << img.rows);
    expectSane(o.propose(img, 50), img.size(), 50);
  }
  cv::Mat gray;
  cv::cvtColor(scene({320, 240}, {{100, 80, 80, 60}}, 6), gray, cv::COLOR_BGR2GRAY);
  const auto wg = o.propose(gray, 50);
  expectSane(wg, gray.size(), 50);
  EXPECT_FALSE(wg.empty());
  cv::Mat bgra;
  cv::cvtColor(gray, bgra, cv::COLOR_GRAY2BGRA);
  expectSane(o.propose(bgra, 50), bgra.size(), 50);
  EXPECT_THROW(o.propose(cv::Mat(10, 10, CV_16UC3), 5), sketchnav::InputError);
  EXPECT_THROW(o.propose(cv::Mat(10, 10, CV_8UC2), 5), sketchnav::InputError);
}

TEST(ObjectnessRobustness, EvaluationSkipsCorruptJpegAndOddAnnotations) {
  namespace fs = std::filesystem;
  const auto dir = sketchnav::test::tempDir("voc-robust");
  fs::create_directories(dir + "/Annotations");
  fs::create_directories(dir + "/JPEGImages");
  // good.jpg with one object and one box outside the image; corrupt.jpg is not a JPEG at all
  // (truncated header); empty.xml has no object.
  cv::imwrite(dir + "/JPEGImages/good.jpg", scene({160, 120}, {{40, 30, 50, 40}}, 7));
  std::ofstream(dir + "/JPEGImages/corrupt.jpg") << "\xff\xd8\xff\xe0 truncated";
  cv::imwrite(dir + "/JPEGImages/empty.jpg", scene({160, 120}, {}, 8));
  const char* obj =
      "<object><name>o</name><bndbox><xmin>41</xmin><ymin>31</ymin><xmax>90</xmax>"
      "<ymax>70</ymax></bndbox></object>";
  const char* out =
      "<object><name>o</name><bndbox><xmin>400</xmin><ymin>300</ymin>"
      "<xmax>500</xmax><ymax>400</ymax></bndbox></object>";
  const std::string size = "<size><width>160</width><height>120</height></size>";
  std::ofstream(dir + "/Annotations/good.xml")
      << "<annotation>" << size << obj << out << "</annotation>";
  std::ofstream(dir + "/Annotations/corrupt.xml")
      << "<annotation>" << size << obj << "</annotation>";
  std::ofstream(dir + "/Annotations/empty.xml") << "<annotation>" << size << "</annotation>";
  const auto set = readVocDataset(dir);
  ASSERT_EQ(set.size(), 3u);
  auto grid = makeSlidingWindow();
  ObjectnessParams p;
  class Ours : public ProposalMethod {
   public:
    std::string name() const override { return "ours"; }
    std::vector<cv::Rect> propose(const cv::Mat& bgr, int n) override {
      std::vector<cv::Rect> r;
      for (const auto& w : o.propose(bgr, n)) r.push_back(w.box);
      return r;
    }
    Objectness o{ObjectnessParams{}};
  } ours;
  const EvalResult r = evaluateProposals(set, {grid.get(), &ours}, {10, 100});
  EXPECT_EQ(r.images, 2);
  EXPECT_EQ(r.objects, 1);  // the box outside the image was dropped
  ASSERT_EQ(r.skipped.size(), 1u);
  EXPECT_NE(r.skipped[0].find("corrupt.jpg"), std::string::npos);
  ASSERT_EQ(r.methods.size(), 2u);
  EXPECT_EQ(r.methods[0].ms.size(), 2u);
  EXPECT_GE(r.methods[1].at.at(100).recall(0.7), 1.0);  // one textured object: found
}

TEST(ObjectnessUnion, RealPhotoFromSharedData) {
  SKETCHNAV_REQUIRE_DATA(dir, "raccoon");
  const auto set = readVocDataset(dir);
  ASSERT_FALSE(set.empty());
  const cv::Mat img = cv::imread(set[0].image_path);
  ASSERT_FALSE(img.empty());
  const auto w = Objectness{ObjectnessParams{}}.propose(img, 100);
  expectSane(w, img.size(), 100);
  ASSERT_FALSE(set[0].objects.empty());
  EXPECT_GE(best(w, set[0].objects[0].box, 100), 0.5);
}
