#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "sketchnav/core/error.h"
#include "sketchnav/core/log.h"
#include "test_data.h"

using namespace sketchnav;

TEST(Log, OneLinePerEventWithFieldsInTheFile) {
  const std::string dir = test::tempDir("log");
  log::setQuiet(true);
  log::setFile(dir + "/run.log");
  log::info("camera", "frame\nskipped", {{"file", "a b.png"}, {"n", "3"}});
  log::debug("nav", "debug lines reach the file too");
  std::ifstream in(dir + "/run.log");
  std::string l1, l2, l3;
  ASSERT_TRUE(std::getline(in, l1));
  ASSERT_TRUE(std::getline(in, l2));
  EXPECT_FALSE(std::getline(in, l3));
  EXPECT_NE(l1.find("INFO  camera: frame skipped file=\"a b.png\" n=3"), std::string::npos) << l1;
  EXPECT_NE(l2.find("DEBUG nav:"), std::string::npos) << l2;
  log::setQuiet(false);
}

TEST(Log, UnwritableFileIsAnInputError) {
  EXPECT_THROW(log::setFile("/nonexistent-dir/x/y.log"), InputError);
}
