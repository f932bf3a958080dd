// The live run page's state and API (run_api.h). One Live record is shared by the HTTP
// threads (reading) and the run thread (the hooks, writing), behind one mutex; frames are
// cloned in, so nothing the run thread reuses is ever read by a request.
// Eigen-using headers (through nav) come in via run_api.h before httplib's macros matter.
#include "run_api.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>

#include "sketchnav/core/error.h"
#include "sketchnav/core/input_file.h"
#include "sketchnav/core/log.h"
#include "sketchnav/core/paths.h"
#include "sketchnav/hw/forwarding.h"

namespace fs = std::filesystem;

namespace sketchnav::ui {

namespace {
double wallNow() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}
Json statsJson(const hw::DeviceStats& s) {
  return {{"received", s.received},
          {"dropped", s.dropped},
          {"incomplete", s.incomplete},
          {"last_error", s.last_error}};
}
// The summary of a run page run that has nothing else to say (it was refused, or its runner
// threw before writing one): why, and what was asked; written to <out_dir>/summary.json when
// out_dir is not "" (a failure to write is logged: the state still says why).
Json errorRecord(const std::string& out_dir, const RunRequest& request, const std::string& reason,
                 bool refused) {
  Json summary = {
      {"success", false}, {"error", true}, {"reason", reason}, {"request", request.toJson()}};
  if (refused) summary["refused"] = true;
  if (out_dir.empty()) return summary;
  summary["out_dir"] = out_dir;
  try {
    writeFileAtomically((fs::path(out_dir) / "summary.json").string(), summary.dump(2) + "\n",
                        "run summary");
  } catch (const std::exception& w) {
    log::error("ui", "cannot write the run's summary", {{"error", w.what()}});
  }
  return summary;
}
}  // namespace

// ---- live state ----------------------------------------------------------------------------

struct RunController::Live {
  mutable std::mutex m;
  // run
  std::string status = "idle";  // idle starting running stopping stopped succeeded failed error
  std::string reason;
  Json request;
  Json summary;
  bool hardware = false;
  double started_wall = 0;
  std::atomic<bool> stop_requested{false};
  // executive
  bool has_tick = false;
  nav::TelemetryRow tick;
  std::string end_mode;  // set when the run has ended: its status, shown as the mode
  int sections = 0;
  double route_length_m = 0;
  std::deque<Json> events;
  std::map<std::string, Json> landmarks;  // id -> {id, class, section, state, ...}
  std::vector<std::pair<double, double>> trajectory;
  Json map_geometry;
  Json placement;  // the route as the executive places it now (RunHooks::on_placement)
  // run record and progress
  std::string run_dir;                            // this run's folder ("" = none)
  std::vector<std::array<double, 8>> ticks;       // t v w servo_error(NaN) x y theta section
  std::vector<std::array<double, 3>> obs;         // t inliers(best) perception_ms
  std::vector<std::pair<double, double>> guides;  // the route's guide points (odometry frame)
  double along_m = 0;                             // progress along them [m]
  double first_tick_wall = 0, first_tick_t = 0;   // for the real-time factor
  double last_tick_wall = 0;
  // camera
  cv::Mat frame;
  std::uint64_t frame_seq = 0;
  double frame_wall = 0;
  std::uint64_t frames = 0;
  hw::DeviceStats camera_stats;
  bool camera_open = false;
  std::vector<nav::Detection> detections;
  std::uint64_t detections_seq = 0;
  cv::Mat obs_frame;  // the frame perception examined last
  std::vector<cv::Rect> windows_boxes;
  std::uint64_t windows_seq = 0;  // obs frame the boxes belong to (0 = none)
  int windows = 0;
  double perception_ms = 0;
  // base
  class StoppableBase* base = nullptr;
  bool base_open = false, base_ok = false;
  hw::DeviceStats base_stats;
  double v_sent = 0, w_sent = 0;
  int base_stops = 0;
  std::uint64_t base_seq = 0;      // StoppableBase call number of v_sent / w_sent / base_last
  std::string base_last = "none";  // none | command | stop

  void reset() {
    status = "starting";
    reason.clear();
    summary = nullptr;
    stop_requested = false;
    has_tick = false;
    tick = {};
    end_mode.clear();
    sections = 0;
    route_length_m = 0;
    events.clear();
    landmarks.clear();
    trajectory.clear();
    map_geometry = nullptr;
    placement = nullptr;
    run_dir.clear();
    ticks.clear();
    obs.clear();
    guides.clear();
    along_m = 0;
    first_tick_wall = first_tick_t = last_tick_wall = 0;
    frame.release();
    frame_seq = frames = 0;
    frame_wall = 0;
    camera_stats = {};
    camera_open = false;
    detections.clear();
    detections_seq = 0;
    obs_frame.release();
    windows_boxes.clear();
    windows_seq = 0;
    windows = 0;
    perception_ms = 0;
    base_open = base_ok = false;
    base_stats = {};
    v_sent = w_sent = 0;
    base_stops = 0;
    base_seq = 0;
    base_last = "none";
  }
};

