// sketchnav ui: the local web UI (sketch editor, live run view and control). Binds 127.0.0.1
// unless told otherwise; see doc/ui.md.
// Eigen-using headers first: a macro pulled in by httplib.h (server.h) breaks Eigen's headers.
// clang-format off
#include "sketchnav/run/run.h"
#include "sketchnav/landmarks/objectness.h"
#include "sketchnav/mapsketch/io.h"
#include "sketchnav/mapsketch/route.h"
#include "sketchnav/nav/executive.h"
#include "sketchnav/nav/sections.h"
#include "sketchnav/sim/world.h"
#include "run_api.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <thread>

#include "cli.h"
#include "server.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/log.h"
#include "sketchnav/core/paths.h"
#include "sketchnav/drivers/register.h"
#include "sketchnav/hw/registry.h"
#include "sketchnav/sim/register.h"
// clang-format on

namespace sketchnav::app {
namespace {
namespace fs = std::filesystem;

// Ctrl+C / SIGTERM only set a flag (async-signal-safe); a watcher thread then stops the run
// (the base first) before it stops the server, so a robot never waits for the server's
// connections (slow or idle clients hold their threads up to the read timeout) to close.
std::atomic<bool> g_signalled{false};
extern "C" void onSignal(int) {
  g_signalled = true;
}

bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// The sketch a run uses when the page names none (as runNavigation picks it).
std::string sketchFor(const ui::RunRequest& rq) {
  if (!rq.sketch.empty()) return rq.sketch;
  return run::defaultSketchPath(rq.hardware() ? "lab" : rq.world);
}

Json worldGeometry(const std::string& world);

// The route as the executive places it now (its SectionTracker's route -> odometry
// alignment, refitted at landmark fixes), for the run page's map. Called after every step;
// reports only when the alignment or the observed goal changed.
class PlacementReporter {
 public:
  /// `path_px`: the drawn path in sketch pixels from the start, y up (scaled by the route's
  /// own scale when reported).
  PlacementReporter(std::vector<Eigen::Vector2d> path_px, std::function<void(const Json&)> out)
      : path_px_(std::move(path_px)), out_(std::move(out)) {}

  void operator()(const nav::Executive& ex, double t) {
    using V = Eigen::Vector2d;
    const nav::SectionTracker& tr = ex.sections();
    const mapsketch::Route& route = tr.route();
    const V a = tr.toOdom(route.start_m), b = tr.toOdom(route.start_m + V(1, 0));
    const std::optional<V> goal = tr.goalOdom();
    auto same = [](const V& p, const V& q) { return (p - q).norm() < 1e-6; };
    if (reported_ && same(a, a_) && same(b, b_) && goal.has_value() == goal_.has_value() &&
        (!goal || same(*goal, *goal_)))
      return;
    if (reported_) ++refits_;
    reported_ = true;
    a_ = a;
    b_ = b;
    goal_ = goal;
    auto pt = [](const V& p) { return Json::array({p.x(), p.y()}); };
    Json path = Json::array(), guides = Json::array(), lms = Json::array();
    for (const auto& p : path_px_)
      path.push_back(pt(tr.toOdom(route.start_m + p * route.scale_m_per_px)));
    for (const auto& p : tr.guidePointsOdom()) guides.push_back(pt(p));
    for (const auto& sec : route.sections)
      for (const auto& l : sec.landmarks) {
        const V p = tr.toOdom(l.position_m);
        lms.push_back({{"id", l.id}, {"x", p.x()}, {"y", p.y()}});
      }
    const V d = b - a;
    // At the start the route is rotated by -start_heading and unscaled: report the change.
    const double rot = wrapAngle(std::atan2(d.y(), d.x()) + route.start_heading_rad);
    out_({{"path", path},
          {"guide_points", guides},
          {"landmarks", lms},
          {"goal", pt(tr.endOdom(tr.count() - 1))},
          {"rotation_deg", rot * 180.0 / M_PI},
          {"scale", d.norm()},
          {"start", pt(a)},
          {"refits", refits_},
          {"t", t}});
  }

