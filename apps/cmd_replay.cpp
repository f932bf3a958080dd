// sketchnav replay: offline servo over an image sequence / video / camera URI; per-frame CSV.
// Each frame goes through exactly what the robot runs (nav::LandmarkPerception: objectness
// windows + RootSIFT matching against the target class's photos) and the servo law
// (servo::TurnLaw), without moving anything: for testing perception + servo on recordings.
// --make-fixture renders a sequence with known directions from the simulator.
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>

#include "cli.h"
#include "scenario.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/paths.h"
#include "sketchnav/hw/registry.h"
#include "sketchnav/landmarks/model.h"
#include "sketchnav/nav/perception.h"
#include "sketchnav/servo/turn_law.h"
#include "sketchnav/sim/register.h"
#include "sketchnav/sim/simulator.h"
#include "sketchnav/sim/world.h"

namespace sketchnav::app {
namespace fs = std::filesystem;
namespace {

/// Frames from a folder of images (sorted by name), a video file, or a camera URI.
class FrameSource {
 public:
  FrameSource(const std::string& spec, double hfov_deg, const Config& cfg) {
    hfov_ = hfov_deg * M_PI / 180.0;
    if (fs::is_directory(spec)) {
      for (const auto& e : fs::directory_iterator(spec)) {
        std::string ext = e.path().extension().string();
        std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
        if (ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".pgm" || ext == ".ppm" ||
            ext == ".bmp" || ext == ".tif" || ext == ".tiff")
          files_.push_back(e.path().string());
      }
      std::sort(files_.begin(), files_.end());
      if (files_.empty()) throw InputError("--frames " + spec + ": no images in the folder");
    } else if (spec.find("://") != std::string::npos) {
      hw::registerBuiltinDrivers();
      sim::registerDrivers();
      hw::DeviceContext ctx;
      ctx.config = cfg;
      camera_ = hw::Registry::instance().createCamera(spec, ctx);
    } else if (fs::is_regular_file(spec)) {
      video_.open(spec);
      if (!video_.isOpened()) throw InputError("--frames " + spec + ": cannot open as a video");
    } else {
      throw InputError("--frames " + spec + ": no such folder, file or URI");
    }
  }

  /// Next frame; false at the end.
  bool next(cv::Mat& img, std::string& name, hw::Intrinsics& k) {
    if (!files_.empty()) {
      if (index_ >= files_.size()) return false;
      name = fs::path(files_[index_]).filename().string();
      img = cv::imread(files_[index_++], cv::IMREAD_COLOR);  // grey files come as 3 channels
      if (img.empty()) throw InputError(name + ": cannot decode image");
    } else if (camera_) {
      hw::Frame f;
      for (;;) {
        const auto st = camera_->grab(f, 2.0);
        if (st == hw::GrabStatus::Ok) break;
        if (st != hw::GrabStatus::Timeout) return false;
      }
      img = f.image;
      name = f.source.empty() ? std::to_string(f.seq) : f.source;
      k = camera_->intrinsics();
      return true;
    } else {
      if (!video_.read(img) || img.empty()) return false;
      name = std::to_string(video_index_++);
    }
    k = hw::Intrinsics::fromFov(img.cols, img.rows, hfov_);
    return true;
  }

 private:
  std::vector<std::string> files_;
  size_t index_ = 0;
  long video_index_ = 0;
  cv::VideoCapture video_;
  std::unique_ptr<hw::Camera> camera_;
  double hfov_ = 1.0;
};

std::string normaliseTurn(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), ::tolower);
  if (s == "l" || s == "left") return "Left";
  if (s == "s" || s == "straight") return "Straight";
  if (s == "r" || s == "right") return "Right";
  if (s == "none" || s == "-") return "None";
  return "";
}

/// Truth CSV: "frame,expected" (frame = index from 0 or the file name; expected
/// Left / Straight / Right / None). A header line is allowed.
std::map<std::string, std::string> readTruth(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError("--truth " + path + ": cannot read");
  std::map<std::string, std::string> t;
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    const auto c = line.find(',');
    if (c == std::string::npos)
      throw InputError(path + ":" + std::to_string(n) + ": expected 'frame,expected'");
    const std::string f = line.substr(0, c), e = line.substr(c + 1);
    const std::string turn = normaliseTurn(e);
    if (turn.empty()) {
      if (n == 1) continue;  // header
      throw InputError(path + ":" + std::to_string(n) +
                       ": expected must be Left, Straight, Right or None, got '" + e + "'");
    }
    t[f] = turn;
  }
  if (t.empty()) throw InputError("--truth " + path + ": no rows");
  return t;
}