// A Base that the page can stop from its own thread. Every call to the real base is
// serialised by one mutex; once halted, each command becomes stop(). A real robot is
// stopped at once from the request's thread (its drivers take stop() from any thread, like
// GatedBase's camera callback); the simulator is stepped by the run thread only, so there the
// halt takes effect at the next control tick (50 ms of simulated time).
class StoppableBase final : public hw::ForwardingBase {
 public:
  StoppableBase(std::unique_ptr<hw::Base> inner, std::shared_ptr<RunController::Live> live)
      : ForwardingBase(std::move(inner)), live_(std::move(live)) {
    std::lock_guard<std::mutex> l(live_->m);
    live_->base = this;
    live_->base_open = true;
    live_->base_ok = this->inner().ok();
  }
  ~StoppableBase() override {
    std::lock_guard<std::mutex> l(live_->m);
    live_->base = nullptr;
  }
  void command(double v, double w) override {
    bool halted;
    std::uint64_t seq;
    {
      std::lock_guard<std::mutex> l(m_);
      halted = halted_;
      if (halted)
        inner().stop();
      else
        inner().command(v, w);
      seq = ++calls_;
    }
    // live_->m is taken after m_ is released (halt() takes them the other way round); `seq`
    // keeps the record in the order the base got the calls.
    if (halted)
      record(0, 0, "stop", seq);
    else
      record(v, w, "command", seq);
  }
  void stop() noexcept override {
    try {
      std::uint64_t seq;
      {
        std::lock_guard<std::mutex> l(m_);
        inner().stop();
        seq = ++calls_;
      }
      record(0, 0, "stop", seq);
    } catch (...) {
    }
  }
  bool odometry(hw::Odometry& out) override {
    std::lock_guard<std::mutex> l(m_);
    return inner().odometry(out);
  }
  bool ok() const override {
    std::lock_guard<std::mutex> l(m_);
    return inner().ok();
  }
  hw::DeviceStats stats() const override {
    std::lock_guard<std::mutex> l(m_);
    return inner().stats();
  }
  // uri() forwards as it is (no lock: the inner URI is fixed).

  /// Called with live_->m held (from RunController::stop()).
  void halt(bool from_this_thread) {
    halted_ = true;
    if (!from_this_thread) return;
    std::lock_guard<std::mutex> l(m_);
    inner().stop();
    live_->base_seq = ++calls_;
    live_->v_sent = live_->w_sent = 0;
    live_->base_stops++;
    live_->base_last = "stop";
  }

 private:
  void record(double v, double w, const char* what, std::uint64_t seq) {
    bool ok;
    hw::DeviceStats st;
    {
      std::lock_guard<std::mutex> l(m_);
      ok = inner().ok();
      st = inner().stats();
    }
    std::lock_guard<std::mutex> l(live_->m);
    live_->base_ok = ok;
    live_->base_stats = st;
    if (std::string(what) == "stop") live_->base_stops++;
    if (seq < live_->base_seq) return;  // a later call (halt) is already recorded
    live_->base_seq = seq;
    live_->v_sent = v;
    live_->w_sent = w;
    live_->base_last = what;
  }
  std::shared_ptr<RunController::Live> live_;
  mutable std::mutex m_;
  std::uint64_t calls_ = 0;  // calls made to inner() (guarded by m_)
  std::atomic<bool> halted_{false};
};

// A Camera that keeps a copy of each frame for the page (live view and capture).
class TapCamera final : public hw::ForwardingCamera {
 public:
  TapCamera(std::unique_ptr<hw::Camera> inner, std::shared_ptr<RunController::Live> live)
      : ForwardingCamera(std::move(inner)), live_(std::move(live)) {
    std::lock_guard<std::mutex> l(live_->m);
    live_->camera_open = true;
  }
  ~TapCamera() override {
    std::lock_guard<std::mutex> l(live_->m);
    live_->camera_open = false;
  }
  hw::GrabStatus grab(hw::Frame& frame, double timeout_s) override {
    const hw::GrabStatus st = inner().grab(frame, timeout_s);
    const hw::DeviceStats stats = inner().stats();
    cv::Mat copy;
    if (st == hw::GrabStatus::Ok && !frame.image.empty()) copy = frame.image.clone();
    std::lock_guard<std::mutex> l(live_->m);
    live_->camera_stats = stats;
    if (!copy.empty()) {
      live_->frame = copy;
      live_->frame_seq = frame.seq;
      live_->frame_wall = wallNow();
      live_->frames++;
    }
    return st;
  }

 private:
  std::shared_ptr<RunController::Live> live_;
};

