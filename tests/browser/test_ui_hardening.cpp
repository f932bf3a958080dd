// Bad-input tests of the server behind `sketchnav ui` (issue 28, item 3): request paths and
// JSON bodies that are not UTF-8, a duplicate Host header, a capture folder holding a huge
// capture number, and idle half-open connections that must not keep STOP from being served.
// Raw sockets on 127.0.0.1 (httplib's client would refuse to send most of these).
// Eigen-using headers first (run_api.h orders its own includes).
#include "run_api.h"
// clang-format off
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <opencv2/imgcodecs.hpp>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include "server.h"
#include "test_data.h"
// clang-format on

using namespace sketchnav;
namespace fs = std::filesystem;

namespace {

int connectTo(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return -1;
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  timeval tv{3, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

// Sends `request` as it is and returns what came back until the server closed (or 3 s).
std::string rawRequest(int port, const std::string& request) {
  const int fd = connectTo(port);
  if (fd < 0) return "";
  ::send(fd, request.data(), request.size(), MSG_NOSIGNAL);
  std::string out;
  char buf[4096];
  for (;;) {
    const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
    if (n <= 0) break;
    out.append(buf, static_cast<size_t>(n));
  }
  ::close(fd);
  return out;
}

std::string statusLine(const std::string& response) {
  return response.substr(0, response.find("\r\n"));
}
std::string bodyOf(const std::string& response) {
  const auto p = response.find("\r\n\r\n");
  return p == std::string::npos ? "" : response.substr(p + 4);
}

// A frame source for the capture test: one run that delivers frames until stopped.
class OneColourCamera final : public hw::Camera {
 public:
  hw::GrabStatus grab(hw::Frame& f, double) override {
    f.image = cv::Mat(120, 160, CV_8UC3, cv::Scalar(60, 90, 120));
    f.seq = ++seq_;
    return hw::GrabStatus::Ok;
  }
  hw::Intrinsics intrinsics() const override { return hw::Intrinsics::fromFov(160, 120, 1.0); }
  hw::DeviceStats stats() const override { return {}; }
  std::string uri() const override { return "fake://camera"; }

 private:
  std::uint64_t seq_ = 0;
};

class UiHardening : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::tempDir("uihardening");
    ui::RunApiOptions ro;
    ro.runner = [](const ui::RunRequest& rq, const ui::RunHooks& h) -> Json {
      auto camera = h.wrap_camera(std::make_unique<OneColourCamera>());
      for (int i = 0; i < 3000 && !h.stop_requested(); ++i) {
        hw::Frame f;
        camera->grab(f, 1.0);
        if (rq.world == "edge") {  // a detection at the frame's right edge
          nav::Observation o;
          nav::Detection d;
          d.class_name = "God-Morgon-Red-Grapefruit-Juice";
          d.window = {130, 40, 30, 40};
          d.inliers = 19;
          o.detections.push_back(d);
          h.on_observation(f, o);
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
      return {{"success", false}, {"reason", "stopped by user"}};
    };
    ro.capture_dir = dir_ + "/captures";
    ro.worlds = {"corridor"};
    rc_ = std::make_unique<ui::RunController>(ro);
    ui::ServerOptions so;
    so.port = 0;
    server_ = std::make_unique<ui::Server>(so);
    ui::EditorOptions eo;
    eo.landmarks_dir = test::sourceDir() + "/share/landmarks";
    eo.sketch_dir = dir_ + "/sketches";
    ui::addEditorRoutes(*server_, eo);
    ui::addRunRoutes(*server_, *rc_);
    server_->get("/api/ping", [](const httplib::Request&, httplib::Response& res) {
      ui::sendJson(res, {{"pong", true}});
    });
    port_ = server_->bind();
    thread_ = std::thread([this] { server_->serve(); });
    cli_ = std::make_unique<httplib::Client>("127.0.0.1", port_);
    cli_->set_connection_timeout(5);
    cli_->set_read_timeout(10);
  }
  void TearDown() override {
    server_->stop();
    thread_.join();
    rc_.reset();
  }
  std::string host() const { return "Host: 127.0.0.1:" + std::to_string(port_) + "\r\n"; }
  std::string get(const std::string& target, const std::string& extra_headers = "") const {
    return rawRequest(port_, "GET " + target + " HTTP/1.1\r\n" + host() + extra_headers +
                                 "Connection: close\r\n\r\n");
  }
  std::string post(const std::string& target, const std::string& body) const {
    return rawRequest(port_, "POST " + target + " HTTP/1.1\r\n" + host() +
                                 "Content-Type: application/json\r\nContent-Length: " +
                                 std::to_string(body.size()) + "\r\nConnection: close\r\n\r\n" +
                                 body);
  }
  bool alive() const {
    const std::string r = get("/api/ping");
    return statusLine(r) == "HTTP/1.1 200 OK";
  }

  std::string dir_;
  std::unique_ptr<ui::RunController> rc_;
  std::unique_ptr<ui::Server> server_;
  std::thread thread_;
  int port_ = 0;
  std::unique_ptr<httplib::Client> cli_;
};

TEST_F(UiHardening, PathsThatAreNotUtf8Get400AndTheServerLives) {
  for (const std::string target :
       {"/%C0%80", "/\xff\xfe", "/%c0%ae%c0%ae/%c0%ae%c0%ae/etc/passwd", "/api/sketches/%FF",
        "/api/classes/%FE%FF/thumbnail", "/api/examples/a%C3"}) {
    const std::string r = get(target);
    EXPECT_EQ(statusLine(r), "HTTP/1.1 400 Bad Request") << target << "\n" << r;
    EXPECT_NE(bodyOf(r).find("not valid UTF-8"), std::string::npos) << bodyOf(r);
    ASSERT_TRUE(alive()) << "server gone after " << target;
  }
  // A query string that is not UTF-8 is not a crash either.
  EXPECT_TRUE(alive());
  const std::string q = get("/api/sketches?x=%FF");
  EXPECT_NE(statusLine(q).find(" 200 "), std::string::npos) << q;
}

TEST_F(UiHardening, DuplicateHostHeaderIsRefused) {
  const std::string r = get("/api/ping", "Host: evil.example\r\n");
  EXPECT_EQ(statusLine(r), "HTTP/1.1 400 Bad Request") << r;
  EXPECT_NE(bodyOf(r).find("Host"), std::string::npos) << bodyOf(r);
  const std::string same = get("/api/ping", host());  // even twice the same name
  EXPECT_EQ(statusLine(same), "HTTP/1.1 400 Bad Request") << same;
  EXPECT_TRUE(alive());
}

TEST_F(UiHardening, JsonBodiesThatAreNotUtf8Get400NamingTheField) {
  // In a string value of the run request, of a capture, and of a sketch.
  std::string r = post("/api/run/start", "{\"world\": \"corr\xff\xfeidor\", \"seed\": 1}");
  EXPECT_EQ(statusLine(r), "HTTP/1.1 400 Bad Request") << r;
  EXPECT_NE(bodyOf(r).find("'world'"), std::string::npos) << bodyOf(r);
  EXPECT_NE(bodyOf(r).find("UTF-8"), std::string::npos) << bodyOf(r);
  EXPECT_EQ(bodyOf(r).find("json.exception"), std::string::npos) << bodyOf(r);

  r = post("/api/capture", "{\"class\": \"M\xc0\xafug\"}");
  EXPECT_EQ(statusLine(r), "HTTP/1.1 400 Bad Request") << r;
  EXPECT_NE(bodyOf(r).find("'class'"), std::string::npos) << bodyOf(r);

  r = post("/api/route", "{\"format\": 1, \"name\": \"\xe9t\xe9\", \"landmarks\": []}");
  EXPECT_EQ(statusLine(r), "HTTP/1.1 400 Bad Request") << r;
  EXPECT_NE(bodyOf(r).find("'name'"), std::string::npos) << bodyOf(r);
  EXPECT_EQ(bodyOf(r).find("json.exception"), std::string::npos) << bodyOf(r);

  r = post("/api/sketches/ok", "{\"format\": 1, \"name\": \"\xff\"}");
  EXPECT_EQ(statusLine(r), "HTTP/1.1 400 Bad Request") << r;
  EXPECT_FALSE(fs::exists(dir_ + "/sketches/ok.sketch.json"));
  EXPECT_TRUE(alive());
}

TEST_F(UiHardening, AHugeCaptureNumberInTheFolderIsNotAnError) {
  fs::create_directories(dir_ + "/captures/Mug");
  std::ofstream(dir_ + "/captures/Mug/capture_99999999999999999999999.jpg") << "x";
  std::ofstream(dir_ + "/captures/Mug/capture_7.jpg") << "x";
  auto r = cli_->Post("/api/run/start", Json{{"world", "corridor"}}.dump(), "application/json");
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  for (int i = 0; i < 300; ++i) {
    auto s = cli_->Get("/api/run/state");
    if (s && Json::parse(s->body)["frame_seq"].get<int>() > 0) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  r = cli_->Post("/api/capture", Json{{"class", "Mug"}}.dump(), "application/json");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200) << r->body;
  EXPECT_TRUE(fs::exists(dir_ + "/captures/Mug/capture_8.jpg"));
  cli_->Post("/api/run/stop", "{}", "application/json");
}

TEST_F(UiHardening, DetectionLabelsStayInsideTheFrame) {
  auto r = cli_->Post("/api/run/start", Json{{"world", "edge"}}.dump(), "application/json");
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  cv::Mat img;
  for (int i = 0; i < 300 && img.empty(); ++i) {
    auto f = cli_->Get("/api/run/frame.jpg");
    if (f && f->status == 200 &&
        Json::parse(cli_->Get("/api/run/state")->body)["shown_seq"] ==
            Json::parse(cli_->Get("/api/run/state")->body)["perception"]["frame_seq"])
      img = cv::imdecode(std::vector<unsigned char>(f->body.begin(), f->body.end()),
                         cv::IMREAD_COLOR);
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  cli_->Post("/api/run/stop", "{}", "application/json");
  ASSERT_FALSE(img.empty());
  // The label's green background, in the rows above the window: it must start far enough
  // left of the window (x = 130 of 160) for the whole text to fit in the frame.
  int leftmost = img.cols;
  for (int y = 0; y < 36; ++y)
    for (int x = 0; x < img.cols; ++x) {
      const cv::Vec3b p = img.at<cv::Vec3b>(y, x);
      if (std::abs(p[0] - 40) < 45 && std::abs(p[1] - 200) < 50 && std::abs(p[2] - 40) < 45)
        leftmost = std::min(leftmost, x);
    }
  EXPECT_LT(leftmost, 60) << "the label starts at x = " << leftmost << " of " << img.cols;
}

TEST_F(UiHardening, StopIsServedWhileManyIdleConnectionsAreHeld) {
  // 500 connections that send half a request line and then nothing (slowloris).
  std::vector<int> idle;
  for (int i = 0; i < 500; ++i) {
    const int fd = connectTo(port_);
    if (fd < 0) break;
    ::send(fd, "GET / HTTP/1.1\r\n", 16, MSG_NOSIGNAL);
    // httplib listens with a backlog of 5: connecting faster than the server accepts only
    // makes the kernel drop SYNs (1 s retransmits), which slows the test, not the server.
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
    idle.push_back(fd);
  }
  ASSERT_EQ(idle.size(), 500u);
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // all accepted by now
  httplib::Client c("127.0.0.1", port_);
  c.set_connection_timeout(2);
  c.set_read_timeout(2);  // the server's own read timeout is longer: no waiting it out
  const auto t0 = std::chrono::steady_clock::now();
  auto r = c.Post("/api/run/stop", "{}", "application/json");
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_TRUE(r) << "STOP not answered while 500 idle connections are held";
  EXPECT_EQ(r->status, 200);
  RecordProperty("stop_ms_with_500_idle", std::to_string(ms));
  r = c.Get("/api/run/state");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
  for (int fd : idle) ::close(fd);
}

}  // namespace
