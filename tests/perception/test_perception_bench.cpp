// Unit tests of the perception benchmark (apps/perception_bench.*): the generator's geometry
// (the poster's true centre is where the warp puts the photo's centre; yaw 0 gives an
// axis-aligned quad), the truth-CSV parser's errors, the report's arithmetic, and (with the
// shared data) the generator's reproducibility and held-out rule.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "perception_bench.h"
#include "sketchnav/core/error.h"
#include "test_data.h"

namespace sketchnav::app::bench {
namespace {
namespace fs = std::filesystem;

cv::Point2d apply(const cv::Mat& H, cv::Point2d p) {
  const double w = H.at<double>(2, 0) * p.x + H.at<double>(2, 1) * p.y + H.at<double>(2, 2);
  return {(H.at<double>(0, 0) * p.x + H.at<double>(0, 1) * p.y + H.at<double>(0, 2)) / w,
          (H.at<double>(1, 0) * p.x + H.at<double>(1, 1) * p.y + H.at<double>(1, 2)) / w};
}

TEST(PosterGeometry, YawZeroGivesAnAxisAlignedQuadOfTheExpectedWidth) {
  PinholeCamera cam;  // f 554, at the origin, looking down +z
  Poster p;
  p.centre = {0.2, -0.1, 2.0};
  p.width_m = 0.4, p.height_m = 0.3;
  const PosterView v = viewPoster(cam, p, {400, 300});
  ASSERT_TRUE(v.valid);
  EXPECT_NEAR(v.quad[0].y, v.quad[1].y, 1e-9);  // top edge horizontal
  EXPECT_NEAR(v.quad[3].y, v.quad[2].y, 1e-9);  // bottom edge horizontal
  EXPECT_NEAR(v.quad[0].x, v.quad[3].x, 1e-9);  // left edge vertical
  EXPECT_NEAR(v.quad[1].x, v.quad[2].x, 1e-9);  // right edge vertical
  EXPECT_NEAR(v.width_px, 554.0 * 0.4 / 2.0, 1e-6);
  EXPECT_NEAR(v.centre.x, 320 + 554.0 * 0.2 / 2.0, 1e-9);
  EXPECT_NEAR(v.yaw_deg, std::atan(0.2 / 2.0) * 180 / M_PI, 1e-6);  // seen from the side a bit
}

TEST(PosterGeometry, TrueCentreIsTheWarpOfThePhotoCentreAtAnyYawAndPan) {
  // (getPerspectiveTransform works in float: 1e-3 px)
  for (double yaw_deg : {0.0, 20.0, -45.0, 60.0})
    for (double pan : {-0.3, 0.0, 0.25}) {
      PinholeCamera cam;
      cam.pan = pan;
      cam.pos = {0.05, 0.02, -0.3};
      Poster p;
      p.centre = {0.3, 0.1, 2.5};
      p.yaw = yaw_deg * M_PI / 180;
      const cv::Size photo(348, 348);
      const PosterView v = viewPoster(cam, p, photo);
      ASSERT_TRUE(v.valid);
      const cv::Point2d c = apply(v.H, {(photo.width - 1) / 2.0, (photo.height - 1) / 2.0});
      EXPECT_NEAR(c.x, v.centre.x, 1e-3) << yaw_deg << " " << pan;
      EXPECT_NEAR(c.y, v.centre.y, 1e-3);
      // The photo's corners land on the quad's corners.
      EXPECT_NEAR(apply(v.H, {-0.5, -0.5}).x, v.quad[0].x, 1e-3);
      EXPECT_NEAR(apply(v.H, {347.5, 347.5}).y, v.quad[2].y, 1e-3);
    }
}

TEST(PosterGeometry, YawIsTheAngleOffTheFaceAndShrinksTheWidth) {
  PinholeCamera cam;
  Poster p;
  p.centre = {0, 0, 3};
  p.yaw = 50 * M_PI / 180;
  const PosterView v = viewPoster(cam, p, {348, 348});
  ASSERT_TRUE(v.valid);
  EXPECT_NEAR(v.yaw_deg, 50, 1e-6);
  Poster q = p;
  q.yaw = 0;
  const PosterView v0 = viewPoster(cam, q, {348, 348});
  EXPECT_NEAR(v.width_px / v0.width_px, std::cos(50 * M_PI / 180), 0.05);  // ~cos, perspective
  // A turned poster is a trapezoid: its near edge is taller than its far edge.
  const double left = v.quad[3].y - v.quad[0].y, right = v.quad[2].y - v.quad[1].y;
  EXPECT_GT(std::abs(left - right), 1.0);
}

TEST(PosterGeometry, PastedPhotoCentreLandsOnTheTrueCentre) {
  // A black photo with a white dot at its centre, pasted at 35 degrees: the brightest pixel of
  // the frame is the view's true centre.
  cv::Mat photo(301, 301, CV_8UC3, cv::Scalar(0, 0, 0));
  cv::circle(photo, {150, 150}, 6, {255, 255, 255}, cv::FILLED);
  PinholeCamera cam;
  cam.pan = 0.1;
  Poster p;
  p.centre = {0.25, 0.05, 1.8};
  p.yaw = -35 * M_PI / 180;
  const PosterView v = viewPoster(cam, p, photo.size());
  ASSERT_TRUE(v.valid);
  cv::Mat frame(480, 640, CV_8UC3, cv::Scalar(0, 0, 0));
  pasteWarped(frame, photo, v.H);
  cv::Mat grey;
  cv::cvtColor(frame, grey, cv::COLOR_BGR2GRAY);
  const cv::Moments m = cv::moments(grey > 128, true);
  ASSERT_GT(m.m00, 5);
  EXPECT_NEAR(m.m10 / m.m00, v.centre.x, 1.0);
  EXPECT_NEAR(m.m01 / m.m00, v.centre.y, 1.0);
}

std::string writeFile(const std::string& name, const std::string& text) {
  const std::string dir = test::tempDir("truthcsv");
  const std::string p = dir + "/" + name;
  std::ofstream(p) << text;
  return p;
}

std::string errorOf(const std::string& text) {
  const std::string p = writeFile("t.csv", text);
  try {
    readTruthCsv(p);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(TruthCsv, ReadsLettersWordsAndUnscoredRows) {
  const auto t = readTruthCsv(writeFile(
      "t.csv", "frame,expected\r\nframe000.jpg,L\n# a comment\n1,straight\n2,R\n3,-\n4,None\n"));
  ASSERT_EQ(t.size(), 5u);
  EXPECT_EQ(t.at("frame000.jpg"), "Left");
  EXPECT_EQ(t.at("1"), "Straight");
  EXPECT_EQ(t.at("2"), "Right");
  EXPECT_EQ(t.at("3"), "");  // unscored
  EXPECT_EQ(t.at("4"), "None");
}

TEST(TruthCsv, BadRowsNameTheFileAndLine) {
  std::string e = errorOf("frame,expected\nf0,L\nf1,Sideways\n");
  EXPECT_NE(e.find("t.csv:3:"), std::string::npos) << e;
  EXPECT_NE(e.find("'Sideways'"), std::string::npos) << e;
  e = errorOf("frame,expected\nf0 L\n");
  EXPECT_NE(e.find("t.csv:2: expected 'frame,expected'"), std::string::npos) << e;
  e = errorOf("f0,L\nf0,R\n");
  EXPECT_NE(e.find("t.csv:2: frame 'f0' appears twice"), std::string::npos) << e;
  e = errorOf("f0,L,extra\n");
  EXPECT_NE(e.find("t.csv:1: expected 2 columns"), std::string::npos) << e;
  e = errorOf(",L\n");
  EXPECT_NE(e.find("t.csv:1: empty frame"), std::string::npos) << e;
  e = errorOf("frame,expected\n");
  EXPECT_NE(e.find("no rows"), std::string::npos) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << "one line";
  EXPECT_THROW(readTruthCsv("/nonexistent/truth.csv"), InputError);
}

FrameScore scored(const std::string& exp, const std::string& got, double yaw, double width,
                  double u_true, double u_found) {
  FrameScore f;
  f.expected = exp;
  f.got = got;
  f.found = got != "None";
  f.u_found = u_found;
  f.has_truth_json = true;
  f.truth.scored = true;
  f.truth.yaw_deg = yaw, f.truth.width_px = width, f.truth.u = u_true;
  f.ms = 100;
  return f;
}

TEST(BenchmarkSummary, CountsAgreementFoundRateBinsAndFalseReports) {
  std::vector<FrameScore> v{scored("Left", "Left", 5, 80, 100, 104),
                            scored("Right", "Left", 20, 120, 500, 300),
                            scored("Right", "None", 50, 200, 450, NAN),
                            scored("Straight", "Straight", 59.9, 299, 320, 322)};
  FrameScore a;  // a frame of a target-absent sequence on which the target was reported
  a.has_truth_json = true, a.absent_sequence = true, a.found = true, a.got = "Left", a.ms = 300;
  v.push_back(a);
  FrameScore out;  // a '-' frame of a present sequence (target out of view): not a false report
  out.has_truth_json = true, out.got = "None", out.ms = 100;
  v.push_back(out);
  // Two full passes with their stages; the other four frames the tracker served.
  v[0].full_pass = true, v[0].objectness_ms = 30, v[0].features_ms = 20, v[0].match_ms = 50;
  v[0].recognise_ms = 40;
  v[4].full_pass = true, v[4].objectness_ms = 60, v[4].features_ms = 40, v[4].match_ms = 200;
  const Json s = summarise(v);
  EXPECT_EQ(s["scored_frames"], 4);
  EXPECT_DOUBLE_EQ(s["agreement"].get<double>(), 0.5);
  EXPECT_DOUBLE_EQ(s["found_rate"].get<double>(), 0.75);
  EXPECT_EQ(s["absent_frames"], 1);
  EXPECT_EQ(s["false_reports"], 1);
  EXPECT_EQ(s["bearing_frames"], 3);
  EXPECT_DOUBLE_EQ(s["bearing_error_px_median"].get<double>(), 4.0);  // of 4, 200, 2
  EXPECT_DOUBLE_EQ(s["ms_per_frame_median"].get<double>(), 100.0);
  EXPECT_DOUBLE_EQ(s["ms_per_frame_p95"].get<double>(), 300.0);
  // Five frames took 100 ms, one 300 ms: none fits 33 or 50 ms, five fit 100 ms.
  const auto& fb = s["frame_budget"];
  ASSERT_EQ(fb.size(), 3u);
  EXPECT_EQ(fb[0]["met"], 0);
  EXPECT_EQ(fb[0]["missed"], 6);
  EXPECT_DOUBLE_EQ(fb[1]["budget_ms"].get<double>(), 50.0);
  EXPECT_EQ(fb[1]["met"], 0);
  EXPECT_DOUBLE_EQ(fb[2]["budget_ms"].get<double>(), 100.0);
  EXPECT_EQ(fb[2]["met"], 5);
  EXPECT_EQ(fb[2]["missed"], 1);
  EXPECT_NEAR(fb[2]["met_rate"].get<double>(), 5.0 / 6, 1e-12);
  const auto& fp = s["full_pass_ms"];
  EXPECT_EQ(fp["frames"], 2);
  EXPECT_EQ(fp["tracked_frames"], 4);
  EXPECT_DOUBLE_EQ(fp["tracked_ms_median"].get<double>(), 100.0);
  EXPECT_DOUBLE_EQ(fp["total"]["median"].get<double>(), 100.0);  // nearest rank of 100, 300
  EXPECT_DOUBLE_EQ(fp["total"]["p95"].get<double>(), 300.0);
  EXPECT_DOUBLE_EQ(fp["objectness"]["median"].get<double>(), 30.0);
  EXPECT_DOUBLE_EQ(fp["match"]["p95"].get<double>(), 200.0);
  EXPECT_DOUBLE_EQ(fp["recognise"]["p95"].get<double>(), 40.0);
  EXPECT_DOUBLE_EQ(fp["fovea"]["median"].get<double>(), 0.0);
  const auto& yb = s["by_yaw_deg"];
  ASSERT_EQ(yb.size(), 4u);
  EXPECT_EQ(yb[0]["frames"], 1);
  EXPECT_EQ(yb[1]["frames"], 1);
  EXPECT_EQ(yb[2]["frames"], 0);
  EXPECT_EQ(yb[3]["frames"], 2);
  EXPECT_DOUBLE_EQ(yb[3]["found_rate"].get<double>(), 0.5);
  const auto& wb = s["by_width_px"];
  ASSERT_EQ(wb.size(), 3u);
  EXPECT_EQ(wb[0]["frames"], 1);
  EXPECT_EQ(wb[2]["frames"], 2);
  EXPECT_TRUE(yb[2]["found_rate"].is_null());
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(SequenceGenerator, SeededReproducibleAndConsistentTruth) {
  SKETCHNAV_REQUIRE_DATA(val, "grocery-packages/val");
  const std::string data = test::dataDir();
  GeneratorOptions o;
  o.data_dir = data;
  o.present = 2, o.absent = 1, o.frames = 5, o.seed = 3;
  o.out_dir = test::tempDir("gen-a");
  const auto names = makeSequences(o);
  ASSERT_EQ(names.size(), 3u);
  GeneratorOptions o2 = o;
  o2.out_dir = test::tempDir("gen-b");
  ASSERT_EQ(makeSequences(o2), names);
  for (const auto& n : names) {
    const fs::path a = fs::path(o.out_dir) / n, b = fs::path(o2.out_dir) / n;
    EXPECT_EQ(slurp(a / "truth.csv"), slurp(b / "truth.csv")) << n;
    EXPECT_EQ(slurp(a / "sequence.json"), slurp(b / "sequence.json")) << n;
    EXPECT_EQ(slurp(a / "frame003.jpg"), slurp(b / "frame003.jpg")) << n;
    const auto truth = readTruthCsv((a / "truth.csv").string());
    const SequenceTruth st = readSequenceJson((a / "sequence.json").string());
    ASSERT_EQ(st.frames.size(), 5u);
    const double db_px = o.servo.dead_band * 0.5 * 640 / std::tan(30 * M_PI / 180);
    for (const auto& [f, t] : st.frames) {
      const std::string e = truth.at(f);
      EXPECT_EQ(!e.empty(), t.scored) << n << " " << f;
      if (st.absent) EXPECT_TRUE(e.empty());
      if (e == "Left") EXPECT_LT(t.u, 320 - db_px);
      if (e == "Right") EXPECT_GT(t.u, 320 + db_px);
      if (e == "Straight") EXPECT_LE(std::abs(t.u - 320), db_px + 1e-6);
      EXPECT_GE(t.yaw_deg, 0);
      EXPECT_LE(t.yaw_deg, 61);
    }
    if (st.absent) EXPECT_NE(st.shown, st.target);
  }
  GeneratorOptions o3 = o;  // another seed gives other sequences
  o3.seed = 4;
  o3.out_dir = test::tempDir("gen-c");
  makeSequences(o3);
  EXPECT_NE(slurp(fs::path(o.out_dir) / names[1] / "sequence.json"),
            slurp(fs::path(o3.out_dir) / names[1] / "sequence.json"));
}

TEST(SequenceGenerator, DevAndHeldOutUseDisjointPhotosAndBackgrounds) {
  SKETCHNAV_REQUIRE_DATA(val, "grocery-packages/val");
  const std::string data = test::dataDir();
  std::set<std::string> photos[2], backgrounds[2];
  for (int s = 0; s < 2; ++s) {
    GeneratorOptions o;
    o.data_dir = data;
    o.split = s == 0 ? Split::Dev : Split::HeldOut;
    o.present = 12, o.absent = 4, o.frames = 2, o.seed = s == 0 ? 1 : 1001;
    o.out_dir = test::tempDir(std::string("split-") + toString(o.split));
    for (const auto& n : makeSequences(o)) {
      std::ifstream in(fs::path(o.out_dir) / n / "sequence.json");
      const Json j = Json::parse(in);
      const std::string photo = j["photo"];
      EXPECT_EQ(photo.find("/train/"), std::string::npos) << photo;  // never a training photo
      photos[s].insert(photo);
      backgrounds[s].insert(j["background"].get<std::string>());
    }
  }
  for (const auto& p : photos[0]) EXPECT_EQ(photos[1].count(p), 0u) << p << " in both splits";
  for (const auto& b : backgrounds[0]) {
    EXPECT_EQ(backgrounds[1].count(b), 0u) << b << " in both splits";
    EXPECT_NE(b.find("raccoon/"), std::string::npos) << b;
  }
  for (const auto& b : backgrounds[1]) EXPECT_NE(b.find("voc07-mini/"), std::string::npos) << b;
  EXPECT_THROW(parseSplit("test"), InputError);
}

}  // namespace
}  // namespace sketchnav::app::bench