// The frame the page shows: the one perception examined last while it is recent (so the
// windows and detections drawn on it are exactly where perception found them), else the
// latest one (perception idle: no landmark expected nearby). Caller holds L.m.
static bool showObserved(const RunController::Live& L) {
  return !L.obs_frame.empty() && L.frame_seq >= L.detections_seq &&
         L.frame_seq - L.detections_seq <= 10;
}

// ---- controller ----------------------------------------------------------------------------

RunController::RunController(RunApiOptions options)
    : opt_(std::move(options)), live_(std::make_shared<Live>()) {
  if (!opt_.runner) throw InputError("ui: no runner given to the run page");
}

RunController::~RunController() {
  stop();
  join();
}

void RunController::join() {
  std::lock_guard<std::mutex> l(start_mutex_);
  if (thread_.joinable()) thread_.join();
}

std::string RunController::newRunDir(const RunRequest& request) const {
  std::string stamp = utcTimestamp();
  for (char& c : stamp)
    if (c == ':') c = '-';
  std::string what = request.hardware() ? "robot" : fs::path(request.world).filename().string();
  if (what.size() > 11 && what.substr(what.size() - 11) == ".world.json")
    what = what.substr(0, what.size() - 11);
  for (char& c : what)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_') c = '_';
  if (what.size() > 40) what.resize(40);
  const std::string name = stamp + "-" + what;
  fs::path dir = fs::path(opt_.runs_dir) / name;
  // Two runs in the same second get distinct folders rather than mixing outputs.
  for (int i = 2; fs::exists(dir); ++i)
    dir = fs::path(opt_.runs_dir) / (name + "-" + std::to_string(i));
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw RuntimeError("runs folder: cannot create " + dir.string() + ": " + ec.message());
  return dir.string();
}

void RunController::start(const RunRequest& request) {
  std::lock_guard<std::mutex> l(start_mutex_);
  {
    std::lock_guard<std::mutex> ll(live_->m);
    const std::string& s = live_->status;
    if (s == "starting" || s == "running" || s == "stopping")
      throw InputError("a run is already going: stop it first");
  }
  if (thread_.joinable()) thread_.join();  // the previous run has finished
  if (opt_.check_request && !request.camera_only) {
    std::string why;
    try {
      opt_.check_request(request);
    } catch (const std::exception& e) {
      why = e.what();
    }
    if (!why.empty()) {
      // Refused (the caller gets a 400 naming the file), and recorded like any run from the
      // page: its folder with a summary saying why, and the state the page's card shows.
      std::string run_dir;
      try {
        if (!opt_.runs_dir.empty()) run_dir = newRunDir(request);
      } catch (const std::exception& w) {
        log::error("ui", "cannot create the refused run's folder", {{"error", w.what()}});
      }
      const Json summary = errorRecord(run_dir, request, why, true);
      {
        std::lock_guard<std::mutex> ll(live_->m);
        live_->reset();
        live_->run_dir = run_dir;
        live_->request = request.toJson();
        live_->hardware = request.hardware();
        live_->summary = summary;
        live_->status = "error";
        live_->reason = why;
        live_->end_mode = "error";
      }
      log::warn("ui", "run refused", {{"error", why}});
      throw InputError(why);
    }
  }
  // The run's folder, as `sketchnav run` writes it: <runs_dir>/<UTC time>-<world or robot>.
  std::string run_dir;
  if (!opt_.runs_dir.empty() && !request.camera_only) run_dir = newRunDir(request);
  {
    std::lock_guard<std::mutex> ll(live_->m);
    live_->reset();
    live_->run_dir = run_dir;
    live_->request = request.toJson();
    live_->hardware = request.hardware();
    live_->started_wall = wallNow();
  }
  log::info("ui", "run started from the page", {{"request", request.toJson().dump()}});
  thread_ = std::thread([this, request] { runThread(request); });
}

bool RunController::stop() {
  std::lock_guard<std::mutex> l(live_->m);
  const std::string s = live_->status;
  if (s != "starting" && s != "running" && s != "stopping") return false;
  live_->stop_requested = true;
  if (live_->base) live_->base->halt(live_->hardware);
  live_->status = "stopping";
  Json e = {{"type", "stop_requested"}, {"t", live_->has_tick ? live_->tick.t : 0.0}};
  live_->events.push_back(e);
  log::warn("ui", "stop pressed on the run page", {});
  return true;
}