struct Row {
  long frame = 0;
  std::string name;
  int windows = 0;
  std::string cls;
  int inliers = 0;
  double error = NAN, w = 0;
  std::string turn = "None";
  double ms = 0;
};

cv::Mat thumbnail(const cv::Mat& img, const nav::Observation& ob, const Row& r,
                  const std::string& truth) {
  cv::Mat a = img.clone();
  for (const auto& d : ob.detections) cv::rectangle(a, d.window, {0, 200, 0}, 3);
  cv::Mat t;
  cv::resize(a, t, {200, static_cast<int>(200.0 * img.rows / img.cols)});
  const cv::Scalar col = r.turn == "None" ? cv::Scalar(160, 160, 160) : cv::Scalar(0, 140, 255);
  cv::rectangle(t, {0, 0}, {t.cols, 16}, {0, 0, 0}, cv::FILLED);
  char buf[96];
  std::snprintf(buf, sizeof buf, "#%ld %s %d inl", r.frame, r.turn.c_str(), r.inliers);
  cv::putText(t, buf, {3, 12}, cv::FONT_HERSHEY_SIMPLEX, 0.38, col, 1, cv::LINE_AA);
  if (!truth.empty()) {
    const bool ok = truth == r.turn;
    cv::rectangle(t, {0, t.rows - 16}, {t.cols, t.rows},
                  ok ? cv::Scalar(0, 110, 0) : cv::Scalar(0, 0, 170), cv::FILLED);
    cv::putText(t, "truth " + truth, {3, t.rows - 4}, cv::FONT_HERSHEY_SIMPLEX, 0.38,
                {255, 255, 255}, 1, cv::LINE_AA);
  }
  // An arrow for the command: the way the robot would turn.
  const cv::Point c(t.cols / 2, t.rows / 2);
  if (r.turn == "Left") cv::arrowedLine(t, c, c + cv::Point(-30, 0), col, 3);
  if (r.turn == "Right") cv::arrowedLine(t, c, c + cv::Point(30, 0), col, 3);
  if (r.turn == "Straight") cv::arrowedLine(t, c, c + cv::Point(0, -30), col, 3);
  return t;
}

/// Renders the lab world's landmark `id` from poses where it appears at known horizontal
/// offsets and writes the frames + truth.csv (expected direction per frame) to `dir`.
int makeFixture(const std::string& dir, const std::string& id, int seed,
                const std::vector<double>& distances) {
  const sim::World world = sim::loadWorldByName("lab");
  const sim::Landmark* lm = world.findLandmark(id);
  if (!lm) throw InputError("--landmark " + id + ": not in the lab world");
  sim::SimParams sp;
  sim::Simulator simr(world, sp, static_cast<std::uint64_t>(seed));
  fs::create_directories(dir);
  std::ofstream truth(dir + "/truth.csv");
  truth << "frame,expected\n";
  const Eigen::Vector2d p(lm->position.x(), lm->position.y());
  const Eigen::Vector2d n(std::cos(lm->yaw), std::sin(lm->yaw)), side(-n.y(), n.x());
  const double cam_x = world.camera.x;
  int k = 0;
  // Offsets of +-0.12 and +-0.25 (normalised; 7 and 14 degrees) are unambiguous turns, 0 is
  // straight ahead. A lateral shift of up to 0.3 m makes some views oblique.
  for (double d : distances)
    for (double x_c : {-0.25, -0.12, 0.0, 0.12, 0.25}) {
      const Eigen::Vector2d base = p + d * n + 0.3 * (k % 3 - 1) * side;
      double th = std::atan2(p.y() - base.y(), p.x() - base.x());
      for (int it = 0; it < 5; ++it) {  // the camera sits ahead of the wheel axis
        const Eigen::Vector2d c = base + cam_x * Eigen::Vector2d(std::cos(th), std::sin(th));
        // x (right) = -tan(angle CCW from the optical axis), so the axis for x_c is:
        th = std::atan2(p.y() - c.y(), p.x() - c.x()) + std::atan(x_c);
      }
      const cv::Mat img = simr.renderView({base.x(), base.y(), th}, 0.0, true);
      char name[32];
      std::snprintf(name, sizeof name, "frame%03d.png", k);
      cv::imwrite(dir + "/" + name, img);
      truth << name << "," << (x_c < -0.05 ? "Left" : x_c > 0.05 ? "Right" : "Straight") << "\n";
      ++k;
    }
  std::cerr << "wrote " << k << " frames of landmark " << id << " (" << lm->class_name
            << ") and truth.csv to " << dir << "\n";
  std::cout << lm->class_name << "\n";
  return 0;
}

