#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>

#include "sketch_fixtures.h"
#include "sketchnav/core/error.h"
#include "sketchnav/mapsketch/io.h"
#include "test_data.h"

using namespace sketchnav;
using namespace sketchnav::mapsketch;
namespace fs = std::filesystem;

namespace {
Json good() {
  return sketchToJson(fixtures::lSketch());
}

// Expects an InputError whose message contains every one of `parts`.
void expectError(const Json& j, std::initializer_list<std::string> parts) {
  try {
    sketchFromJson(j, "t.sketch.json");
    ADD_FAILURE() << "accepted: " << j.dump().substr(0, 200);
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    EXPECT_EQ(m.rfind("t.sketch.json: ", 0), 0u) << m;
    for (const auto& p : parts)
      EXPECT_NE(m.find(p), std::string::npos) << "'" << p << "' not in: " << m;
  }
}
}  // namespace

TEST(SketchIo, RoundTripKeepsEverything) {
  const Sketch a = fixtures::lSketch();
  const Sketch b = sketchFromJson(sketchToJson(a));
  EXPECT_EQ(b.format, 1);
  EXPECT_EQ(b.name, a.name);
  ASSERT_EQ(b.landmarks.size(), a.landmarks.size());
  EXPECT_EQ(b.landmarks[2].class_name, a.landmarks[2].class_name);
  EXPECT_DOUBLE_EQ(b.landmarks[2].rect.w, a.landmarks[2].rect.w);
  EXPECT_DOUBLE_EQ(b.landmarks[2].distance_m, a.landmarks[2].distance_m);
  ASSERT_EQ(b.path.size(), a.path.size());
  EXPECT_EQ(b.path[17], a.path[17]);
  EXPECT_EQ(b.start, a.start);
  EXPECT_EQ(b.goal, a.goal);
}

TEST(SketchIo, FileTextParsesBackToTheSameSketch) {
  Sketch a = fixtures::lSketch();
  a.notes = "drawn by hand";
  const std::string text = sketchToText(a);
  EXPECT_EQ(sketchToJson(sketchFromText(text)), sketchToJson(a));
  EXPECT_LT(std::count(text.begin(), text.end(), '\n'), static_cast<long>(a.path.size() / 8 + 20))
      << "path points are packed, not one number per line";
  EXPECT_EQ(text.find("\"format\""), 4u) << "format comes first for people reading the file";
}

TEST(SketchIo, SaveAndLoadAFile) {
  const std::string dir = sketchnav::test::tempDir("sketchio");
  const std::string p = dir + "/a.sketch.json";
  saveSketch(fixtures::lSketch(), p);
  const Sketch b = loadSketch(p);
  EXPECT_EQ(b.landmarks.size(), 4u);
  EXPECT_FALSE(fs::exists(p + ".tmp"));
}

TEST(SketchIo, AGoalDoorwayRoundTripsAndReachesTheRoute) {
  Sketch a = fixtures::lSketch();
  EXPECT_FALSE(sketchToJson(a).contains("goal_place")) << "a plain goal writes no goal_place";
  a.goal_place.kind = GoalPlace::Kind::Doorway;
  a.goal_place.standoff_m = 0.7;
  const std::string text = sketchToText(a);
  EXPECT_NE(text.find("\"goal_place\": {\"kind\":\"doorway\""), std::string::npos) << text;
  const Sketch b = sketchFromText(text);
  EXPECT_EQ(b.goal_place.kind, GoalPlace::Kind::Doorway);
  EXPECT_DOUBLE_EQ(b.goal_place.standoff_m, 0.7);
  const Route r = toRoute(b);
  EXPECT_EQ(r.goal_place.kind, GoalPlace::Kind::Doorway);
  EXPECT_DOUBLE_EQ(r.goal_place.standoff_m, 0.7);
  EXPECT_EQ(routeToJson(r)["goal_place"]["kind"], "doorway");
  // Without a standoff the default applies; "point" is the plain goal.
  Json j = good();
  j["goal_place"] = {{"kind", "doorway"}};
  EXPECT_DOUBLE_EQ(sketchFromJson(j).goal_place.standoff_m, GoalPlace{}.standoff_m);
  j["goal_place"] = {{"kind", "point"}};
  EXPECT_EQ(sketchFromJson(j).goal_place.kind, GoalPlace::Kind::Point);
}

TEST(SketchValidation, ABadGoalPlaceNamesTheField) {
  Json j = good();
  j["goal_place"] = {{"kind", "window"}};
  expectError(j, {"goal_place.kind", "'window'", "doorway"});
  j["goal_place"] = {{"kind", "doorway"}, {"standoff_m", -0.2}};
  expectError(j, {"goal_place.standoff_m", "[0, 3]"});
  j["goal_place"] = {{"kind", "doorway"}, {"width", 1}};
  expectError(j, {"goal_place.width", "unknown field"});
  j["goal_place"] = "doorway";
  expectError(j, {"goal_place", "expected an object"});
  j["goal_place"] = Json::object();
  expectError(j, {"goal_place.kind", "missing"});
}

