// Unit tests of the experiment variants (issue #8): every variant yields a world the simulator
// loads and a sketch the route builder accepts, with the transformation it promises, and the
// sketch noise is seeded.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <set>

#include "sketchnav/core/error.h"
#include "sketchnav/core/paths.h"
#include "sketchnav/mapsketch/io.h"
#include "sketchnav/mapsketch/route.h"
#include "sketchnav/run/experiments.h"
#include "sketchnav/run/plot.h"
#include "sketchnav/sim/world.h"

namespace sketchnav::app {
using run::ConfusionSpec;
using run::drawConfusionMatrix;
using run::drawLinePlot;
using run::plotColor;
using run::PlotSpec;
// The experiment model is the run library's (run/experiments.h); the plot writer is the app's.
using run::makeSketch;
using run::makeVariant;
using run::SketchNoise;
using run::summariseFailures;
using run::TrialFailure;
using run::trialFailure;
using run::Variant;
using run::variantNames;
using run::writeVariantSketch;
namespace {

int landmarkCount(const Variant& v) {
  return static_cast<int>(v.world["landmarks"].size());
}

TEST(ExperimentVariants, ThirteenStableNames) {
  const auto& n = variantNames();
  ASSERT_EQ(n.size(), 13u);
  EXPECT_EQ(std::set<std::string>(n.begin(), n.end()).size(), 13u);
  EXPECT_EQ(n.front(), "exp2-moved-a");
  EXPECT_EQ(n.back(), "exp4-pedestrian-right");
  EXPECT_THROW(makeVariant("exp5"), InputError);
}

TEST(ExperimentVariants, EveryVariantLoadsAndRoutes) {
  for (const auto& name : variantNames()) {
    SCOPED_TRACE(name);
    const Variant v = makeVariant(name);
    const sim::World w = sim::worldFromJson(v.world, name, resourceDir());
    EXPECT_EQ(static_cast<int>(w.landmarks.size()), landmarkCount(v));
    const Json sj = makeSketch(v, SketchNoise{}, 3);
    const mapsketch::Sketch s = mapsketch::sketchFromJson(sj, name);
    EXPECT_EQ(s.landmarks.size(), v.sketched.size());
    const mapsketch::Route r = mapsketch::toRoute(s);
    EXPECT_GE(r.sections.size(), 3u);
    // The route's scale comes from the distances: 52 px per metre within the noise.
    EXPECT_NEAR(r.scale_m_per_px * 52.0, 1.0, 0.25);
    // The robot is put down facing along the first stroke.
    const auto d0 = v.drawn_path[1] - v.drawn_path[0];
    EXPECT_NEAR(w.start.theta, std::atan2(d0.y(), d0.x()), 1e-6);
    // The goal stands 0.6 m in front of room B's right door, and the sketch says so.
    EXPECT_EQ(r.goal_place.kind, mapsketch::GoalPlace::Kind::Doorway);
    EXPECT_DOUBLE_EQ(r.goal_place.standoff_m, 0.6);
  }
  SketchNoise point;
  point.goal_doorway = false;
  EXPECT_FALSE(makeSketch(makeVariant("exp3-4"), point, 3).contains("goal_place"));
  // A goal far from every door is a point whatever the setting.
  Variant far = makeVariant("exp3-4");
  far.world["doors"] = Json::array();
  EXPECT_FALSE(makeSketch(far, SketchNoise{}, 3).contains("goal_place"));
}

TEST(ExperimentVariants, TransformationsAsDocumented) {
  EXPECT_EQ(landmarkCount(makeVariant("exp3-8")), 8);
  EXPECT_EQ(landmarkCount(makeVariant("exp3-6")), 6);
  EXPECT_EQ(landmarkCount(makeVariant("exp3-4")), 4);
  const Variant uneven = makeVariant("exp3-4-uneven");
  ASSERT_EQ(landmarkCount(uneven), 4);
  // None in room B (its wall with the walkway is at x = 10 m): room B on odometry alone.
  for (const auto& l : uneven.world["landmarks"]) EXPECT_LT(l["position"][0].get<double>(), 10.0);
  for (const char* name : {"exp4-repeated-a", "exp4-repeated-b"}) {
    std::map<std::string, int> per_class;
    const Variant v = makeVariant(name);  // (not a temporary: the loop refers into it)
    for (const auto& l : v.world["landmarks"]) ++per_class[l["class"].get<std::string>()];
    int max_same = 0;
    for (const auto& [c, n] : per_class) max_same = std::max(max_same, n);
    EXPECT_EQ(max_same, 3) << name;
    EXPECT_EQ(landmarkCount(makeVariant(name)), 8);
  }
  const Variant ped = makeVariant("exp4-pedestrian-left");
  const auto& p = ped.world["pedestrians"].back();
  EXPECT_DOUBLE_EQ(p["speed"].get<double>(), 0.4);
  EXPECT_GT(p["path"][0][1].get<double>(), 6.3);  // left of the line (heading +x: y larger)
  EXPECT_LT(
      makeVariant("exp4-pedestrian-right").world["pedestrians"].back()["path"][0][1].get<double>(),
      6.3);
  EXPECT_EQ(makeVariant("exp4-static-obstacle").world["obstacles"].size(),
            makeVariant("exp3-8").world["obstacles"].size() + 1);
  EXPECT_NE(makeVariant("exp2-redrawn-c").drawn_path.size(),
            makeVariant("exp3-8").drawn_path.size());
}

TEST(ExperimentVariants, ATrialsSketchDependsOnItsVariantAndSeedOnly) {
  // The variant's place in the full list is mixed in, not its place among the variants run:
  // `--variants exp3-4` alone draws the same sketches as the full batch does for exp3-4.
  const auto& names = variantNames();
  const std::string dir = ::testing::TempDir();
  auto written = [&](const std::string& name, int seed) {
    const std::string path = dir + "/sketch-" + name + ".json";
    writeVariantSketch(makeVariant(name), SketchNoise{}, seed, path);
    std::ifstream in(path);
    return Json::parse(in);
  };
  const size_t i4 = std::find(names.begin(), names.end(), "exp3-4") - names.begin();
  ASSERT_LT(i4, names.size());
  EXPECT_EQ(written("exp3-4", 2), makeSketch(makeVariant("exp3-4"), SketchNoise{}, 2 * 101 + i4));
  // Variants do not share drawing errors: exp3-8 and exp4-static-obstacle sketch the same
  // lab, seed for seed, with different noise.
  EXPECT_NE(written("exp3-8", 2)["landmarks"], written("exp4-static-obstacle", 2)["landmarks"]);
}

TEST(ExperimentVariants, SketchNoiseIsSeeded) {
  const Variant v = makeVariant("exp3-8");
  EXPECT_EQ(makeSketch(v, SketchNoise{}, 5), makeSketch(v, SketchNoise{}, 5));
  EXPECT_NE(makeSketch(v, SketchNoise{}, 5), makeSketch(v, SketchNoise{}, 6));
  SketchNoise none;
  none.landmark_sigma_m = none.distance_sigma = none.distance_round_m = 0;
  none.path_sigma_m = none.jitter_px = 0;
  // Without noise the distances are the true ones: L1's from the world's start pose.
  const Json s = makeSketch(v, none, 1);
  const Json& l1 = v.world["landmarks"][0];
  ASSERT_EQ(l1["id"], "L1");
  const double dx = l1["position"][0].get<double>() - v.world["start"]["x"].get<double>();
  const double dy = l1["position"][1].get<double>() - v.world["start"]["y"].get<double>();
  EXPECT_NEAR(s["landmarks"][0]["distance_m"].get<double>(), std::hypot(dx, dy), 1e-9);
  SketchNoise bad;
  bad.distance_sigma = -1;
  EXPECT_THROW(makeSketch(v, bad, 1), InputError);
}

// Pixels of exactly colour c: what a plot drew in that colour.
int countColour(const cv::Mat& img, const cv::Vec3b& c) {
  int n = 0;
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x) n += img.at<cv::Vec3b>(y, x) == c;
  return n;
}

TEST(Plot, DrawsAxesAndSeries) {
  PlotSpec spec;
  spec.title = "t";
  const cv::Mat img = drawLinePlot(spec, {{"a", {0, 1, 2}, {1, 3, 2}, plotColor(0)},
                                          {"no data", {0, 1, 2}, {NAN, NAN, NAN}, plotColor(1)}});
  ASSERT_EQ(img.cols, spec.width);
  ASSERT_EQ(img.rows, spec.height);
  // Some pixels carry the first series' colour (the line was drawn).
  EXPECT_GT(countColour(img, cv::Vec3b(180, 100, 30)), 50);
}

TEST(Plot, ConfusionMatrixShadesByRowShareAndOutlinesTheRightAnswers) {
  ConfusionSpec spec;
  spec.title = "t";
  spec.rows = {"a", "b"};
  spec.cols = {"a", "b", "(none)"};
  spec.counts = {{3, 1, 0}, {0, 0, 2}};
  spec.row_notes = {"top-1 0.75", "top-1 0.00"};
  const cv::Mat two = drawConfusionMatrix(spec);
  const cv::Vec3b full_row(180, 55, 30);  // b -> (none): the whole row
  const cv::Vec3b outline(40, 160, 40);   // a -> a and b -> b
  EXPECT_GT(countColour(two, full_row), 100);
  EXPECT_GT(countColour(two, outline), 2 * 4 * 14);
  // Without a right answer in a row, no outline; with a third row, one cell taller.
  spec.rows.push_back("c");
  spec.counts.push_back({0, 0, 1});
  const cv::Mat three = drawConfusionMatrix(spec);
  EXPECT_EQ(three.rows, two.rows + 18);
  EXPECT_EQ(countColour(three, outline), countColour(two, outline));
}

}  // namespace
}  // namespace sketchnav::app

