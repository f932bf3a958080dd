// sketchnav replay: offline servo over an image sequence / video / camera URI; per-frame CSV.
// Each frame goes through exactly what the robot runs (nav::LandmarkPerception: objectness
// windows + RootSIFT matching against the target class's photos) and the servo law
// (servo::TurnLaw), without moving anything: for testing perception + servo on recordings.
// --make-fixture renders a sequence with known directions from the simulator.
// --make-sequences / --eval: the perception benchmark of the real task (product photos pasted
// into real backgrounds; apps/perception_bench.h, doc/perception-benchmark.md).
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>

#include "cli.h"
#include "perception_bench.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/image_file.h"
#include "sketchnav/core/log.h"
#include "sketchnav/core/paths.h"
#include "sketchnav/drivers/file_cameras.h"
#include "sketchnav/drivers/register.h"
#include "sketchnav/hw/registry.h"
#include "sketchnav/landmarks/model.h"
#include "sketchnav/landmarks/recognition.h"
#include "sketchnav/nav/perception.h"
#include "sketchnav/run/run.h"
#include "sketchnav/run/scenario.h"
#include "sketchnav/servo/turn_law.h"
#include "sketchnav/sim/register.h"
#include "sketchnav/sim/simulator.h"
#include "sketchnav/sim/world.h"

namespace sketchnav::app {
namespace fs = std::filesystem;
namespace {

/// Frames from a folder of images, a video file or a camera URI, through the camera drivers
/// (drivers::FolderCamera, drivers::VideoCamera, the registry): the same natural order,
/// unreadable-frame skipping and error texts as a run's camera. Names: the file name of a
/// folder's image, the frame index of a video, the camera's source otherwise.
class FrameSource {
 public:
  FrameSource(const std::string& spec, double hfov_deg, const Config& cfg) : hfov_deg_(hfov_deg) {
    std::error_code ec;
    try {
      if (fs::is_directory(spec, ec)) {
        drivers::FolderCameraParams p;
        p.hfov_deg = hfov_deg;
        camera_ = std::make_unique<drivers::FolderCamera>(spec, p);
        kind_ = Kind::Folder;
      } else if (spec.find("://") != std::string::npos) {
        drivers::registerDrivers();
        sim::registerDrivers();
        hw::DeviceContext ctx;
        ctx.config = cfg;
        camera_ = hw::Registry::instance().createCamera(spec, ctx);
        kind_ = Kind::Uri;
      } else if (fs::is_regular_file(spec, ec)) {
        camera_ = std::make_unique<drivers::VideoCamera>(spec, hfov_deg);
        kind_ = Kind::Video;
      } else {
        throw InputError("no such folder, file or URI");
      }
    } catch (const InputError& e) {
      throw InputError("--frames " + spec + ": " + e.what());
    }
  }

  /// Next frame; false at the end (or when the camera fails: its error is logged).
  bool next(cv::Mat& img, std::string& name, hw::Intrinsics& k) {
    hw::Frame f;
    for (;;) {
      const auto st = camera_->grab(f, 2.0);
      if (st == hw::GrabStatus::Ok) break;
      if (st == hw::GrabStatus::Timeout) continue;  // a live camera may still deliver
      if (st == hw::GrabStatus::Error)
        log::warn("replay", "camera failed", {{"error", camera_->stats().last_error}});
      return false;
    }
    img = f.image;
    switch (kind_) {
      case Kind::Folder:
        name = fs::path(f.source).filename().string();
        break;
      case Kind::Video:
        name = std::to_string(f.seq);
        break;
      case Kind::Uri:
        name = f.source.empty() ? std::to_string(f.seq) : f.source;
        k = camera_->intrinsics();
        return true;
    }
    // Per frame: a folder may mix image sizes.
    k = hw::Intrinsics::fromFov(img.cols, img.rows, hfov_deg_ * M_PI / 180.0);
    return true;
  }
  /// Frames skipped as unreadable so far.
  std::uint64_t dropped() const { return camera_->stats().dropped; }

