// HTTP tests of the live run page's API (`sketchnav ui`, run_api.h): start/state/frame/map,
// Stop reaching the base, captures into the landmark set, and the guards refusing
// cross-origin control requests. The run is a scripted runner that drives the hooks the way
// `sketchnav run`'s harness does, so these tests stay fast and need no simulator.
// Eigen-using headers first (run_api.h orders its own includes).
#include "run_api.h"
// clang-format off
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <thread>

#include "server.h"
#include "test_data.h"
// clang-format on

using namespace sketchnav;
namespace fs = std::filesystem;

namespace {

// Devices of the scripted run.
struct FakeBaseLog {
  std::atomic<int> commands{0}, stops{0};
  std::atomic<bool> moving{false};
  std::atomic<bool> stopped_from_other_thread{false};
  std::thread::id run_thread;
  // Set by a test that compares two drawings of one frame: the runner keeps ticking but sends
  // no new observation, so the frame on the page cannot change between the two requests.
  std::atomic<bool> hold_observations{false};
  std::atomic<int> ticks{0};
};

class FakeBase final : public hw::Base {
 public:
  explicit FakeBase(std::shared_ptr<FakeBaseLog> log) : log_(std::move(log)) {}
  void command(double v, double w) override {
    log_->commands++;
    log_->moving = v != 0 || w != 0;
  }
  void stop() noexcept override {
    log_->stops++;
    log_->moving = false;
    if (std::this_thread::get_id() != log_->run_thread) log_->stopped_from_other_thread = true;
  }
  bool odometry(hw::Odometry& out) override { return true; }
  bool ok() const override { return true; }
  hw::DeviceStats stats() const override { return {}; }
  std::string uri() const override { return "fake://base"; }

 private:
  std::shared_ptr<FakeBaseLog> log_;
};

class FakeCamera final : public hw::Camera {
 public:
  hw::GrabStatus grab(hw::Frame& f, double) override {
    f.image = cv::Mat(240, 320, CV_8UC3, cv::Scalar(60, 90, 120));
    cv::rectangle(f.image, {100, 60, 80, 100}, {20, 200, 240}, cv::FILLED);
    f.seq = ++seq_;
    f.stamp = seq_ * 0.1;
    return hw::GrabStatus::Ok;
  }
  hw::Intrinsics intrinsics() const override { return hw::Intrinsics::fromFov(320, 240, 1.0); }
  hw::DeviceStats stats() const override {
    hw::DeviceStats s;
    s.received = seq_;
    return s;
  }
  std::string uri() const override { return "fake://camera"; }