// A 1x1 PNG as the editor stores a floor plan: a base64 data URL.
const char* kPlanPng =
    "data:image/png;base64,iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mP8z8Dw"
    "HwAFBQIAX8jx0gAAAABJRU5ErkJggg==";

TEST(SketchIo, AFloorPlanRoundTripsWithItsScale) {
  Sketch a = fixtures::lSketch();
  EXPECT_FALSE(sketchToJson(a).contains("floor_plan")) << "no plan, no field";
  FloorPlan fp;
  fp.image = kPlanPng;
  fp.rect = {0, 0, a.canvas_width, a.canvas_height};
  fp.m_per_px = 0.025;
  fp.scale_points = {{100, 200}, {300, 200}};
  a.floor_plan = fp;
  const std::string text = sketchToText(a);
  EXPECT_NE(text.find("\"floor_plan\": {\"rect\""), std::string::npos)
      << text.substr(text.size() - 400);
  const Sketch b = sketchFromText(text);
  ASSERT_TRUE(b.floor_plan.has_value());
  EXPECT_EQ(b.floor_plan->image, kPlanPng);
  EXPECT_DOUBLE_EQ(b.floor_plan->rect.w, a.canvas_width);
  EXPECT_DOUBLE_EQ(b.floor_plan->m_per_px, 0.025);
  ASSERT_EQ(b.floor_plan->scale_points.size(), 2u);
  EXPECT_EQ(b.floor_plan->scale_points[1], Eigen::Vector2d(300, 200));
  EXPECT_EQ(sketchToJson(b), sketchToJson(a));
  // The robot's route does not depend on it.
  EXPECT_EQ(routeToJson(toRoute(b)), routeToJson(toRoute(fixtures::lSketch())));
  // Without a scale: no m_per_px, no scale_points written.
  a.floor_plan->m_per_px = 0;
  a.floor_plan->scale_points.clear();
  const Json j = sketchToJson(a);
  EXPECT_FALSE(j["floor_plan"].contains("m_per_px"));
  EXPECT_FALSE(j["floor_plan"].contains("scale_points"));
  EXPECT_DOUBLE_EQ(sketchFromJson(j).floor_plan->m_per_px, 0);
}

TEST(SketchValidation, ABadFloorPlanNamesTheField) {
  Json j = good();
  const Json plan = {{"image", kPlanPng},
                     {"rect", {{"x", 0}, {"y", 0}, {"w", 1000}, {"h", 700}}},
                     {"m_per_px", 0.02}};
  j["floor_plan"] = plan;
  EXPECT_NO_THROW(sketchFromJson(j));
  j["floor_plan"]["opacity"] = 0.4;
  expectError(j, {"floor_plan.opacity", "unknown field"});
  j["floor_plan"] = plan;
  j["floor_plan"]["image"] = "http://example.invalid/plan.png";
  expectError(j, {"floor_plan.image", "data URL"});
  j["floor_plan"]["image"] = "data:text/html;base64,PGI+";
  expectError(j, {"floor_plan.image", "data URL"});
  j["floor_plan"]["image"] = "data:image/png;base64,iVBO\"><script>";
  expectError(j, {"floor_plan.image", "not base64"});
  j["floor_plan"]["image"] = "data:image/png;base64,iVB";
  expectError(j, {"floor_plan.image", "truncated"});
  j["floor_plan"]["image"] =
      std::string("data:image/png;base64,") + std::string(kMaxFloorPlanBytes, 'A');
  expectError(j, {"floor_plan.image", "too large"});
  j["floor_plan"] = plan;
  j["floor_plan"].erase("image");
  expectError(j, {"floor_plan.image", "missing"});
  j["floor_plan"] = plan;
  j["floor_plan"]["rect"]["w"] = 0;
  expectError(j, {"floor_plan.rect", "positive"});
  j["floor_plan"] = plan;
  j["floor_plan"]["m_per_px"] = -1;
  expectError(j, {"floor_plan.m_per_px", "positive"});
  j["floor_plan"]["m_per_px"] = 1e9;
  expectError(j, {"floor_plan.m_per_px", "(0, 100]"});
  j["floor_plan"] = plan;
  j["floor_plan"]["scale_points"] = {{1, 2}};
  expectError(j, {"floor_plan.scale_points", "2 points"});
  j["floor_plan"]["scale_points"] = {{1, 2}, {90000, 2}};
  expectError(j, {"floor_plan.scale_points[1]", "outside the canvas"});
  j["floor_plan"] = "plan.png";
  expectError(j, {"floor_plan", "expected an object"});
}

