// The registry alone (sketchnav::hw, no driver registered): factories by scheme, unknown
// schemes and parameters named. The drivers' own schemes are tested in hw/drivers/tests.
#include <gtest/gtest.h>

#include <cmath>

#include "sketchnav/core/error.h"
#include "sketchnav/hw/registry.h"

using namespace sketchnav;
using namespace sketchnav::hw;

namespace {
struct NullRange final : RangeSensor {
  explicit NullRange(std::string u = "null://") : uri_(std::move(u)) {}
  bool read(RangeScan& s) override {
    s.ranges = {1.0f};
    return true;
  }
  DeviceStats stats() const override { return {}; }
  std::string uri() const override { return uri_; }
  std::string uri_;
};
}  // namespace

TEST(Registry, CustomFactoriesAreUsedByScheme) {
  Registry::instance().addRange(
      "null", [](const Uri&, DeviceContext&) { return std::make_unique<NullRange>(); });
  DeviceContext ctx;
  auto r = Registry::instance().createRange("null://x", ctx);
  RangeScan s;
  ASSERT_TRUE(r->read(s));
  EXPECT_EQ(s.ranges.size(), 1u);
}

TEST(Registry, UnknownSchemeNamesItAndTheKnownOnes) {
  Registry::instance().addRange(
      "null", [](const Uri&, DeviceContext&) { return std::make_unique<NullRange>(); });
  DeviceContext ctx;
  try {
    Registry::instance().createRange("nolaser://x", ctx);
    FAIL();
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("'nolaser'"), std::string::npos) << m;
    EXPECT_NE(m.find("null"), std::string::npos) << m;
  }
  EXPECT_THROW(Registry::instance().createRange("not a uri", ctx), InputError);
}

// A scheme registered without parameters takes none; "*" lets any key through; a known one
// abbreviated or misspelt is named.
TEST(Registry, UnknownUriParameterIsRefusedBeforeTheFactoryRuns) {
  int made = 0;
  Registry::instance().addRange("bare", [&made](const Uri&, DeviceContext&) {
    ++made;
    return std::make_unique<NullRange>();
  });
  Registry::instance().addRange(
      "open", [](const Uri&, DeviceContext&) { return std::make_unique<NullRange>(); },
      {Registry::kAnyParameter});
  Registry::instance().addRange(
      "tuned", [](const Uri&, DeviceContext&) { return std::make_unique<NullRange>(); },
      {"rate_hz", "loop"});
  DeviceContext ctx;
  try {
    Registry::instance().createRange("bare://x?rate=3", ctx);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "range sensor URI 'bare://x?rate=3': unknown parameter 'rate' (bare:// takes no "
                 "parameters)");
  }
  EXPECT_EQ(made, 0);
  try {
    Registry::instance().createRange("tuned://x?rate=3", ctx);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(),
                 "range sensor URI 'tuned://x?rate=3': unknown parameter 'rate' (did you mean "
                 "'rate_hz'?)");
  }
  EXPECT_NO_THROW(Registry::instance().createRange("open://x?rate=3&anything=1", ctx));
  EXPECT_NO_THROW(Registry::instance().createRange("tuned://x?rate_hz=3&loop=1", ctx));
  EXPECT_NO_THROW(Registry::instance().createRange("bare://x", ctx));
  EXPECT_EQ(made, 1);
}

TEST(Intrinsics, FromFovPutsThePrincipalPointAtTheCentre) {
  const Intrinsics k = Intrinsics::fromFov(20, 10, M_PI / 2);
  EXPECT_NEAR(k.fx, 10.0, 1e-12);
  EXPECT_NEAR(k.fy, 10.0, 1e-12);
  EXPECT_NEAR(k.cx, 9.5, 1e-12);
  EXPECT_NEAR(k.cy, 4.5, 1e-12);
}
