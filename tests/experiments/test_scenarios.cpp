// The scenario generator (run/scenario_gen.h): every family, seeded and reproducible, every
// scenario passing the world and sketch checks, and the drawing errors within their bounds
// (measured on the files, not only read back from the record). No simulation.
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <map>
#include <set>

#include "sketchnav/core/error.h"
#include "sketchnav/core/paths.h"
#include "sketchnav/mapsketch/io.h"
#include "sketchnav/run/scenario_gen.h"
#include "sketchnav/sim/simulator.h"
#include "sketchnav/sim/world.h"
#include "sketchnav/sim/world_check.h"

using namespace sketchnav;
using run::GeneratedScenario;

namespace {

std::vector<std::string> demoClasses() {
  return mapsketch::landmarkClasses(resourceDir() + "/landmarks");
}

}  // namespace

TEST(ScenarioGenerator, EveryFamilyPassesTheChecks) {
  const auto classes = demoClasses();
  for (const auto& fam : run::scenarioFamilies())
    for (std::uint64_t seed = 1; seed <= 6; ++seed) {
      const GeneratedScenario s = run::generateScenario(fam, seed, classes);
      EXPECT_TRUE(run::scenarioProblems(s, classes).empty()) << s.name;
      EXPECT_TRUE(s.warnings.empty()) << s.name << ": " << s.warnings.front();
    }
}

TEST(ScenarioGenerator, SameFamilyAndSeedGiveTheSameFilesOtherSeedsOthers) {
  const auto classes = demoClasses();
  for (const auto& fam : run::scenarioFamilies()) {
    const GeneratedScenario a = run::generateScenario(fam, 42, classes);
    const GeneratedScenario b = run::generateScenario(fam, 42, classes);
    const GeneratedScenario c = run::generateScenario(fam, 43, classes);
    EXPECT_EQ(a.world.dump(), b.world.dump()) << fam;
    EXPECT_EQ(a.sketch.dump(), b.sketch.dump()) << fam;
    EXPECT_EQ(a.toJson().dump(), b.toJson().dump()) << fam;
    EXPECT_NE(a.world.dump(), c.world.dump()) << fam;
    EXPECT_EQ(a.name, fam + "-42");
  }
  EXPECT_THROW(run::generateScenario("castle", 1, classes), InputError);
}

TEST(ScenarioGenerator, WorldsHaveWhatTheirFamilyPromises) {
  const auto classes = demoClasses();
  int people = 0, aside = 0, in_way = 0, on_furniture = 0, doors = 0, closed = 0;
  for (std::uint64_t seed = 1; seed <= 12; ++seed)
    for (const auto& fam : run::scenarioFamilies()) {
      const GeneratedScenario s = run::generateScenario(fam, seed, classes);
      const sim::World w = sim::worldFromJson(s.world, s.name, resourceDir());
      EXPECT_GE(w.landmarks.size(), 2u) << s.name;
      EXPECT_GE(w.walls.size(), 4u) << s.name;
      const double len = s.meta["route_length_m"].get<double>();
      if (fam == "mixed") {
        EXPECT_GE(len, 20.0) << s.name;
        EXPECT_LE(len, 60.0) << s.name;
      }
      if (fam == "office" || fam == "mixed") EXPECT_FALSE(w.doors.empty()) << s.name;
      for (const auto& d : w.doors) {
        ++doors;
        closed += !d.open;
      }
      for (const auto& p : s.meta["people"]) {
        ++people;
        aside += p["kind"] == "steps_aside";
      }
      in_way += s.meta["obstacle_in_the_way"].get<bool>();
      for (const auto& p : s.meta["landmark_places"]) on_furniture += p["on"] != "wall";
      // Textures: the iconic photos, never the demo model's training folder.
      for (const auto& l : w.landmarks) {
        EXPECT_NE(l.texture.find("/textures/"), std::string::npos) << l.texture;
        EXPECT_EQ(l.texture.find("/landmarks/"), std::string::npos) << l.texture;
      }
    }
  EXPECT_GT(people, 5);
  EXPECT_GT(aside, 0);
  EXPECT_LT(aside, people);
  EXPECT_GT(in_way, 0);
  EXPECT_GT(on_furniture, 5);
  EXPECT_GT(doors, 10);
  EXPECT_GT(closed, 0);
}