 private:
  std::vector<Eigen::Vector2d> path_px_;
  std::function<void(const Json&)> out_;
  bool reported_ = false;
  int refits_ = 0;
  Eigen::Vector2d a_{0, 0}, b_{0, 0};
  std::optional<Eigen::Vector2d> goal_;
};

// What the page's map shows, in the odometry frame (origin at the start, x along the
// robot's initial heading) where the executive's pose estimate lives: the sketch as the
// executive aligns it (start on the robot, first section along its heading) and, in
// simulation, the world seen from the robot's start pose.
Json mapGeometry(const ui::RunRequest& rq) {
  Json g = {{"frame", "odometry"}};
  using V = Eigen::Vector2d;
  auto pt = [](const V& p) { return Json::array({p.x(), p.y()}); };
  const std::string sketch_path = sketchFor(rq);
  if (!sketch_path.empty() && fs::exists(sketch_path)) {
    const mapsketch::Sketch sk = mapsketch::loadSketch(sketch_path);
    const mapsketch::Route route = mapsketch::toRoute(sk);
    const double c = std::cos(-route.start_heading_rad), s = std::sin(-route.start_heading_rad);
    auto toOdom = [&](const V& p) {
      const V d = p - route.start_m;
      return V(c * d.x() - s * d.y(), s * d.x() + c * d.y());
    };
    Json path = Json::array();
    for (const auto& p : run::drawnPathInRoute(sk, route)) path.push_back(pt(toOdom(p)));
    Json guides = Json::array(), lms = Json::array();
    for (const auto& p : route.guide_points_m) guides.push_back(pt(toOdom(p)));
    for (const auto& sec : route.sections)
      for (const auto& l : sec.landmarks) {
        const V p = toOdom(l.position_m);
        lms.push_back({{"id", l.id}, {"class", l.class_name}, {"x", p.x()}, {"y", p.y()}});
      }
    g["sketch"] = sketch_path;
    g["sketch_path"] = path;
    g["guide_points"] = guides;
    g["sketch_landmarks"] = lms;
  }
  if (!rq.hardware()) g.update(worldGeometry(rq.world));
  return g;
}

// A simulated world seen from its start pose (the odometry frame: origin at the start, x along
// the start heading): floor, walls (closed doors too), obstacles, landmarks and the goal.
Json worldGeometry(const std::string& world) {
  using V = Eigen::Vector2d;
  auto pt = [](const V& p) { return Json::array({p.x(), p.y()}); };
  Json g = {{"frame", "odometry"}};
  {
    const sim::World w = sim::loadWorldByName(world);
    const double c = std::cos(-w.start.theta), s = std::sin(-w.start.theta);
    auto toOdom = [&](const V& p) {
      const V d = p - V(w.start.x, w.start.y);
      return V(c * d.x() - s * d.y(), s * d.x() + c * d.y());
    };
    Json floor = Json::array(), walls = Json::array(), obst = Json::array(), lms = Json::array();
    for (const auto& p : w.floor) floor.push_back(pt(toOdom(p)));
    for (const auto& wl : w.walls) {
      const V a = toOdom(wl.a), b = toOdom(wl.b);
      walls.push_back({a.x(), a.y(), b.x(), b.y(), wl.thickness});
    }
    for (const auto& d : w.doors)
      if (!d.open) {
        const V a = toOdom(d.a), b = toOdom(d.b);
        walls.push_back({a.x(), a.y(), b.x(), b.y(), 0.05});
      }
    for (const auto& o : w.obstacles) {
      if (o.shape == sim::Obstacle::Shape::Cylinder) {
        const V p = toOdom(o.centre);
        obst.push_back({{"x", p.x()}, {"y", p.y()}, {"r", o.radius}});
      } else {
        Json poly = Json::array();
        const double cy = std::cos(o.yaw), sy = std::sin(o.yaw);
        for (const auto& [u, v] : {std::pair{1, 1}, {-1, 1}, {-1, -1}, {1, -1}}) {
          const double dx = u * o.size_x / 2, dy = v * o.size_y / 2;
          poly.push_back(pt(toOdom(o.centre + V(cy * dx - sy * dy, sy * dx + cy * dy))));
        }
        obst.push_back({{"polygon", poly}});
      }
    }
    for (const auto& l : w.landmarks) {
      const V p = toOdom(l.position);
      lms.push_back({{"id", l.id}, {"class", l.class_name}, {"x", p.x()}, {"y", p.y()}});
    }
    const V goal = toOdom(w.goal.centre);
    g["world"] = world;
    g["floor"] = floor;
    g["walls"] = walls;
    g["obstacles"] = obst;
    g["world_landmarks"] = lms;
    g["goal"] = {{"x", goal.x()}, {"y", goal.y()}, {"r", w.goal.radius}};
  }
  return g;
}

// "Camera only": frames for the live view and captures (e.g. building a landmark set with the
// robot's camera, or a webcam: video://0), nothing else opened, nothing driven.
Json cameraOnly(const ui::RunRequest& rq, const ui::RunHooks& h) {
  drivers::registerDrivers();
  sim::registerDrivers();
  hw::DeviceContext ctx;
  ctx.clock = std::make_shared<hw::SteadyClock>();
  auto camera = h.wrap_camera(hw::Registry::instance().createCamera(rq.camera, ctx));
  h.on_event({0.0, nav::event::Start{0, 0.0}});  // no route: nothing but the camera
  int errors = 0;
  auto next = std::chrono::steady_clock::now();
  while (!h.stop_requested()) {
    hw::Frame f;
    const hw::GrabStatus st = camera->grab(f, 0.5);
    if (st == hw::GrabStatus::EndOfStream)
      return {{"success", true}, {"reason", "end of the images"}};
    if (st == hw::GrabStatus::Error && ++errors > 20)
      throw RuntimeError("camera " + rq.camera + ": " + camera->stats().last_error);
    if (st == hw::GrabStatus::Ok) errors = 0;
    // Recorded sources (folder://, video files) deliver at once: show them at ~10 Hz.
    std::this_thread::sleep_until(next);
    next = std::chrono::steady_clock::now() + std::chrono::milliseconds(100);
  }
  return {{"success", true}, {"reason", "camera closed"}};
}

// The run page's runner: `sketchnav run` (runNavigation) in real time, reporting to the page.
Json runFromPage(const ui::RunRequest& rq, const ui::RunHooks& h, const std::string& landmarks,
                 const std::string& model_cache) {
  run::RunOptions o;
  o.world = rq.world;
  o.sketch = rq.sketch;
  o.robot = rq.robot;
  o.camera = rq.camera;
  o.laser = rq.laser;
  o.sonar = rq.sonar;
  o.seed = rq.seed;
  o.max_time_s = rq.max_time_s;
  o.realtime = true;  // a person is watching: the simulator at the robot's pace
  o.landmark_dir = landmarks;
  o.cache_dir = model_cache;
  o.progress = true;
  o.wrap_camera = h.wrap_camera;
  o.wrap_base = h.wrap_base;
  o.on_event = h.on_event;
  o.on_tick = h.on_tick;
  o.on_observation = h.on_observation;
  o.stop_requested = h.stop_requested;
  o.out_dir = h.out_dir;  // the run folder `sketchnav run` writes, for the page's record
  if (h.on_placement) {
    // The refitted sketch on the map: read from the executive after each step (no change to
    // what it does; runNavigation steps it itself whenever stop_requested is set anyway).
    std::vector<Eigen::Vector2d> path_px;
    try {
      const std::string sp = sketchFor(rq);
      if (!sp.empty() && fs::exists(sp)) {
        const mapsketch::Sketch sk = mapsketch::loadSketch(sp);
        for (const auto& p : sk.path)
          path_px.emplace_back(p.x() - sk.start.x(), -(p.y() - sk.start.y()));
      }
    } catch (const std::exception&) {
      // the run reports a bad sketch itself; the map then shows the guide points only
    }
    auto rep = std::make_shared<PlacementReporter>(std::move(path_px), h.on_placement);
    auto last_t = std::make_shared<double>(0.0);
    auto on_tick = o.on_tick;
    o.on_tick = [on_tick, last_t](const nav::TelemetryRow& r) {
      *last_t = r.t;
      if (on_tick) on_tick(r);
    };
    o.after_step = [rep, last_t](const nav::Executive& ex) { (*rep)(ex, *last_t); };
  }
  try {
    h.on_map(mapGeometry(rq));
  } catch (const std::exception& e) {
    // The run reports a bad world or sketch itself, with the same message.
    log::warn("ui", "no map for the run page", {{"error", e.what()}});
    h.on_map(Json::object());
  }
  return run::runNavigation(o);
}

std::vector<std::string> filesEndingIn(const std::string& dir, const std::string& suffix) {
  std::vector<std::string> out;
  std::error_code ec;
  if (dir.empty() || !fs::is_directory(dir, ec)) return out;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.is_regular_file() && endsWith(e.path().filename().string(), suffix))
      out.push_back(e.path().string());
  std::sort(out.begin(), out.end());
  return out;
}

// The user's data folder for what the UI writes (sketches, captures): $XDG_DATA_HOME/sketchnav,
// else ~/.local/share/sketchnav, else runs/ui: never the source tree or the shipped share/.
std::string userDataDir() {
  const char* xdg = std::getenv("XDG_DATA_HOME");
  if (xdg && *xdg && fs::path(xdg).is_absolute()) return (fs::path(xdg) / "sketchnav").string();
  const char* home = std::getenv("HOME");
  if (home && *home) return (fs::path(home) / ".local/share/sketchnav").string();
  return "runs/ui";
}

// The run page's sketch list, read again on every request: [{path, file, source}].
Json sketchList(const std::string& examples_dir, const std::string& sketch_dir) {
  Json out = Json::array();
  for (const auto& [dir, source] : {std::pair{examples_dir, "example"}, {sketch_dir, "user"}})
    for (const auto& f : filesEndingIn(dir, ".sketch.json"))
      out.push_back({{"path", f}, {"file", fs::path(f).filename().string()}, {"source", source}});
  return out;
}

int runUi(const std::vector<std::string>& argv, GlobalOptions& g) {
  Args args("ui", "the local web UI: sketch editor, live run view and control", "[options]");
  args.option("landmarks", "landmark set: one folder per class (default: the demo set)")
      .option("sketch-dir",
              "directory sketches are opened from and saved to (default: "
              "$XDG_DATA_HOME/sketchnav/sketches, i.e. ~/.local/share/sketchnav/sketches)")
      .option("capture-dir",
              "where the run page saves captured photos, one folder per class (default: "
              "$XDG_DATA_HOME/sketchnav/captures; give the --landmarks folder to train on them)")
      .option("runs-dir",
              "where every run started from the page writes its folder (summary.json, "
              "trajectory.png, telemetry.csv, events.jsonl; default: "
              "$XDG_DATA_HOME/sketchnav/runs)")
      .option("model-cache", "landmark model cache directory (default: ~/.cache/sketchnav)")
      .option("host", "address to bind (only loopback is safe)", "127.0.0.1")
      .option("port", "TCP port (0 = any free port)", "8080")
      .option("allow-host", "extra Host name to accept, e.g. robot.local (with --host 0.0.0.0)");
  if (!args.parse(argv)) return 0;
  g.config.requireAllUsed();  // the UI takes no settings (its runs use the page's)
  const int port = args.getInt("port");
  if (port < 0 || port > 65535) throw InputError("sketchnav ui: --port must be in 0..65535");

  ui::ServerOptions so;
  so.host = args.get("host");
  so.port = port;
  so.web_root = resourcePath("web");
  if (args.has("allow-host")) so.extra_hosts.push_back(args.get("allow-host"));
  ui::EditorOptions eo;
  eo.landmarks_dir = args.has("landmarks") ? args.get("landmarks") : resourcePath("landmarks");
  eo.sketch_dir = args.has("sketch-dir") ? args.get("sketch-dir") : userDataDir() + "/sketches";
  eo.examples_dir = resourcePath("sketches");

  ui::RunApiOptions ro;
  const std::string landmarks = eo.landmarks_dir;
  const std::string cache = args.has("model-cache") ? args.get("model-cache") : "";
  ro.runner = [landmarks, cache](const ui::RunRequest& rq, const ui::RunHooks& h) {
    return rq.camera_only ? cameraOnly(rq, h) : runFromPage(rq, h, landmarks, cache);
  };
  // The live view draws the windows perception examined: the same proposer, same settings.
  auto objectness = std::make_shared<landmarks::Objectness>(landmarks::ObjectnessParams{});
  // A world or sketch that does not load is refused on the start request itself (400 naming
  // the file), not reported by a run that was already answered 200.
  ro.check_request = [](const ui::RunRequest& rq) {
    if (!rq.hardware()) sim::loadWorldByName(rq.world);
    const std::string sp = sketchFor(rq);
    std::error_code ec;
    if (!rq.sketch.empty() || (!sp.empty() && fs::exists(sp, ec))) mapsketch::loadSketch(sp);
  };
  ro.propose_windows = [objectness](const cv::Mat& img) {
    std::vector<cv::Rect> boxes;
    for (const auto& w : objectness->propose(img, nav::PerceptionParams{}.max_windows))
      boxes.push_back(w.box);
    return boxes;
  };
  ro.runs_dir = args.has("runs-dir") ? args.get("runs-dir") : userDataDir() + "/runs";
  ro.capture_dir = args.has("capture-dir") ? args.get("capture-dir") : userDataDir() + "/captures";
  {
    std::error_code ec;
    ro.captures_train = fs::exists(ro.capture_dir, ec) &&
                        fs::equivalent(ro.capture_dir, eo.landmarks_dir, ec) && !ec;
  }
  ro.worlds = {"lab"};
  for (const auto& f : filesEndingIn(resourcePath("worlds"), ".world.json")) {
    const std::string n = fs::path(f).filename().string();
    const std::string name = n.substr(0, n.size() - 11);
    if (std::find(ro.worlds.begin(), ro.worlds.end(), name) == ro.worlds.end())
      ro.worlds.push_back(name);
  }
  ro.list_sketches = [ex = eo.examples_dir, mine = eo.sketch_dir] { return sketchList(ex, mine); };

  // Declared before the server so the server (whose routes use it) goes first.
  ui::RunController runs(ro);
  ui::Server server(so);
  ui::addEditorRoutes(server, eo);
  ui::addRunRoutes(server, runs);
  // The editor's background: a world offered on the run page, as the robot starts in it.
  server.get(R"(/api/worlds/([^/]+)/map)",
             [worlds = ro.worlds](const httplib::Request& req, httplib::Response& res) {
               const std::string name = req.matches[1];
               if (std::find(worlds.begin(), worlds.end(), name) == worlds.end())
                 return ui::sendError(res, 404,
                                      "world map: 'world' '" + name.substr(0, 60) +
                                          "' is not one of the worlds offered");
               Json g = worldGeometry(name);
               const sim::World w = sim::loadWorldByName(name);
               g["start_world"] = {{"x", w.start.x}, {"y", w.start.y}, {"theta", w.start.theta}};
               ui::sendJson(res, g);
             });
  server.bind();
  if (so.host != "127.0.0.1" && so.host != "localhost" && so.host != "::1")
    log::warn("ui", "listening beyond this machine: anyone who can reach it can drive the robot",
              {{"host", so.host}});
  if (g.json)
    printJson({{"url", server.url()},
               {"port", server.port()},
               {"sketch_dir", fs::absolute(eo.sketch_dir).string()},
               {"capture_dir", fs::absolute(ro.capture_dir).string()},
               {"runs_dir", fs::absolute(ro.runs_dir).string()}});
  else
    std::cout << "sketchnav ui: editor at " << server.url() << ", live run at " << server.url()
              << "run.html; sketches in " << fs::absolute(eo.sketch_dir).string()
              << ", captures to " << fs::absolute(ro.capture_dir).string()
              << (ro.captures_train ? " (the landmark set)" : "") << ", runs recorded in "
              << fs::absolute(ro.runs_dir).string() << " (Ctrl+C to stop)" << std::endl;
  std::signal(SIGINT, onSignal);
  std::signal(SIGTERM, onSignal);
  std::atomic<bool> served{false};
  std::thread watcher([&] {
    while (!served) {
      if (g_signalled) {
        runs.stop();  // the base stops now, whatever the server is still waiting for
        server.stop();
        // A client dribbling bytes keeps its connection (and the server's shutdown) going
        // for as long as it likes: after 3 s, end the run and exit without it.
        for (int i = 0; i < 150 && !served; ++i)
          std::this_thread::sleep_for(std::chrono::milliseconds(20));
        if (!served) {
          log::warn("ui", "connections still open 3 s after the stop signal: exiting anyway", {});
          runs.join();
          std::cout.flush();
          std::_Exit(0);
        }
        return;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  });
  server.serve();
  served = true;
  watcher.join();
  return 0;  // ~RunController stops a run still going (the base first) and waits for it
}
const CommandRegistration reg("ui", "the local web UI: sketch editor, live run view and control",
                              runUi);
}  // namespace
}  // namespace sketchnav::app
