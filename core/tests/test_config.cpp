#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>

#include "sketchnav/core/camera_mount.h"
#include "sketchnav/core/config.h"
#include "sketchnav/core/error.h"
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

TEST(Config, UnknownSettingNamesTheClosestKnownKey) {
  Config c;
  c.set("demo.lamda=0.3");  // typo
  DemoParams p;
  applyConfig(p, c, "demo");
  EXPECT_DOUBLE_EQ(p.lambda, 0.5);  // the typo changed nothing
  try {
    c.requireAllUsed();
    FAIL() << "a typo was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "--set demo.lamda: unknown setting 'demo.lamda' (did you mean 'demo.lambda'?)");
  }
}

TEST(Config, UnknownSettingFromAFileNamesTheFile) {
  Config c = Config::fromJson(Json{{"demo", {{"window_cont", 3}}}}, "my.json");
  DemoParams p;
  applyConfig(p, c, "demo");
  try {
    c.requireAllUsed();
    FAIL() << "a typo was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "my.json: unknown setting 'demo.window_cont' (did you mean 'demo.window_count'?)");
  }
}

TEST(Config, NoSuggestionWhenNothingIsKnown) {
  Config c;
  c.set("x.y=1");
  try {
    c.requireAllUsed();
    FAIL() << "an unused key was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown setting 'x.y' (this command takes no settings)"),
              std::string::npos)
        << e.what();
  }
}

// An empty object sets nothing, but a misspelt key holding one was accepted without a word
// (issue 28: 0 silent accepts of unknown keys in --config).
TEST(Config, AnEmptyObjectUnderAnUnknownKeyIsRefusedLikeAnyUnknownSetting) {
  const auto refusal = [](const Json& j, const std::vector<std::string>& deferred = {}) {
    Config c = Config::fromJson(j, "my.json");
    DemoParams p;
    try {
      applyConfig(p, c, "demo");
      if (deferred.empty())
        c.requireAllUsed();
      else
        c.requireAllUsedExcept(deferred);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(refusal(Json::parse(R"({"demo": {"lamda": {}}})")),
            "my.json: unknown setting 'demo.lamda' (did you mean 'demo.lambda'?)");
  EXPECT_EQ(refusal(Json::parse(R"({"dmeo": {}})")),
            "my.json: unknown setting 'dmeo' (did you mean 'demo.name'?)");
  EXPECT_EQ(refusal(Json::parse(R"({"demo": {"lambda": {}}})")),
            "my.json: setting 'demo.lambda' has the wrong type (got {})");
  // A section of known settings may be empty; a deferred one is checked later.
  EXPECT_EQ(refusal(Json::parse(R"({"demo": {}})")), "");
  EXPECT_EQ(refusal(Json::parse(R"({"camera": {"folder": {}}})"), {"camera."}), "");
  EXPECT_NE(refusal(Json::parse(R"({"camera": {"folder": {}}})")), "");
}

// Integer settings take whole numbers in their type's range only (issue 28: `--set
// sim.seed=-1` ran with seed 18446744073709551615).
struct IntegerParams {
  std::uint64_t seed = 1;  // a seed
  int count = 1;           // a count
  template <class B>
  void bind(B& b) {
    b("seed", seed);
    b("count", count);
  }
  void validate() const {}
};

TEST(Config, IntegerSettingsRefuseNegativeFractionalAndOutOfRangeNumbers) {
  using P = IntegerParams;
  const auto apply = [](const std::string& assignment) {
    Config c;
    c.set(assignment);
    P p;
    try {
      applyConfig(p, c, "p");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("taken: seed ") + std::to_string(p.seed) + ", count " +
           std::to_string(p.count);
  };
  EXPECT_EQ(apply("p.seed=-1"),
            "--set p.seed: setting 'p.seed' must be a whole number in [0, 18446744073709551615] "
            "(got -1)");
  EXPECT_EQ(apply("p.count=4294967297"),
            "--set p.count: setting 'p.count' must be a whole number in [-2147483648, "
            "2147483647] (got 4294967297)");
  EXPECT_EQ(apply("p.count=2.7"),
            "--set p.count: setting 'p.count' must be a whole number in [-2147483648, "
            "2147483647] (got 2.7)");
  EXPECT_EQ(apply("p.seed=18446744073709551615"), "taken: seed 18446744073709551615, count 1");
  EXPECT_EQ(apply("p.count=-3"), "taken: seed 1, count -3");
  EXPECT_EQ(apply("p.count=1e3"), "taken: seed 1, count 1000");
  EXPECT_NE(apply("p.count=\"7\"").find("has the wrong type"), std::string::npos);
}

TEST(Config, CopiesShareTheUsageRecord) {
  Config c;
  c.set("demo.lambda=0.3");
  const Config copy = c;  // e.g. handed to a device context
  DemoParams p;
  applyConfig(p, copy, "demo");
  EXPECT_NO_THROW(c.requireAllUsed());
  EXPECT_EQ(c.knownKeys().size(), 4u);  // every bound field is known, set or not
}

TEST(Config, RequireAllUsedExceptSkipsDeferredPrefixes) {
  Config c;
  c.set("base.dani.port=5000");
  EXPECT_NO_THROW(c.requireAllUsedExcept({"base."}));
  EXPECT_THROW(c.requireAllUsedExcept({"camera."}), InputError);
}

TEST(Config, ClosestKeyIsTheNearestByEditDistance) {
  const std::vector<std::string> known = {"servo.lambda", "servo.max_w", "nav.max_w",
                                          "route.simplify_tolerance"};
  EXPECT_EQ(closestKey("servo.lamda", known), "servo.lambda");
  EXPECT_EQ(closestKey("route.simplify_tolerence", known), "route.simplify_tolerance");
  EXPECT_EQ(closestKey("nav.max_v", known), "nav.max_w");
  EXPECT_EQ(closestKey("servo.maxw", known), "servo.max_w");
  EXPECT_EQ(closestKey("anything", {}), "");
}

TEST(CameraMount, OneSettingGroupAndTheOldNamesPointToIt) {
  Config c;
  c.set("robot.camera.x_m", 0.2);
  c.set("robot.camera.pitch", 0.1);
  const CameraMount m = cameraMountFrom(c);
  EXPECT_DOUBLE_EQ(m.x_m, 0.2);
  EXPECT_DOUBLE_EQ(m.z_m, CameraMount{}.z_m);
  EXPECT_DOUBLE_EQ(m.pitch, 0.1);
  EXPECT_NO_THROW(c.requireAllUsed());
  // The quantity had three homes (servo.*, nav.perception.*, the world file); a setting under an
  // old name is an error that names the new one, not a value silently ignored.
  for (const auto& [old_key, new_key] : cameraMountRenames()) {
    Config o;
    o.set(old_key, 0.1);
    try {
      cameraMountFrom(o);
      FAIL() << old_key << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(new_key), std::string::npos) << e.what();
    }
  }
  Config bad;
  bad.set("robot.camera.pitch", 2.0);
  try {
    cameraMountFrom(bad);
    FAIL() << "a pitch of 2 rad accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("robot.camera.pitch"), std::string::npos) << e.what();
  }
}