void RunController::runThread(RunRequest request) {
  auto live = live_;
  RunHooks h;
  h.on_event = [live](const nav::NavEvent& e) {
    namespace event = nav::event;
    std::lock_guard<std::mutex> l(live->m);
    live->events.push_back(e.toJson());
    while (live->events.size() > 40) live->events.pop_front();
    if (const auto* s = e.as<event::Start>()) {
      live->sections = s->sections;
      live->route_length_m = s->route_length_m;
      if (live->status == "starting") live->status = "running";
    }
    // The landmark table: its state is the last landmark event's (seen passed missed lost).
    auto landmark = [&](const std::string& id, const char* state, int section) -> Json& {
      Json& lm = live->landmarks[id];
      lm["id"] = id;
      lm["section"] = section;
      lm["state"] = state;
      return lm;
    };
    if (const auto* x = e.as<event::LandmarkSeen>()) {
      Json& lm = landmark(x->id, "seen", x->section);
      lm["class"] = x->class_name;
      lm["inliers"] = x->inliers;
    } else if (const auto* x = e.as<event::LandmarkPassed>()) {
      landmark(x->id, "passed", x->section)["class"] = x->class_name;
    } else if (const auto* x = e.as<event::LandmarkMissed>()) {
      landmark(x->id, "missed", x->section)["class"] = x->class_name;
    } else if (const auto* x = e.as<event::LandmarkLost>()) {
      landmark(x->id, "lost", x->section);
    }
  };
  h.on_tick = [live](const nav::TelemetryRow& r) {
    const double now = wallNow();
    std::lock_guard<std::mutex> l(live->m);
    if (!live->has_tick) {
      live->first_tick_wall = now;
      live->first_tick_t = r.t;
    }
    live->tick = r;
    live->has_tick = true;
    live->last_tick_wall = now;
    live->ticks.push_back({r.t, r.v_cmd, r.w_cmd,
                           std::isfinite(r.servo_error) ? r.servo_error : std::nan(""), r.odom.x,
                           r.odom.y, r.odom.theta, static_cast<double>(r.section)});
    // Progress: the pose projected on the guide segment of the section being driven.
    const auto& g = live->guides;
    if (g.size() >= 2) {
      const int k = std::clamp(r.section, 0, static_cast<int>(g.size()) - 2);
      double before = 0;
      for (int i = 0; i < k; ++i)
        before += std::hypot(g[i + 1].first - g[i].first, g[i + 1].second - g[i].second);
      const double dx = g[k + 1].first - g[k].first, dy = g[k + 1].second - g[k].second;
      const double len2 = dx * dx + dy * dy;
      const double u =
          len2 > 0
              ? std::clamp(((r.odom.x - g[k].first) * dx + (r.odom.y - g[k].second) * dy) / len2,
                           0.0, 1.0)
              : 0.0;
      live->along_m = before + u * std::sqrt(len2);
    }
    if (live->status == "starting") live->status = "running";
    const auto& tr = live->trajectory;
    if (tr.empty() || std::hypot(tr.back().first - r.odom.x, tr.back().second - r.odom.y) > 0.05)
      live->trajectory.emplace_back(r.odom.x, r.odom.y);
  };
  h.on_observation = [live](const hw::Frame& f, const nav::Observation& o) {
    cv::Mat copy = f.image.clone();
    std::lock_guard<std::mutex> l(live->m);
    live->obs_frame = copy;
    live->detections = o.detections;
    live->detections_seq = f.seq;
    live->windows = o.timing.windows;
    live->perception_ms = o.timing.total_ms;
    live->obs.push_back({live->has_tick ? live->tick.t : 0.0,
                         o.detections.empty() ? 0.0 : static_cast<double>(o.detections[0].inliers),
                         o.timing.total_ms});
  };
  h.wrap_camera = [live](std::unique_ptr<hw::Camera> c) -> std::unique_ptr<hw::Camera> {
    return std::make_unique<TapCamera>(std::move(c), live);
  };
  h.wrap_base = [live](std::unique_ptr<hw::Base> b) -> std::unique_ptr<hw::Base> {
    auto sb = std::make_unique<StoppableBase>(std::move(b), live);
    // Stop pressed while the devices were opening: the base never moves.
    if (live->stop_requested) sb->stop();
    return sb;
  };
  h.stop_requested = [live] { return live->stop_requested.load(); };
  h.on_map = [live](const Json& m) {
    std::lock_guard<std::mutex> l(live->m);
    live->map_geometry = m;
    live->guides.clear();
    if (m.is_object() && m.contains("guide_points"))
      for (const auto& p : m["guide_points"])
        if (p.is_array() && p.size() == 2)
          live->guides.emplace_back(p[0].get<double>(), p[1].get<double>());
  };
  h.on_placement = [live](const Json& p) {
    std::lock_guard<std::mutex> l(live->m);
    live->placement = p;
  };
  {
    std::lock_guard<std::mutex> l(live->m);
    h.out_dir = live->run_dir;
  }

  Json summary;
  std::string status, reason;
  try {
    summary = opt_.runner(request, h);
    const bool ok = summary.value("success", false);
    reason = summary.value("reason", "");
    status = live->stop_requested ? "stopped" : ok ? "succeeded" : "failed";
  } catch (const std::exception& e) {
    status = "error";
    reason = e.what();
    log::error("ui", "run failed", {{"error", reason}});
    // The record of the run says why there is nothing else in its folder.
    if (!h.out_dir.empty() && !fs::exists(fs::path(h.out_dir) / "summary.json"))
      summary = errorRecord(h.out_dir, request, reason, false);
  }
  std::lock_guard<std::mutex> l(live->m);
  live->summary = summary;
  live->status = status;
  live->reason = reason;
  live->base_open = false;
  // The executive's last tick was before it stopped the base: show the robot at rest.
  live->tick.v_cmd = live->tick.w_cmd = 0;
  live->end_mode = status;
}

