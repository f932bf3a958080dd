#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "sketchnav/core/error.h"
#include "sketchnav/drivers/register.h"
#include "sketchnav/hw/registry.h"
#include "test_data.h"

using namespace sketchnav;
using namespace sketchnav::hw;
using namespace sketchnav::drivers;

TEST(DriverRegistry, UnknownSchemeNamesItAndTheKnownOnes) {
  registerDrivers();
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

TEST(DriverRegistry, CreatesAFolderCameraWithUriParamsAndConfig) {
  registerDrivers();
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

// Issue 28: an unknown URI parameter is an error like an unknown setting, before the device
// is opened (folder:///x?fsp=10 ran at the default 30 fps).
TEST(DriverRegistry, UnknownUriParameterNamesItAndTheClosestKnownOne) {
  registerDrivers();
  const std::string dir = test::tempDir("registry-params");
  cv::imwrite(dir + "/1.png", cv::Mat(10, 20, CV_8UC3, cv::Scalar(1, 2, 3)));
  DeviceContext ctx;
  auto message = [&](const std::string& uri) -> std::string {
    try {
      Registry::instance().createCamera(uri, ctx);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(
      message("folder://" + dir + "?fsp=10"),
      "camera URI 'folder://" + dir + "?fsp=10': unknown parameter 'fsp' (did you mean 'fps'?)");
  EXPECT_EQ(message("folder://" + dir + "?fps=4&hfov=70"),
            "camera URI 'folder://" + dir +
                "?fps=4&hfov=70': unknown parameter 'hfov' (did you mean 'hfov_deg'?)");
  // Checked before the factory runs: the folder need not exist for the parameter to be named.
  EXPECT_NE(message("folder:///nonexistent-sketchnav?lop=1")
                .find("unknown parameter 'lop' (did you mean 'loop'?)"),
            std::string::npos);
  EXPECT_EQ(message("folder://" + dir + "?fps=4&loop=1&hfov_deg=70"), "");
}
