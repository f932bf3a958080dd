// HTTP tests of the local web server behind `sketchnav ui`: the editor API and its guards
// (Host/Origin, body size, bad JSON, path traversal). A real server on a free port.
// Eigen-using headers first: a macro from httplib.h breaks Eigen's headers.
#include "../../mapsketch/tests/sketch_fixtures.h"
#include "sketchnav/mapsketch/io.h"
// clang-format off
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <thread>

#include <opencv2/imgcodecs.hpp>

#include "server.h"
#include "test_data.h"
// clang-format on

using namespace sketchnav;
namespace fs = std::filesystem;

namespace {

class UiHttp : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::tempDir("uihttp");
    ui::ServerOptions so;
    so.port = 0;
    so.web_root = test::sourceDir() + "/share/web";
    so.max_body_bytes = 1 << 20;
    server_ = std::make_unique<ui::Server>(so);
    ui::EditorOptions eo;
    eo.landmarks_dir = test::sourceDir() + "/share/landmarks";
    eo.sketch_dir = dir_ + "/sketches";
    eo.examples_dir = test::sourceDir() + "/share/sketches";
    ui::addEditorRoutes(*server_, eo);
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
  }
  static std::string goodSketch() {
    return mapsketch::sketchToJson(mapsketch::fixtures::lSketch()).dump();
  }
  static Json body(const httplib::Result& r) { return Json::parse(r->body); }

  std::string dir_;
  std::unique_ptr<ui::Server> server_;
  std::thread thread_;
  int port_ = 0;
  std::unique_ptr<httplib::Client> cli_;
};

TEST_F(UiHttp, ServesThePageAndTheClasses) {
  auto r = cli_->Get("/");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
  EXPECT_NE(r->body.find("sketch editor"), std::string::npos);
  r = cli_->Get("/api/classes");
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200);
  const Json j = body(r);
  ASSERT_EQ(j["classes"].size(), 8u);
  EXPECT_EQ(j["classes"][0]["name"], "Alpro-Blueberry-Soyghurt");
  r = cli_->Get("/api/classes/Oatly-Oat-Milk/thumbnail");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
  EXPECT_EQ(r->get_header_value("Content-Type"), "image/jpeg");
  EXPECT_GT(r->body.size(), 1000u);
  r = cli_->Get("/api/classes/Nope/thumbnail");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 404);
}

TEST_F(UiHttp, ConvertsASketchToItsRoute) {
  auto r = cli_->Post("/api/route", goodSketch(), "application/json");
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  const Json j = body(r);
  EXPECT_EQ(j["sections"].size(), 2u);
  EXPECT_EQ(j["sections"][0]["landmarks"][0]["id"], "A");
}

TEST_F(UiHttp, BadJsonAndInvalidSketchesGetAClearMessage) {
  auto r = cli_->Post("/api/route", "{\"format\": 1,", "application/json");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 400);
  EXPECT_NE(body(r)["error"].get<std::string>().find("not valid JSON"), std::string::npos);

  Json s = Json::parse(goodSketch());
  s["landmarks"][1]["distance_m"] = -2;
  r = cli_->Post("/api/route", s.dump(), "application/json");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 400);
  EXPECT_NE(body(r)["error"].get<std::string>().find("landmarks[1].distance_m"), std::string::npos);

  s = Json::parse(goodSketch());
  s["landmarks"][0]["class"] = "Tesla-Model-3";
  r = cli_->Post("/api/route", s.dump(), "application/json");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 400);
  EXPECT_NE(body(r)["error"].get<std::string>().find("unknown class 'Tesla-Model-3'"),
            std::string::npos);

  r = cli_->Post("/api/route", "", "application/json");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 400);
}

TEST_F(UiHttp, OversizedBodiesAreRefused) {
  const std::string big(2 << 20, ' ');
  auto r = cli_->Post("/api/route", big, "application/json");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 413);
  r = cli_->Post("/api/sketches/big", big, "application/json");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 413);
  EXPECT_FALSE(fs::exists(dir_ + "/sketches/big.sketch.json"));
}

