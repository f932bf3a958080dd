#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "sketchnav/core/error.h"
#include "sketchnav/hw/registry.h"
#include "test_data.h"

using namespace sketchnav;
using namespace sketchnav::hw;

TEST(Registry, UnknownSchemeNamesItAndTheKnownOnes) {
  registerBuiltinDrivers();
  DeviceContext ctx;
  try {
    Registry::instance().createCamera("gopro://cam0", ctx);
    FAIL();
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("'gopro'"), std::string::npos) << m;
    EXPECT_NE(m.find("folder"), std::string::npos) << m;
    EXPECT_NE(m.find("video"), std::string::npos) << m;
  }
  EXPECT_THROW(Registry::instance().createBase("nobase://x", ctx), InputError);
  EXPECT_THROW(Registry::instance().createRange("nolaser://x", ctx), InputError);
  EXPECT_THROW(Registry::instance().createCamera("not a uri", ctx), InputError);
}

TEST(Registry, CreatesAFolderCameraWithUriParamsAndConfig) {
  registerBuiltinDrivers();
  const std::string dir = test::tempDir("registry");
  cv::imwrite(dir + "/1.png", cv::Mat(10, 20, CV_8UC3, cv::Scalar(1, 2, 3)));
  DeviceContext ctx;
  ctx.config.set("camera.folder.hfov_deg=90");
  auto cam = Registry::instance().createCamera("folder://" + dir + "?fps=4", ctx);
  Frame f;
  ASSERT_EQ(cam->grab(f), GrabStatus::Ok);
  ASSERT_EQ(cam->grab(f), GrabStatus::EndOfStream);
  EXPECT_NEAR(cam->intrinsics().fx, 10.0, 1e-9);  // 90 deg over 20 px
  ctx.config.set("camera.folder.fps=-3");
  EXPECT_THROW(Registry::instance().createCamera("folder://" + dir, ctx), InputError);
}

TEST(Registry, CustomFactoriesAreUsedByScheme) {
  struct NullRange final : RangeSensor {
    bool read(RangeScan& s) override {
      s.ranges = {1.0f};
      return true;
    }
    DeviceStats stats() const override { return {}; }
    std::string uri() const override { return "null://"; }
  };
  Registry::instance().addRange(
      "null", [](const Uri&, DeviceContext&) { return std::make_unique<NullRange>(); });
  DeviceContext ctx;
  auto r = Registry::instance().createRange("null://x", ctx);
  RangeScan s;
  ASSERT_TRUE(r->read(s));
  EXPECT_EQ(s.ranges.size(), 1u);
}
