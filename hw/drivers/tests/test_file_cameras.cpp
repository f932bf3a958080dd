#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <fstream>

#include "sketchnav/core/error.h"
#include "sketchnav/drivers/file_cameras.h"
#include "test_data.h"

using namespace sketchnav;
using namespace sketchnav::hw;
using namespace sketchnav::drivers;

namespace {
cv::Mat numbered(int i, int w = 64, int h = 48) {
  cv::Mat m(h, w, CV_8UC3, cv::Scalar(10 * i, 255 - 10 * i, 128));
  cv::putText(m, std::to_string(i), {5, 30}, cv::FONT_HERSHEY_SIMPLEX, 0.8, {255, 255, 255});
  return m;
}
}  // namespace

TEST(FolderCamera, DeliversFramesInNaturalOrderThenEnds) {
  const std::string dir = test::tempDir("folder-order");
  for (int i : {10, 2, 1}) cv::imwrite(dir + "/frame" + std::to_string(i) + ".png", numbered(i));
  std::ofstream(dir + "/notes.txt") << "not an image";
  FolderCameraParams p;
  p.fps = 5;
  FolderCamera cam(dir, p);
  ASSERT_EQ(cam.files().size(), 3u);
  Frame f;
  std::vector<std::string> order;
  while (cam.grab(f) == GrabStatus::Ok) {
    EXPECT_EQ(f.image.type(), CV_8UC3);
    EXPECT_DOUBLE_EQ(f.stamp, f.seq / 5.0);
    order.push_back(f.source.substr(f.source.rfind('/') + 1));
  }
  EXPECT_EQ(order, (std::vector<std::string>{"frame1.png", "frame2.png", "frame10.png"}));
  EXPECT_EQ(cam.grab(f), GrabStatus::EndOfStream);
  EXPECT_EQ(cam.stats().received, 3u);
  EXPECT_EQ(cam.intrinsics().width, 64);
  EXPECT_EQ(cam.intrinsics().height, 48);
}

TEST(FolderCamera, CorruptFrameIsSkippedWithAWarningNotACrash) {
  const std::string dir = test::tempDir("folder-corrupt");
  cv::imwrite(dir + "/a1.jpg", numbered(1));
  // A truncated JPEG: header of a real one, then cut.
  std::vector<uchar> buf;
  cv::imencode(".jpg", numbered(2), buf);
  std::ofstream(dir + "/a2.jpg", std::ios::binary)
      .write(reinterpret_cast<const char*>(buf.data()), 20);
  std::ofstream(dir + "/a3.jpg", std::ios::binary) << "garbage bytes, not a jpeg";
  cv::imwrite(dir + "/a4.png", numbered(4));
  FolderCamera cam(dir, FolderCameraParams{});
  Frame f;
  ASSERT_EQ(cam.grab(f), GrabStatus::Ok);
  EXPECT_NE(f.source.find("a1.jpg"), std::string::npos);
  ASSERT_EQ(cam.grab(f), GrabStatus::Ok);
  EXPECT_NE(f.source.find("a4.png"), std::string::npos);
  EXPECT_EQ(cam.grab(f), GrabStatus::EndOfStream);
  EXPECT_EQ(cam.stats().dropped, 2u);
  EXPECT_EQ(cam.stats().received, 2u);
  EXPECT_NE(cam.stats().last_error.find("a3.jpg"), std::string::npos);
}

TEST(FolderCamera, GrayscaleBecomesBgrAndLoopRestarts) {
  const std::string dir = test::tempDir("folder-gray");
  cv::Mat g(20, 30, CV_8UC1, cv::Scalar(77));
  cv::imwrite(dir + "/g.png", g);
  FolderCameraParams p;
  p.loop = true;
  FolderCamera cam(dir, p);
  Frame f;
  for (int i = 0; i < 3; ++i) {
    ASSERT_EQ(cam.grab(f), GrabStatus::Ok);
    EXPECT_EQ(f.image.type(), CV_8UC3);
    EXPECT_EQ(f.image.at<cv::Vec3b>(0, 0)[1], 77);
  }
  EXPECT_EQ(f.seq, 2u);
}

TEST(FolderCamera, MissingOrEmptyFolderNamesThePath) {
  const std::string dir = test::tempDir("folder-empty");
  try {
    FolderCamera cam(dir + "/nope", FolderCameraParams{});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(dir + "/nope"), std::string::npos) << e.what();
  }
  try {
    FolderCamera cam(dir, FolderCameraParams{});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no images"), std::string::npos) << e.what();
  }
  std::ofstream(dir + "/only.jpg") << "corrupt";
  EXPECT_THROW(FolderCamera(dir, FolderCameraParams{}), InputError);
}

TEST(FolderCamera, BadParamsAreRejected) {
  const std::string dir = test::tempDir("folder-params");
  cv::imwrite(dir + "/x.png", numbered(1));
  FolderCameraParams p;
  p.fps = 0;
  EXPECT_THROW(FolderCamera(dir, p), InputError);
}

TEST(VideoCamera, ReadsAWrittenClipAndEnds) {
  const std::string dir = test::tempDir("video");
  const std::string path = dir + "/clip.avi";
  {
    cv::VideoWriter w(path, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 10, {64, 48});
    ASSERT_TRUE(w.isOpened());
    for (int i = 0; i < 5; ++i) w.write(numbered(i));
  }
  VideoCamera cam(path, 60.0);
  Frame f;
  int n = 0;
  while (cam.grab(f) == GrabStatus::Ok) {
    EXPECT_EQ(f.image.cols, 64);
    ++n;
  }
  EXPECT_EQ(n, 5);
  EXPECT_EQ(cam.intrinsics().width, 64);
}

TEST(VideoCamera, MissingOrBogusFileIsAnInputError) {
  const std::string dir = test::tempDir("video-bad");
  EXPECT_THROW(VideoCamera(dir + "/none.mp4", 60.0), InputError);
  std::ofstream(dir + "/bogus.mp4") << "this is not a video";
  EXPECT_THROW(VideoCamera(dir + "/bogus.mp4", 60.0), InputError);
}

TEST(Intrinsics, FromFovAndNormalisation) {
  const Intrinsics k = Intrinsics::fromFov(640, 480, M_PI / 2);
  EXPECT_NEAR(k.fx, 320.0, 1e-9);
  EXPECT_NEAR(k.normalisedX(k.cx), 0.0, 1e-12);
  EXPECT_GT(k.normalisedX(600), 0.0);  // right of centre is positive x
}