TEST(SketchIo, PointsAsObjectsAreAccepted) {
  Json j = good();
  j["start"] = {{"x", 100}, {"y", 600}};
  EXPECT_EQ(sketchFromJson(j).start, Eigen::Vector2d(100, 600));
}

TEST(SketchValidation, MissingOrWrongFormat) {
  Json j = good();
  j.erase("format");
  expectError(j, {"format", "missing"});
  j["format"] = 2;
  expectError(j, {"format", "newer"});
  j["format"] = "1";
  expectError(j, {"format", "integer"});
}

TEST(SketchValidation, WrongTypesNameTheField) {
  Json j = good();
  j["landmarks"][1]["distance_m"] = "3";
  expectError(j, {"landmarks[1].distance_m", "expected a number, got a string"});
  j = good();
  j["path"][3] = {1, 2, 3};
  expectError(j, {"path[3]", "[x, y]"});
  j = good();
  j["landmarks"] = Json::object();
  expectError(j, {"landmarks", "expected an array"});
  j = good();
  j["landmarks"][0]["rect"]["w"] = nullptr;
  expectError(j, {"landmarks[0].rect.w", "null"});
}

TEST(SketchValidation, NaNAndInfinityAreRefused) {
  Json j = good();
  j["landmarks"][0]["distance_m"] = std::numeric_limits<double>::quiet_NaN();
  expectError(j, {"landmarks[0].distance_m", "finite"});
  j = good();
  j["path"][5][0] = std::numeric_limits<double>::infinity();
  expectError(j, {"path[5][0]", "finite"});
}

TEST(SketchValidation, NonPositiveAndAbsurdDistances) {
  Json j = good();
  j["landmarks"][2]["distance_m"] = 0;
  expectError(j, {"landmarks[2].distance_m", "positive"});
  j["landmarks"][2]["distance_m"] = -4;
  expectError(j, {"landmarks[2].distance_m", "positive"});
  j["landmarks"][2]["distance_m"] = 25000;
  expectError(j, {"landmarks[2].distance_m", "absurd"});
}

TEST(SketchValidation, DuplicateIds) {
  Json j = good();
  j["landmarks"][3]["id"] = "A";
  expectError(j, {"landmarks[3].id", "duplicate", "'A'"});
}

TEST(SketchValidation, TooFewPathPoints) {
  Json j = good();
  j["path"] = Json::array({{100, 600}});
  expectError(j, {"path", "at least 2 points, got 1"});
}

TEST(SketchValidation, TooManyPathPoints) {
  Json j = good();
  Json path = Json::array();
  for (size_t i = 0; i <= kMaxPathPoints; ++i) path.push_back({100 + 0.01 * i, 600});
  j["path"] = path;
  expectError(j, {"path", "too many points"});
}

TEST(SketchValidation, PathThatNeverComesNearALandmark) {
  Json j = good();
  for (auto& l : j["landmarks"]) {  // all landmarks into the top-left corner
    l["rect"]["x"] = 10;
    l["rect"]["y"] = 10;
  }
  j["path"] = Json::array({{600, 650}, {990, 650}});
  j["start"] = {600, 650};
  j["goal"] = {990, 650};
  expectError(j, {"path", "never comes near a landmark"});
}

TEST(SketchValidation, UnknownFieldsAndBadGeometry) {
  Json j = good();
  j["landmark"] = Json::array();
  expectError(j, {"landmark", "unknown field"});
  j = good();
  j["landmarks"][0]["rect"]["h"] = 0;
  expectError(j, {"landmarks[0].rect", "positive"});
  j = good();
  j["goal"] = {5000, 100};
  expectError(j, {"goal", "outside the canvas"});
  j = good();
  j["canvas"]["width"] = -1;
  expectError(j, {"canvas.width"});
  j = good();
  j["landmarks"] = Json::array();
  expectError(j, {"landmarks", "at least one"});
}

TEST(SketchValidation, UnknownClass) {
  const Sketch s = fixtures::lSketch();
  EXPECT_NO_THROW(
      validateClasses(s, {"Oatly-Oat-Milk", "Arla-Standard-Milk", "Bravo-Orange-Juice"}));
  try {
    validateClasses(s, {"Oatly-Oat-Milk", "Arla-Standard-Milk"}, "f.sketch.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("landmarks[3].class: unknown class 'Bravo-Orange-Juice'"),
              std::string::npos)
        << e.what();
  }
}

