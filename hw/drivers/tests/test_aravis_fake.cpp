// aravis:// against Aravis's in-process Fake device (no network at all). The real GigE
// Vision path over loopback is tested in tests/hardware (it needs arv-fake-gv-camera-0.8).
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "sketchnav/core/error.h"
#include "sketchnav/drivers/aravis_camera.h"
#include "sketchnav/drivers/register.h"
#include "sketchnav/hw/registry.h"

using namespace sketchnav;
using namespace sketchnav::hw;
using namespace sketchnav::drivers;

TEST(AravisFake, StreamsConfiguredMonoFramesAsBgrWithStampsAndSequence) {
  AravisParams p;
  p.pixel_format = "Mono8";
  p.width = 320;
  p.height = 240;
  p.fps = 50;
  AravisCamera cam("Fake_1", p, nullptr);
  EXPECT_EQ(cam.pixelFormat(), "Mono8");
  EXPECT_EQ(cam.intrinsics().width, 320);
  EXPECT_EQ(cam.intrinsics().height, 240);
  Frame f;
  double last_stamp = -1;
  std::uint64_t last_seq = 0;
  for (int i = 0; i < 10; ++i) {
    ASSERT_EQ(cam.grab(f, 2.0), GrabStatus::Ok) << cam.stats().last_error;
    EXPECT_EQ(f.image.type(), CV_8UC3);
    EXPECT_EQ(f.image.cols, 320);
    EXPECT_EQ(f.image.rows, 240);
    if (i > 0) {
      EXPECT_GE(f.stamp, last_stamp);
      EXPECT_EQ(f.seq, last_seq + 1);
    }
    last_stamp = f.stamp;
    last_seq = f.seq;
  }
  // Mono delivered as BGR: the three channels are equal, and the fake's pattern is not flat.
  std::vector<cv::Mat> ch;
  cv::split(f.image, ch);
  EXPECT_EQ(cv::norm(ch[0], ch[1], cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(ch[1], ch[2], cv::NORM_INF), 0.0);
  double lo, hi;
  cv::minMaxLoc(ch[0], &lo, &hi);
  EXPECT_LT(lo, hi);
  EXPECT_EQ(cam.stats().received, 10u);
  EXPECT_EQ(cam.stats().incomplete, 0u);
  EXPECT_TRUE(cam.connected());
}

TEST(AravisFake, ConvertsBayerRgbAndMono16) {
  for (const char* pf : {"BayerRG8", "BayerGR8", "RGB8", "Mono16"}) {
    AravisParams p;
    p.pixel_format = pf;
    p.width = 64;
    p.height = 48;
    AravisCamera cam("Fake_1", p, nullptr);
    Frame f;
    ASSERT_EQ(cam.grab(f, 2.0), GrabStatus::Ok) << pf << ": " << cam.stats().last_error;
    EXPECT_EQ(f.image.type(), CV_8UC3) << pf;
    EXPECT_EQ(f.image.size(), cv::Size(64, 48)) << pf;
    EXPECT_GT(cv::norm(f.image, cv::NORM_L1), 0.0) << pf << " delivered a black frame";
  }
}

TEST(AravisFake, RegistryAppliesUriParamsAndNamesRefusedSettings) {
  registerDrivers();
  DeviceContext ctx;
  ctx.config.set("camera.aravis.height=100");
  auto cam =
      Registry::instance().createCamera("aravis://Fake_7?width=160&pixel_format=BayerBG8", ctx);
  EXPECT_EQ(cam->intrinsics().width, 160);
  EXPECT_EQ(cam->intrinsics().height, 100);
  Frame f;
  ASSERT_EQ(cam->grab(f, 2.0), GrabStatus::Ok);
  EXPECT_EQ(f.image.cols, 160);
  try {
    DeviceContext c2;
    Registry::instance().createCamera("aravis://Fake_1?pixel_format=NoSuchFormat", c2);
    FAIL() << "an unknown pixel format was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("pixel_format"), std::string::npos) << e.what();
  }
  DeviceContext c3;
  EXPECT_THROW(Registry::instance().createCamera("aravis://Fake_1?buffers=1", c3), InputError);
}
