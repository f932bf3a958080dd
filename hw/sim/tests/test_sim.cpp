// Simulator tests: world files and their validation, rendering geometry, odometry noise
// statistics, laser/sonar against known geometry, pedestrians, collisions, determinism, the
// time model, the sim:// registry and the top-down map.
#include <gtest/gtest.h>
#include <visp3/core/vpImage.h>
#include <visp3/robot/vpImageSimulator.h>
#include <opencv2/calib3d.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <sys/stat.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <thread>

#include "sketchnav/core/error.h"
#include "sketchnav/core/paths.h"
#include "sketchnav/hw/pose.h"
#include "sketchnav/hw/registry.h"
#include "sketchnav/sim/map_render.h"
#include "sketchnav/sim/register.h"
#include "sketchnav/sim/simulator.h"
#include "sketchnav/sim/world.h"
#include "test_data.h"

using namespace sketchnav;
using sim::Vec2;

namespace {

std::string texture(const std::string& cls) {
  return resourcePath("textures/" + cls + "/" + cls + "_Iconic.jpg");
}

/// An empty rectangular room [0, w] x [0, h] with 0.1 m walls; robot at (1, h/2) facing +x.
sim::World boxWorld(double w = 8, double h = 4) {
  sim::World world;
  world.name = "box";
  world.floor = {{0, 0}, {w, 0}, {w, h}, {0, h}};
  world.walls = {{"south", {0, 0}, {w, 0}},
                 {"east", {w, 0}, {w, h}},
                 {"north", {w, h}, {0, h}},
                 {"west", {0, h}, {0, 0}}};
  world.start = {1.0, h / 2, 0.0};
  world.goal.centre = {w - 1, h / 2};
  world.camera.pitch = 0.0;
  world.sonar.beams = {{0.2, 0.0, 0.0}};
  return world;
}

sim::SimParams exactParams() {
  sim::SimParams p;
  p.image_noise_std = 0;
  p.odom_slip_std = p.odom_turn_slip_std = p.odom_scale_error = p.odom_drift = 0;
  p.range_noise_scale = 0;
  p.camera_hz = 0;
  return p;
}

/// Pixels where two renders differ: the landmark's footprint.
cv::Mat diffMask(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat d, g;
  cv::absdiff(a, b, d);
  cv::cvtColor(d, g, cv::COLOR_BGR2GRAY);
  return g > 8;
}

cv::Point2d centroid(const cv::Mat& mask) {
  const cv::Moments m = cv::moments(mask, true);
  if (m.m00 <= 0) return {-1, -1};
  return {m.m10 / m.m00, m.m01 / m.m00};
}

std::string writeJson(const std::string& dir, const std::string& name, const Json& j) {
  const std::string p = dir + "/" + name;
  std::ofstream(p) << j.dump(1);
  return p;
}

std::string loadError(const Json& j) {
  const std::string dir = test::tempDir("world");
  try {
    sim::loadWorld(writeJson(dir, "w.world.json", j));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

Json minimalWorldJson() {
  return {{"floor", {{0, 0}, {6, 0}, {6, 4}, {0, 4}}},
          {"walls", {{{"from", {0, 0}}, {"to", {6, 0}}}, {{"from", {6, 0}}, {"to", {6, 4}}}}},
          {"landmarks",
           {{{"id", "L1"},
             {"class", "Oatly-Oat-Milk"},
             {"texture", "textures/Oatly-Oat-Milk/Oatly-Oat-Milk_Iconic.jpg"},
             {"position", {5.9, 2}},
             {"yaw_deg", 180}}}},
          {"start", {{"x", 1}, {"y", 2}}},
          {"goal", {{"x", 5}, {"y", 2}}}};
}

}  // namespace

// ---------------------------------------------------------------- world files
TEST(World, LabWorldLoadsWithEightDistinctLandmarkClasses) {
  const sim::World w = sim::labWorld();
  EXPECT_EQ(w.name, "lab");
  ASSERT_EQ(w.landmarks.size(), 8u);
  std::set<std::string> classes;
  for (const auto& l : w.landmarks) {
    classes.insert(l.class_name);
    EXPECT_TRUE(std::filesystem::exists(l.texture)) << l.texture;
    // The class is a folder of the shipped landmark set.
    EXPECT_TRUE(std::filesystem::is_directory(resourceDir() + "/landmarks/" + l.class_name));
  }
  EXPECT_EQ(classes.size(), 8u);
  // About 18 x 13 m.
  double xmax = 0, ymax = 0;
  for (const auto& p : w.floor) {
    xmax = std::max(xmax, p.x());
    ymax = std::max(ymax, p.y());
  }
  EXPECT_NEAR(xmax, 18, 0.5);
  EXPECT_NEAR(ymax, 13, 0.5);
  EXPECT_LT(w.start.x, 2.0);           // near the left door
  EXPECT_GT(w.goal.centre.x(), 16.0);  // at the right door
  EXPECT_FALSE(w.pedestrians.empty());
}

TEST(World, JsonRoundTripKeepsEverything) {
  const sim::World a = sim::labWorld();
  const sim::World b = sim::worldFromJson(sim::worldToJson(a), "roundtrip", "");
  EXPECT_EQ(sim::worldToJson(a).dump(), sim::worldToJson(b).dump());
}

TEST(World, CorridorAndByNameLoading) {
  const sim::World c = sim::loadWorldByName("corridor");
  EXPECT_EQ(c.name, "corridor");
  EXPECT_EQ(c.landmarks.size(), 1u);
  EXPECT_THROW(sim::loadWorldByName("no-such-world"), InputError);
}

TEST(World, DefaultSonarRingWhenNoneGiven) {
  const sim::World w = sim::labWorld();
  EXPECT_EQ(w.sonar.beams.size(), 8u);
}

TEST(WorldValidation, MinimalWorldIsValid) {
  EXPECT_EQ(loadError(minimalWorldJson()), "");
}

TEST(WorldValidation, UnknownKeyNamesTheField) {
  Json j = minimalWorldJson();
  j["walls"][0]["thicknes"] = 0.2;
  const std::string e = loadError(j);
  EXPECT_NE(e.find("walls[0].thicknes: unknown key"), std::string::npos) << e;
  j = minimalWorldJson();
  j["colour"] = 1;
  EXPECT_NE(loadError(j).find("colour: unknown key"), std::string::npos);
}

TEST(WorldValidation, OverlappingWalls) {
  Json j = minimalWorldJson();
  j["walls"].push_back({{"from", {2, 0}}, {"to", {4, 0}}});  // on top of walls[0]
  const std::string e = loadError(j);
  EXPECT_NE(e.find("walls[2]: overlaps walls[0]"), std::string::npos) << e;
  j = minimalWorldJson();
  j["walls"].push_back({{"from", {3, -1}}, {"to", {3, 1}}});  // crosses walls[0]
  EXPECT_NE(loadError(j).find("walls[2]: overlaps"), std::string::npos);
  j = minimalWorldJson();
  j["walls"].push_back({{"from", {3, 0}}, {"to", {3, 1}}});  // a T-junction is fine
  EXPECT_EQ(loadError(j), "");
}

TEST(WorldValidation, LandmarkOutsideTheFloor) {
  Json j = minimalWorldJson();
  j["landmarks"][0]["position"] = {7.5, 2};
  const std::string e = loadError(j);
  EXPECT_NE(e.find("landmarks[0].position: is outside the floor polygon"), std::string::npos) << e;
}

TEST(WorldValidation, MissingTexture) {
  Json j = minimalWorldJson();
  j["landmarks"][0]["texture"] = "landmarks/nothing/here.jpg";
  const std::string e = loadError(j);
  EXPECT_NE(e.find("landmarks[0].texture: file 'landmarks/nothing/here.jpg' not found"),
            std::string::npos)
      << e;
}

TEST(WorldValidation, OtherBadFields) {
  Json j = minimalWorldJson();
  j["pedestrians"] = {{{"path", {{1, 1}}}}};
  EXPECT_NE(loadError(j).find("pedestrians[0].path: needs at least 2 points"), std::string::npos);
  j = minimalWorldJson();
  j["walls"][0]["thickness"] = "thick";
  EXPECT_NE(loadError(j).find("walls[0].thickness: must be a number"), std::string::npos);
  j = minimalWorldJson();
  j["obstacles"] = {{{"shape", "box"}, {"centre", {1.1, 2}}, {"size", {0.5, 0.5}}}};
  EXPECT_NE(loadError(j).find("start: robot"), std::string::npos);  // start inside a box
  j = minimalWorldJson();
  j["obstacles"] = {{{"shape", "cone"}, {"centre", {3, 2}}}};
  EXPECT_NE(loadError(j).find("obstacles[0].shape"), std::string::npos);
  j = minimalWorldJson();
  j.erase("goal");
  EXPECT_NE(loadError(j).find("goal: is required"), std::string::npos);
  j = minimalWorldJson();
  j["laser"] = {{"fov_deg", 400}};
  EXPECT_NE(loadError(j).find("laser.fov_deg"), std::string::npos);
  // Every message is one line and names the file.
  const std::string e = loadError(j);
  EXPECT_EQ(e.find('\n'), std::string::npos);
  EXPECT_NE(e.find("w.world.json"), std::string::npos);
}

// Issue 28: laser.rate_hz = 1e9 made `sim drive` take > 40 s; a range sensor's rate is bounded.
TEST(WorldValidation, RangeSensorRatesHaveAnUpperBound) {
  for (const char* sensor : {"laser", "sonar"}) {
    Json j = minimalWorldJson();
    j[sensor] = {{"rate_hz", 1e9}};
    const std::string e = loadError(j);
    EXPECT_NE(e.find(std::string(sensor) + ".rate_hz: must be in (0, 100] Hz"), std::string::npos)
        << e;
    j[sensor] = {{"rate_hz", sim::kMaxRangeRateHz}};
    EXPECT_EQ(loadError(j), "") << sensor;
    j[sensor] = {{"rate_hz", 0}};
    EXPECT_NE(loadError(j).find(std::string(sensor) + ".rate_hz"), std::string::npos);
  }
}

TEST(WorldValidation, InvalidJsonAndMissingFile) {
  EXPECT_THROW(sim::loadWorld("/nonexistent/x.world.json"), InputError);
  const std::string dir = test::tempDir("badjson");
  std::ofstream(dir + "/bad.json") << "{ \"floor\": [";
  EXPECT_THROW(sim::loadWorld(dir + "/bad.json"), InputError);
}

TEST(SimParams, ValidateNamesTheField) {
  sim::SimParams p;
  p.substep = 0;
  try {
    p.validate();
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("sim.substep"), std::string::npos);
  }
  sim::SimParams q;
  q.pedestrian_keep_behind_m = std::nan("");
  try {
    q.validate();
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("sim.pedestrian_keep_behind_m"), std::string::npos);
  }
}

