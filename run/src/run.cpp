#include "sketchnav/run/run.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "sketchnav/core/angles.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/hash.h"
#include "sketchnav/core/image_file.h"
#include "sketchnav/core/input_file.h"
#include "sketchnav/core/log.h"
#include "sketchnav/core/paths.h"
#include "sketchnav/drivers/rawlog.h"
#include "sketchnav/drivers/recording.h"
#include "sketchnav/drivers/register.h"
#include "sketchnav/hw/gated_base.h"
#include "sketchnav/hw/registry.h"
#include "sketchnav/landmarks/model.h"
#include "sketchnav/landmarks/photo_hash.h"
#include "sketchnav/mapsketch/io.h"
#include "sketchnav/mapsketch/route.h"
#include "sketchnav/nav/executive.h"
#include "sketchnav/nav/sections.h"
#include "sketchnav/run/judge.h"
#include "sketchnav/run/run_folder.h"
#include "sketchnav/run/scenario.h"
#include "sketchnav/run/summary.h"
#include "sketchnav/sim/map_render.h"
#include "sketchnav/sim/register.h"
#include "sketchnav/sim/simulator.h"
#include "sketchnav/sim/world_check.h"

#include "frames.h"

namespace sketchnav::run {
namespace fs = std::filesystem;

std::string modelCachePath(const std::string& landmark_dir, const std::string& cache_dir) {
  std::string dir = cache_dir;
  if (dir.empty()) {
    if (const char* x = std::getenv("XDG_CACHE_HOME"); x && *x)
      dir = std::string(x) + "/sketchnav";
    else if (const char* h = std::getenv("HOME"); h && *h)
      dir = std::string(h) + "/.cache/sketchnav";
    else
      dir = (fs::temp_directory_path() / "sketchnav-cache").string();
  }
  // FNV-1a of the landmark set's fingerprint (paths + sizes): a changed set gets a new file.
  const std::string fingerprint = landmarks::landmarkSetFingerprint(landmark_dir);
  const std::uint64_t h = fnv1a(fingerprint.data(), fingerprint.size());
  std::ostringstream name;
  // The format version is in the name too: builds of different versions sharing one cache
  // directory would otherwise keep retraining over each other's file.
  name << "landmarks-v" << landmarks::LandmarkModel::kFormatVersion << "-" << std::hex
       << std::setw(16) << std::setfill('0') << h << ".slm";
  return (fs::path(dir) / name.str()).string();
}

namespace {

// A world texture that is one of the model's database photos (or a near-duplicate of one).
struct TrainingTexture {
  std::string texture, photo;
  int distance = 0;  // [bits] perceptual-hash distance
};

std::vector<TrainingTexture> trainingTextures(const sim::World& w,
                                              const landmarks::LandmarkModel& model) {
  std::vector<std::string> files;
  std::vector<cv::Mat> images;
  std::set<std::string> seen;
  for (const auto& l : w.landmarks)
    for (const std::string& tex : {l.texture, l.back_texture}) {
      if (tex.empty() || !seen.insert(tex).second) continue;
      cv::Mat img = readImageFile(tex, "texture");
      files.push_back(tex);
      images.push_back(std::move(img));
    }
  const auto hits = landmarks::findTrainingPhotos(model, images);
  std::vector<TrainingTexture> out;
  for (size_t i = 0; i < files.size(); ++i)
    if (!hits[i].empty())
      out.push_back({files[i], hits[i].front().photo, hits[i].front().distance});
  return out;
}

// World checks that need the model and the sketch (sim/world_check.h): a landmark of a class
// the model does not know is an error, so is a start heading the sketch contradicts; doubts
// (a free-standing board, furniture overlapping furniture, a start heading 30-90 deg off) are
// logged as warnings. The geometry's errors were thrown when the world was loaded.
void checkWorldForRun(const sim::World& w, const landmarks::LandmarkModel& model,
                      const mapsketch::Route& route, const std::string& world_name,
                      const std::string& model_path, const std::string& sketch_path) {
  const std::string origin = w.source.empty() ? world_name : w.source;
  std::vector<sim::WorldIssue> issues = sim::checkWorldGeometry(w);
  for (auto& i : sim::checkLandmarkClasses(w, model.classes())) {
    i.message += " of the model " + model_path;
    issues.push_back(i);
  }
  sim::RoutePlacement placed{route.start_m, route.start_heading_rad, {}};
  for (const auto& sec : route.sections)
    for (const auto& lm : sec.landmarks) placed.landmarks.push_back({lm.id, lm.position_m});
  for (const auto& i : sim::checkStartHeading(w, placed, sketch_path)) issues.push_back(i);
  for (const auto& i : issues)
    if (i.isError()) throw InputError(i.text(origin));
  for (const auto& i : issues) log::warn("run", i.text(origin));
}

// Route frame -> world frame for drawing: the route's start at the world start pose, facing
// along the first section (the executive's initial alignment).
struct RouteToWorld {
  hw::Pose2D start;
  Eigen::Vector2d route_start{0, 0};
  double rot = 0;
  Eigen::Vector2d operator()(const Eigen::Vector2d& p) const {
    const Eigen::Vector2d d = p - route_start;
    const double a = rot, c = std::cos(a), s = std::sin(a);
    return odomToWorld(start, {c * d.x() - s * d.y(), s * d.x() + c * d.y()});
  }
};

class RunObserver final : public nav::ExecutiveObserver {
 public:
  RunObserver(const std::string& out, bool progress, sim::Simulator* sim, int sections)
      : progress_(progress), sim_(sim), sections_(sections) {
    if (!out.empty()) {
      events_.open(out + "/events.jsonl");
      // (The telemetry writer flushes its header at open and writes every row whole.)
      const bool tele_ok = tele_.open(out + "/telemetry.csv");
      if (!events_ || !tele_ok) throw RuntimeError("cannot write run files in " + out);
    }
  }
  std::vector<hw::Pose2D> odom;  // for hardware runs' trajectory
  // The simulator's truth at the last tick: odometry is judged against the truth of its own
  // tick (the truth at run end can be a tick later, 2.3 deg apart when turning at 0.8 rad/s).
  hw::Pose2D last_truth;
  std::optional<Eigen::Vector2d> goal_odom;  // where the executive finally put the goal