TEST(SketchValidation, BadJsonAndOversizedText) {
  try {
    sketchFromText("{\"format\": 1,,}", "x.sketch.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("x.sketch.json: not valid JSON"), std::string::npos)
        << e.what();
  }
  const std::string big(kMaxSketchBytes + 1, ' ');
  try {
    sketchFromText(big, "big.sketch.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("too large"), std::string::npos) << e.what();
  }
}

TEST(SketchValidation, OversizedAndMissingFiles) {
  const std::string dir = sketchnav::test::tempDir("sketchbig");
  const std::string p = dir + "/big.sketch.json";
  {
    std::ofstream out(p);
    out << std::string(kMaxSketchBytes + 10, ' ');
  }
  EXPECT_THROW(loadSketch(p), InputError);
  EXPECT_THROW(loadSketch(dir + "/none.sketch.json"), InputError);
}

TEST(LandmarkSet, ClassesAreTheFolderNames) {
  const auto classes = landmarkClasses(sketchnav::test::sourceDir() + "/share/landmarks");
  EXPECT_EQ(classes.size(), 8u);
  EXPECT_NE(std::find(classes.begin(), classes.end(), "Oatly-Oat-Milk"), classes.end());
  EXPECT_THROW(landmarkClasses("/nonexistent-dir"), InputError);
}

TEST(Examples, ShippedSketchesAreValidAndConvert) {
  const fs::path dir = fs::path(sketchnav::test::sourceDir()) / "share" / "sketches";
  ASSERT_TRUE(fs::is_directory(dir));
  const auto classes = landmarkClasses(sketchnav::test::sourceDir() + "/share/landmarks");
  int n = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name.size() < 12 || name.substr(name.size() - 12) != ".sketch.json") continue;
    SCOPED_TRACE(name);
    const Sketch s = loadSketch(e.path().string());
    EXPECT_NO_THROW(validateClasses(s, classes));
    const Route r = toRoute(s);
    EXPECT_GE(r.sections.size(), 1u);
    EXPECT_GT(r.total_length_m, 1.0);
    ++n;
  }
  EXPECT_GE(n, 2);
}

TEST(Examples, LabSketchFollowsThePapersRoute) {
  // The default sketch of `sketchnav run`: eight landmarks passed in the order of the lab
  // world's route, on the sides a robot driving it sees them.
  const Sketch s = loadSketch(sketchnav::test::sourceDir() + "/share/sketches/lab.sketch.json");
  ASSERT_EQ(s.landmarks.size(), 8u);
  EXPECT_GE(s.path.size(), 200u);
  const Route r = toRoute(s);
  std::vector<std::string> order;
  std::map<std::string, Side> side;
  for (const auto& sec : r.sections)
    for (const auto& l : sec.landmarks) {
      order.push_back(l.id);
      side[l.id] = l.side;
    }
  EXPECT_EQ(order, (std::vector<std::string>{"L1", "L2", "L3", "L4", "L5", "L6", "L7", "L8"}));
  EXPECT_EQ(side["L1"], Side::Right);
  EXPECT_EQ(side["L2"], Side::Left);
  EXPECT_EQ(side["L3"], Side::Right);
  EXPECT_EQ(side["L5"], Side::Left);
  EXPECT_EQ(side["L6"], Side::Left);
  EXPECT_EQ(side["L7"], Side::Right);
  // Drawn as a person would: the distances do not quite agree with the drawing, but the
  // route is about as long as the real one (~22.5 m in an 18 x 13 m lab).
  EXPECT_GT(r.scale_residual, 0.05);
  EXPECT_GT(r.total_length_m, 18);
  EXPECT_LT(r.total_length_m, 30);
  // The paper's goal is the right door of room B: the robot stops 0.6 m in front of it.
  EXPECT_EQ(r.goal_place.kind, GoalPlace::Kind::Doorway);
  EXPECT_DOUBLE_EQ(r.goal_place.standoff_m, 0.6);
}

// Bad-input campaign (issue 28): deep nesting and 1e400 name the file, never a bare library
// message; huge values are quoted only in part.
TEST(SketchValidation, DeepNestingAndNumberOverflowNameTheFile) {
  const std::string deep =
      "{\"format\": " + std::string(100000, '[') + std::string(100000, ']') + "}";
  try {
    sketchFromText(deep, "deep.sketch.json");
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("deep.sketch.json: JSON nested deeper"), std::string::npos)
        << e.what();
  }
  const std::string dir = test::tempDir("sketch_overflow");
  const std::string p = dir + "/big.sketch.json";
  std::string text = sketchToJson(fixtures::lSketch()).dump();
  text.replace(text.find("\"distance_m\":") + 13, 0, "1e400,\"x\":");
  std::ofstream(p) << text;
  try {
    loadSketch(p);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find(p), std::string::npos) << m;
    EXPECT_NE(m.find("overflow"), std::string::npos) << m;
  }
}