// The drawing errors stay within their stated bounds, read from the record and measured on
// the files: the start heading against the first stroke of the route, each sketched distance
// against the true distance, a moved landmark against where the sketch remembers it.
TEST(ScenarioGenerator, SketchErrorsAreWithinTheirBounds) {
  const auto classes = demoClasses();
  const run::SketchErrorBounds B;
  std::map<std::string, int> applied;
  for (std::uint64_t seed = 100; seed < 130; ++seed)
    for (const auto& fam : run::scenarioFamilies()) {
      const GeneratedScenario s = run::generateScenario(fam, seed, classes);
      const sim::World w = sim::worldFromJson(s.world, s.name, resourceDir());
      double bias = 1;
      std::set<std::string> moved, missing;
      for (const auto& e : s.errors) {
        ++applied[e.kind];
        const Json& p = e.params;
        if (e.kind == "rotation") {
          EXPECT_LE(std::abs(p["deg"].get<double>()), B.rotation_deg + 0.01) << s.name;
          EXPECT_GE(std::abs(p["deg"].get<double>()), 5 - 0.01) << s.name;
        } else if (e.kind == "anisotropic_scale") {
          for (const char* k : {"x", "y"})
            EXPECT_LE(std::abs(p[k].get<double>() - 1), B.scale + 1e-3) << s.name;
        } else if (e.kind == "distance_bias") {
          bias = p["factor"].get<double>();
          EXPECT_LE(std::abs(bias - 1), B.distance_bias + 1e-3) << s.name;
          EXPECT_GE(std::abs(bias - 1), 0.1 - 1e-3) << s.name;
        } else if (e.kind == "corners_misplaced") {
          EXPECT_LE(p["max_m"].get<double>(), B.corner_m + 0.01) << s.name;
        } else if (e.kind == "start_heading") {
          EXPECT_LE(std::abs(p["deg"].get<double>()), B.heading_deg + 0.01) << s.name;
        } else if (e.kind == "landmark_moved") {
          moved.insert(p["id"].get<std::string>());
          EXPECT_GE(p["moved_m"].get<double>(), B.move_min_m - 0.01) << s.name;
          EXPECT_LE(p["moved_m"].get<double>(), B.move_max_m + 0.01) << s.name;
        } else if (e.kind == "landmark_missing") {
          missing.insert(p["id"].get<std::string>());
        }
      }
      // Measured: the start heading against the route's first leg (as drawn, when its first
      // corner was drawn round the other way: the person faces the robot along their stroke).
      Eigen::Vector2d first_corner = s.route[1];
      for (const auto& e : s.errors)
        if (e.kind == "corner_wrong_side" && e.params["corner"] == 1)
          first_corner = {e.params["drawn_at"][0].get<double>(),
                          e.params["drawn_at"][1].get<double>()};
      const Eigen::Vector2d d0 = first_corner - s.route[0];
      const double first = std::atan2(d0.y(), d0.x());
      const double err = std::remainder(w.start.theta - first, 2 * M_PI) * 180 / M_PI;
      EXPECT_LE(std::abs(err), s.hasError("start_heading") ? B.heading_deg + 0.01 : 0.01) << s.name;
      // A missing landmark is in the sketch and not in the world.
      for (const auto& id : missing) EXPECT_EQ(w.findLandmark(id), nullptr) << s.name;
      // Measured: every sketched distance between landmarks that stayed where they were,
      // against the truth, within the bias, the noise (2 sigma) and the rounding.
      Eigen::Vector2d prev(w.start.x, w.start.y);
      bool prev_known = true;
      for (const auto& l : s.sketch["landmarks"]) {
        const std::string id = l["id"];
        const sim::Landmark* wl = w.findLandmark(id);
        const bool known = wl && !moved.count(id);
        if (known && prev_known) {
          const double truth = (wl->position - prev).norm() * bias;
          const double said = l["distance_m"].get<double>();
          EXPECT_LE(std::abs(said - truth),
                    truth * 2 * B.distance_noise + B.distance_round_m / 2 + 0.01)
              << s.name << " " << id << ": said " << said << " for " << truth;
        }
        if (wl) prev = wl->position;
        prev_known = known;
      }
    }
  // Every kind is drawn in this sample (p = 0.4 each over 120 scenarios).
  for (const auto& k : run::sketchErrorKinds()) EXPECT_GT(applied[k], 5) << k;
}

// Every landmark can be seen: rendered from 1 m in front of it (camera pitched at it), the view
// differs from the same view without that landmark over a large area. Catches photos buried in
// their furniture (a box rounded to centimetres once hid the photo on its face).
TEST(ScenarioGenerator, EveryLandmarkIsVisibleFromInFrontOfIt) {
  const auto classes = demoClasses();
  int checked = 0;
  for (std::uint64_t seed = 1; seed <= 3; ++seed)
    for (const auto& fam : run::scenarioFamilies()) {
      const GeneratedScenario s = run::generateScenario(fam, seed, classes);
      const sim::World w = sim::worldFromJson(s.world, s.name, resourceDir());
      for (size_t i = 0; i < w.landmarks.size(); ++i) {
        const sim::Landmark& l = w.landmarks[i];
        const Eigen::Vector2d n(std::cos(l.yaw), std::sin(l.yaw));
        sim::World with = w;
        with.pedestrians.clear();
        with.camera.pitch = std::atan2(l.elevation - with.camera.z, 1.0);
        sim::World without = with;
        without.landmarks.erase(without.landmarks.begin() + static_cast<long>(i));
        const Eigen::Vector2d robot = l.position + n * (1.0 + with.camera.x);
        const hw::Pose2D pose{robot.x(), robot.y(), std::atan2(-n.y(), -n.x())};
        sim::SimParams sp;
        sp.camera_hz = 0;
        const cv::Mat a = sim::Simulator(with, sp, 1).renderView(pose, 0.0);
        const cv::Mat b = sim::Simulator(without, sp, 1).renderView(pose, 0.0);
        cv::Mat d, g;
        cv::absdiff(a, b, d);
        cv::cvtColor(d, g, cv::COLOR_BGR2GRAY);
        EXPECT_GT(cv::countNonZero(g > 10), 3000) << s.name << " " << l.id;
        ++checked;
      }
    }
  EXPECT_GT(checked, 40);
}