Json RunController::state() const {
  const Live& L = *live_;
  std::lock_guard<std::mutex> l(L.m);
  Json s;
  s["status"] = L.status;
  s["reason"] = L.reason;
  s["request"] = L.request;
  s["active"] = L.status == "starting" || L.status == "running" || L.status == "stopping";
  s["sections"] = L.sections;
  s["route_length_m"] = L.route_length_m;
  if (L.has_tick) {
    const auto& r = L.tick;
    s["t"] = r.t;
    s["section"] = std::min(r.section + 1, std::max(L.sections, 1));  // 1-based k of n
    // Once the run is over the page shows how it ended instead of the last tick's mode.
    s["mode"] = L.end_mode.empty() ? std::string(nav::toString(r.mode)) : L.end_mode;
    s["turn"] = L.end_mode.empty() ? std::string(servo::toString(r.turn)) : std::string();
    s["v"] = r.v_cmd;
    s["w"] = r.w_cmd;
    s["servo_error"] = std::isfinite(r.servo_error) ? Json(r.servo_error) : Json(nullptr);
    s["pose"] = {{"x", r.odom.x}, {"y", r.odom.y}, {"theta", r.odom.theta}};
    s["landmark"] = r.landmark;
    s["front_free_m"] = r.front_free_m;
  } else {
    s["t"] = 0;
    s["section"] = 0;
    s["mode"] = "";
    s["turn"] = "";
    s["v"] = 0;
    s["w"] = 0;
    s["pose"] = nullptr;
    s["landmark"] = "";
  }
  // What actually reached the base: after Stop this is 0 even while the executive winds down.
  s["base"] = {{"v", L.v_sent},
               {"w", L.w_sent},
               {"last", L.base_last},
               {"stops", L.base_stops},
               {"open", L.base_open}};
  Json lms = Json::array();
  for (const auto& [id, lm] : L.landmarks) lms.push_back(lm);
  s["landmarks"] = lms;
  const double now = wallNow();
  const double age = L.frame_wall > 0 ? now - L.frame_wall : -1;
  const bool active = s["active"].get<bool>();
  Json cam = statsJson(L.camera_stats);
  cam["open"] = L.camera_open;
  cam["frames"] = L.frames;
  cam["seq"] = L.frame_seq;
  cam["age_s"] = age;
  cam["ok"] = L.camera_open && age >= 0 && age < 2.0 && L.camera_stats.last_error.empty();
  Json base = statsJson(L.base_stats);
  base["open"] = L.base_open;
  base["ok"] = L.base_open && L.base_ok;
  Json range = {{"front_free_m", L.has_tick ? Json(L.tick.front_free_m) : Json(nullptr)}};
  s["health"] = {{"camera", cam}, {"base", base}, {"range", range}, {"active", active}};
  s["perception"] = {{"windows", L.windows},
                     {"detections", L.detections.size()},
                     {"ms", L.perception_ms},
                     {"frame_seq", L.detections_seq}};
  s["frame_seq"] = L.frame_seq;
  s["shown_seq"] = showObserved(L) ? L.detections_seq : L.frame_seq;
  s["events"] = Json(std::vector<Json>(L.events.begin(), L.events.end()));
  s["last_event"] = L.events.empty() ? Json(nullptr) : L.events.back();
  // The summary without its settings (the full one is the run folder's summary.json).
  Json summary = L.summary;
  if (summary.is_object()) summary.erase("settings");
  s["summary"] = summary;
  s["elapsed_s"] = L.started_wall > 0 ? now - L.started_wall : 0.0;
  // Where the run is written and how far along the route it is.
  s["run_dir"] = L.run_dir;
  s["run_id"] = L.run_dir.empty() ? std::string() : fs::path(L.run_dir).filename().string();
  double route_m = 0;
  for (size_t i = 1; i < L.guides.size(); ++i)
    route_m += std::hypot(L.guides[i].first - L.guides[i - 1].first,
                          L.guides[i].second - L.guides[i - 1].second);
  Json prog = {{"along_m", L.along_m}, {"route_m", route_m}};
  prog["fraction"] = route_m > 0 ? Json(std::clamp(L.along_m / route_m, 0.0, 1.0)) : Json(nullptr);
  prog["remaining_m"] = route_m > 0 ? Json(std::max(0.0, route_m - L.along_m)) : Json(nullptr);
  // Simulated (or robot) seconds per wall second since the first control tick.
  const double wall_run = L.has_tick ? (active ? now : L.last_tick_wall) - L.first_tick_wall : 0;
  prog["real_time_factor"] =
      L.has_tick && wall_run > 0.5 ? Json((L.tick.t - L.first_tick_t) / wall_run) : Json(nullptr);
  s["progress"] = prog;
  // The attended landmark's class (its database photo is shown beside the live view).
  std::string attended_class;
  if (L.has_tick && !L.tick.landmark.empty()) {
    const auto it = L.landmarks.find(L.tick.landmark);
    if (it != L.landmarks.end() && it->second.contains("class"))
      attended_class = it->second["class"].get<std::string>();
    else if (L.map_geometry.is_object() && L.map_geometry.contains("sketch_landmarks"))
      for (const auto& lm : L.map_geometry["sketch_landmarks"])
        if (lm.value("id", "") == L.tick.landmark) attended_class = lm.value("class", "");
  }
  s["landmark_class"] = attended_class;
  return s;
}