 private:
  enum class Kind { Folder, Video, Uri };
  Kind kind_ = Kind::Folder;
  std::unique_ptr<hw::Camera> camera_;
  double hfov_deg_ = 60.0;
};

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

// One frame through perception and the turn law, as the robot runs them: the CSV row (timed
// over perception), the observation and the best detection's x_t / x_d (NaN when none).
struct FrameResult {
  Row row;
  nav::Observation ob;
  double x_t = NAN, x_d = NAN;
};
FrameResult runFrame(nav::Perception& perception, const servo::TurnLaw& law, const cv::Mat& img,
                     const std::string& name, long i, const hw::Intrinsics& k,
                     const std::string& target) {
  hw::Frame f;
  f.image = img;
  f.seq = static_cast<std::uint64_t>(i);
  f.source = name;
  FrameResult out;
  const auto t0 = std::chrono::steady_clock::now();
  out.ob = perception.observe(f, k, {target});
  Row& r = out.row;
  r.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  r.frame = i;
  r.name = name;
  r.windows = out.ob.timing.windows;
  if (!out.ob.detections.empty()) {
    const auto& d = out.ob.detections.front();
    r.cls = d.class_name;
    r.inliers = d.inliers;
    out.x_t = d.x_t, out.x_d = d.x_d;
    const servo::TurnCommand c = law.compute(d.x_t, d.x_d);
    r.error = c.error;
    r.w = c.w;
    r.turn = servo::toString(c.state);
  }
  return out;
}

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

/// The benchmark's record of one frame (the sidecar, when there is one, gives u/yaw/width).
bench::FrameScore score(const std::string& name, const std::string& expected, const Row& r,
                        const nav::Observation& ob, double x_t, const hw::Intrinsics& k,
                        const std::optional<bench::SequenceTruth>& seq) {
  bench::FrameScore s;
  s.expected = expected;
  s.got = r.turn;
  s.found = r.turn != "None";
  s.u_found = std::isfinite(x_t) ? k.cx + x_t * k.fx : NAN;
  s.ms = r.ms;
  s.full_pass = ob.timing.full_pass;
  s.objectness_ms = ob.timing.objectness_ms, s.features_ms = ob.timing.features_ms;
  s.match_ms = ob.timing.match_ms, s.recognise_ms = ob.timing.recognise_ms;
  s.fovea_ms = ob.timing.fovea_ms;
  if (seq) {
    s.absent_sequence = seq->absent;
    if (auto it = seq->frames.find(name); it != seq->frames.end())
      s.has_truth_json = true, s.truth = it->second;
  }
  return s;
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

/// --data, else $SKETCHNAV_DATA, else ../shared/data beside the source tree's share/ (the
/// project's data convention).
std::string dataDir(const Args& args) {
  std::string d = args.get("data");
  if (!d.empty()) return d;
  const char* env = std::getenv("SKETCHNAV_DATA");
  if (env && *env) return env;
  return (fs::path(resourceDir()).parent_path().parent_path() / "shared" / "data").string();
}

/// The landmark model of --model (the demo set's, trained on first use when none is given), its
/// search indexes built before the first frame (run::buildIndexes): the per-frame times and
/// their mean are perception's, not the index build's.
std::shared_ptr<landmarks::LandmarkModel> replayModel(const Args& args, GlobalOptions& g) {
  auto model = std::make_shared<landmarks::LandmarkModel>(
      run::loadModel(args.get("model"), true, run::runSettingsFrom(g.config).train));
  run::buildIndexes(*model, "replay");
  return model;
}

/// --make-sequences: the benchmark generator (apps/perception_bench.cpp).
int makeBenchSequences(const Args& args, GlobalOptions& g) {
  bench::GeneratorOptions o;
  o.out_dir = args.get("make-sequences");
  o.data_dir = dataDir(args);
  if (!fs::is_directory(o.data_dir))
    throw InputError("--data " + o.data_dir + ": no such folder (give --data or SKETCHNAV_DATA)");
  o.split = bench::parseSplit(args.get("split"));
  o.seed = args.getInt("seed");
  o.present = args.getInt("present");
  o.absent = args.getInt("absent");
  o.frames = args.getInt("seq-frames");
  o.classes = args.getList("classes");
  o.hfov_deg = args.getDouble("hfov");
  if (!(o.hfov_deg > 1 && o.hfov_deg < 179)) throw InputError("--hfov must be in (1, 179) degrees");
  o.servo = servo::turnLawParamsFrom(g.config);
  const auto names = bench::makeSequences(o);
  if (g.json)
    printJson({{"sequences", names}, {"out", o.out_dir}, {"split", bench::toString(o.split)}});
  else
    std::cout << "wrote " << names.size() << " sequences (" << bench::toString(o.split) << ") to "
              << o.out_dir << "\n";
  return 0;
}

/// The photo ceiling of an eval: each target sequence's source photo recognised on its own, at
/// its full resolution, without clutter, perspective or nuisances (landmarks::recognise, the
/// loop's recognition settings). A sequence whose photo is not recognised even so is beyond
/// what any placement in a frame can fix; the figures over the others say how far the loop is
/// from what its model allows. Null when the data folder or a photo is missing.
Json photoCeiling(const landmarks::LandmarkModel& model, const nav::PerceptionParams& pp,
                  const std::string& data_dir, const std::vector<bench::SequenceTruth>& seqs,
                  const std::vector<std::vector<bench::FrameScore>>& scores) {
  std::map<std::string, bool> recognised;  // photo -> its class recognised
  for (const auto& s : seqs) {
    if (s.absent) continue;
    if (s.photo.empty()) return nullptr;
    if (recognised.count(s.photo)) continue;
    cv::Mat img;
    try {
      img = readImageFile((fs::path(data_dir) / s.photo).string(), "photo");
    } catch (const InputError&) {
      return nullptr;
    }
    const auto r = landmarks::recognise(model, img, {}, 1, pp.recognition);
    recognised[s.photo] = !r.empty() && !r[0].rejected && r[0].class_name == s.shown;
  }
  std::vector<bench::FrameScore> frames;
  int photos_ok = 0;
  for (const auto& [photo, ok] : recognised) photos_ok += ok;
  for (size_t i = 0; i < seqs.size(); ++i)
    if (!seqs[i].absent && recognised[seqs[i].photo])
      frames.insert(frames.end(), scores[i].begin(), scores[i].end());
  const Json j = bench::summarise(frames);
  return {{"photos", recognised.size()},
          {"photos_recognised", photos_ok},
          {"scored_frames", j["scored_frames"]},
          {"agreement", j["agreement"]},
          {"found_rate", j["found_rate"]}};
}

/// --eval DIR: every sequence folder below DIR through perception + servo; the aggregate.
int runEval(const Args& args, GlobalOptions& g) {
  const fs::path root = args.get("eval");
  if (!fs::is_directory(root)) throw InputError("--eval " + root.string() + ": no such folder");
  std::vector<fs::path> dirs;
  for (const auto& e : fs::directory_iterator(root))
    if (e.is_directory() && fs::is_regular_file(e.path() / "truth.csv") &&
        fs::is_regular_file(e.path() / "sequence.json"))
      dirs.push_back(e.path());
  std::sort(dirs.begin(), dirs.end());
  if (dirs.empty())
    throw InputError("--eval " + root.string() +
                     ": no sequence folders (truth.csv + sequence.json)");
  const double hfov = args.getDouble("hfov");
  if (!(hfov > 1 && hfov < 179)) throw InputError("--hfov must be in (1, 179) degrees");
  const long max_frames = args.getInt("max-frames");
  // Read every truth file first: a bad one fails before any work.
  std::vector<std::map<std::string, std::string>> truths;
  std::vector<bench::SequenceTruth> seqs;
  for (const auto& d : dirs) {
    truths.push_back(bench::readTruthCsv((d / "truth.csv").string()));
    seqs.push_back(bench::readSequenceJson((d / "sequence.json").string()));
  }
  const auto model = replayModel(args, g);
  const auto& cls = model->classes();
  for (size_t s = 0; s < seqs.size(); ++s)
    if (std::find(cls.begin(), cls.end(), seqs[s].target) == cls.end())
      throw InputError((dirs[s] / "sequence.json").string() + ": target " + seqs[s].target +
                       " is not a class of the model");
  const std::string out = makeOutputDir(args.get("out"));
  const nav::PerceptionParams pp = nav::perceptionParamsFrom(g.config);
  const servo::TurnLawParams tp = servo::turnLawParamsFrom(g.config);
  nav::LandmarkPerception perception(model, pp);
  servo::TurnLaw law(tp);

  std::ofstream csv(out + "/eval.csv");
  csv << "sequence,frame,target,motion,absent,expected,turn,found,u_true,u_found,yaw_deg,"
         "width_px,visible,inliers,ms,full_pass,objectness_ms,features_ms,match_ms,"
         "recognise_ms\n";
  std::vector<bench::FrameScore> all;
  std::vector<std::vector<bench::FrameScore>> seq_scores(dirs.size());
  std::map<std::string, std::vector<bench::FrameScore>> by_motion;
  Json per_seq = Json::array();
  for (size_t s = 0; s < dirs.size(); ++s) {
    FrameSource source(dirs[s].string(), hfov, g.config);
    perception.reset();  // each sequence is another camera: nothing tracks across them
    std::vector<bench::FrameScore>& mine = seq_scores[s];
    cv::Mat img;
    std::string name;
    hw::Intrinsics k;
    long i = 0;
    while ((max_frames <= 0 || i < max_frames) && source.next(img, name, k)) {
      const FrameResult fr = runFrame(perception, law, img, name, i, k, seqs[s].target);
      const Row& r = fr.row;
      const double x_t = fr.x_t;
      ++i;
      const auto it = truths[s].find(name);
      if (it == truths[s].end()) continue;
      const bench::FrameScore sc = score(name, it->second, r, fr.ob, x_t, k, seqs[s]);
      mine.push_back(sc);
      auto opt = [](double v) { return std::isfinite(v) ? std::to_string(v) : std::string(); };
      csv << dirs[s].filename().string() << ',' << name << ',' << seqs[s].target << ','
          << seqs[s].motion << ',' << seqs[s].absent << ','
          << (sc.expected.empty() ? "-" : sc.expected) << ',' << r.turn << ',' << sc.found << ','
          << opt(sc.truth.u) << ',' << opt(sc.u_found) << ',' << opt(sc.truth.yaw_deg) << ','
          << opt(sc.truth.width_px) << ',' << sc.truth.visible << ',' << r.inliers << ',' << r.ms
          << ',' << sc.full_pass << ',' << sc.objectness_ms << ',' << sc.features_ms << ','
          << sc.match_ms << ',' << sc.recognise_ms << '\n';
    }
    const Json sj = bench::summarise(mine);
    std::cerr << dirs[s].filename().string() << " (" << seqs[s].target
              << (seqs[s].absent ? ", shows " + seqs[s].shown : std::string()) << "): agreement "
              << (sj["agreement"].is_number() ? std::to_string(sj["agreement"].get<double>()) : "-")
              << ", found " << sj["found"] << "/" << sj["scored_frames"] << ", false reports "
              << sj["false_reports"] << "/" << sj["absent_frames"] << "\n";
    per_seq.push_back({{"sequence", dirs[s].filename().string()},
                       {"target", seqs[s].target},
                       {"shown", seqs[s].shown},
                       {"motion", seqs[s].motion},
                       {"absent", seqs[s].absent},
                       {"scored_frames", sj["scored_frames"]},
                       {"agreement", sj["agreement"]},
                       {"found_rate", sj["found_rate"]},
                       {"false_reports", sj["false_reports"]},
                       {"absent_frames", sj["absent_frames"]}});
    auto& bm = by_motion[seqs[s].absent ? "absent" : seqs[s].motion];
    bm.insert(bm.end(), mine.begin(), mine.end());
    all.insert(all.end(), mine.begin(), mine.end());
  }
  Json result = bench::summarise(all);
  result["sequences"] = dirs.size();
  result["eval_dir"] = root.string();
  for (const auto& [m, v] : by_motion) {
    const Json j = bench::summarise(v);
    result["by_motion"][m] = {{"frames", j["frames"]},
                              {"scored_frames", j["scored_frames"]},
                              {"agreement", j["agreement"]},
                              {"found_rate", j["found_rate"]},
                              {"false_report_rate", j["false_report_rate"]}};
  }
  result["per_sequence"] = per_seq;
  result["photo_ceiling"] = photoCeiling(*model, pp, dataDir(args), seqs, seq_scores);
  result["csv"] = out + "/eval.csv";
  result["plot"] = out + "/found_rate.png";
  bench::writeBinPlot(result, root.filename().string(), out + "/found_rate.png");
  std::ofstream(out + "/eval.json") << result.dump(2) << "\n";
  if (g.json) {
    printJson(result);
  } else {
    auto pct = [](const Json& v) {
      return v.is_number()
                 ? std::to_string(static_cast<int>(std::lround(100 * v.get<double>()))) + " %"
                 : std::string("-");
    };
    std::cout << dirs.size() << " sequences, " << result["frames"] << " frames ("
              << result["scored_frames"] << " scored): agreement " << pct(result["agreement"])
              << ", target found " << pct(result["found_rate"]) << ", reported on "
              << result["false_reports"] << " / " << result["absent_frames"]
              << " target-absent frames, bearing error median " << result["bearing_error_px_median"]
              << " px, " << result["ms_per_frame_median"] << " ms per frame (median)\n";
    std::cout << "frame budget:";
    for (const auto& b : result["frame_budget"])
      std::printf(" %.0f ms met on %s", b["budget_ms"].get<double>(), pct(b["met_rate"]).c_str());
    std::cout << " of the frames\n";
    const Json& fp = result["full_pass_ms"];
    auto ms = [](const Json& v) {
      return v.is_number() ? std::to_string(static_cast<int>(std::lround(v.get<double>())))
                           : std::string("-");
    };
    std::cout << "full pass (" << fp["frames"] << " frames), median ms: total "
              << ms(fp["total"]["median"]) << " = objectness " << ms(fp["objectness"]["median"])
              << " + features " << ms(fp["features"]["median"]) << " + match "
              << ms(fp["match"]["median"]) << " (recognition " << ms(fp["recognise"]["median"])
              << "); tracked frames (" << fp["tracked_frames"] << ") "
              << ms(fp["tracked_ms_median"]) << "\n";
    for (const char* key : {"by_yaw_deg", "by_width_px"})
      for (const auto& b : result[key])
        std::cout << "  " << key << " " << b["lo"] << "-" << b["hi"] << ": found "
                  << pct(b["found_rate"]) << ", agreement " << pct(b["agreement"]) << " of "
                  << b["frames"] << "\n";
    if (const Json& c = result["photo_ceiling"]; c.is_object())
      std::cout << "  photo ceiling: " << c["photos_recognised"] << " of " << c["photos"]
                << " pasted photos recognised on their own; on their sequences agreement "
                << pct(c["agreement"]) << ", found " << pct(c["found_rate"]) << " of "
                << c["scored_frames"] << " scored frames\n";
    std::cout << "outputs in " << out << "\n";
  }
  return 0;
}

int runReplay(const std::vector<std::string>& argv, GlobalOptions& g) {
  Args args("replay", "offline servo over an image sequence / video / camera URI; per-frame CSV",
            "--frames DIR|VIDEO|URI --target CLASS [--model M] [--truth CSV] [--out DIR]\n"
            "       sketchnav replay --make-fixture DIR [--landmark L1]\n"
            "       sketchnav replay --make-sequences DIR [--split dev|heldout] [--seed S]\n"
            "       sketchnav replay --eval DIR [--model M] [--out DIR]");
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
      .option("distances", "with --make-fixture: distances from the landmark [m]", "1.2,1.6,2.0")
      .option("make-sequences",
              "write benchmark sequences (a product photo pasted as a poster into real "
              "backgrounds, truth.csv + sequence.json each) into DIR "
              "(doc/perception-benchmark.md)")
      .option("split", "with --make-sequences: dev or heldout (photos and backgrounds)", "dev")
      .option("present", "with --make-sequences: sequences with the target", "12")
      .option("absent", "with --make-sequences: target-absent sequences", "4")
      .option("seq-frames", "with --make-sequences: frames per sequence", "20")
      .option("classes", "with --make-sequences: comma-separated target classes (default: all)")
      .option("data",
              "with --make-sequences and --eval: the shared data folder (the eval's photo "
              "ceiling reads the pasted photos from it; default: $SKETCHNAV_DATA or "
              "../shared/data)")
      .option("eval",
              "run every sequence folder (truth.csv + sequence.json) in DIR and report "
              "the aggregate (eval.json, eval.csv, found_rate.png)");
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
  if (!args.get("make-sequences").empty()) return makeBenchSequences(args, g);
  if (!args.get("eval").empty()) return runEval(args, g);
  if (args.get("frames").empty()) throw InputError("sketchnav replay: --frames is required");
  if (args.get("target").empty()) throw InputError("sketchnav replay: --target CLASS is required");
  const std::string target = args.get("target");
  const double hfov = args.getDouble("hfov");
  if (!(hfov > 1 && hfov < 179)) throw InputError("--hfov must be in (1, 179) degrees");
  const long max_frames = args.getInt("max-frames");
  std::map<std::string, std::string> truth;
  std::optional<bench::SequenceTruth> seq_truth;
  if (!args.get("truth").empty()) {
    truth = bench::readTruthCsv(args.get("truth"));
    // The generator's sidecar next to the CSV gives the true centre, yaw and width per frame.
    const fs::path side = fs::path(args.get("truth")).parent_path() / "sequence.json";
    if (fs::is_regular_file(side)) seq_truth = bench::readSequenceJson(side.string());
  }

  const auto model = replayModel(args, g);
  const auto& cls = model->classes();
  if (std::find(cls.begin(), cls.end(), target) == cls.end()) {
    std::string known;
    for (const auto& c : cls) known += (known.empty() ? "" : ", ") + c;
    throw InputError("--target " + target + ": not a class of the model (" + known + ")");
  }
  const nav::PerceptionParams pp = nav::perceptionParamsFrom(g.config);
  const servo::TurnLawParams tp = servo::turnLawParamsFrom(g.config);
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
  std::vector<bench::FrameScore> scores;
  cv::Mat img;
  std::string name;
  hw::Intrinsics k;
  long i = 0;
  while ((max_frames <= 0 || i < max_frames) && source.next(img, name, k)) {
    const FrameResult fr = runFrame(perception, law, img, name, i, k, target);
    const nav::Observation& ob = fr.ob;
    const Row& r = fr.row;
    const double x_t = fr.x_t, x_d = fr.x_d;
    if (!ob.detections.empty()) ++detected;
    std::string expected;
    bool in_truth = true;
    if (auto it = truth.find(name); it != truth.end())
      expected = it->second;
    else if (auto it2 = truth.find(std::to_string(i)); it2 != truth.end())
      expected = it2->second;
    else
      in_truth = false;
    if (in_truth) scores.push_back(score(name, expected, r, ob, x_t, k, seq_truth));
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
                 {"dropped_frames", source.dropped()},  // unreadable, skipped with a warning
                 {"csv", out + "/replay.csv"},
                 {"contact_sheet", out + "/contact.png"}};
  if (!truth.empty()) {
    result["truth_frames"] = truth_n;
    result["agreement"] = truth_n ? static_cast<double>(agree) / truth_n : 0.0;
    result["confusion"] = confusion;
    // The servo's part alone: agreement on the frames where perception found the landmark.
    result["agreement_when_detected"] =
        truth_detected ? static_cast<double>(agree_detected) / truth_detected : 0.0;
    // The benchmark's figures (found rate, false reports, bearing error, bins, time).
    result["benchmark"] = bench::summarise(scores);
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
      const Json b = bench::summarise(scores);
      std::printf(
          "target found on %d / %d scored frames; reported on %d / %d target-absent "
          "frames; bearing error median %s px; %.0f ms per frame (median)\n",
          b["found"].get<int>(), b["scored_frames"].get<int>(), b["false_reports"].get<int>(),
          b["absent_frames"].get<int>(),
          b["bearing_error_px_median"].is_number()
              ? std::to_string(b["bearing_error_px_median"].get<double>()).c_str()
              : "-",
          b["ms_per_frame_median"].get<double>());
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