 private:
  std::uint64_t seq_ = 0;
};

// Ticks every 10 ms (wall time) for at most `max_ticks`, moving forward, in 3 sections; ends
// like the executive: "stopped by user" when asked, else "arrived".
ui::Runner scriptedRunner(std::shared_ptr<FakeBaseLog> log, int max_ticks = 3000) {
  return [log, max_ticks](const ui::RunRequest& rq, const ui::RunHooks& h) -> Json {
    log->run_thread = std::this_thread::get_id();
    if (rq.world == "missing") throw InputError("--world missing: no such world");
    h.on_map({{"frame", "odometry"}, {"sketch_path", {{0, 0}, {3, 0}, {3, 2}}}});
    auto camera = h.wrap_camera(std::make_unique<FakeCamera>());
    auto base = h.wrap_base(std::make_unique<FakeBase>(log));
    h.on_event({0.0, nav::event::Start{3, 5.0}});
    // The route as refitted at a landmark fix (cmd_ui's PlacementReporter reports this).
    if (h.on_placement)
      h.on_placement({{"path", {{0, 0.2}, {3, 0.2}, {3, 2.2}}},
                      {"refits", 1},
                      {"scale", 1.0},
                      {"rotation_deg", 0.0},
                      {"start", {0, 0.2}},
                      {"t", 0.0}});
    std::string reason = "arrived";
    bool success = true;
    for (int i = 0; i < max_ticks; ++i) {
      if (h.stop_requested()) {
        base->stop();
        reason = "stopped by user";
        success = false;
        h.on_event({i * 0.05, nav::event::Failed{nav::FailureCode::Stopped, reason}});
        break;
      }
      hw::Frame f;
      camera->grab(f, 1.0);
      if (i % 4 == 0 && !log->hold_observations.load()) {
        nav::Observation o;
        nav::Detection d;
        d.class_name = "Oatly-Oat-Milk";
        d.window = {100, 60, 80, 100};
        d.inliers = 33;
        o.detections.push_back(d);
        if (rq.seed == 19) {
          // A second one at the frame's right edge: its label must be drawn inside the frame.
          nav::Detection e;
          e.class_name = "God-Morgon-Red-Grapefruit-Juice";
          e.window = {270, 150, 48, 60};
          e.inliers = 19;
          o.detections.push_back(e);
        }
        o.timing.windows = 30;
        h.on_observation(f, o);
      }
      base->command(0.3, 0.1);
      nav::TelemetryRow r;
      r.t = i * 0.05;
      r.odom.x = i * 0.015;
      r.v_cmd = 0.3;
      r.w_cmd = 0.1;
      r.mode = nav::Mode::Follow;
      r.turn = servo::Turn::Straight;
      r.section = std::min(2, i / 20);
      h.on_tick(r);
      log->ticks++;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return {{"success", success}, {"reason", reason}};
  };
}

class UiRunHttp : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::tempDir("uirunhttp");
    log_ = std::make_shared<FakeBaseLog>();
    ui::RunApiOptions ro;
    ro.runner = scriptedRunner(log_);
    ro.capture_dir = dir_ + "/landmarks";
    ro.worlds = {"corridor", "lab"};
    // What `sketchnav ui` checks before a run starts (its world and sketch load): a stand-in
    // that refuses one name the way a world file that does not parse is refused.
    ro.check_request = [](const ui::RunRequest& rq) {
      if (rq.world == "unloadable")
        throw InputError("world 'unloadable.world.json': nested deeper than 256 levels");
    };
    ro.propose_windows = [this](const cv::Mat& img) {
      windows_calls_++;
      return std::vector<cv::Rect>{{10, 10, 50, 50}};
    };
    rc_ = std::make_unique<ui::RunController>(ro);
    ui::ServerOptions so;
    so.port = 0;
    server_ = std::make_unique<ui::Server>(so);
    ui::addRunRoutes(*server_, *rc_);
    port_ = server_->bind();
    thread_ = std::thread([this] { server_->serve(); });
    cli_ = std::make_unique<httplib::Client>("127.0.0.1", port_);
    cli_->set_connection_timeout(5);
    cli_->set_read_timeout(10);
  }
  void TearDown() override {
    server_->stop();
    thread_.join();
    rc_.reset();  // stops and joins a run still going
  }
  static Json body(const httplib::Result& r) { return Json::parse(r->body); }
  httplib::Result post(const std::string& path, const Json& j, const httplib::Headers& extra = {}) {
    return cli_->Post(path.c_str(), extra, j.dump(), "application/json");
  }
  // Polls the state until `pred` holds (bounded; no timing is asserted).
  Json waitFor(const std::function<bool(const Json&)>& pred) {
    Json s;
    for (int i = 0; i < 500; ++i) {
      auto r = cli_->Get("/api/run/state");
      s = body(r);
      if (pred(s)) return s;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    ADD_FAILURE() << "state never reached: " << s.dump();
    return s;
  }

  std::string dir_;
  std::shared_ptr<FakeBaseLog> log_;
  std::atomic<int> windows_calls_{0};
  std::unique_ptr<ui::RunController> rc_;
  std::unique_ptr<ui::Server> server_;
  std::thread thread_;
  int port_ = 0;
  std::unique_ptr<httplib::Client> cli_;
};

TEST_F(UiRunHttp, IdleStateHasNoFrame) {
  auto s = body(cli_->Get("/api/run/state"));
  EXPECT_EQ(s["status"], "idle");
  EXPECT_FALSE(s["active"].get<bool>());
  auto f = cli_->Get("/api/run/frame.jpg");
  ASSERT_TRUE(f);
  EXPECT_EQ(f->status, 404);
  EXPECT_EQ(body(cli_->Get("/api/run/worlds"))["worlds"], Json({"corridor", "lab"}));
  // Stop with nothing running is harmless.
  auto r = post("/api/run/stop", Json::object());
  EXPECT_EQ(r->status, 200);
  EXPECT_FALSE(body(r)["stopped"].get<bool>());
}

TEST_F(UiRunHttp, StartShowsProgressAndStopStopsTheBase) {
  auto r = post("/api/run/start", {{"world", "corridor"}, {"seed", 3}});
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  // A second start while running is refused.
  auto again = post("/api/run/start", {{"world", "corridor"}});
  EXPECT_EQ(again->status, 400);
  EXPECT_NE(body(again)["error"].get<std::string>().find("already"), std::string::npos);

  Json s = waitFor([](const Json& s) { return s["section"].get<int>() >= 2; });
  EXPECT_EQ(s["status"], "running");
  EXPECT_EQ(s["sections"], 3);
  EXPECT_EQ(s["turn"], "Straight");
  EXPECT_DOUBLE_EQ(s["v"].get<double>(), 0.3);
  EXPECT_GT(s["pose"]["x"].get<double>(), 0.2);
  EXPECT_EQ(s["request"]["world"], "corridor");
  EXPECT_EQ(s["request"]["seed"], 3);
  EXPECT_TRUE(s["health"]["camera"]["ok"].get<bool>());
  EXPECT_TRUE(s["health"]["base"]["ok"].get<bool>());
  EXPECT_EQ(s["base"]["last"], "command");
  EXPECT_EQ(s["perception"]["windows"], 30);

  // The frame must stay the same across the two drawings compared below: hold the runner's
  // observations and wait until it has ticked past the hold (an observation it was sending
  // when the hold was set has then landed). A loaded machine can take longer than one
  // observation period (40 ms) between two requests.
  log_->hold_observations = true;
  const int t0 = log_->ticks.load();
  for (int i = 0; i < 500 && log_->ticks.load() < t0 + 2; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_GE(log_->ticks.load(), t0 + 2) << "the scripted run stopped ticking";

  auto f = cli_->Get("/api/run/frame.jpg");
  ASSERT_EQ(f->status, 200);
  EXPECT_EQ(f->get_header_value("Content-Type"), "image/jpeg");
  const cv::Mat img =
      cv::imdecode(std::vector<unsigned char>(f->body.begin(), f->body.end()), cv::IMREAD_COLOR);
  ASSERT_EQ(img.cols, 320);
  // The detection's window is drawn in green on its edge (the frame there was yellow-ish).
  const cv::Vec3b edge = img.at<cv::Vec3b>(120, 100);
  EXPECT_GT(edge[1], 150);
  EXPECT_LT(edge[2], 120);
  // The objectness windows of that frame, thin, blue-ish and faded, computed once per frame
  // shown: the pixel on a window's edge is much bluer than the same pixel drawn without them.
  const cv::Vec3b win = img.at<cv::Vec3b>(35, 10);
  EXPECT_EQ(windows_calls_.load(), 1);
  auto f0 = cli_->Get("/api/run/frame.jpg?windows=0");
  ASSERT_EQ(f0->status, 200);
  const cv::Mat bare =
      cv::imdecode(std::vector<unsigned char>(f0->body.begin(), f0->body.end()), cv::IMREAD_COLOR);
  ASSERT_EQ(bare.size(), img.size());
  const cv::Vec3b b0 = bare.at<cv::Vec3b>(35, 10);
  EXPECT_GT(int(win[0]) - int(win[2]), int(b0[0]) - int(b0[2]) + 40);
  EXPECT_EQ(windows_calls_.load(), 1);  // the second drawing reused them
  EXPECT_EQ(s["perception"]["detections"], 1);

  auto m = body(cli_->Get("/api/run/map"));
  EXPECT_EQ(m["geometry"]["frame"], "odometry");
  EXPECT_GE(m["trajectory"].size(), 3u);
  EXPECT_TRUE(m["pose"].is_object());
  // The refitted route, as the runner reported it, beside the sketched one.
  ASSERT_TRUE(m["placement"].is_object()) << m.dump();
  EXPECT_EQ(m["placement"]["refits"], 1);
  EXPECT_EQ(m["placement"]["path"][1][1], 0.2);

  EXPECT_TRUE(log_->moving.load());
  auto st = post("/api/run/stop", Json::object());
  ASSERT_EQ(st->status, 200);
  EXPECT_TRUE(body(st)["stopped"].get<bool>());
  s = waitFor([](const Json& s) { return !s["active"].get<bool>(); });
  EXPECT_EQ(s["status"], "stopped");
  EXPECT_EQ(s["reason"], "stopped by user");
  EXPECT_EQ(s["base"]["v"], 0.0);
  EXPECT_EQ(s["v"], 0.0);
  EXPECT_EQ(s["mode"], "stopped");
  EXPECT_EQ(s["base"]["last"], "stop");
  EXPECT_GE(s["base"]["stops"].get<int>(), 1);
  EXPECT_FALSE(log_->moving.load());
  EXPECT_GE(log_->stops.load(), 1);
  // The simulator is only ever touched by the run thread.
  EXPECT_FALSE(log_->stopped_from_other_thread.load());
  bool stop_event = false;
  for (const auto& e : s["events"])
    if (e.value("reason", "") == "stopped by user") stop_event = true;
  EXPECT_TRUE(stop_event) << s["events"].dump();

  // A new run can start after the previous one ended.
  EXPECT_EQ(post("/api/run/start", {{"world", "lab"}})->status, 200);
  waitFor([](const Json& s) { return s["status"] == "running"; });
  post("/api/run/stop", Json::object());
  waitFor([](const Json& s) { return s["status"] == "stopped"; });
}

// Issue 29, bug 9: a detection at the frame's right edge had its label cut ("19 inl"): the
// label (amber, filled) is moved left until it ends inside the frame.
TEST_F(UiRunHttp, DetectionLabelsStayInsideTheFrame) {
  ASSERT_EQ(post("/api/run/start", {{"world", "corridor"}, {"seed", 19}})->status, 200);
  waitFor([](const Json& s) { return s["perception"]["detections"] == 2; });
  auto f = cli_->Get("/api/run/frame.jpg?windows=0&detections=-1");
  ASSERT_EQ(f->status, 200);
  const cv::Mat img =
      cv::imdecode(std::vector<unsigned char>(f->body.begin(), f->body.end()), cv::IMREAD_COLOR);
  ASSERT_EQ(img.cols, 320);
  // The label's band just above the window (y 150): amber pixels left of the window, where
  // the whole label ("God-Morgon-Red-Grapefruit-Juice  19 inl", wider than the 50 px from the
  // window to the edge) now starts. Drawn from the window's x it had none there. (Columns
  // 95-185 hold the camera's own yellow box.)
  int amber = 0;
  for (int y = 132; y < 150; ++y)
    for (int x = 0; x < 260; ++x) {
      if (x >= 95 && x < 185) continue;
      const cv::Vec3b p = img.at<cv::Vec3b>(y, x);
      if (p[0] < 100 && p[1] > 120 && p[1] < 230 && p[2] > 190) ++amber;
    }
  EXPECT_GT(amber, 500);
  post("/api/run/stop", Json::object());
}

TEST_F(UiRunHttp, StopOnARealRobotStopsTheBaseFromTheRequest) {
  ASSERT_EQ(post("/api/run/start", {{"robot", "dani://10.0.0.2"}, {"camera", "aravis://"}})->status,
            200);
  waitFor([](const Json& s) { return s["base"]["last"] == "command"; });
  post("/api/run/stop", Json::object());
  // Stopped by the request itself, not only at the run's next tick.
  EXPECT_TRUE(log_->stopped_from_other_thread.load());
  EXPECT_FALSE(log_->moving.load());
  const Json s = waitFor([](const Json& s) { return s["status"] == "stopped"; });
  EXPECT_EQ(s["request"]["mode"], "hardware");
}

TEST_F(UiRunHttp, RunnerErrorsAreShown) {
  ASSERT_EQ(post("/api/run/start", {{"world", "missing"}})->status, 200);
  const Json s = waitFor([](const Json& s) { return !s["active"].get<bool>(); });
  EXPECT_EQ(s["status"], "error");
  EXPECT_NE(s["reason"].get<std::string>().find("no such world"), std::string::npos);
}

// Issue 28: a world that does not load used to be answered 200 and then reported as the
// run's error; it is refused on the start request itself, naming the file. Nothing runs (the
// runner is never called); the refusal is the run's state, as an error, for the page's card.
TEST_F(UiRunHttp, AStartWhoseWorldDoesNotLoadIsA400NamingTheFile) {
  const auto r = post("/api/run/start", {{"world", "unloadable"}});
  ASSERT_EQ(r->status, 400);
  EXPECT_NE(r->body.find("unloadable.world.json"), std::string::npos) << r->body;
  const Json s = body(cli_->Get("/api/run/state"));
  EXPECT_EQ(s["status"], "error");
  EXPECT_NE(s["reason"].get<std::string>().find("unloadable.world.json"), std::string::npos);
  EXPECT_FALSE(s["active"].get<bool>());
  EXPECT_EQ(log_->ticks.load(), 0) << "the runner ran";
  // The page is not stuck: a good request starts.
  EXPECT_EQ(post("/api/run/start", {{"world", "corridor"}})->status, 200);
}

TEST_F(UiRunHttp, BadStartRequestsAreRefused) {
  EXPECT_EQ(post("/api/run/start", {{"world", "corridor"}, {"seed", -1}})->status, 400);
  EXPECT_EQ(post("/api/run/start", {{"world", 5}})->status, 400);
  EXPECT_EQ(post("/api/run/start", {{"camera", "aravis://"}})->status, 400);  // no robot
  EXPECT_EQ(post("/api/run/start", {{"max_time_s", "long"}})->status, 400);
  EXPECT_EQ(post("/api/run/start", {{"camera_only", true}})->status, 400);  // which camera?
  EXPECT_EQ(post("/api/run/start", {{"camera_only", "yes"}, {"camera", "video://0"}})->status, 400);
  auto r = cli_->Post("/api/run/start", "{not json", "application/json");
  EXPECT_EQ(r->status, 400);
  // Issue 28 (fuzz_webui): a seed beyond int used to wrap (4294967297 ran as seed 1), and a
  // number overflowing double escaped the body parser as a 500.
  EXPECT_EQ(post("/api/run/start", {{"world", "corridor"}, {"seed", 4294967297ull}})->status, 400);
  r = cli_->Post("/api/run/start", R"({"world": "corridor", "seed": 1e400})", "application/json");
  EXPECT_EQ(r->status, 400);
  EXPECT_EQ(body(cli_->Get("/api/run/state"))["status"], "idle");
}

TEST_F(UiRunHttp, ControlEndpointsRefuseCrossOriginRequests) {
  const httplib::Headers evil = {{"Origin", "http://evil.example"}};
  const httplib::Headers cross = {{"Sec-Fetch-Site", "cross-site"}};
  const httplib::Headers rebind = {{"Host", "evil.example:" + std::to_string(port_)}};
  for (const auto& h : {evil, cross, rebind}) {
    EXPECT_EQ(post("/api/run/start", {{"world", "corridor"}}, h)->status, 403);
    EXPECT_EQ(post("/api/run/stop", Json::object(), h)->status, 403);
    EXPECT_EQ(post("/api/capture", {{"class", "X"}}, h)->status, 403);
    EXPECT_EQ(cli_->Get("/api/run/frame.jpg", h)->status, 403);  // the camera is private too
  }
  EXPECT_EQ(body(cli_->Get("/api/run/state"))["status"], "idle");
  // The page's own origin is fine.
  const httplib::Headers own = {{"Origin", "http://127.0.0.1:" + std::to_string(port_)}};
  EXPECT_EQ(post("/api/run/start", {{"world", "corridor"}}, own)->status, 200);
  // A cross-origin Stop is refused as well, and the run goes on until the page stops it.
  EXPECT_EQ(post("/api/run/stop", Json::object(), evil)->status, 403);
  EXPECT_TRUE(body(cli_->Get("/api/run/state"))["active"].get<bool>());
  EXPECT_EQ(post("/api/run/stop", Json::object(), own)->status, 200);
}

TEST_F(UiRunHttp, CaptureSavesFramesAndCropsIntoClassFolders) {
  // No camera yet.
  auto r = post("/api/capture", {{"class", "Mug"}});
  EXPECT_EQ(r->status, 400);
  ASSERT_EQ(post("/api/run/start", {{"world", "corridor"}})->status, 200);
  waitFor([](const Json& s) { return s["frame_seq"].get<int>() > 0; });

  r = post("/api/capture", {{"class", "Red Mug"}});
  ASSERT_EQ(r->status, 200) << r->body;
  Json j = body(r);
  EXPECT_EQ(j["class"], "Red Mug");
  EXPECT_TRUE(j["new_class"].get<bool>());
  const fs::path first = dir_ + "/landmarks/Red Mug/capture_1.jpg";
  ASSERT_TRUE(fs::exists(first));
  EXPECT_EQ(cv::imread(first.string()).cols, 320);

  r = post("/api/capture", {{"class", "Red Mug"}, {"box", {100.4, 60, 80, 100}}});
  ASSERT_EQ(r->status, 200) << r->body;
  const cv::Mat crop = cv::imread(dir_ + "/landmarks/Red Mug/capture_2.jpg");
  ASSERT_FALSE(crop.empty());
  EXPECT_EQ(crop.cols, 80);
  EXPECT_EQ(crop.rows, 100);
  // The crop is of the raw frame (no drawn boxes): the yellow-ish patch.
  const cv::Vec3b c = crop.at<cv::Vec3b>(50, 40);
  EXPECT_GT(c[2], 200);
  EXPECT_FALSE(body(r)["new_class"].get<bool>());
  // A box partly outside the frame is clipped to it.
  r = post("/api/capture", {{"class", "Red Mug"}, {"box", {310, 200, 100, 100}}});
  EXPECT_EQ(r->status, 400);  // 10x40 left: too small
  r = post("/api/capture", {{"class", "Red Mug"}, {"box", {280, 180, 100, 100}}});
  ASSERT_EQ(r->status, 200);
  EXPECT_EQ(body(r)["width"], 40);

  for (const std::string bad : {"../evil", "a/b", "", ".hidden", "..", "a\\b", "x\n"}) {
    auto b = post("/api/capture", {{"class", bad}});
    EXPECT_EQ(b->status, 400) << bad;
  }
  EXPECT_EQ(post("/api/capture", {{"class", "Mug"}, {"box", {1, 2, 3}}})->status, 400);
  EXPECT_EQ(post("/api/capture", {{"class", "Mug"}, {"box", {1e300, 2, 3, 4}}})->status, 400);
  EXPECT_EQ(post("/api/capture", Json::object())->status, 400);
  EXPECT_FALSE(fs::exists(dir_ + "/evil"));
  int files = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir_ + "/landmarks"))
    files += e.is_regular_file();
  EXPECT_EQ(files, 3);
  post("/api/run/stop", Json::object());
}

