// World plausibility checks (sim/world_check.h): each check on a world built to break it, and
// the shipped worlds passing them. Part of the test_sim executable.
#include <gtest/gtest.h>

#include <cmath>

#include "sketchnav/core/error.h"
#include "sketchnav/core/paths.h"
#include "sketchnav/sim/world.h"
#include "sketchnav/sim/world_check.h"

using namespace sketchnav;
using sim::Vec2;

namespace {

// A 6 x 4 m room, 0.1 m walls on its centre lines; south wall = walls[0] (y in [-0.05, 0.05]).
Json roomJson() {
  return {{"floor", {{0, 0}, {6, 0}, {6, 4}, {0, 4}}},
          {"walls",
           {{{"name", "south"}, {"from", {0, 0}}, {"to", {6, 0}}},
            {{"name", "east"}, {"from", {6, 0}}, {"to", {6, 4}}},
            {{"name", "north"}, {"from", {6, 4}}, {"to", {0, 4}}},
            {{"name", "west"}, {"from", {0, 4}}, {"to", {0, 0}}}}},
          {"landmarks", Json::array()},
          {"obstacles", Json::array()},
          {"start", {{"x", 1}, {"y", 2}}},
          {"goal", {{"x", 5}, {"y", 2}}}};
}

Json poster(const Vec2& p, double yaw_deg, double elevation = 1.0,
            const std::string& cls = "Oatly-Oat-Milk", const std::string& id = "L1") {
  return {{"id", id},
          {"class", cls},
          {"texture", "textures/Oatly-Oat-Milk/Oatly-Oat-Milk_Iconic.jpg"},
          {"position", {p.x(), p.y()}},
          {"yaw_deg", yaw_deg},
          {"elevation", elevation}};
}

Json box(const std::string& name, const Vec2& c, const Vec2& size, double height = 0.8) {
  return {{"name", name},
          {"shape", "box"},
          {"centre", {c.x(), c.y()}},
          {"size", {size.x(), size.y()}},
          {"height", height}};
}

sim::World load(const Json& j) {
  return sim::worldFromJson(j, "w.world.json", resourceDir());
}

std::string loadError(const Json& j) {
  try {
    load(j);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

int count(const std::vector<sim::WorldIssue>& v, bool errors) {
  int n = 0;
  for (const auto& i : v) n += i.isError() == errors;
  return n;
}

}  // namespace

TEST(WorldCheck, PosterOnAWallFaceFacingTheRoomIsFine) {
  Json j = roomJson();
  j["landmarks"].push_back(poster({3, 0.05}, 90));
  const auto issues = sim::checkWorldGeometry(load(j));
  EXPECT_TRUE(issues.empty()) << issues.front().text("w");
}

TEST(WorldCheck, PosterInsideAWallIsAnErrorNamingTheFieldAndTheWall) {
  Json j = roomJson();
  j["landmarks"].push_back(poster({3, 0.02}, 90));
  const std::string e = loadError(j);
  EXPECT_NE(e.find("w.world.json: landmarks[0].position:"), std::string::npos) << e;
  EXPECT_NE(e.find("inside walls[0] ('south')"), std::string::npos) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos);  // one line
}

TEST(WorldCheck, PosterFacingIntoItsWallIsAnError) {
  Json j = roomJson();
  j["landmarks"].push_back(poster({3, 0.05}, -90));
  const std::string e = loadError(j);
  EXPECT_NE(e.find("landmarks[0].yaw_deg:"), std::string::npos) << e;
  EXPECT_NE(e.find("faces into walls[0]"), std::string::npos) << e;
}

TEST(WorldCheck, FreeStandingPosterIsAWarningAndLoads) {
  Json j = roomJson();
  j["landmarks"].push_back(poster({3, 2}, 0));
  const sim::World w = load(j);  // no throw
  const auto issues = sim::checkWorldGeometry(w);
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_FALSE(issues[0].isError());
  EXPECT_EQ(issues[0].field, "landmarks[0].position");
  EXPECT_NE(issues[0].message.find("on no wall or furniture face"), std::string::npos);
  EXPECT_NE(issues[0].text("w").find("warning"), std::string::npos);
}

TEST(WorldCheck, PosterOnFurnitureFaceOrTopIsFineInsideBelowTheTopIsAnError) {
  Json j = roomJson();
  j["obstacles"].push_back(box("cabinet", {3, 2}, {1.0, 0.6}, 0.8));  // y in [1.7, 2.3]
  Json face = j, top = j, inside = j;
  face["landmarks"].push_back(poster({3, 2.3}, 90, 0.5));
  top["landmarks"].push_back(poster({3, 2}, 90, 1.0));  // bottom 0.8 = the top
  inside["landmarks"].push_back(poster({3, 2.1}, 90, 0.5));
  EXPECT_EQ(count(sim::checkWorldGeometry(load(face)), true), 0);
  EXPECT_TRUE(sim::checkWorldGeometry(load(top)).empty());
  const std::string e = loadError(inside);
  EXPECT_NE(e.find("landmarks[0].position:"), std::string::npos) << e;
  EXPECT_NE(e.find("inside obstacles[0] ('cabinet')"), std::string::npos) << e;
}

TEST(WorldCheck, ObstacleOverlappingAWallIsAnError) {
  Json j = roomJson();
  j["obstacles"].push_back(box("desk", {3, 0.25}, {1.0, 0.6}));  // y down to -0.05: 0.10 deep
  const std::string e = loadError(j);
  EXPECT_NE(e.find("w.world.json: obstacles[0]: 'desk' overlaps walls[0] ('south')"),
            std::string::npos)
      << e;
  // A cylinder too.
  Json c = roomJson();
  c["obstacles"].push_back(
      {{"name", "bin"}, {"shape", "cylinder"}, {"centre", {5.9, 2}}, {"radius", 0.2}});
  EXPECT_NE(loadError(c).find("obstacles[0]: 'bin' overlaps walls[1] ('east')"), std::string::npos);
  // Standing against the wall (touching) is fine.
  Json t = roomJson();
  t["obstacles"].push_back(box("desk", {3, 0.35}, {1.0, 0.6}));
  EXPECT_TRUE(sim::checkWorldGeometry(load(t)).empty());
}

TEST(WorldCheck, ObstaclesOverlappingEachOtherAreAWarning) {
  Json j = roomJson();
  j["obstacles"].push_back(box("desk", {3, 2}, {1.0, 0.6}));
  j["obstacles"].push_back(box("return", {3.6, 2.2}, {0.6, 1.0}));
  const auto issues = sim::checkWorldGeometry(load(j));
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_FALSE(issues[0].isError());
  EXPECT_EQ(issues[0].field, "obstacles[1]");
  EXPECT_NE(issues[0].message.find("overlaps obstacles[0] ('desk')"), std::string::npos);
}

TEST(WorldCheck, UnknownLandmarkClassIsAnErrorPerLandmark) {
  Json j = roomJson();
  j["landmarks"].push_back(poster({3, 0.05}, 90, 1.0, "Oatly-Oat-Milk", "L1"));
  j["landmarks"].push_back(poster({5.95, 2}, 180, 1.0, "Oatley-Oat-Milk", "L2"));
  const sim::World w = load(j);
  const auto issues = sim::checkLandmarkClasses(w, {"Oatly-Oat-Milk", "Arla-Standard-Milk"});
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_TRUE(issues[0].isError());
  EXPECT_EQ(issues[0].field, "landmarks[1].class");
  EXPECT_NE(issues[0].message.find("'Oatley-Oat-Milk' is not in the landmark set"),
            std::string::npos);
  EXPECT_TRUE(sim::checkLandmarkClasses(w, {"Oatly-Oat-Milk", "Oatley-Oat-Milk"}).empty());
}

TEST(WorldCheck, StartHeadingAgainstTheSketchWarnsThenErrs) {
  // Landmarks ahead-left and ahead-right of a start facing +x; the route frame is the world
  // frame shifted (start at the origin, first stroke along +y: heading 90 deg).
  Json j = roomJson();
  j["landmarks"].push_back(poster({5.95, 3.0}, 180, 1.0, "Oatly-Oat-Milk", "A"));
  j["landmarks"].push_back(poster({5.95, 1.0}, 180, 1.0, "Oatly-Oat-Milk", "B"));
  const sim::World w = load(j);  // start (1, 2) yaw 0
  auto placed = [&](double err_deg) {
    // The sketch as drawn: the world rotated into a route frame whose first stroke is +y,
    // then turned by err_deg (what the start heading gets wrong).
    sim::RoutePlacement r;
    r.start = {10, 10};
    r.start_heading = M_PI / 2;
    const double a = M_PI / 2 + err_deg * M_PI / 180;
    for (const auto& l : w.landmarks) {
      const Vec2 d = l.position - Vec2(w.start.x, w.start.y);
      r.landmarks.push_back({l.id, r.start + Vec2(std::cos(a) * d.x() - std::sin(a) * d.y(),
                                                  std::sin(a) * d.x() + std::cos(a) * d.y())});
    }
    return r;
  };
  double delta = 1;
  EXPECT_TRUE(sim::checkStartHeading(w, placed(0), "s.sketch.json", {}, &delta).empty());
  EXPECT_NEAR(delta, 0, 1e-9);
  EXPECT_TRUE(sim::checkStartHeading(w, placed(20), "s.sketch.json").empty());
  const auto warn = sim::checkStartHeading(w, placed(40), "s.sketch.json", {}, &delta);
  ASSERT_EQ(warn.size(), 1u);
  EXPECT_FALSE(warn[0].isError());
  EXPECT_EQ(warn[0].field, "start.yaw_deg");
  EXPECT_NEAR(delta, -40 * M_PI / 180, 1e-6);  // the sketch must turn back clockwise
  EXPECT_NE(warn[0].message.find("40 deg clockwise"), std::string::npos) << warn[0].message;
  const auto err = sim::checkStartHeading(w, placed(-120), "s.sketch.json");
  ASSERT_EQ(err.size(), 1u);
  EXPECT_TRUE(err[0].isError());
  // No sketched landmark in the world: nothing to say.
  sim::RoutePlacement none;
  none.landmarks = {{"Z", {3, 3}}};
  EXPECT_TRUE(sim::checkStartHeading(w, none, "s").empty());
}

TEST(WorldCheck, ShippedWorldsHaveNoErrors) {
  for (const std::string name : {"lab", "corridor"}) {
    const sim::World w = sim::loadWorldByName(name);
    EXPECT_EQ(count(sim::checkWorldGeometry(w), true), 0) << name;
  }
}

TEST(WorldCheck, FreePathFoundAroundFurnitureAndNotThroughAWall) {
  Json j = roomJson();
  const double open = sim::freePathLength(load(j));
  EXPECT_GT(open, 3.3);  // start (1, 2) to the goal circle around (5, 2), radius 0.5: 3.5 m
  EXPECT_LT(open, 3.7);
  // A partition across the room with a 0.8 m gap near the north wall: the way goes round.
  Json g = roomJson();
  g["walls"].push_back({{"name", "partition"}, {"from", {3, 0}}, {"to", {3, 3.2}}});
  const double around = sim::freePathLength(load(g));
  EXPECT_GT(around, 4.2);  // via the gap at (3, 3.6): about 4.4 m
  // Closed completely: none.
  Json c = roomJson();
  c["walls"].push_back({{"name", "partition"}, {"from", {3, 0}}, {"to", {3, 4}}});
  EXPECT_LT(sim::freePathLength(load(c)), 0);
  // A gap narrower than the robot (0.3 m < 2 x 0.25 m) is no way either.
  Json n = roomJson();
  n["walls"].push_back({{"name", "partition"}, {"from", {3, 0}}, {"to", {3, 3.7}}});
  EXPECT_LT(sim::freePathLength(load(n)), 0);
}