TEST_F(UiHttp, ForeignHostAndOriginAreRefused) {
  auto r = cli_->Get("/api/classes", {{"Host", "evil.example:" + std::to_string(port_)}});
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 403);
  r = cli_->Get("/", {{"Host", "attacker.com"}});  // DNS rebinding: a foreign name for us
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 403);
  r = cli_->Post("/api/sketches/x", {{"Origin", "http://evil.example"}}, goodSketch(),
                 "application/json");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 403);
  EXPECT_FALSE(fs::exists(dir_ + "/sketches/x.sketch.json"));
  r = cli_->Post("/api/route", {{"Origin", "null"}}, goodSketch(), "application/json");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 403);
  r = cli_->Post("/api/route", {{"Sec-Fetch-Site", "cross-site"}}, goodSketch(),
                 "application/json");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 403);
  // The page itself (same origin) is allowed, under either local name.
  r = cli_->Post("/api/route", {{"Origin", "http://127.0.0.1:" + std::to_string(port_)}},
                 goodSketch(), "application/json");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
  r = cli_->Get("/api/classes", {{"Host", "localhost:" + std::to_string(port_)}});
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
}

TEST_F(UiHttp, RoutesAddedByOtherAreasGetTheSameGuards) {
  auto r = cli_->Get("/api/ping");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
  r = cli_->Get("/api/ping", {{"Host", "evil.example"}});
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 403);
}

TEST_F(UiHttp, SavesOpensAndListsSketches) {
  auto r = cli_->Post("/api/sketches/my-lab_1", goodSketch(), "application/json");
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  EXPECT_EQ(body(r)["saved"], "my-lab_1.sketch.json");
  const std::string file = dir_ + "/sketches/my-lab_1.sketch.json";
  ASSERT_TRUE(fs::exists(file));
  EXPECT_EQ(mapsketch::loadSketch(file).landmarks.size(), 4u);
  // A second save does not silently overwrite; with overwrite=1 it does.
  r = cli_->Post("/api/sketches/my-lab_1", goodSketch(), "application/json");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 409);
  r = cli_->Post("/api/sketches/my-lab_1?overwrite=1", goodSketch(), "application/json");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
  r = cli_->Get("/api/sketches");
  ASSERT_TRUE(r);
  const Json list = body(r);
  EXPECT_EQ(list["files"], Json::array({"my-lab_1.sketch.json"}));
  EXPECT_GE(list["examples"].size(), 2u);
  r = cli_->Get("/api/sketches/my-lab_1.sketch.json");
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200);
  EXPECT_EQ(body(r)["landmarks"].size(), 4u);
  r = cli_->Get("/api/sketches/none.sketch.json");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 404);
  // An invalid sketch is not saved.
  Json bad = Json::parse(goodSketch());
  bad["path"] = Json::array();
  r = cli_->Post("/api/sketches/broken", bad.dump(), "application/json");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 400);
  EXPECT_FALSE(fs::exists(dir_ + "/sketches/broken.sketch.json"));
}

TEST_F(UiHttp, PathTraversalIsRefused) {
  for (const std::string& name :
       std::vector<std::string>{"..", "..%2Fescape", "%2E%2E%2Fescape", ".hidden", "a%5Cb",
                                "sub%2Fx", "%00x", "x%20y", std::string(150, 'a')}) {
    SCOPED_TRACE(name);
    auto r = cli_->Post("/api/sketches/" + name, goodSketch(), "application/json");
    ASSERT_TRUE(r);
    EXPECT_TRUE(r->status == 400 || r->status == 404) << r->status << " " << r->body;
    r = cli_->Get("/api/sketches/" + name);
    ASSERT_TRUE(r);
    EXPECT_TRUE(r->status == 400 || r->status == 404) << r->status << " " << r->body;
  }
  EXPECT_FALSE(fs::exists(dir_ + "/escape.sketch.json"));
  EXPECT_FALSE(fs::exists(dir_ + "/escape"));
  auto r = cli_->Get("/../../../../etc/passwd");
  ASSERT_TRUE(r);
  EXPECT_NE(r->status, 200);
  r = cli_->Get("/api/examples/..%2F..%2FCMakeLists.txt");
  ASSERT_TRUE(r);
  EXPECT_NE(r->status, 200);
}