TEST(RunRequest, CameraOnlyNeedsOnlyACamera) {
  const auto r = ui::RunRequest::fromJson({{"camera_only", true}, {"camera", "video://0"}});
  EXPECT_TRUE(r.camera_only);
  EXPECT_EQ(r.toJson()["mode"], "camera");
  EXPECT_EQ(r.toJson()["camera"], "video://0");
  const auto sim = ui::RunRequest::fromJson({{"world", "lab"}, {"max_time_s", 30}});
  EXPECT_FALSE(sim.hardware());
  EXPECT_EQ(sim.toJson()["mode"], "sim");
  EXPECT_DOUBLE_EQ(sim.max_time_s, 30);
}

// Issue 28: a field the request does not take is refused like an unknown setting (a misspelt
// "sede" started a run with seed 1).
TEST(RunRequest, UnknownFieldsAreRefusedNamingTheClosestKnownOne) {
  const auto refusal = [](const Json& j, bool capture) {
    try {
      if (capture)
        ui::CaptureRequest::fromJson(j);
      else
        ui::RunRequest::fromJson(j);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(refusal({{"world", "lab"}, {"sede", 3}}, false),
            "run request: unknown field 'sede' (did you mean 'seed'?)");
  EXPECT_EQ(refusal({{"class", "Oatly-Oat-Milk"}, {"bx", {0, 0, 10, 10}}}, true),
            "capture: unknown field 'bx' (did you mean 'box'?)");
  // What the pages send is taken (share/web/run.js and app.js).
  EXPECT_EQ(
      refusal(
          {{"mode", "sim"}, {"max_time_s", 0}, {"world", "corridor"}, {"sketch", ""}, {"seed", 1}},
          false),
      "");
  EXPECT_EQ(refusal({{"mode", "camera"}, {"camera_only", true}, {"camera", "video://0"}}, false),
            "");
  EXPECT_EQ(refusal(ui::RunRequest::fromJson({{"world", "lab"}}).toJson(), false), "");
  EXPECT_EQ(refusal({{"class", "Oatly-Oat-Milk"}, {"box", {0, 0, 10, 10}}}, true), "");
}

TEST(SafeClassName, AcceptsFolderNamesOfTheLandmarkSet) {
  EXPECT_EQ(ui::safeClassName("Oatly-Oat-Milk"), "Oatly-Oat-Milk");
  EXPECT_EQ(ui::safeClassName("Red Mug 2"), "Red Mug 2");
  EXPECT_THROW(ui::safeClassName(std::string(81, 'a')), InputError);
  EXPECT_THROW(ui::safeClassName("mug."), InputError);
}

}  // namespace