  std::function<void(const nav::NavEvent&)> on_event;  // RunOptions hooks
  std::function<void(const nav::TelemetryRow&)> on_tick;

  void onEvent(const nav::NavEvent& ev) override {
    namespace event = nav::event;
    if (on_event) on_event(ev);
    if (const auto* d = ev.as<event::SectionDone>(); d && d->section == sections_ - 1)
      goal_odom = d->end_odom;
    // One line, written whole and flushed (one write()): a run killed at any moment leaves
    // events.jsonl readable to its last whole line.
    if (events_.is_open()) events_ << ev.toJson().dump() + '\n' << std::flush;
    if (!progress_) return;
    char head[64];
    std::snprintf(head, sizeof head, "[t=%6.1fs] ", ev.t);
    auto sec = [&](int section) {
      return "section " + std::to_string(section + 1) + "/" + std::to_string(sections_);
    };
    std::string msg;
    if (ev.is<event::Start>()) {
      msg = "start: " + std::to_string(sections_) + " sections";
    } else if (const auto* e = ev.as<event::LandmarkSeen>()) {
      msg = sec(e->section) + ": landmark " + e->id + " (" + e->class_name + ") seen, " +
            std::to_string(e->inliers) + " inliers, range " + fmt(e->range_m) + " m";
    } else if (const auto* e = ev.as<event::LandmarkPassed>()) {
      msg = sec(e->section) + ": landmark " + e->id + " passed";
    } else if (const auto* e = ev.as<event::LandmarkMissed>()) {
      msg = sec(e->section) + ": landmark " + e->id + " not seen, continuing on odometry";
    } else if (const auto* e = ev.as<event::LandmarkLost>()) {
      msg = sec(e->section) + ": landmark " + e->id + " lost";
    } else if (const auto* e = ev.as<event::SectionDone>()) {
      msg = sec(e->section) + " done";
    } else if (const auto* e = ev.as<event::AvoidStart>()) {
      msg = sec(e->section) + ": obstacle " + fmt(e->front_free_m) + " m ahead, dodging " +
            nav::toString(e->side);
    } else if (ev.is<event::AvoidEnd>()) {
      msg = "obstacle cleared";
    } else if (const auto* e = ev.as<event::GoalDoor>()) {
      msg = "goal doorway found (" + fmt(e->width_m) + " m wide): the goal moved " +
            fmt(e->moved_m) + " m to " + fmt(e->standoff_m) + " m in front of it";
    } else if (const auto* e = ev.as<event::Fault>()) {
      msg = "FAULT: " + e->reason;
    } else if (const auto* e = ev.as<event::Arrived>()) {
      msg = "arrived: " + e->reason;
    } else if (const auto* e = ev.as<event::Failed>()) {
      msg = "failed: " + e->reason;
    }
    if (!msg.empty()) std::cerr << head << msg << "\n";
  }