Json RunController::map() const {
  const Live& L = *live_;
  std::lock_guard<std::mutex> l(L.m);
  Json tr = Json::array();
  for (const auto& [x, y] : L.trajectory) tr.push_back({x, y});
  Json m = {{"geometry", L.map_geometry}, {"trajectory", tr}, {"placement", L.placement}};
  m["pose"] = L.has_tick
                  ? Json{{"x", L.tick.odom.x}, {"y", L.tick.odom.y}, {"theta", L.tick.odom.theta}}
                  : Json(nullptr);
  return m;
}

Json RunController::series(std::size_t from_tick, std::size_t from_obs) const {
  const Live& L = *live_;
  std::lock_guard<std::mutex> l(L.m);
  auto num = [](double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); };
  Json ticks = Json::array(), obs = Json::array();
  for (std::size_t i = from_tick; i < L.ticks.size(); ++i) {
    Json row = Json::array();
    for (double v : L.ticks[i]) row.push_back(num(v));
    ticks.push_back(std::move(row));
  }
  for (std::size_t i = from_obs; i < L.obs.size(); ++i)
    obs.push_back({L.obs[i][0], L.obs[i][1], L.obs[i][2]});
  return {{"ticks", ticks},
          {"obs", obs},
          {"tick_rows", L.ticks.size()},
          {"obs_rows", L.obs.size()},
          {"columns", {"t", "v", "w", "servo_error", "x", "y", "theta", "section"}},
          {"obs_columns", {"t", "inliers", "ms"}}};
}