TEST(ExperimentsReport, FailuresCountByCodeWithTheirDetails) {
  using sketchnav::run::summariseFailures;
  using sketchnav::run::TrialFailure;
  using sketchnav::run::trialFailure;
  const sketchnav::Json short1 = {{"distance_to_goal_m", 0.613}};
  const sketchnav::Json short2 = {{"distance_to_goal_m", 0.82}};
  const sketchnav::Json hit = {{"collision_with", "pedestrian left"}};
  const std::vector<TrialFailure> failures = {
      trialFailure("short_of_goal", "route completed but the robot stopped 0.61 m from the goal",
                   short1),
      trialFailure("collision", "collision with pedestrian left; safety stop: base link lost", hit),
      trialFailure("short_of_goal", "route completed but the robot stopped 0.82 m from the goal",
                   short2),
      // The reason's words do not decide the group: the code does.
      trialFailure("lost", "lost: 3 landmarks in a row not found (L2, L3, L4)", {}),
      trialFailure("lost", "something else entirely", {}),
      // A summary older than the code is counted by its reason.
      trialFailure("", "an old reason 1.5 m", {})};
  EXPECT_EQ(summariseFailures(failures),
            "2x stopped short of the goal [m] (0.61, 0.82); 1x collision (pedestrian left); "
            "2x lost (landmarks in a row not found); 1x an old reason 1.5 m");
  // Long reasons are not cut (the report's row once was, at 300 characters).
  std::vector<TrialFailure> many(5, TrialFailure{"", std::string(120, 'x'), ""});
  EXPECT_EQ(summariseFailures(many), "5x " + std::string(120, 'x'));
  EXPECT_EQ(summariseFailures({}), "");
}