  void onTick(const nav::TelemetryRow& r) override {
    if (on_tick) on_tick(r);
    hw::Pose2D truth;
    if (sim_) truth = sim_->truePose();
    last_truth = truth;
    odom.push_back(r.odom);
    tele_.write(r, sim_ ? &truth : nullptr);
    if (progress_ && r.t >= next_progress_) {
      next_progress_ = r.t + 5.0;
      char buf[200];
      std::snprintf(buf, sizeof buf,
                    "[t=%6.1fs] section %d/%d %-6s v=%.2f m/s w=%+.2f rad/s %-8s landmark %s", r.t,
                    r.section + 1, sections_, nav::toString(r.mode), r.v_cmd, r.w_cmd,
                    servo::toString(r.turn), r.landmark.empty() ? "-" : r.landmark.c_str());
      std::cerr << buf << "\n";
    }
  }

 private:
  static std::string fmt(double v) {
    char b[32];
    std::snprintf(b, sizeof b, "%.2f", v);
    return b;
  }
  bool progress_;
  sim::Simulator* sim_;
  int sections_;
  std::ofstream events_;
  TelemetryWriter tele_;
  double next_progress_ = 0;
};

// Hands every frame perception examined, and its result, to RunOptions::on_observation.
class TappedPerception final : public nav::Perception {
 public:
  TappedPerception(nav::Perception& inner,
                   std::function<void(const hw::Frame&, const nav::Observation&)> tap)
      : inner_(inner), tap_(std::move(tap)) {}
  nav::Observation observe(const hw::Frame& frame, const hw::Intrinsics& k,
                           const std::vector<std::string>& classes) override {
    nav::Observation obs = inner_.observe(frame, k, classes);
    if (tap_) tap_(frame, obs);
    return obs;
  }
  nav::Observation observe(const hw::Frame& frame, const hw::Intrinsics& k,
                           const std::vector<nav::LookFor>& look_for) override {
    nav::Observation obs = inner_.observe(frame, k, look_for);
    if (tap_) tap_(frame, obs);
    return obs;
  }