TEST(UiHttpClasses, ClassNamesWithSpacesAndSymbolsGetWorkingThumbnailUrls) {
  const std::string dir = test::tempDir("uiclasses");
  const std::string src =
      test::sourceDir() + "/share/landmarks/Oatly-Oat-Milk/Oatly-Oat-Milk_001.jpg";
  fs::create_directories(dir + "/set/Milk 2% fat");
  fs::create_directories(dir + "/set/empty");  // no image: not a class
  fs::copy_file(src, dir + "/set/Milk 2% fat/a.jpg");
  ui::ServerOptions so;
  so.port = 0;
  ui::Server server(so);
  ui::addEditorRoutes(server, {dir + "/set", dir + "/sketches", ""});
  const int port = server.bind();
  std::thread t([&] { server.serve(); });
  httplib::Client cli("127.0.0.1", port);
  auto r = cli.Get("/api/classes");
  ASSERT_TRUE(r);
  const Json j = Json::parse(r->body);
  ASSERT_EQ(j["classes"].size(), 1u);
  EXPECT_EQ(j["classes"][0]["name"], "Milk 2% fat");
  const std::string url = j["classes"][0]["thumbnail"];
  EXPECT_EQ(url, "/api/classes/Milk%202%25%20fat/thumbnail");
  r = cli.Get(url);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
  EXPECT_EQ(r->body.size(), fs::file_size(src));
  r = cli.Get("/api/sketches");  // no examples directory: an empty list, not an error
  ASSERT_TRUE(r);
  EXPECT_EQ(Json::parse(r->body)["examples"], Json::array());
  server.stop();
  t.join();
}

// Landmark sets may hold any image format the loaders read (isImageFileName); a browser may not
// show a BMP or TIFF, so such a thumbnail is sent as JPEG.
TEST(UiClasses, ThumbnailOfAClassWithOnlyABmpIsSentAsJpeg) {
  const std::string dir = test::tempDir("uibmp");
  fs::create_directories(dir + "/set/Boxy");
  const cv::Mat img(40, 30, CV_8UC3, cv::Scalar(10, 200, 30));
  ASSERT_TRUE(cv::imwrite(dir + "/set/Boxy/a.bmp", img));
  ui::ServerOptions so;
  so.port = 0;
  ui::Server server(so);
  ui::addEditorRoutes(server, {dir + "/set", dir + "/sketches", ""});
  const int port = server.bind();
  std::thread t([&] { server.serve(); });
  httplib::Client cli("127.0.0.1", port);
  auto r = cli.Get("/api/classes");
  ASSERT_TRUE(r);
  ASSERT_EQ(Json::parse(r->body)["classes"].size(), 1u);
  r = cli.Get("/api/classes/Boxy/thumbnail");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
  EXPECT_EQ(r->get_header_value("Content-Type"), "image/jpeg");
  const cv::Mat back = cv::imdecode(std::vector<uchar>(r->body.begin(), r->body.end()),
                                    cv::IMREAD_COLOR);
  ASSERT_FALSE(back.empty());
  EXPECT_EQ(back.size(), img.size());
  server.stop();
  t.join();
}

TEST(SafeSketchName, AcceptsPlainNamesOnly) {
  EXPECT_EQ(ui::safeSketchFileName("lab"), "lab.sketch.json");
  EXPECT_EQ(ui::safeSketchFileName("lab.sketch.json"), "lab.sketch.json");
  EXPECT_EQ(ui::safeSketchFileName("Lab_2-b"), "Lab_2-b.sketch.json");
  for (const char* bad : {"", "..", "../x", "a/b", "a\\b", ".x", "a..b", "x y", "/etc/passwd"})
    EXPECT_THROW(ui::safeSketchFileName(bad), InputError) << bad;
}

}  // namespace
