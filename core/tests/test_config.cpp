#include <gtest/gtest.h>

#include <fstream>

#include "sketchnav/core/config.h"
#include "test_data.h"

using namespace sketchnav;

namespace {
struct DemoParams {
  double lambda = 0.5;  // [1/s]
  int window_count = 100;
  bool enabled = true;
  std::string name = "demo";
  template <class B>
  void bind(B& b) {
    b("lambda", lambda);
    b("window_count", window_count);
    b("enabled", enabled);
    b("name", name);
  }
  void validate() const {
    require(lambda > 0 && lambda < 10, "demo.lambda", "must be in (0, 10)");
    require(window_count >= 1, "demo.window_count", "must be >= 1");
  }
};
}  // namespace

TEST(Config, DefaultsStayWithoutOverrides) {
  DemoParams p;
  applyConfig(p, Config(), "demo");
  EXPECT_DOUBLE_EQ(p.lambda, 0.5);
  EXPECT_EQ(p.window_count, 100);
}

TEST(Config, SetOverridesWithTypedValues) {
  Config c;
  c.set("demo.lambda=0.25");
  c.set("demo.window_count=7");
  c.set("demo.enabled=false");
  c.set("demo.name=hello world");
  DemoParams p;
  applyConfig(p, c, "demo");
  EXPECT_DOUBLE_EQ(p.lambda, 0.25);
  EXPECT_EQ(p.window_count, 7);
  EXPECT_FALSE(p.enabled);
  EXPECT_EQ(p.name, "hello world");
  EXPECT_TRUE(c.unusedKeys().empty());
}

TEST(Config, FileIsFlattenedAndSetWinsWhenAppliedLater) {
  const std::string dir = test::tempDir("config");
  const std::string path = dir + "/c.json";
  std::ofstream(path) << R"({"demo": {"lambda": 2.0, "window_count": 3}, "other": {"x": 1}})";
  Config c = Config::fromFile(path);
  c.set("demo.lambda=3");
  DemoParams p;
  applyConfig(p, c, "demo");
  EXPECT_DOUBLE_EQ(p.lambda, 3.0);
  EXPECT_EQ(p.window_count, 3);
  ASSERT_EQ(c.unusedKeys().size(), 1u);
  EXPECT_EQ(c.unusedKeys().front(), "other.x");
  EXPECT_EQ(c.toJson()["demo"]["window_count"], 3);
}

TEST(Config, ValidationNamesTheField) {
  Config c;
  c.set("demo.lambda=-1");
  DemoParams p;
  try {
    applyConfig(p, c, "demo");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("demo.lambda"), std::string::npos) << e.what();
  }
}

TEST(Config, WrongTypeNamesKeyAndOrigin) {
  Config c;
  c.set("demo.window_count=\"many\"");
  DemoParams p;
  try {
    applyConfig(p, c, "demo");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("demo.window_count"), std::string::npos) << m;
    EXPECT_NE(m.find("--set"), std::string::npos) << m;
  }
}

TEST(Config, BadFilesAreInputErrorsNamingTheFile) {
  const std::string dir = test::tempDir("config-bad");
  EXPECT_THROW(Config::fromFile(dir + "/missing.json"), InputError);
  std::ofstream(dir + "/bad.json") << "{ not json";
  try {
    Config::fromFile(dir + "/bad.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.json"), std::string::npos);
  }
  std::ofstream(dir + "/array.json") << "[1, 2]";
  EXPECT_THROW(Config::fromFile(dir + "/array.json"), InputError);
  Config c;
  EXPECT_THROW(c.set("novalue"), InputError);
}

TEST(Config, RequireAllUsedReportsTypos) {
  Config c;
  c.set("demo.lamda=0.3");  // typo
  DemoParams p;
  applyConfig(p, c, "demo");
  EXPECT_THROW(c.requireAllUsed("demo"), InputError);
}

TEST(Config, ParamsToJsonRoundTrips) {
  DemoParams p;
  p.lambda = 1.5;
  const Json j = paramsToJson(p);
  EXPECT_DOUBLE_EQ(j["lambda"].get<double>(), 1.5);
  Config c = Config::fromJson(Json{{"demo", j}});
  DemoParams q;
  applyConfig(q, c, "demo");
  EXPECT_DOUBLE_EQ(q.lambda, 1.5);
}