// ---------------------------------------------------------------- rendering
class Rendering : public ::testing::Test {
 protected:
  void SetUp() override {
    world_ = boxWorld(10, 6);
    sim::Landmark l;
    l.id = "L1";
    l.class_name = "Oatly-Oat-Milk";
    l.texture = texture(l.class_name);
    l.position = {4.0, 3.0};
    l.yaw = M_PI;  // facing the robot
    l.width = l.height = 0.5;
    l.elevation = world_.camera.z;  // at camera height: centred vertically too
    world_.landmarks = {l};
    bare_ = world_;
    bare_.landmarks.clear();
  }
  /// Expected pixel of a world point for a robot pose (pinhole through rMc).
  cv::Point2d project(const hw::Pose2D& r, const Eigen::Vector3d& P) const {
    Eigen::Isometry3d wMr = Eigen::Isometry3d::Identity();
    wMr.translation() = Eigen::Vector3d(r.x, r.y, 0);
    wMr.linear() = Eigen::AngleAxisd(r.theta, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const Eigen::Vector3d c = (wMr * world_.camera.rMc()).inverse() * P;
    const auto K = world_.camera.intrinsics();
    return {K.fx * c.x() / c.z() + K.cx, K.fy * c.y() / c.z() + K.cy};
  }
  sim::World world_, bare_;
};

TEST_F(Rendering, LandmarkStraightAheadAppearsCentred) {
  sim::Simulator with(world_, exactParams()), without(bare_, exactParams());
  const hw::Pose2D pose{1.0, 3.0, 0.0};
  const cv::Mat a = with.renderView(pose, 0), b = without.renderView(pose, 0);
  ASSERT_EQ(a.size(), cv::Size(640, 480));
  const cv::Mat mask = diffMask(a, b);
  const cv::Point2d c = centroid(mask);
  EXPECT_NEAR(c.x, 319.5, 2.0);
  EXPECT_NEAR(c.y, 239.5, 2.0);
  // Its apparent width matches the pinhole model: 0.5 m at 2.9 m from the camera.
  const cv::Rect box = cv::boundingRect(mask);
  const double expected = with.world().camera.intrinsics().fx * 0.5 / (4.0 - 0.004 - 1.1);
  EXPECT_NEAR(box.width, expected, 3.0);
  // And it shows the photo, not a flat patch: the landmark region has texture.
  cv::Scalar mean, stddev;
  cv::meanStdDev(a(box), mean, stddev);
  EXPECT_GT(stddev[0] + stddev[1] + stddev[2], 60.0);
}

TEST_F(Rendering, TurningMovesTheLandmarkTheRightWay) {
  sim::Simulator with(world_, exactParams()), without(bare_, exactParams());
  for (double turn : {0.2, -0.2}) {
    const hw::Pose2D pose{1.0, 3.0, turn};
    const cv::Point2d c = centroid(diffMask(with.renderView(pose, 0), without.renderView(pose, 0)));
    const cv::Point2d e = project(pose, Eigen::Vector3d(4.0, 3.0, world_.camera.z));
    // Turning left (CCW) puts the landmark to the right of the image centre.
    if (turn > 0)
      EXPECT_GT(c.x, 380);
    else
      EXPECT_LT(c.x, 260);
    EXPECT_NEAR(c.x, e.x, 3.0);
    EXPECT_NEAR(c.y, e.y, 3.0);
  }
}

TEST_F(Rendering, LandmarkIsNotMirroredAndHiddenFromBehind) {
  sim::Simulator with(world_, exactParams()), without(bare_, exactParams());
  const cv::Mat tex = cv::imread(world_.landmarks[0].texture);
  const hw::Pose2D pose{2.5, 3.0, 0.0};
  const cv::Mat a = with.renderView(pose, 0);
  const cv::Rect box = cv::boundingRect(diffMask(a, without.renderView(pose, 0)));
  cv::Mat crop, t_small, t_flip;
  cv::resize(a(box), crop, cv::Size(64, 64), 0, 0, cv::INTER_AREA);
  cv::resize(tex, t_small, cv::Size(64, 64), 0, 0, cv::INTER_AREA);
  cv::flip(t_small, t_flip, 1);
  const double err = cv::norm(crop, t_small, cv::NORM_L1),
               err_flip = cv::norm(crop, t_flip, cv::NORM_L1);
  EXPECT_LT(err, 0.7 * err_flip);
  // From behind (no back texture) the photo is not visible.
  const hw::Pose2D behind{6.0, 3.0, M_PI};
  const cv::Mat back = with.renderView(behind, 0);
  cv::Mat back_crop;
  cv::resize(back(cv::boundingRect(diffMask(back, without.renderView(behind, 0)))), back_crop,
             cv::Size(64, 64), 0, 0, cv::INTER_AREA);
  cv::Scalar mean, stddev;
  cv::meanStdDev(back_crop, mean, stddev);
  EXPECT_LT(stddev[0] + stddev[1] + stddev[2], 15.0);  // a plain board
}

TEST_F(Rendering, ObstacleOccludesLandmarkBehindIt) {
  sim::World w = world_;
  sim::Obstacle o;
  o.name = "crate";
  o.centre = {2.5, 3.0};
  o.size_x = o.size_y = 0.8;
  o.height = 1.0;
  w.obstacles = {o};
  sim::World wb = w;
  wb.landmarks.clear();
  sim::Simulator with(w, exactParams()), without(wb, exactParams());
  const hw::Pose2D pose{1.0, 3.0, 0.0};
  EXPECT_EQ(cv::countNonZero(diffMask(with.renderView(pose, 0), without.renderView(pose, 0))), 0);
}

TEST_F(Rendering, AgreesWithVispImageSimulator) {
  // The same landmark plane rendered by ViSP's vpImageSimulator from the same camera pose
  // (cMo built from rMc and the landmark pose) lands on the same pixels: our camera model and
  // the ViSP conventions the servo law uses agree.
  const sim::Landmark& l = world_.landmarks[0];
  const cv::Mat tex = cv::imread(l.texture);
  vpImage<vpRGBa> vtex(static_cast<unsigned>(tex.rows), static_cast<unsigned>(tex.cols));
  for (int r = 0; r < tex.rows; ++r)
    for (int c = 0; c < tex.cols; ++c) {
      const auto p = tex.at<cv::Vec3b>(r, c);
      vtex[r][c] = vpRGBa(p[2], p[1], p[0]);
    }
  vpColVector X[4];
  const double hw = 0.5 * l.width, hh = 0.5 * l.height;
  const double corners[4][2] = {{-hw, -hh}, {hw, -hh}, {hw, hh}, {-hw, hh}};  // TL TR BR BL
  for (int k = 0; k < 4; ++k) {
    X[k].resize(3);
    X[k][0] = corners[k][0];
    X[k][1] = corners[k][1];
    X[k][2] = 0;
  }
  vpImageSimulator vsim(vpImageSimulator::COLORED);
  vsim.init(vtex, X);
  const auto K = world_.camera.intrinsics();
  const vpCameraParameters cam(K.fx, K.fy, K.cx, K.cy);
  sim::Simulator with(world_, exactParams()), without(bare_, exactParams());
  // Object frame: x = the viewer's right, y = down, z = into the face.
  const Eigen::Vector3d n(std::cos(l.yaw), std::sin(l.yaw), 0);
  Eigen::Isometry3d wMo = Eigen::Isometry3d::Identity();
  wMo.linear().col(0) = Eigen::Vector3d(-n.y(), n.x(), 0);
  wMo.linear().col(1) = -Eigen::Vector3d::UnitZ();
  wMo.linear().col(2) = -n;
  wMo.translation() = Eigen::Vector3d(l.position.x(), l.position.y(), l.elevation) + 0.004 * n;
  for (const hw::Pose2D pose :
       {hw::Pose2D{1.0, 3.0, 0.0}, hw::Pose2D{1.5, 2.2, 0.35}, hw::Pose2D{2.0, 3.6, -0.25}}) {
    Eigen::Isometry3d wMr = Eigen::Isometry3d::Identity();
    wMr.translation() = Eigen::Vector3d(pose.x, pose.y, 0);
    wMr.linear() = Eigen::AngleAxisd(pose.theta, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const Eigen::Matrix4d cMo = ((wMr * world_.camera.rMc()).inverse() * wMo).matrix();
    vpHomogeneousMatrix vcMo;
    for (unsigned r = 0; r < 4; ++r)
      for (unsigned c = 0; c < 4; ++c) vcMo[r][c] = cMo(r, c);
    vsim.setCameraPosition(vcMo);
    vpImage<vpRGBa> img(480, 640, vpRGBa(0, 0, 0));
    vsim.getImage(img, cam);
    cv::Mat vmask(480, 640, CV_8U, cv::Scalar(0));
    for (int r = 0; r < 480; ++r)
      for (int c = 0; c < 640; ++c) {
        const vpRGBa& p = img[r][c];
        if (p.R + p.G + p.B > 0) vmask.at<uchar>(r, c) = 255;
      }
    const cv::Mat ours = diffMask(with.renderView(pose, 0), without.renderView(pose, 0));
    const cv::Rect a = cv::boundingRect(ours), b = cv::boundingRect(vmask);
    EXPECT_NEAR(a.x, b.x, 2) << pose.x << "," << pose.y << "," << pose.theta;
    EXPECT_NEAR(a.y, b.y, 2);
    EXPECT_NEAR(a.br().x, b.br().x, 2);
    EXPECT_NEAR(a.br().y, b.br().y, 2);
  }
}

TEST(LabRendering, EveryLandmarkIsVisibleFromTheRouteSide) {
  // Stand 1.5 m in front of each landmark, facing it: the photo must be in view, not buried
  // in its furniture or cut by the image border.
  const sim::World lab = sim::labWorld();
  sim::World bare = lab;
  bare.landmarks.clear();
  bare.pedestrians.clear();
  sim::World lab_np = lab;
  lab_np.pedestrians.clear();
  sim::Simulator with(lab_np, exactParams()), without(bare, exactParams());
  for (const auto& l : lab.landmarks) {
    const Vec2 n(std::cos(l.yaw), std::sin(l.yaw));
    const Vec2 p = l.position + 1.5 * n;
    const hw::Pose2D pose{p.x(), p.y(), std::atan2(-n.y(), -n.x())};
    const cv::Mat mask = diffMask(with.renderView(pose, 0), without.renderView(pose, 0));
    const int area = cv::countNonZero(mask);
    const double expected = std::pow(554.3 * l.width / 1.6, 1) * 554.3 * l.height / 1.6;
    EXPECT_GT(area, 0.6 * expected) << l.id;
    const cv::Rect box = cv::boundingRect(mask);
    EXPECT_GT(box.y, 0) << l.id << " cut at the top";
    EXPECT_NEAR(centroid(mask).x, 319.5, 25) << l.id;
  }
}

TEST(LabRendering, LooksLikeARoomNotAFlatColour) {
  sim::Simulator s(sim::labWorld(), exactParams());
  const cv::Mat img = s.renderView(s.world().start, 0);
  cv::Scalar mean, stddev;
  cv::meanStdDev(img, mean, stddev);
  EXPECT_GT(stddev[0], 20);
  // Floor (bottom rows) and ceiling (top rows) differ, and edges exist throughout.
  cv::Mat gray, edges;
  cv::cvtColor(img, gray, cv::COLOR_BGR2GRAY);
  cv::Canny(gray, edges, 50, 150);
  EXPECT_GT(cv::countNonZero(edges), 2000);
  if (const char* dir = std::getenv("SKETCHNAV_SIM_SAVE"))
    cv::imwrite(std::string(dir) + "/start.png", img);
}

TEST(LabRendering, NoiseBlurAndBrightnessApply) {
  sim::SimParams p = exactParams();
  sim::Simulator clean(sim::labWorld(), p);
  p.image_noise_std = 4;
  p.blur_sigma = 1.0;
  sim::Simulator noisy(sim::labWorld(), p);
  const hw::Pose2D pose = clean.world().start;
  const cv::Mat a = clean.renderView(pose, 0, true), b = noisy.renderView(pose, 0, true);
  EXPECT_GT(cv::norm(a, b, cv::NORM_L1) / a.total(), 1.0);
  sim::World dark = sim::labWorld();
  dark.lighting.brightness = 0.5;
  sim::Simulator d(dark, exactParams());
  EXPECT_LT(cv::mean(d.renderView(pose, 0))[1], 0.6 * cv::mean(a)[1]);
}

// ---------------------------------------------------------------- odometry
TEST(Odometry, ExactWithoutNoiseAndInTheStartFrame) {
  sim::World w = boxWorld(20, 20);
  w.start = {5, 5, 0.5};
  sim::Simulator s(w, exactParams());
  s.base().command(0.3, 0.2);
  s.clock()->sleepUntil(4.0);
  hw::Odometry o;
  ASSERT_TRUE(s.base().odometry(o));
  const hw::Pose2D truth_rel = hw::composePose(hw::inversePose(w.start), s.truePose());
  EXPECT_NEAR(o.pose.x, truth_rel.x, 1e-6);
  EXPECT_NEAR(o.pose.y, truth_rel.y, 1e-6);
  EXPECT_NEAR(o.pose.theta, truth_rel.theta, 1e-6);
  EXPECT_NEAR(o.stamp, 4.0, 1e-9);
  EXPECT_NEAR(o.v, 0.3, 1e-9);
}

TEST(Odometry, NoiseStatisticsMatchTheModel) {
  // Drive 2 m straight in many seeded runs: the distance error has mean scale_error * D and
  // std slip * sqrt(D); the heading drifts by drift * D on average.
  sim::World w = boxWorld(20, 6);
  sim::SimParams p = exactParams();
  p.odom_slip_std = 0.03;
  p.odom_scale_error = 0.02;
  p.odom_drift = 0.02;
  p.odom_turn_slip_std = 0.0;
  const int runs = 60;
  std::vector<double> dist_err, yaw;
  double D = 0;
  for (int seed = 1; seed <= runs; ++seed) {
    p.seed = static_cast<std::uint64_t>(seed);
    sim::Simulator s(w, p);
    s.base().command(0.5, 0.0);
    s.clock()->sleepUntil(4.2);
    hw::Odometry o;
    s.base().odometry(o);
    D = s.stats().distance;
    dist_err.push_back(o.pose.x / std::cos(0.5 * o.pose.theta) - D);
    yaw.push_back(o.pose.theta);
  }
  ASSERT_NEAR(D, 2.0, 0.1);
  const double mean = std::accumulate(dist_err.begin(), dist_err.end(), 0.0) / runs;
  double var = 0;
  for (double e : dist_err) var += (e - mean) * (e - mean);
  const double sd = std::sqrt(var / (runs - 1));
  const double expected_sd = 0.03 * std::sqrt(D);
  EXPECT_NEAR(mean, 0.02 * D, 3 * expected_sd / std::sqrt(runs));
  EXPECT_NEAR(sd, expected_sd, 0.3 * expected_sd);
  const double mean_yaw = std::accumulate(yaw.begin(), yaw.end(), 0.0) / runs;
  EXPECT_NEAR(mean_yaw, 0.02 * D, 1e-3);
}

TEST(Odometry, HeadingSlipGrowsWithTurning) {
  sim::World w = boxWorld(20, 20);
  w.start = {10, 10, 0};
  sim::SimParams p = exactParams();
  p.odom_turn_slip_std = 0.05;
  std::vector<double> err;
  for (int seed = 1; seed <= 40; ++seed) {
    p.seed = static_cast<std::uint64_t>(seed);
    sim::Simulator s(w, p);
    s.base().command(0.0, 1.0);
    s.clock()->sleepUntil(2.0);
    const double truth = wrapAngle(s.truePose().theta);
    err.push_back(wrapAngle(s.odometryPose().theta - truth));
  }
  double var = 0;
  for (double e : err) var += e * e;
  const double sd = std::sqrt(var / err.size());
  const double turned = 2.0 - 0.5 / 3.0;  // 1 rad/s, less the acceleration ramp
  EXPECT_NEAR(sd, 0.05 * std::sqrt(turned), 0.35 * 0.05 * std::sqrt(turned));
}

TEST(Base, VelocityAndAccelerationLimits) {
  sim::World w = boxWorld(30, 30);
  w.start = {5, 15, 0};
  sim::SimParams p = exactParams();
  p.v_max = 0.4;
  p.acc_max = 0.5;
  sim::Simulator s(w, p);
  s.base().command(2.0, 0.0);
  s.clock()->sleepUntil(0.4);
  hw::Odometry o;
  s.base().odometry(o);
  EXPECT_NEAR(o.v, 0.2, 1e-6);  // ramping at 0.5 m/s^2
  s.clock()->sleepUntil(3.0);
  s.base().odometry(o);
  EXPECT_NEAR(o.v, 0.4, 1e-9);  // capped
  s.base().stop();
  s.clock()->sleepUntil(4.0);
  s.base().odometry(o);
  EXPECT_NEAR(o.v, 0.0, 1e-9);
}

// ---------------------------------------------------------------- range sensors
TEST(Range, LaserAndSonarAgainstAKnownWall) {
  sim::World w = boxWorld(5, 6);  // east wall inner face at x = 4.95
  w.start = {2.0, 3.0, 0.0};
  sim::Simulator s(w, exactParams());
  hw::RangeScan scan;
  ASSERT_TRUE(s.laser().read(scan));
  EXPECT_EQ(scan.kind, hw::RangeScan::Kind::Laser);
  ASSERT_EQ(scan.ranges.size(), 241u);  // 240 deg at 1 deg, both ends included
  const double d = 4.95 - 2.0 - w.laser.x;
  for (size_t i = 0; i < scan.ranges.size(); ++i) {
    const double a = scan.angles[i];
    if (std::abs(a) < 0.5) EXPECT_NEAR(scan.ranges[i], d / std::cos(a), 1e-4) << a;
  }
  // Straight left: the north wall inner face at y = 5.95.
  for (size_t i = 0; i < scan.ranges.size(); ++i)
    if (std::abs(scan.angles[i] - M_PI / 2) < 1e-4) EXPECT_NEAR(scan.ranges[i], 5.95 - 3.0, 1e-4);
  ASSERT_TRUE(s.sonar().read(scan));
  EXPECT_EQ(scan.kind, hw::RangeScan::Kind::Sonar);
  ASSERT_EQ(scan.ranges.size(), 1u);
  // From the robot's centre (the scan's mount), not from the transducer 0.2 m ahead of it.
  EXPECT_NEAR(scan.mount.x, 0.0, 1e-12);
  EXPECT_NEAR(scan.ranges[0], 4.95 - 2.0, 1e-4);
  EXPECT_GT(scan.beam_width, 0.0f);
}

TEST(Range, NoiseHasTheConfiguredSpread) {
  sim::World w = boxWorld(5, 6);
  w.start = {2.0, 3.0, 0.0};
  w.laser.noise_std = 0.02;
  sim::SimParams p = exactParams();
  p.range_noise_scale = 1.0;
  sim::Simulator s(w, p);
  hw::RangeScan scan;
  std::vector<double> r;
  for (int k = 0; k < 50; ++k) {
    s.clock()->sleepUntil(0.1 * k);
    s.laser().read(scan);
    r.push_back(scan.ranges[120] - (4.95 - 2.0 - w.laser.x));  // the beam straight ahead
  }
  const double mean = std::accumulate(r.begin(), r.end(), 0.0) / r.size();
  double var = 0;
  for (double e : r) var += (e - mean) * (e - mean);
  EXPECT_NEAR(mean, 0.0, 0.01);
  EXPECT_NEAR(std::sqrt(var / (r.size() - 1)), 0.02, 0.008);
}

TEST(Range, PedestrianCrossingTheLaser) {
  sim::World w = boxWorld(12, 12);
  w.start = {2.0, 6.0, 0.0};
  sim::Pedestrian p;
  p.name = "walker";
  p.path = {{5.0, 3.0}, {5.0, 9.0}};
  p.speed = 1.0;
  p.radius = 0.25;
  w.pedestrians = {p};
  sim::Simulator s(w, exactParams());
  hw::RangeScan scan;
  auto rangeAhead = [&](const hw::RangeScan& sc) { return sc.ranges[120]; };
  auto bearingOfClosest = [&](const hw::RangeScan& sc) {
    size_t k = std::min_element(sc.ranges.begin(), sc.ranges.end()) - sc.ranges.begin();
    return sc.angles[k];
  };
  s.laser().read(scan);  // t = 0: pedestrian at (5, 3), 45 deg to the right
  const double free_ahead = 11.95 - 2.0 - w.laser.x;
  EXPECT_NEAR(rangeAhead(scan), std::min(free_ahead, w.laser.max_range), 1e-3);
  EXPECT_NEAR(bearingOfClosest(scan), std::atan2(3.0 - 6.0, 5.0 - 2.15), 0.05);
  s.clock()->sleepUntil(3.0);  // pedestrian at (5, 6): straight ahead
  s.laser().read(scan);
  EXPECT_NEAR(rangeAhead(scan), 5.0 - 0.25 - 2.15, 1e-3);
  EXPECT_NEAR(s.pedestrians()[0].position.y(), 6.0, 1e-9);
  s.clock()->sleepUntil(6.0);  // at (5, 9), then it turns back
  s.laser().read(scan);
  EXPECT_NEAR(bearingOfClosest(scan), std::atan2(3.0, 5.0 - 2.15), 0.05);
  s.clock()->sleepUntil(7.0);
  EXPECT_NEAR(s.pedestrians()[0].position.y(), 8.0, 1e-9);
  EXPECT_LT(s.pedestrians()[0].velocity.y(), 0.0);
  // Sonar sees it too when it is in front.
  s.clock()->sleepUntil(9.0);
  ASSERT_TRUE(s.sonar().read(scan));
  EXPECT_NEAR(scan.ranges[0], 5.0 - 0.25 - 2.0, 1e-3);  // from the robot's centre
}

TEST(Range, PedestrianVisibleInTheCamera) {
  sim::World w = boxWorld(12, 12);
  w.start = {2.0, 6.0, 0.0};
  sim::Pedestrian p;
  p.name = "walker";
  p.path = {{5.0, 3.0}, {5.0, 9.0}};
  w.pedestrians = {p};
  sim::World empty = w;
  empty.pedestrians.clear();
  sim::Simulator a(w, exactParams()), b(empty, exactParams());
  const double t_centre = 3.0 / p.speed;
  const cv::Mat mask = diffMask(a.renderView(w.start, t_centre), b.renderView(w.start, t_centre));
  EXPECT_GT(cv::countNonZero(mask), 5000);
  EXPECT_NEAR(centroid(mask).x, 319.5, 20);
}

// ---------------------------------------------------------------- collisions
TEST(Collision, DrivingIntoAWallEndsTheRun) {
  sim::World w = boxWorld(5, 4);
  w.start = {2.0, 2.0, 0.0};
  sim::Simulator s(w, exactParams());
  s.base().command(0.5, 0.0);
  s.clock()->sleepUntil(10.0);
  EXPECT_TRUE(s.collided());
  EXPECT_EQ(s.collisionWith(), "east");
  EXPECT_FALSE(s.base().ok());
  EXPECT_NE(s.base().stats().last_error.find("east"), std::string::npos);
  const hw::Pose2D p = s.truePose();
  EXPECT_LE(p.x, 4.95 - w.robot.radius + 1e-9);
  EXPECT_GT(p.x, 4.95 - w.robot.radius - 0.01);
  EXPECT_LE(s.minClearance(), 0.0);
  // Commands are ignored after a collision.
  s.base().command(-0.3, 0.0);
  s.clock()->sleepUntil(12.0);
  EXPECT_NEAR(s.truePose().x, p.x, 1e-12);
}

TEST(Collision, PedestrianWalkingIntoTheRobot) {
  sim::World w = boxWorld(10, 10);
  w.start = {5.0, 5.0, 0.0};
  sim::Pedestrian ped;
  ped.name = "walker";
  ped.path = {{5.0, 1.0}, {5.0, 9.0}};
  w.pedestrians = {ped};
  sim::Simulator s(w, exactParams());
  s.clock()->sleepUntil(12.0);
  EXPECT_TRUE(s.collided());
  EXPECT_EQ(s.collisionWith(), "walker");
}

TEST(Collision, ClearanceIsTrackedWithoutContact) {
  sim::World w = boxWorld(6, 4);
  w.start = {2.0, 2.0, 0.0};
  sim::Simulator s(w, exactParams());
  s.base().command(0.5, 0.0);
  s.clock()->sleepUntil(6.0);
  s.base().stop();
  s.clock()->sleepUntil(8.0);
  EXPECT_FALSE(s.collided());
  const double x = s.truePose().x;
  EXPECT_NEAR(s.minClearance(), std::min(5.95 - x, 1.95) - w.robot.radius, 1e-6);
}

// ---------------------------------------------------------------- determinism and time
namespace {
struct RunRecord {
  std::vector<sim::TrajectorySample> traj;
  std::vector<cv::Mat> frames;
  std::vector<std::vector<float>> scans;
};
RunRecord runScript(std::uint64_t seed) {
  sim::SimParams p;
  p.seed = seed;
  p.brightness_jitter = 0.05;
  sim::World w = sim::labWorld();
  sim::Simulator s(w, p);
  RunRecord r;
  hw::Frame f;
  hw::RangeScan scan;
  for (int k = 0; k < 20; ++k) {
    s.base().command(0.3, k < 10 ? -0.3 : 0.2);
    s.camera().grab(f, 1.0);
    r.frames.push_back(f.image.clone());
    s.laser().read(scan);
    r.scans.push_back(scan.ranges);
    s.sonar().read(scan);
    r.scans.push_back(scan.ranges);
  }
  r.traj = s.trajectory();
  return r;
}
}  // namespace

TEST(Determinism, SameSeedSameTrajectoryImagesAndScans) {
  const RunRecord a = runScript(7), b = runScript(7), c = runScript(8);
  ASSERT_EQ(a.traj.size(), b.traj.size());
  ASSERT_GT(a.traj.size(), 10u);
  for (size_t i = 0; i < a.traj.size(); ++i) {
    EXPECT_EQ(a.traj[i].truth.x, b.traj[i].truth.x);
    EXPECT_EQ(a.traj[i].odom.x, b.traj[i].odom.x);
    EXPECT_EQ(a.traj[i].odom.theta, b.traj[i].odom.theta);
  }
  ASSERT_EQ(a.frames.size(), b.frames.size());
  for (size_t i = 0; i < a.frames.size(); ++i)
    EXPECT_EQ(cv::norm(a.frames[i], b.frames[i], cv::NORM_INF), 0.0);
  EXPECT_EQ(a.scans, b.scans);
  // Another seed: same truth (commands are exact), different noise.
  EXPECT_EQ(a.traj.back().truth.x, c.traj.back().truth.x);
  EXPECT_NE(a.traj.back().odom.x, c.traj.back().odom.x);
  EXPECT_GT(cv::norm(a.frames.back(), c.frames.back(), cv::NORM_L1), 0.0);
}

TEST(TimeModel, CameraDeliversFramesAtItsRate) {
  sim::SimParams p = exactParams();
  p.camera_hz = 10;
  sim::Simulator s(boxWorld(), p);
  hw::Frame f;
  std::vector<double> stamps;
  for (int k = 0; k < 3; ++k) {
    ASSERT_EQ(s.camera().grab(f, 1.0), hw::GrabStatus::Ok);
    stamps.push_back(f.stamp);
  }
  EXPECT_NEAR(stamps[0], 0.0, 1e-9);
  EXPECT_NEAR(stamps[1], 0.1, 1e-9);  // the camera blocked: simulated time moved
  EXPECT_NEAR(stamps[2], 0.2, 1e-9);
  s.clock()->sleepUntil(0.35);
  s.camera().grab(f, 1.0);
  EXPECT_NEAR(f.stamp, 0.35, 1e-9);  // a new frame period had started: delivered at once
  s.camera().grab(f, 1.0);
  EXPECT_NEAR(f.stamp, 0.4, 1e-9);
  EXPECT_EQ(f.seq, 4u);
  EXPECT_EQ(s.camera().grab(f, 0.01), hw::GrabStatus::Timeout);
  EXPECT_EQ(s.stats().frames_rendered, 5u);
}

TEST(TimeModel, DevicesIntegrateLazilyToTheClock) {
  sim::World w = boxWorld(20, 6);
  sim::Simulator s(w, exactParams());
  s.base().command(0.2, 0.0);
  s.clock()->sleepUntil(5.0);
  // Nothing integrated until a device (or truePose) is read; then exactly up to now.
  const double x = s.truePose().x;
  const double ramp = 0.2 * 0.2 / (2 * 1.0);  // distance lost while accelerating
  EXPECT_NEAR(x, 1.0 + 0.2 * 5.0 - ramp, 0.003);
  s.advanceTo(6.0);
  EXPECT_NEAR(s.clock()->now(), 6.0, 1e-12);
}

// A paced run (--realtime) whose loop stalled (simulated time stands still meanwhile) goes on
// at the wall clock's pace: it used to run the whole backlog at full speed, a world faster
// than real time for as long as the stall had lasted.
TEST(TimeModel, APacedRunDoesNotRaceToCatchUpAfterAStall) {
  sim::World w = boxWorld(20, 6);
  sim::SimParams p = exactParams();
  p.realtime = true;
  sim::Simulator s(w, p);
  s.advanceTo(0.1);                                             // the pacing's origin
  std::this_thread::sleep_for(std::chrono::milliseconds(600));  // the loop computes
  const auto t0 = std::chrono::steady_clock::now();
  for (int k = 1; k <= 10; ++k) s.advanceTo(0.1 + 0.05 * k);  // ticks, as the loop's
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // 0.5 s simulated, of which at most 0.1 s (the catch-up allowed) plus the first tick's
  // 0.05 s without waiting; sleeps only ever last longer, so a slow machine cannot fail this.
  EXPECT_GE(wall, 0.34);
}

// ---------------------------------------------------------------- registry and map
// Issue 28: sim://lab?sed=3 ran with the default seed; now it names the parameter.
TEST(Registry, UnknownSimUriParameterIsRefusedWithTheClosestKnownOne) {
  sim::registerDrivers();
  hw::DeviceContext ctx;
  auto message = [&](auto create) -> std::string {
    try {
      create();
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  };
  auto& r = hw::Registry::instance();
  EXPECT_EQ(message([&] { r.createCamera("sim://corridor?sed=3", ctx); }),
            "camera URI 'sim://corridor?sed=3': unknown parameter 'sed' (did you mean 'seed'?)");
  EXPECT_EQ(message([&] { r.createBase("sim://corridor?seed=3&realtim=1", ctx); }),
            "base URI 'sim://corridor?seed=3&realtim=1': unknown parameter 'realtim' (did you "
            "mean 'realtime'?)");
  EXPECT_EQ(message([&] { r.createRange("sim://corridor?sensr=sonar", ctx); }),
            "range sensor URI 'sim://corridor?sensr=sonar': unknown parameter 'sensr' (did you "
            "mean 'sensor'?)");
  // None of them created the simulator.
  EXPECT_EQ(ctx.shared.count("sim:corridor"), 0u);
}

TEST(Registry, SimUrisShareOneSimulatorAndItsClock) {
  sim::registerDrivers();
  hw::DeviceContext ctx;
  ctx.config.set("sim.image_noise_std=0");
  auto cam = hw::Registry::instance().createCamera("sim://corridor?seed=3", ctx);
  auto base = hw::Registry::instance().createBase("sim://corridor?seed=3", ctx);
  auto laser = hw::Registry::instance().createRange("sim://corridor", ctx);
  auto sonar = hw::Registry::instance().createRange("sim://corridor?sensor=sonar", ctx);
  ASSERT_TRUE(ctx.clock);
  auto s = sim::simulatorFor("sim://corridor", ctx);
  EXPECT_EQ(s->params().seed, 3u);
  EXPECT_EQ(s->params().image_noise_std, 0.0);
  EXPECT_EQ(ctx.clock.get(), s->clock().get());
  base->command(0.3, 0);
  ctx.clock->sleepUntil(2.0);
  hw::Odometry o;
  ASSERT_TRUE(base->odometry(o));
  EXPECT_GT(o.pose.x, 0.4);
  EXPECT_NEAR(s->truePose().x, 1.0 + o.pose.x, 0.05);  // default odometry noise
  hw::RangeScan sc;
  ASSERT_TRUE(sonar->read(sc));
  EXPECT_EQ(sc.kind, hw::RangeScan::Kind::Sonar);
  ASSERT_TRUE(laser->read(sc));
  EXPECT_EQ(sc.kind, hw::RangeScan::Kind::Laser);
  hw::Frame f;
  EXPECT_EQ(cam->grab(f, 1.0), hw::GrabStatus::Ok);
  EXPECT_EQ(f.image.size(), cv::Size(640, 480));
  EXPECT_THROW(hw::Registry::instance().createRange("sim://corridor?sensor=radar", ctx),
               InputError);
  EXPECT_THROW(hw::Registry::instance().createCamera("sim://nowhere", ctx), InputError);
  EXPECT_THROW(hw::Registry::instance().createCamera("sim:///no/such/world.json", ctx), InputError);
}

TEST(MapCanvas, DrawsTheWorldAndTrajectories) {
  const sim::World w = sim::labWorld();
  sim::MapCanvas m(w, 20.0, 0.5);
  EXPECT_EQ(m.image().cols, static_cast<int>(std::ceil(19 * 20.0)));
  EXPECT_EQ(m.toPixel({-0.5, 13.5}), cv::Point(0, 0));
  EXPECT_EQ(m.toPixel({0.0, 0.0}), cv::Point(10, 270));
  // The start is a black dot.
  const cv::Vec3b start = m.image().at<cv::Vec3b>(m.toPixel({w.start.x, w.start.y}));
  EXPECT_LT(start[0] + start[1] + start[2], 60);
  const cv::Mat before = m.image().clone();
  m.drawPolyline({{1, 1}, {6, 1}}, cv::Scalar(255, 0, 0), true, 2);
  cv::Mat diff;
  cv::absdiff(before, m.image(), diff);
  EXPECT_GT(cv::countNonZero(diff.reshape(1)), 50);
  const std::string dir = test::tempDir("map");
  m.save(dir + "/map.png");
  EXPECT_FALSE(cv::imread(dir + "/map.png").empty());
  // A missing folder is bad input (outputs go only into folders that exist).
  EXPECT_THROW(m.save("/nonexistent-dir/map.png"), InputError);
}

TEST(Range, ClosedDoorBlocksOpenDoorDoesNot) {
  sim::World w = boxWorld(10, 4);
  w.start = {2.0, 2.0, 0.0};
  // A partition at x = 5 with a 1 m door opening around y = 2.
  w.walls.push_back({"partition low", {5, 0}, {5, 1.5}});
  w.walls.push_back({"partition high", {5, 2.5}, {5, 4}});
  w.doors = {{"door", {5, 1.5}, {5, 2.5}, true}};
  hw::RangeScan scan;
  {
    sim::Simulator s(w, exactParams());
    s.laser().read(scan);
    EXPECT_NEAR(scan.ranges[120], 9.95 - 2.15, 1e-4);  // through the open door
  }
  w.doors[0].open = false;
  sim::Simulator s(w, exactParams());
  s.laser().read(scan);
  EXPECT_NEAR(scan.ranges[120], 5.0 - 0.025 - 2.15, 1e-4);
  s.base().command(0.5, 0);
  s.clock()->sleepUntil(10);
  EXPECT_TRUE(s.collided());
  EXPECT_EQ(s.collisionWith(), "door");
}

TEST(LabWorld, ReferenceRouteIsFreeAndPassesEveryLandmark) {
  // The route the paper describes: around the humidifier table, past the robot and the
  // toolbox, through the walkway, past the trash can, behind the lab bench to the right door.
  const std::vector<Vec2> route = {{0.8, 10.1}, {2.5, 11.3}, {5.0, 11.3}, {6.6, 8.8}, {7.0, 6.5},
                                   {11.0, 6.5}, {16.6, 6.5}, {17.0, 3.4}, {17.4, 2.6}};
  sim::World w = sim::labWorld();
  w.pedestrians.clear();
  sim::Simulator s(w, exactParams());
  for (size_t i = 1; i < route.size(); ++i) {
    const Vec2 a = route[i - 1], b = route[i];
    const int n = static_cast<int>((b - a).norm() / 0.05) + 1;
    for (int k = 0; k <= n; ++k) {
      const Vec2 p = a + (b - a) * (static_cast<double>(k) / n);
      s.setTruePose({p.x(), p.y(), 0});
      EXPECT_GT(s.clearance(), 0.1) << "route blocked near " << p.transpose();
    }
  }
  EXPECT_LT((route.back() - w.goal.centre).norm(), w.goal.radius);
  for (const auto& l : w.landmarks) {
    double d = 1e9;
    for (size_t i = 1; i < route.size(); ++i) {
      const Vec2 ab = route[i] - route[i - 1];
      const double t = std::clamp((l.position - route[i - 1]).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
      d = std::min(d, (route[i - 1] + t * ab - l.position).norm());
    }
    EXPECT_GE(d, 1.0) << l.id;
    EXPECT_LE(d, 2.5) << l.id;
  }
}

TEST(LabRendering, RenderedLandmarksMatchTheirDatabasePhotos) {
  // What the recogniser will do: SIFT keypoints of a rendered view (default noise) matched to
  // the landmark's iconic photo, ratio test + RANSAC homography. A simulator whose photos did
  // not survive rendering would make every closed-loop result meaningless.
  const sim::World lab = sim::labWorld();
  sim::Simulator s(lab, sim::SimParams{});
  auto sift = cv::SIFT::create();
  cv::BFMatcher matcher(cv::NORM_L2);
  for (const auto& l : lab.landmarks) {
    const Vec2 n(std::cos(l.yaw), std::sin(l.yaw));
    const Vec2 p = l.position + 2.0 * n;
    const cv::Mat view = s.renderView({p.x(), p.y(), std::atan2(-n.y(), -n.x())}, 0, true);
    const cv::Mat photo = cv::imread(l.texture, cv::IMREAD_GRAYSCALE);
    cv::Mat gray;
    cv::cvtColor(view, gray, cv::COLOR_BGR2GRAY);
    std::vector<cv::KeyPoint> kv, kp;
    cv::Mat dv, dp;
    sift->detectAndCompute(gray, cv::noArray(), kv, dv);
    sift->detectAndCompute(photo, cv::noArray(), kp, dp);
    ASSERT_FALSE(dp.empty()) << l.id;
    std::vector<std::vector<cv::DMatch>> knn;
    matcher.knnMatch(dp, dv, knn, 2);
    std::vector<cv::Point2f> src, dst;
    for (const auto& m : knn)
      if (m.size() == 2 && m[0].distance < 0.8f * m[1].distance) {
        src.push_back(kp[m[0].queryIdx].pt);
        dst.push_back(kv[m[0].trainIdx].pt);
      }
    ASSERT_GE(src.size(), 8u) << l.id << " " << l.class_name;
    cv::Mat inliers;
    cv::findHomography(src, dst, cv::RANSAC, 4.0, inliers);
    EXPECT_GE(cv::countNonZero(inliers), 8) << l.id << " " << l.class_name;
  }
}

// Bad-input campaign (issue 28): a world nested 100,000 deep crashed `sim map` (SIGSEGV);
// a FIFO as world or texture blocked for ever; a 30,000-element value was quoted whole.
TEST(WorldValidation, DeepNestingIsAnInputErrorNamingTheFile) {
  const std::string dir = test::tempDir("world_deep");
  std::string text = minimalWorldJson().dump();
  const std::string deep = std::string(100000, '[') + std::string(100000, ']');
  text.replace(text.find("[0,0]"), 5, deep);
  const std::string p = dir + "/deep.world.json";
  std::ofstream(p) << text;
  try {
    sim::loadWorld(p);
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find(p), std::string::npos) << m;
    EXPECT_NE(m.find("nested deeper than"), std::string::npos) << m;
  }
}

TEST(WorldValidation, SpecialFilesAreRefused) {
  const std::string dir = test::tempDir("world_fifo");
  const std::string fifo = dir + "/pipe.world.json";
  ::unlink(fifo.c_str());
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_THROW(sim::loadWorld(fifo), InputError);
  EXPECT_THROW(sim::loadWorld(dir), InputError);
  const std::string tex = dir + "/pipe.jpg";
  ::unlink(tex.c_str());
  ASSERT_EQ(::mkfifo(tex.c_str(), 0600), 0);
  Json j = minimalWorldJson();
  j["landmarks"][0]["texture"] = tex;
  const std::string m = loadError(j);
  EXPECT_NE(m.find("texture"), std::string::npos) << m;
  EXPECT_NE(m.find("not a regular file"), std::string::npos) << m;
}

TEST(WorldValidation, HugeValuesAreQuotedInPart) {
  Json j = minimalWorldJson();
  j["start"]["x"] = Json::array();
  for (int i = 0; i < 30000; ++i) j["start"]["x"].push_back(i);
  const std::string m = loadError(j);
  EXPECT_NE(m.find("start"), std::string::npos) << m;
  EXPECT_LT(m.size(), 400u);
}

// A pedestrian coming up behind the robot waits short of it (the robot does not see behind
// it); from the front it walks on into it. Off, it walks into it from behind too.
TEST(Pedestrians, WaitBehindTheRobotButNotInFrontOfIt) {
  sim::World w = boxWorld(20, 6);
  w.start = {6.0, 3.0, 0.0};  // facing +x; the walker comes along y = 3 from x = 1
  sim::Pedestrian p;
  p.name = "walker";
  p.path = {{1.0, 3.0}, {15.0, 3.0}};
  p.speed = 0.5;
  p.radius = 0.25;
  w.pedestrians = {p};
  const double reach = p.radius + w.robot.radius;
  {
    sim::Simulator s(w, exactParams());
    s.clock()->sleepUntil(20.0);  // it would be at x = 11 by now
    EXPECT_FALSE(s.collided());
    const auto st = s.pedestrians()[0];
    EXPECT_NEAR(6.0 - st.position.x() - reach, 0.5, 0.02);  // waiting 0.5 m short
    EXPECT_EQ(st.velocity.norm(), 0.0);
    EXPECT_NEAR(s.minClearancePeople(), 0.5, 0.02);
    // The robot drives on: the walker follows, and never closes in on it.
    s.base().command(0.3, 0.0);
    s.clock()->sleepUntil(26.0);
    EXPECT_FALSE(s.collided());
    EXPECT_GT(s.pedestrians()[0].position.x(), st.position.x() + 1.0);
    EXPECT_GE(s.minClearancePeople(), 0.45);
  }
  {
    sim::SimParams off = exactParams();
    off.pedestrian_keep_behind_m = 0;
    sim::Simulator s(w, off);
    s.clock()->sleepUntil(20.0);
    EXPECT_TRUE(s.collided());
    EXPECT_EQ(s.collisionWith(), "walker");
    EXPECT_LT(s.minClearancePeople(), 0.0);
  }
  {
    sim::World front = w;
    front.start = {6.0, 3.0, M_PI};  // facing the walker: it walks on
    sim::Simulator s(front, exactParams());
    s.clock()->sleepUntil(20.0);
    EXPECT_TRUE(s.collided());
  }
}