std::vector<unsigned char> RunController::frameJpeg(const FrameOverlay& overlay) const {
  Live& L = *live_;
  cv::Mat img;
  std::vector<nav::Detection> dets;
  std::vector<cv::Rect> windows;
  bool observed = false, need_windows = false;
  std::uint64_t seq = 0;
  {
    std::lock_guard<std::mutex> l(L.m);
    if (L.frame.empty()) return {};
    observed = showObserved(L);
    img = (observed ? L.obs_frame : L.frame).clone();
    if (observed) {
      dets = L.detections;
      seq = L.detections_seq;
      need_windows = opt_.propose_windows && L.windows_seq != seq;
      windows = L.windows_boxes;
    }
  }
  if (need_windows) {
    // Computed here, outside the lock and off the run thread, once per examined frame.
    try {
      windows = opt_.propose_windows(img);
    } catch (const std::exception& e) {
      windows.clear();
      log::warn("ui", "objectness windows for the live view failed", {{"error", e.what()}});
    }
    std::lock_guard<std::mutex> l(L.m);
    if (L.detections_seq == seq) {
      L.windows_boxes = windows;
      L.windows_seq = seq;
    }
  }
  if (img.type() == CV_8UC1) cv::cvtColor(img, img, cv::COLOR_GRAY2BGR);
  const double fs = std::max(0.4, img.cols / 1000.0);
  if (overlay.windows >= 0 && windows.size() > static_cast<size_t>(overlay.windows))
    windows.resize(overlay.windows);
  if (overlay.detections >= 0 && dets.size() > static_cast<size_t>(overlay.detections))
    dets.resize(overlay.detections);
  if (!windows.empty()) {
    // Faded: the windows say where perception looked, the detections what it found.
    cv::Mat layer = img.clone();
    for (const auto& w : windows) cv::rectangle(layer, w, cv::Scalar(230, 200, 60), 1, cv::LINE_AA);
    cv::addWeighted(layer, 0.55, img, 0.45, 0, img);
  }
  for (size_t i = 0; i < dets.size(); ++i) {
    const auto& d = dets[i];
    // The best detection (what the executive servos on) thick green, the others amber.
    const cv::Scalar c = i == 0 ? cv::Scalar(40, 200, 40) : cv::Scalar(0, 170, 255);
    cv::rectangle(img, d.window, c, i == 0 ? 3 : 2);
    char label[160];
    std::snprintf(label, sizeof label, "%s  %d inl", d.class_name.c_str(), d.inliers);
    int base = 0;
    const cv::Size ts = cv::getTextSize(label, cv::FONT_HERSHEY_SIMPLEX, fs, 1, &base);
    // Inside the frame: a window at the right edge would cut its label ("19 inl").
    const cv::Point org(std::max(2, std::min(d.window.x, img.cols - ts.width - 3)),
                        std::max(ts.height + 4, d.window.y - 4));
    cv::rectangle(img, org + cv::Point(-2, base), org + cv::Point(ts.width + 2, -ts.height - 2), c,
                  cv::FILLED);
    cv::putText(img, label, org, cv::FONT_HERSHEY_SIMPLEX, fs, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }
  std::vector<unsigned char> buf;
  cv::imencode(".jpg", img, buf, {cv::IMWRITE_JPEG_QUALITY, 80});
  return buf;
}

Json RunController::capture(const std::string& class_name, const std::optional<cv::Rect>& box) {
  const std::string cls = safeClassName(class_name);
  if (opt_.capture_dir.empty()) throw InputError("capture: no landmark folder configured");
  cv::Mat img;
  {
    std::lock_guard<std::mutex> l(live_->m);
    if (live_->frame.empty())
      throw InputError("capture: no camera frame yet (start a run to open the camera)");
    // The frame on the page, so a box dragged on it frames what the user saw.
    img = (showObserved(*live_) ? live_->obs_frame : live_->frame).clone();
  }
  if (box) {
    const cv::Rect r = *box & cv::Rect(0, 0, img.cols, img.rows);
    if (r.width < 16 || r.height < 16)
      throw InputError("capture: the box must be at least 16x16 pixels inside the frame");
    img = img(r).clone();
  }
  const fs::path dir = fs::path(opt_.capture_dir) / cls;
  const bool new_class = !fs::is_directory(dir) || fs::is_empty(dir);
  fs::create_directories(dir);
  // Next free number: never overwrite an earlier capture.
  int n = 1;
  // Numbers of up to 9 digits count; a longer one (a file named by someone else) is ignored.
  static const std::regex num(R"(capture_(\d{1,9})\.jpg)");
  for (const auto& e : fs::directory_iterator(dir)) {
    std::smatch m;
    const std::string name = e.path().filename().string();
    if (std::regex_match(name, m, num)) n = std::max(n, std::stoi(m[1]) + 1);
  }
  const fs::path file = dir / ("capture_" + std::to_string(n) + ".jpg");
  if (!cv::imwrite(file.string(), img, {cv::IMWRITE_JPEG_QUALITY, 95}))
    throw RuntimeError("capture: cannot write " + file.string());
  log::info("ui", "captured a landmark photo", {{"file", file.string()}});
  return {{"file", file.string()},
          {"class", cls},
          {"width", img.cols},
          {"height", img.rows},
          {"new_class", new_class},
          // Whether the next run trains on it: only when captures go into the landmark set.
          {"trains_next_run", opt_.captures_train},
          {"capture_dir", opt_.capture_dir}};
}

// ---- routes --------------------------------------------------------------------------------

namespace {
// An integer query parameter in [lo, hi]; `fallback` when absent; InputError naming it.
int queryInt(const httplib::Request& req, const char* name, int fallback, int lo, int hi) {
  if (!req.has_param(name)) return fallback;
  const std::string v = req.get_param_value(name);
  static const std::regex num(R"(-?\d{1,10})");
  long long x = 0;
  if (std::regex_match(v, num)) x = std::stoll(v);
  if (!std::regex_match(v, num) || x < lo || x > hi)
    throw InputError(std::string("'") + name + "' must be an integer in " + std::to_string(lo) +
                     ".." + std::to_string(hi) + " (got '" + v.substr(0, 20) + "')");
  return static_cast<int>(x);
}

// A run folder named by a request: a plain folder name inside runs_dir, nothing else.
fs::path runFolder(const std::string& runs_dir, const std::string& id) {
  static const std::regex ok(R"([A-Za-z0-9][A-Za-z0-9_.-]{0,119})");
  if (runs_dir.empty()) throw InputError("run: no runs folder configured");
  if (!std::regex_match(id, ok) || id.find("..") != std::string::npos)
    throw InputError("run: 'id' '" + id.substr(0, 60) + "' is not a run folder name");
  return fs::path(runs_dir) / id;
}

// The run folders, newest first (names start with the UTC time), with their outcome.
Json listRuns(const std::string& runs_dir) {
  Json out = Json::array();
  std::error_code ec;
  if (runs_dir.empty() || !fs::is_directory(runs_dir, ec)) return out;
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(runs_dir, ec))
    if (e.is_directory()) names.push_back(e.path().filename().string());
  std::sort(names.rbegin(), names.rend());
  if (names.size() > 100) names.resize(100);
  for (const auto& n : names) {
    const fs::path d = fs::path(runs_dir) / n;
    Json r = {{"id", n}};
    Json files = Json::array();
    for (const char* f : {"summary.json", "trajectory.png", "telemetry.csv", "events.jsonl"})
      if (fs::exists(d / f, ec)) files.push_back(f);
    r["files"] = files;
    try {
      std::ifstream in(d / "summary.json");
      if (in) {
        const Json s = Json::parse(in);
        for (const char* k : {"success", "reason", "world", "sketch", "time_s", "path_length_m",
                              "distance_to_goal_m", "mode"})
          if (s.contains(k)) r[k] = s[k];
      }
    } catch (const std::exception&) {
      r["reason"] = "summary.json cannot be read";
    }
    out.push_back(r);
  }
  return out;
}
}  // namespace