 private:
  nav::Perception& inner_;
  std::function<void(const hw::Frame&, const nav::Observation&)> tap_;
};

void drawTrajectory(const std::string& path, const sim::World& world,
                    const mapsketch::Sketch& sketch, const mapsketch::Route& route,
                    const RouteToWorld& r2w, const std::vector<hw::Pose2D>& traj) {
  sim::MapCanvas canvas(world, 40.0, 0.5, true);
  // The hand-drawn path as drawn (canvas px -> route frame -> world), solid.
  std::vector<Eigen::Vector2d> drawn;
  for (const auto& p : drawnPathInRoute(sketch, route)) drawn.push_back(r2w(p));
  canvas.drawPolyline(drawn, {0, 0, 0}, false, 2);
  // Where the sketch put the landmarks (hollow grey), next to the real ones the map shows.
  for (const auto& sec : route.sections)
    for (const auto& lm : sec.landmarks) {
      canvas.drawStar(r2w(lm.position_m), {150, 150, 150}, 6);
      canvas.drawText(r2w(lm.position_m) + Eigen::Vector2d(0.15, -0.15), lm.id + "?",
                      {120, 120, 120}, 0.35);
    }
  canvas.drawPoses(traj, {200, 60, 20}, true, 2);
  canvas.drawStart({world.start.x, world.start.y});
  canvas.drawGoal(world.goal.centre, world.goal.radius);
  canvas.drawLegend({{"sketched path", {0, 0, 0}},
                     {"actual trajectory (dashed)", {200, 60, 20}},
                     {"sketched landmark position", {150, 150, 150}}});
  canvas.save(path);
}

}  // namespace

bool isWorldFile(const std::string& s) {
  return s.find('/') != std::string::npos || (s.size() > 5 && s.substr(s.size() - 5) == ".json");
}

std::string defaultSketchPath(const std::string& world) {
  if (!isWorldFile(world)) return resourcePath("sketches/" + world + ".sketch.json");
  const std::string suffix = ".world.json";
  if (world.size() > suffix.size() && world.substr(world.size() - suffix.size()) == suffix)
    return world.substr(0, world.size() - suffix.size()) + ".sketch.json";
  return "";
}

std::vector<Eigen::Vector2d> drawnPathInRoute(const mapsketch::Sketch& sketch,
                                              const mapsketch::Route& route) {
  std::vector<Eigen::Vector2d> out;
  out.reserve(sketch.path.size());
  for (const auto& p : sketch.path)
    out.push_back(route.start_m +
                  Eigen::Vector2d((p.x() - sketch.start.x()) * route.scale_m_per_px,
                                  -(p.y() - sketch.start.y()) * route.scale_m_per_px));
  return out;
}

RunSettings runSettingsFrom(const Config& c) {
  RunSettings r;
  applyConfig(r.route, c, "route");
  applyConfig(r.train, c, "landmarks.train");
  r.camera = cameraMountFrom(c);
  r.nav = nav::navSettingsFrom(c);
  r.perception = nav::perceptionParamsFrom(c);
  applyConfig(r.sim, c, "sim");
  return r;
}

Json runSettingsJson(const RunSettings& r, bool with_sim) {
  Json j = Json::object();
  j["robot"]["camera"] = paramsToJson(r.camera);
  j["route"] = paramsToJson(r.route);
  j["landmarks"]["train"] = paramsToJson(r.train);
  j["landmarks"]["recognition"] = paramsToJson(r.perception.recognition);
  j["landmarks"]["match"] = paramsToJson(r.perception.match);
  Json n = paramsToJson(r.nav.exec);
  n["sections"] = paramsToJson(r.nav.sections);
  n["select"] = paramsToJson(r.nav.select);
  n["locate"] = paramsToJson(r.nav.locate);
  n["avoid"] = paramsToJson(r.nav.avoid);
  n["safety"] = paramsToJson(r.nav.safety);
  n["laser_odometry"] = paramsToJson(r.nav.laser_odometry);
  n["planner"] = paramsToJson(r.nav.planner);
  n["movers"] = paramsToJson(r.nav.movers);
  n["goal_door"] = paramsToJson(r.nav.goal_door);
  n["perception"] = paramsToJson(r.perception);
  n["perception"]["track"] = paramsToJson(r.perception.track);
  j["nav"] = n;
  j["servo"] = paramsToJson(r.nav.servo);
  Json ob = paramsToJson(r.perception.objectness);
  ob["ccs"] = paramsToJson(r.perception.objectness.ccs);
  ob["scs"] = paramsToJson(r.perception.objectness.scs);
  j["objectness"] = ob;
  if (with_sim) j["sim"] = paramsToJson(r.sim);
  return j;
}

const std::vector<std::string>& driverSettingPrefixes() {
  static const std::vector<std::string> p = {"base.", "camera.", "laser.", "sonar."};
  return p;
}

Json runNavigation(const RunOptions& o) {
  using wall = std::chrono::steady_clock;
  drivers::registerDrivers();
  sim::registerDrivers();
  const bool replay = !o.replay.empty();
  if (replay && (!o.robot.empty() || !o.camera.empty() || !o.laser.empty() || !o.sonar.empty()))
    throw InputError("--replay cannot be combined with --robot/--camera/--laser/--sonar");
  // A replayed rawlog is treated like hardware (no simulator, no world map, odometry only).
  const bool hardware =
      replay || !o.robot.empty() || !o.camera.empty() || !o.laser.empty() || !o.sonar.empty();
  if (o.seed < 0) throw InputError("--seed must be >= 0");
  // Every setting first: a typo fails here, before a device is opened or a model trained.
  // Device drivers' settings are checked once the devices are open.
  RunSettings rs = runSettingsFrom(o.config);
  o.config.requireAllUsedExcept(driverSettingPrefixes());
  hw::DeviceContext ctx;
  ctx.config = o.config;
  if (o.realtime) ctx.config.set("sim.realtime", true);

  // --- devices ----------------------------------------------------------------------------
  std::shared_ptr<sim::Simulator> simr;
  // `base` before `camera`: the camera may hold a pointer to the base's gate (below), so it
  // is destroyed first.
  std::unique_ptr<hw::Base> base;
  std::unique_ptr<hw::Camera> camera;
  std::unique_ptr<hw::RangeSensor> laser, sonar;
  std::string world_name = o.world;
  if (!hardware) {
    std::string world_uri;
    if (isWorldFile(o.world)) {
      if (!fs::exists(o.world)) throw InputError("--world " + o.world + ": no such file");
      world_uri = "sim://" + fs::absolute(o.world).string();
    } else {
      world_uri = "sim://" + o.world;
    }
    const std::string q = "?seed=" + std::to_string(o.seed);
    simr = sim::simulatorFor(world_uri + q, ctx);
    base = hw::Registry::instance().createBase(world_uri + q, ctx);
    camera = hw::Registry::instance().createCamera(world_uri + q, ctx);
    if (simr->world().laser.enabled)
      laser = hw::Registry::instance().createRange(world_uri + q + "&sensor=laser", ctx);
    if (simr->world().sonar.enabled)
      sonar = hw::Registry::instance().createRange(world_uri + q + "&sensor=sonar", ctx);
  } else if (replay) {
    if (!fs::exists(o.replay)) throw InputError("--replay " + o.replay + ": no such file");
    // A ROS bag (.bag: camera, odometry, scans as `ros sim` publishes them, or as `run
    // --record x.bag` writes them) or an MRPT rawlog.
    const bool bag = fs::path(o.replay).extension() == ".bag";
    const std::string uri = (bag ? "bag://" : "rawlog://") + fs::absolute(o.replay).string();
    // Simulated time: the log is replayed at its recorded pace on a clock that jumps, so the
    // replay runs as fast as the CPU allows and every device stays in step.
    ctx.clock = std::make_shared<hw::SimClock>();
    base = hw::Registry::instance().createBase(uri, ctx);
    camera = hw::Registry::instance().createCamera(uri + "?realtime=1", ctx);
    // A log may hold no laser or no sonar scans: that device is then simply absent.
    try {
      laser = hw::Registry::instance().createRange(uri + (bag ? "?kind=laser" : ""), ctx);
    } catch (const InputError&) {
    }
    try {
      sonar =
          hw::Registry::instance().createRange(uri + (bag ? "?kind=sonar" : "?label=SONAR"), ctx);
    } catch (const InputError&) {
    }
  } else {
    if (o.robot.empty()) throw InputError("--robot URI is required with hardware devices");
    ctx.clock = std::make_shared<hw::SteadyClock>();
    base = hw::Registry::instance().createBase(o.robot, ctx);
    if (!o.camera.empty()) camera = hw::Registry::instance().createCamera(o.camera, ctx);
    if (!o.laser.empty()) laser = hw::Registry::instance().createRange(o.laser, ctx);
    if (!o.sonar.empty()) sonar = hw::Registry::instance().createRange(o.sonar, ctx);
  }
  if (o.wrap_camera && camera) camera = o.wrap_camera(std::move(camera));
  if (o.wrap_base && base) base = o.wrap_base(std::move(base));
  if (!camera) throw InputError("--camera URI is required: landmarks are seen by a camera");
  o.config.requireAllUsed();
  std::shared_ptr<drivers::Recorder> rec;
  if (!o.record.empty()) {
    rec = drivers::openRecorder(o.record);
    camera = drivers::recordCamera(std::move(camera), rec);
    base = drivers::recordBase(std::move(base), rec, ctx.clock);
    if (laser) laser = drivers::recordRange(std::move(laser), rec, "LASER");
    if (sonar) sonar = drivers::recordRange(std::move(sonar), rec, "SONAR");
  }
  // A camera that reports losing its device (aravis://, after its lost_timeout_s) stops the
  // base in that call and blocks motion until frames flow again, whoever commands it; the
  // executive then sees the base not ok and fails the run with the camera named. Outermost, so
  // the recording and the run page's base get that stop too.
  base = hw::stopBaseWhileCameraIsLost(std::move(base), *camera);

  // --- sketch -> route ----------------------------------------------------------------------
  std::string sketch_path = o.sketch;
  if (sketch_path.empty()) {
    sketch_path = defaultSketchPath(o.world);
    if (isWorldFile(o.world)) {
      // A world file not named *.world.json has no sketch beside it by convention: the file
      // itself is tried, and loadSketch says why it is not a sketch.
      if (sketch_path.empty()) sketch_path = o.world;
      if (!fs::exists(sketch_path))
        throw InputError("--sketch is required (no " + sketch_path + ")");
    }
  }
  const mapsketch::Sketch sketch = mapsketch::loadSketch(sketch_path);
  const mapsketch::Route route = mapsketch::toRoute(sketch, rs.route);

  // --- landmark model -------------------------------------------------------------------------
  std::string model_path = o.model;
  const landmarks::ModelParams& mp = rs.train;
  auto model = std::make_shared<landmarks::LandmarkModel>();
  if (!model_path.empty()) {
    *model = landmarks::LandmarkModel::load(model_path);
  } else {
    const std::string dir = o.landmark_dir.empty() ? resourcePath("landmarks") : o.landmark_dir;
    model_path = modelCachePath(dir, o.cache_dir);
    const bool cached = fs::exists(model_path);
    if (o.progress && !cached)
      std::cerr << "training the landmark model from " << dir << " (first use; cached in "
                << model_path << ")\n";
    int last_pct = -1;
    *model = landmarks::loadOrTrainModel(
        dir, model_path, mp, [&](const std::string& stage, int done, int total) {
          const int pct = total > 0 ? 100 * done / total : 0;
          if (o.progress && pct / 25 != last_pct / 25)
            std::cerr << "  " << stage << " " << done << "/" << total << "\n";
          last_pct = pct;
        });
  }
  mapsketch::validateClasses(sketch, model->classes(), sketch_path);
  std::vector<TrainingTexture> training_textures;
  if (simr) {
    checkWorldForRun(simr->world(), *model, route, world_name, model_path, sketch_path);
    training_textures = trainingTextures(simr->world(), *model);
    for (const auto& t : training_textures)
      log::warn("run",
                "the world shows the model one of its training photos: this run tests the "
                "model on its own training data, not as a real camera would",
                {{"texture", t.texture},
                 {"training_photo", t.photo},
                 {"hash_distance_bits", std::to_string(t.distance)}});
  }

  // The model's search indexes are built now, before the route starts, rather than by the first
  // perception pass.
  buildIndexes(*model, "run");

  // --- settings -----------------------------------------------------------------------------
  nav::NavSettings& settings = rs.nav;
  nav::PerceptionParams& pp = rs.perception;
  if (simr) {
    // The simulated robot's geometry, unless the user overrides it.
    const auto& w = simr->world();
    if (!o.config.has("robot.camera.x_m")) rs.camera.x_m = w.camera.x;
    if (!o.config.has("robot.camera.z_m")) rs.camera.z_m = w.camera.z;
    if (!o.config.has("robot.camera.yaw")) rs.camera.yaw = w.camera.yaw;
    if (!o.config.has("robot.camera.pitch")) rs.camera.pitch = w.camera.pitch;
    if (!o.config.has("nav.avoid.robot_radius_m")) settings.avoid.robot_radius_m = w.robot.radius;
    if (!o.config.has("nav.camera_period_s") && simr->params().camera_hz > 0)
      settings.exec.camera_period_s = 1.0 / simr->params().camera_hz;
  }
  if (replay) {
    // The robot's geometry the recorded run used (RunInfo), unless the user overrides it: a
    // replay with another camera mount would servo differently on the same frames.
    // Recordings made before the mount was one setting group name it the old way.
    // A recording without run info (a bag recorded beside a ROS robot) may still show the
    // camera's mount in its tf, as `ros nav` took it live (readRecordedRobot).
    const Json info = drivers::readRunInfo(o.replay);
    std::optional<Json> robot;  // read only when the run info lacks a key (another bag scan)
    const auto take = [&](const std::string& key, double& v) {
      std::string k = key;
      for (const auto& [old_key, new_key] : cameraMountRenames())
        if (new_key == key && !info.contains(key) && info.contains(old_key)) k = old_key;
      if (o.config.has(key)) return;
      const bool recorded = info.contains(k);
      if (!recorded && !robot) robot = drivers::readRecordedRobot(o.replay);
      const Json& from = recorded ? info : *robot;
      if (!from.contains(k)) return;
      if (!from[k].is_number())
        throw InputError("--replay " + o.replay + ": " + (recorded ? "run info" : "recorded tf") +
                         " '" + k + "' is not a number");
      v = from[k].get<double>();
    };
    take("robot.camera.x_m", rs.camera.x_m);
    take("robot.camera.z_m", rs.camera.z_m);
    take("nav.avoid.robot_radius_m", settings.avoid.robot_radius_m);
    take("nav.camera_period_s", settings.exec.camera_period_s);
    take("robot.camera.yaw", rs.camera.yaw);
    take("robot.camera.pitch", rs.camera.pitch);
  }
  rs.camera.validate();
  settings.servo.setCamera(rs.camera);
  pp.setCamera(rs.camera);
  if (rec)
    rec->addRunInfo({{"robot.camera.x_m", rs.camera.x_m},
                     {"robot.camera.z_m", rs.camera.z_m},
                     {"nav.avoid.robot_radius_m", settings.avoid.robot_radius_m},
                     {"nav.camera_period_s", settings.exec.camera_period_s},
                     {"robot.camera.yaw", rs.camera.yaw},
                     {"robot.camera.pitch", rs.camera.pitch}});
  if (o.max_time_s > 0) settings.exec.max_time_s = o.max_time_s;
  settings.exec.validate();
  settings.servo.validate();
  settings.avoid.validate();
  pp.validate();

  if (!o.out_dir.empty()) fs::create_directories(o.out_dir);
  RunObserver observer(o.out_dir, o.progress, simr.get(), static_cast<int>(route.sections.size()));
  nav::LandmarkPerception perception(model, pp);
  observer.on_event = o.on_event;
  observer.on_tick = o.on_tick;
  TappedPerception tapped(perception, o.on_observation);
  nav::Devices dev;
  dev.camera = camera.get();
  dev.base = base.get();
  if (laser) dev.ranges.push_back(laser.get());
  if (sonar) dev.ranges.push_back(sonar.get());
  dev.clock = ctx.clock.get();

  const auto w0 = wall::now();
  nav::ExecutiveSummary es;
  {
    nav::Perception& used = o.on_observation ? static_cast<nav::Perception&>(tapped) : perception;
    nav::Executive ex(route, dev, used, settings, &observer);
    if (o.stop_requested || o.after_step) {
      // Executive::run()'s loop, asking before every tick whether the user pressed Stop.
      ex.start();
      double next = dev.clock->now();
      while (!ex.done()) {
        next += settings.exec.tick_s;
        dev.clock->sleepUntil(next);
        // A clock that returned early (the ROS clock when a camera frame arrives) re-phases
        // the ticks on that instant rather than running the next one a tick_s too early.
        next = std::min(next, dev.clock->now());
        if (o.stop_requested && o.stop_requested())
          ex.stop("stopped by user");
        else
          ex.step();
        if (o.after_step) o.after_step(ex);
      }
      es = ex.summary();
    } else {
      es = ex.run();
    }
  }
  const double wall_s = std::chrono::duration<double>(wall::now() - w0).count();

  // --- summary ------------------------------------------------------------------------------
  // The figures its users read back are typed (RunSummary, written by its toJson at the end);
  // the rest is added here.
  Json s;
  RunSummary fig;
  bool success = es.status == nav::RunStatus::Succeeded;
  std::string reason = es.reason;
  s["mode"] = replay ? "replay" : hardware ? "hardware" : "sim";
  if (!o.record.empty()) s["record"] = o.record;
  fig.time_s = es.time_s;
  fig.wall_time_s = wall_s;
  fig.real_time_factor = wall_s > 0 ? es.time_s / wall_s : 0.0;
  s["odom_path_m"] = es.odom_path_m;
  fig.path_length_m = es.odom_path_m;
  s["seed"] = o.seed;
  s["world"] = hardware ? "" : world_name;
  s["sketch"] = sketch_path;
  s["model"] = model_path;
  Json tt = Json::array();
  for (const auto& t : training_textures)
    tt.push_back(
        {{"texture", t.texture}, {"training_photo", t.photo}, {"distance_bits", t.distance}});
  s["training_textures"] = tt;
  Json recognised = Json::array();
  for (const auto& l : es.landmarks)
    if (l.frames_seen > 0) recognised.push_back(l.id);
  s["landmarks_recognised"] = recognised;
  s["landmarks_expected"] = es.landmarks.size();
  const Json ej = es.toJson();
  s["landmarks"] = ej["landmarks"];
  s["sections_done"] = es.sections_done;
  s["sections"] = es.sections;
  s["avoidance_manoeuvres"] = es.avoidance_manoeuvres;
  s["recoveries"] = es.recoveries;
  s["laser_odometry"] = ej["laser_odometry"];
  s["perception"] = {{"frames", es.frames},
                     {"frames_processed", es.frames_processed},
                     {"mean_ms", es.perception_ms_mean},
                     {"max_ms", es.perception_ms_max},
                     {"objectness_ms", es.objectness_ms_mean},
                     {"features_ms", es.features_ms_mean},
                     {"match_ms", es.match_ms_mean},
                     {"full_passes", es.full_passes},
                     {"tracked_detections", es.tracked_detections}};
  // Loop rates over the run's clock and the wall, and the latency percentiles (nav::LoopTiming).
  s["timing"] = ej["timing"];
  s["executive"] = {{"status", nav::toString(es.status)},
                    {"failure", nav::toString(es.failure)},
                    {"reason", es.reason}};
  fig.executive_success = es.status == nav::RunStatus::Succeeded;
  // Every setting the run used, as --config takes them (the simulator's as it ran: its seed is
  // the run's --seed).
  if (simr) rs.sim = simr->params();
  s["settings"] = runSettingsJson(rs, simr != nullptr);

  RouteToWorld r2w;
  r2w.route_start = route.start_m;
  r2w.rot = -route.start_heading_rad;
  std::vector<hw::Pose2D> traj;
  if (simr) {
    simr->sync();
    const auto& w = simr->world();
    r2w.start = w.start;
    for (const auto& t : simr->trajectory()) traj.push_back(t.truth);
    traj.push_back(simr->truePose());
    const bool collided = simr->collided();
    const bool at_goal = simr->atGoal();
    const auto tp = simr->truePose();
    const double to_goal = std::hypot(tp.x - w.goal.centre.x(), tp.y - w.goal.centre.y());
    s["collided"] = collided;
    if (collided) s["collision_with"] = simr->collisionWith();
    s["at_goal"] = at_goal;
    s["distance_to_goal_m"] = to_goal;
    fig.min_clearance_m = simr->minClearance();
    const double people = simr->minClearancePeople();  // inf: no pedestrians
    fig.min_clearance_people_m = std::isfinite(people) ? people : NAN;
    fig.path_length_m = simr->stats().distance;
    s["frames_rendered"] = simr->stats().frames_rendered;
    // Where the robot's belief went wrong, against ground truth: its odometry (the executive's
    // pose, scan-matched) and where the re-fitted sketch put the goal. The distance to the goal
    // is roughly their sum, so a short stop shows which one to work on.
    if (!observer.odom.empty()) {
      const hw::Pose2D o = observer.odom.back();
      RunSummary::Diagnostics d;
      const hw::Pose2D& ot = observer.last_truth;
      d.odometry_error_m = (odomToWorld(w.start, {o.x, o.y}) - Eigen::Vector2d(ot.x, ot.y)).norm();
      d.odometry_heading_error_deg = wrapAngle(w.start.theta + o.theta - ot.theta) * 180.0 / M_PI;
      if (observer.goal_odom) {
        const Eigen::Vector2d g = odomToWorld(w.start, *observer.goal_odom);
        d.goal_estimate_error_m = (g - w.goal.centre).norm();
        d.goal_estimate_world = std::array<double, 2>{g.x(), g.y()};
      }
      // The drawing's own share: a goal error near this one is the sketch's, not the robot's.
      d.sketch_goal_error_m = sketchGoalErrorM(w, route, settings.exec.fit_outlier_m);
      fig.diagnostics = d;
    }
    s["render_s"] = simr->stats().render_seconds;
    // Ground truth decides success in simulation (doc/navigation.md): the robot's centre in
    // the goal region and nothing hit, whatever the executive concluded. Its own verdict is
    // reported beside it ("executive_success"): a run that stands in the goal region but whose
    // executive failed is a success with a reason saying so.
    const RunVerdict v =
        judgeSimulatedRun(success, es.reason, at_goal, collided, simr->collisionWith(), to_goal);
    success = v.success;
    reason = v.reason;
  } else {
    traj = observer.odom;
  }
  // Deviation of the actual trajectory from the sketched path (in the world / odometry frame).
  std::vector<Eigen::Vector2d> sketched;
  for (const auto& g : route.guide_points_m) sketched.push_back(r2w(g));
  if (!traj.empty()) {
    double sum = 0, mx = 0;
    for (const auto& p : traj) {
      const double d = mapsketch::closestOnPolyline({p.x, p.y}, sketched).distance;
      sum += d;
      mx = std::max(mx, d);
    }
    fig.deviation_mean_m = sum / traj.size();
    fig.deviation_max_m = mx;
  }
  fig.success = success;
  fig.reason = reason;
  fig.failure = failureCode(success, s.value("collided", false), es);
  s.update(fig.toJson());

  if (!o.out_dir.empty()) {
    // Whole or not at all (temp file + rename): a run killed while writing it leaves no
    // half summary.
    writeFileAtomically(o.out_dir + "/summary.json", s.dump(2) + "\n", "run summary");
    if (simr) {
      drawTrajectory(o.out_dir + "/trajectory.png", simr->world(), sketch, route, r2w, traj);
    } else {
      // No world map on a real robot: an empty floor around the sketch and the odometry.
      sim::World w;
      double x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
      auto grow = [&](double x, double y) {
        x0 = std::min(x0, x), y0 = std::min(y0, y), x1 = std::max(x1, x), y1 = std::max(y1, y);
      };
      for (const auto& p : sketched) grow(p.x(), p.y());
      for (const auto& p : traj) grow(p.x, p.y);
      w.floor = {{x0 - 1, y0 - 1}, {x1 + 1, y0 - 1}, {x1 + 1, y1 + 1}, {x0 - 1, y1 + 1}};
      w.goal.centre = sketched.back();
      drawTrajectory(o.out_dir + "/trajectory.png", w, sketch, route, r2w, traj);
    }
    s["out_dir"] = o.out_dir;
  }
  return s;
}

}  // namespace sketchnav::run