int runReplay(const std::vector<std::string>& argv, GlobalOptions& g) {
  Args args("replay", "offline servo over an image sequence / video / camera URI; per-frame CSV",
            "--frames DIR|VIDEO|URI --target CLASS [--model M] [--truth CSV] [--out DIR]\n"
            "       sketchnav replay --make-fixture DIR [--landmark L1]");
  args.option("frames",
              "a folder of images (sorted by name), a video file, or a camera URI "
              "(folder://, video://, sim://...)")
      .option("model", "landmark model (.slm); default: the demo set's cached model")
      .option("target", "the landmark class to servo on")
      .option("truth",
              "CSV 'frame,expected' (frame index or file name; Left/Straight/Right/None): "
              "prints the agreement")
      .option("out", "output folder (default: runs/<UTC timestamp>)")
      .option("hfov", "horizontal field of view of the frames [deg] (folders and videos)", "60")
      .option("max-frames", "stop after N frames (0 = all)", "0")
      .option("make-fixture", "render a sequence with truth.csv from the simulator into DIR")
      .option("landmark", "with --make-fixture: the lab world's landmark id", "L1")
      .option("seed", "with --make-fixture: image noise seed", "1")
      .option("distances", "with --make-fixture: distances from the landmark [m]", "1.2,1.6,2.0");
  if (!args.parse(argv)) return 0;
  if (!args.get("make-fixture").empty()) {
    std::vector<double> ds;
    for (const auto& d : args.getList("distances")) {
      try {
        ds.push_back(std::stod(d));
      } catch (...) {
        throw InputError("--distances: '" + d + "' is not a number");
      }
      if (!(ds.back() > 0.3 && ds.back() < 20))
        throw InputError("--distances: each in (0.3, 20) m");
    }
    return makeFixture(args.get("make-fixture"), args.get("landmark"), args.getInt("seed"), ds);
  }
  if (args.get("frames").empty()) throw InputError("sketchnav replay: --frames is required");
  if (args.get("target").empty()) throw InputError("sketchnav replay: --target CLASS is required");
  const std::string target = args.get("target");
  const double hfov = args.getDouble("hfov");
  if (!(hfov > 1 && hfov < 179)) throw InputError("--hfov must be in (1, 179) degrees");
  const long max_frames = args.getInt("max-frames");
  std::map<std::string, std::string> truth;
  if (!args.get("truth").empty()) truth = readTruth(args.get("truth"));

  auto model = std::make_shared<landmarks::LandmarkModel>(
      landmarks::LandmarkModel::load(ensureModel(args.get("model"), true)));
  const auto& cls = model->classes();
  if (std::find(cls.begin(), cls.end(), target) == cls.end()) {
    std::string known;
    for (const auto& c : cls) known += (known.empty() ? "" : ", ") + c;
    throw InputError("--target " + target + ": not a class of the model (" + known + ")");
  }
  nav::PerceptionParams pp;
  applyConfig(pp, g.config, "nav.perception");
  applyConfig(pp.recognition, g.config, "landmarks.recognition");
  pp.objectness = landmarks::objectnessParamsFrom(g.config);
  pp.validate();
  servo::TurnLawParams tp;
  applyConfig(tp, g.config, "servo");
  tp.validate();
  // A camera URI's driver settings (sim.*, camera.*) are applied when it is opened.
  g.config.requireAllUsedExcept({"sim.", "camera."});
  FrameSource source(args.get("frames"), hfov, g.config);
  g.config.requireAllUsed();
  const std::string out = makeOutputDir(args.get("out"));
  nav::LandmarkPerception perception(model, pp);
  servo::TurnLaw law(tp);

  std::ofstream csv(out + "/replay.csv");
  csv << "frame,file,windows,class,inliers,x_t,x_d,error,w,turn,expected,ms\n";
  std::vector<cv::Mat> thumbs;
  int agree = 0, truth_n = 0, detected = 0, truth_detected = 0, agree_detected = 0;
  std::map<std::string, std::map<std::string, int>> confusion;  // expected -> got -> n
  cv::Mat img;
  std::string name;
  hw::Intrinsics k;
  long i = 0;
  while ((max_frames <= 0 || i < max_frames) && source.next(img, name, k)) {
    hw::Frame f;
    f.image = img;
    f.seq = static_cast<std::uint64_t>(i);
    f.source = name;
    const auto t0 = std::chrono::steady_clock::now();
    const nav::Observation ob = perception.observe(f, k, {target});
    Row r;
    r.frame = i;
    r.name = name;
    r.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    r.windows = ob.timing.windows;
    double x_t = NAN, x_d = NAN;
    if (!ob.detections.empty()) {
      const auto& d = ob.detections.front();
      r.cls = d.class_name;
      r.inliers = d.inliers;
      x_t = d.x_t, x_d = d.x_d;
      const servo::TurnCommand c = law.compute(d.x_t, d.x_d);
      r.error = c.error;
      r.w = c.w;
      r.turn = servo::toString(c.state);
      ++detected;
    }
    std::string expected;
    if (auto it = truth.find(name); it != truth.end())
      expected = it->second;
    else if (auto it2 = truth.find(std::to_string(i)); it2 != truth.end())
      expected = it2->second;
    if (!expected.empty()) {
      ++truth_n;
      agree += expected == r.turn;
      if (r.turn != "None") ++truth_detected, agree_detected += expected == r.turn;
      ++confusion[expected][r.turn];
    }
    auto opt = [](double v) { return std::isfinite(v) ? std::to_string(v) : std::string(); };
    csv << i << ',' << name << ',' << r.windows << ',' << r.cls << ',' << r.inliers << ','
        << opt(x_t) << ',' << opt(x_d) << ',' << opt(r.error) << ',' << r.w << ',' << r.turn << ','
        << expected << ',' << r.ms << '\n';
    thumbs.push_back(thumbnail(img, ob, r, expected));
    std::cerr << "frame " << i << " " << name << ": " << r.turn << " (" << r.inliers << " inliers, "
              << static_cast<int>(r.ms) << " ms)" << (expected.empty() ? "" : " truth " + expected)
              << "\n";
    ++i;
  }
  if (i == 0) throw InputError("--frames " + args.get("frames") + ": no frames");
  {  // Contact sheet: up to 48 frames evenly spread, 6 per row.
    const size_t n = std::min<size_t>(48, thumbs.size());
    const int cols = 6, rows = static_cast<int>((n + cols - 1) / cols);
    const cv::Size ts = thumbs.front().size();
    cv::Mat sheet(rows * ts.height, cols * ts.width, CV_8UC3, cv::Scalar(255, 255, 255));
    for (size_t j = 0; j < n; ++j) {
      const size_t src = n == thumbs.size() ? j : j * (thumbs.size() - 1) / (n - 1);
      cv::Mat t = thumbs[src];
      if (t.size() != ts) cv::resize(t, t, ts);
      t.copyTo(sheet(cv::Rect(static_cast<int>(j % cols) * ts.width,
                              static_cast<int>(j / cols) * ts.height, ts.width, ts.height)));
    }
    cv::imwrite(out + "/contact.png", sheet);
  }
  Json result = {{"frames", i},
                 {"detected", detected},
                 {"detection_rate", static_cast<double>(detected) / i},
                 {"target", target},
                 {"csv", out + "/replay.csv"},
                 {"contact_sheet", out + "/contact.png"}};
  if (!truth.empty()) {
    result["truth_frames"] = truth_n;
    result["agreement"] = truth_n ? static_cast<double>(agree) / truth_n : 0.0;
    result["confusion"] = confusion;
    // The servo's part alone: agreement on the frames where perception found the landmark.
    result["agreement_when_detected"] =
        truth_detected ? static_cast<double>(agree_detected) / truth_detected : 0.0;
  }
  std::ofstream(out + "/replay.json") << result.dump(2) << "\n";
  if (g.json) {
    printJson(result);
  } else {
    std::cout << i << " frames, landmark found in " << detected << "\n";
    if (!truth.empty()) {
      std::printf(
          "agreement with truth: %d / %d = %.1f %% (%d / %d = %.1f %% of the frames "
          "where the landmark was found)\n",
          agree, truth_n, truth_n ? 100.0 * agree / truth_n : 0.0, agree_detected, truth_detected,
          truth_detected ? 100.0 * agree_detected / truth_detected : 0.0);
      for (const auto& [e, m] : confusion) {
        std::cout << "  expected " << e << ":";
        for (const auto& [gg, cnt] : m) std::cout << " " << gg << " " << cnt;
        std::cout << "\n";
      }
    }
    std::cout << "outputs in " << out << "\n";
  }
  return 0;
}

const CommandRegistration reg(
    "replay", "offline servo over an image sequence / video / rawlog; per-frame CSV", runReplay);
}  // namespace
}  // namespace sketchnav::app