void addRunRoutes(Server& server, RunController& rc) {
  server.post("/api/run/start", [&rc](const httplib::Request& req, httplib::Response& res) {
    const RunRequest r = RunRequest::fromJson(parseJsonBody(req, "run request"));
    rc.start(r);
    sendJson(res, rc.state());
  });
  server.post("/api/run/stop", [&rc](const httplib::Request&, httplib::Response& res) {
    const bool was_running = rc.stop();
    Json s = rc.state();
    s["stopped"] = was_running;
    sendJson(res, s);
  });
  server.get("/api/run/state",
             [&rc](const httplib::Request&, httplib::Response& res) { sendJson(res, rc.state()); });
  server.get("/api/run/map",
             [&rc](const httplib::Request&, httplib::Response& res) { sendJson(res, rc.map()); });
  server.get("/api/run/frame.jpg", [&rc](const httplib::Request& req, httplib::Response& res) {
    FrameOverlay ov;
    ov.windows = queryInt(req, "windows", -1, -1, 1000);
    ov.detections = queryInt(req, "detections", -1, -1, 1000);
    const auto jpg = rc.frameJpeg(ov);
    if (jpg.empty()) return sendError(res, 404, "no camera frame yet");
    res.set_content(std::string(jpg.begin(), jpg.end()), "image/jpeg");
  });
  server.get("/api/run/series", [&rc](const httplib::Request& req, httplib::Response& res) {
    sendJson(res,
             rc.series(queryInt(req, "tick", 0, 0, 1 << 30), queryInt(req, "obs", 0, 0, 1 << 30)));
  });
  server.get("/api/runs", [&rc](const httplib::Request&, httplib::Response& res) {
    sendJson(res, {{"runs_dir", rc.options().runs_dir}, {"runs", listRuns(rc.options().runs_dir)}});
  });
  server.get(R"(/api/runs/([^/]+)/([^/]+))",
             [&rc](const httplib::Request& req, httplib::Response& res) {
               const std::string id = req.matches[1], file = req.matches[2];
               static const std::map<std::string, std::string> kinds = {
                   {"summary.json", "application/json"},
                   {"trajectory.png", "image/png"},
                   {"telemetry.csv", "text/plain; charset=utf-8"},
                   {"events.jsonl", "text/plain; charset=utf-8"}};
               const auto kind = kinds.find(file);
               if (kind == kinds.end())
                 throw InputError(
                     "run file: 'file' must be summary.json, trajectory.png, telemetry.csv or "
                     "events.jsonl (not '" +
                     file.substr(0, 60) + "')");
               const fs::path p = runFolder(rc.options().runs_dir, id) / file;
               std::ifstream in(p, std::ios::binary);
               if (!in) return sendError(res, 404, "run '" + id + "' has no " + file + " (yet)");
               std::ostringstream ss;
               ss << in.rdbuf();
               res.set_content(ss.str(), kind->second);
             });
  server.get("/api/run/worlds", [&rc](const httplib::Request&, httplib::Response& res) {
    const auto& o = rc.options();
    // Listed on every request: a sketch saved in the editor appears without a restart.
    Json list = Json::array();
    for (const auto& s : o.sketches) list.push_back(s);
    Json detailed = o.list_sketches ? o.list_sketches() : Json::array();
    for (const auto& s : detailed)
      if (s.contains("path")) list.push_back(s["path"]);
    sendJson(res, {{"worlds", o.worlds}, {"sketches", list}, {"sketch_files", detailed}});
  });
  server.post("/api/capture", [&rc](const httplib::Request& req, httplib::Response& res) {
    const CaptureRequest c = CaptureRequest::fromJson(parseJsonBody(req, "capture"));
    sendJson(res, rc.capture(c.class_name, c.box));
  });
}

}  // namespace sketchnav::ui
