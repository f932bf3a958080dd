// sketchnav recognise: classify images with a landmark model; --eval DIR prints accuracy.
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>

#include "cli.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/image_file.h"
#include "sketchnav/core/log.h"
#include "sketchnav/landmarks/landmark_set.h"
#include "sketchnav/landmarks/objectness.h"
#include "sketchnav/landmarks/recognition.h"
#include "sketchnav/run/plot.h"

namespace sketchnav::app {
using run::ConfusionSpec;
using run::drawConfusionMatrix;
namespace {

namespace lm = landmarks;

// The answer "none of these" in the evaluation's per-class counts (and its plot's last column).
constexpr const char* kNoAnswer = "(none)";

double threadCpuMs() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

struct Runner {
  const lm::LandmarkModel& model;
  lm::RecognitionParams params;
  int windows = 0;  // objectness windows per image; 0 = whole image
  std::unique_ptr<lm::Objectness> objectness;
  cv::Size frame_size;      // non-empty: letterbox every image into a frame of this size
  bool with_match = false;  // also run match() for the recognised class (servo cost)
  lm::MatchParams match_params;
  lm::FeatureParams frame_features;  // SIFT settings for the images (model's frame_* by default)
  std::ofstream* details = nullptr;  // --details: one JSON line per evaluated image
  // CPU ms per stage, summed over images: features (SIFT, RootSIFT, colours, words), objectness,
  // recognise, match.
  mutable double stage_ms[4] = {0, 0, 0, 0};
  // CPU ms of OpenCV's SIFT alone (detect + describe, the same settings), timed in a separate
  // pass outside run(): the floor of `features` that none of this project's code sets, and so a
  // measure of the machine's speed beside the pipeline's figures of the same run.
  mutable double sift_ms = 0;

  void timeSiftAlone(const cv::Mat& img) const {
    std::vector<cv::KeyPoint> kps;
    cv::Mat u8;
    const double c0 = threadCpuMs();
    lm::detectSift(img, frame_features, kps, u8);
    sift_ms += threadCpuMs() - c0;
  }

  cv::Mat prepare(const cv::Mat& img) const {
    if (frame_size.area() == 0) return img;
    // Letterbox: the photo scaled to fit, centred on a grey frame, as a camera frame would be.
    const double s = std::min(static_cast<double>(frame_size.width) / img.cols,
                              static_cast<double>(frame_size.height) / img.rows);
    cv::Mat scaled, frame(frame_size, CV_8UC3, cv::Scalar(127, 127, 127));
    // At least 1 px on each side: a 1 x 4000 photo scaled by 0.12 would round to 0 px wide,
    // which cv::resize refuses with an assertion.
    const cv::Size to(
        std::clamp(static_cast<int>(std::lround(img.cols * s)), 1, frame_size.width),
        std::clamp(static_cast<int>(std::lround(img.rows * s)), 1, frame_size.height));
    cv::resize(img, scaled, to, 0, 0, s < 1 ? cv::INTER_AREA : cv::INTER_LINEAR);
    scaled.copyTo(frame(cv::Rect((frame_size.width - scaled.cols) / 2,
                                 (frame_size.height - scaled.rows) / 2, scaled.cols, scaled.rows)));
    return frame;
  }

  // Recognition of one image, timed (features + windows + BoW + verification; not decoding):
  // wall-clock ms, and this thread's CPU ms (robust to other processes sharing the cores).
  // match_out: the answer's match() (as the servo would get it; unmatched when rejected).
  std::vector<lm::Recognition> run(const cv::Mat& img, int top_k, double& ms,
                                   double* cpu_ms = nullptr,
                                   lm::MatchResult* match_out = nullptr) const {
    const double c0 = threadCpuMs();
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<cv::Rect> boxes;
    if (objectness)
      for (const auto& w : objectness->propose(img, windows)) boxes.push_back(w.box);
    const double c1 = threadCpuMs();
    const lm::FrameFeatures frame = lm::computeFrameFeatures(model, img, frame_features);
    const double c2 = threadCpuMs();
    auto out = lm::recognise(model, frame, boxes, top_k, params);
    const double c3 = threadCpuMs();
    if ((with_match || match_out) && !out.empty() && !out.front().rejected) {
      auto m = lm::match(model, frame, out.front().window, out.front().class_name, match_params);
      if (match_out) *match_out = std::move(m);
    }
    const double c4 = threadCpuMs();
    stage_ms[0] += c2 - c1;
    stage_ms[1] += c1 - c0;
    stage_ms[2] += c3 - c2;
    stage_ms[3] += c4 - c3;
    ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    if (cpu_ms) *cpu_ms = threadCpuMs() - c0;
    return out;
  }
};

Json modeJson(const Runner& r) {
  return {{"descriptor", r.model.params().features.root_sift ? "RootSIFT" : "SIFT"},
          {"words", r.model.vocabulary().size()},
          {"verify", r.params.verify},
          {"windows", r.windows == 0 ? Json("whole image") : Json(r.windows)},
          {"frame", r.frame_size.area() ? Json(std::to_string(r.frame_size.width) + "x" +
                                               std::to_string(r.frame_size.height))
                                        : Json("as is")},
          {"match", r.with_match},
          {"frame_features", paramsToJson(r.frame_features)},
          {"match_params", paramsToJson(r.match_params)},
          {"params", paramsToJson(r.params)}};
}

// One image with what recognition made of it: the answer's database photo outlined where its
// homography puts it, the inlier keypoints, the window searched, and the candidates listed.
cv::Mat annotate(const cv::Mat& img, const std::vector<lm::Recognition>& res,
                 const lm::MatchResult& m) {
  cv::Mat bgr = img;
  if (img.channels() == 1) cv::cvtColor(img, bgr, cv::COLOR_GRAY2BGR);
  // Small images are enlarged to 640 px wide so the candidate lines fit on them; never drawn
  // on in place (the caller's image).
  const double s = std::max(1.0, 640.0 / std::max(1, bgr.cols));
  cv::Mat vis;
  if (s > 1)
    cv::resize(bgr, vis, cv::Size(), s, s, cv::INTER_LINEAR);
  else
    vis = bgr.clone();
  const float sf = static_cast<float>(s);
  const bool rejected = res.empty() || res.front().rejected;
  const cv::Scalar green(40, 200, 40), orange(0, 140, 255), white(255, 255, 255);
  if (!res.empty() && res.front().window.area() > 0) {
    const cv::Rect2f w(res.front().window);
    cv::rectangle(vis, cv::Rect2f(w.x * sf, w.y * sf, w.width * sf, w.height * sf),
                  cv::Scalar(200, 200, 0), 1);
  }
  if (m.matched && !m.H.empty()) {
    const float w = static_cast<float>(m.database_size.width),
                h = static_cast<float>(m.database_size.height);
    std::vector<cv::Point2f> corners{{0, 0}, {w, 0}, {w, h}, {0, h}}, out;
    cv::perspectiveTransform(corners, out, m.H);
    std::vector<cv::Point> poly;
    for (const auto& p : out) poly.emplace_back(p * sf);
    cv::polylines(vis, poly, true, green, 2, cv::LINE_AA);
    for (const auto& p : m.x_t) cv::circle(vis, p * sf, 3, orange, 1, cv::LINE_AA);
  }
  // Candidates, best first, on a dark band so they read on any image.
  const int font = cv::FONT_HERSHEY_SIMPLEX;
  const double fs = 0.45;
  std::vector<std::string> lines;
  lines.push_back(rejected ? "none of these" : res.front().class_name);
  char b[160];
  for (size_t i = 0; i < res.size() && i < 3; ++i) {
    const auto& r = res[i];
    std::snprintf(b, sizeof b, "%zu. %s  inliers %d  votes %d  colour p %.2f%s", i + 1,
                  r.class_name.c_str(), r.inliers, r.votes, r.colour_probability,
                  r.rejected ? "" : (r.colour_rescued ? "  (colour rescued)" : "  (verified)"));
    lines.push_back(b);
  }
  const int line_h = 18;
  const cv::Rect band(0, 0, vis.cols,
                      std::min(vis.rows, 8 + line_h * static_cast<int>(lines.size())));
  cv::Mat roi = vis(band);
  cv::addWeighted(roi, 0.35, cv::Mat(roi.size(), roi.type(), cv::Scalar(0, 0, 0)), 0.65, 0, roi);
  for (size_t i = 0; i < lines.size(); ++i)
    cv::putText(vis, lines[i], {6, 16 + line_h * static_cast<int>(i)}, font, i == 0 ? 0.55 : fs,
                i == 0 ? (rejected ? orange : green) : white, 1, cv::LINE_AA);
  return vis;
}

// The evaluation's confusion matrix as a picture: the eval folder's classes as rows (those the
// model does not know last), the answers as columns in the same order, then any other class
// answered, then "(none)".
void writeConfusionPlot(const std::string& path, const std::string& dir, const Json& per_class,
                        const lm::LandmarkModel& model) {
  ConfusionSpec spec;
  std::vector<std::string> names;
  for (bool known : {true, false})
    for (const auto& [name, pc] : per_class.items())
      if (pc["known"].get<bool>() == known) names.push_back(name);
  for (const auto& n : names)
    if (model.classId(n) >= 0) spec.cols.push_back(n);
  std::vector<std::string> others;
  for (const auto& [name, pc] : per_class.items())
    for (const auto& [pred, k] : pc["predicted"].items())
      if (pred != kNoAnswer &&
          std::find(spec.cols.begin(), spec.cols.end(), pred) == spec.cols.end() &&
          std::find(others.begin(), others.end(), pred) == others.end())
        others.push_back(pred);
  std::sort(others.begin(), others.end());
  spec.cols.insert(spec.cols.end(), others.begin(), others.end());
  spec.cols.push_back(kNoAnswer);
  char note[64];
  for (const auto& n : names) {
    const Json& pc = per_class[n];
    const bool known = pc["known"].get<bool>();
    spec.rows.push_back(known ? n : n + " (not in model)");
    std::vector<int> row(spec.cols.size(), 0);
    for (const auto& [pred, k] : pc["predicted"].items()) {
      const auto it = std::find(spec.cols.begin(), spec.cols.end(), pred);
      if (it != spec.cols.end()) row[it - spec.cols.begin()] += k.get<int>();
    }
    spec.counts.push_back(row);
    const int images = pc["images"].get<int>();
    if (known)
      std::snprintf(note, sizeof note, "top-1 %.2f of %d", pc["top1"].get<double>(), images);
    else
      std::snprintf(note, sizeof note, "rejected %d of %d", pc["rejected"].get<int>(), images);
    spec.row_notes.push_back(note);
  }
  spec.title = "sketchnav recognise --eval " + dir;
  if (!cv::imwrite(path, drawConfusionMatrix(spec), {cv::IMWRITE_PNG_COMPRESSION, 9}))
    throw RuntimeError("sketchnav recognise: cannot write --plot file '" + path + "'");
}

int evaluate(const Runner& runner, const std::string& dir, double index_ms, GlobalOptions& g,
             const std::string& plot_path) {
  const lm::LandmarkSet set = lm::scanLandmarkSet(dir);
  int n_known = 0, n_unknown = 0, top1 = 0, top1_any = 0, top3 = 0, false_rej = 0, unknown_rej = 0,
      failed = 0;
  double ms_sum = 0, cpu_sum = 0;
  std::vector<double> times;
  Json per_class = Json::object();
  size_t total = 0, done = 0;
  for (const auto& c : set.classes) total += c.photos.size();
  for (const auto& c : set.classes) {
    const bool known = runner.model.classId(c.name) >= 0;
    Json pc = {{"images", 0}, {"top1", 0.0}, {"rejected", 0}, {"predicted", Json::object()}};
    int pc_ok = 0, pc_n = 0;
    for (const auto& path : c.photos) {
      ++done;
      if (!(g.json && !g.verbose))
        std::cerr << "\rrecognise: " << done << "/" << total << std::flush;
      cv::Mat img;
      try {
        img = readImageFile(path, "image");
      } catch (const InputError& e) {
        log::warn("recognise", "skipping unreadable image", {{"file", path}, {"error", e.what()}});
        ++failed;
        continue;
      }
      img = runner.prepare(img);
      double ms = 0, cpu = 0;
      const auto res = runner.run(img, runner.details ? 8 : 3, ms, &cpu);
      runner.timeSiftAlone(img);
      if (runner.details) {
        Json cands = Json::array();
        for (const auto& r : res)
          cands.push_back({{"class", r.class_name},
                           {"inliers", r.inliers},
                           {"verified", r.verified},
                           {"vote_inliers", r.vote_inliers},
                           {"votes", r.votes},
                           {"vote_share", r.vote_share},
                           {"bow_probability", r.bow_probability},
                           {"colour_probability", r.colour_probability},
                           {"colour_rescued", r.colour_rescued},
                           {"appearance", r.appearance},
                           {"evidence", r.evidence},
                           {"rejected", r.rejected}});
        *runner.details << Json{{"image", path},
                                {"class", c.name},
                                {"known", known},
                                {"cpu_ms", cpu},
                                {"candidates", cands}}
                               .dump()
                        << "\n";
      }
      ms_sum += ms;
      cpu_sum += cpu;
      times.push_back(ms);
      const bool rejected = res.empty() || res.front().rejected;
      const std::string pred = rejected ? kNoAnswer : res.front().class_name;
      ++pc_n;
      pc["predicted"][pred] = pc["predicted"].value(pred, 0) + 1;
      if (rejected) pc["rejected"] = pc["rejected"].get<int>() + 1;
      if (!known) {
        ++n_unknown;
        unknown_rej += rejected ? 1 : 0;
        continue;
      }
      ++n_known;
      if (rejected) ++false_rej;
      if (!rejected && pred == c.name) ++top1, ++pc_ok;
      if (!res.empty() && res.front().class_name == c.name) ++top1_any;
      for (size_t i = 0; i < res.size() && i < 3; ++i)
        if (res[i].class_name == c.name) {
          ++top3;
          break;
        }
    }
    pc["images"] = pc_n;
    pc["known"] = known;
    pc["top1"] = pc_n ? static_cast<double>(pc_ok) / pc_n : 0.0;
    per_class[c.name] = pc;
  }
  if (!(g.json && !g.verbose)) std::cerr << "\n";
  const int n = n_known + n_unknown;
  if (n == 0) throw InputError(dir + ": no readable images to evaluate");
  std::sort(times.begin(), times.end());
  auto frac = [](int a, int b) { return b ? static_cast<double>(a) / b : 0.0; };
  Json j = {{"images", n},
            {"classes", runner.model.classes().size()},
            {"top1", frac(top1, n_known)},
            {"top3", frac(top3, n_known)},
            {"top1_ignoring_rejection", frac(top1_any, n_known)},
            {"rejected", n_unknown ? Json(frac(unknown_rej, n_unknown)) : Json(nullptr)},
            {"false_rejected", frac(false_rej, n_known)},
            {"known_images", n_known},
            {"unknown_images", n_unknown},
            {"unreadable", failed},
            {"ms_mean", ms_sum / n},
            {"cpu_ms_mean", cpu_sum / n},
            {"index_build_ms", index_ms},
            {"stage_cpu_ms_mean",
             {{"features", runner.stage_ms[0] / n},
              {"objectness", runner.stage_ms[1] / n},
              {"recognise", runner.stage_ms[2] / n},
              {"match", runner.stage_ms[3] / n}}},
            {"sift_alone_cpu_ms_mean", runner.sift_ms / n},
            {"ms_p95", times[std::min(times.size() - 1, times.size() * 95 / 100)]},
            {"mode", modeJson(runner)},
            {"per_class", per_class}};
  if (!plot_path.empty()) writeConfusionPlot(plot_path, dir, per_class, runner.model);
  if (g.json) {
    printJson(j);
    return 0;
  }
  std::printf("%-40s %6s %6s %8s  %s\n", "class", "images", "top1", "rejected", "predicted as");
  for (const auto& [name, pc] : per_class.items()) {
    std::string conf;
    for (const auto& [p, k] : pc["predicted"].items())
      if (p != name) conf += p + "×" + std::to_string(k.get<int>()) + " ";
    std::printf("%-40s %6d %6.2f %8d  %s%s\n", name.c_str(), pc["images"].get<int>(),
                pc["top1"].get<double>(), pc["rejected"].get<int>(), conf.c_str(),
                pc["known"].get<bool>() ? "" : "(not in model)");
  }
  std::printf("\nimages %d (known %d, unknown %d), classes in model %zu\n", n, n_known, n_unknown,
              runner.model.classes().size());
  std::printf("top-1 %.3f   top-3 %.3f   false rejections %.3f\n", frac(top1, n_known),
              frac(top3, n_known), frac(false_rej, n_known));
  if (n_unknown) std::printf("rejected unknown-class images %.3f\n", frac(unknown_rej, n_unknown));
  std::printf(
      "ms per image: mean %.1f, p95 %.1f (CPU of this thread: mean %.1f; OpenCV's SIFT "
      "alone on the same images: %.1f)\n",
      ms_sum / n, j["ms_p95"].get<double>(), cpu_sum / n, runner.sift_ms / n);
  return 0;
}

int runRecognise(const std::vector<std::string>& argv, GlobalOptions& g) {
  Args args("recognise", "classify images with a landmark model; --eval DIR prints accuracy",
            "--model MODEL IMAGE... | --model MODEL --eval DIR");
  args.positionals("IMAGE", "images to classify", 0, -1)
      .option("model", "landmark model (.slm) from `sketchnav train`")
      .option("eval", "folder of class folders (same layout as training): print accuracy")
      .option("top-k", "candidates printed per image", "3")
      .option("windows", "objectness windows per image (0 = the whole image)", "0")
      .option("details", "with --eval: write one JSON line per image (candidates and evidence)")
      .option("plot", "with --eval: write the confusion matrix as a PNG (rows: true class)")
      .option("annotate", "with IMAGE...: write each image with its answer drawn into this folder")
      .option("frame", "letterbox each image into a WxH camera frame first, e.g. 640x480")
      .flag("match", "also match the recognised class (the servo's per-frame cost) in the timing")
      .flag("no-verify", "BoW + SVM only, no geometric verification (for comparisons)");
  if (!args.parse(argv)) return 0;
  if (args.get("model").empty()) throw InputError("sketchnav recognise: --model is required");
  if (args.get("eval").empty() && args.positional().empty())
    throw InputError("sketchnav recognise: give IMAGE... or --eval DIR");
  const int top_k = args.getInt("top-k");
  if (top_k < 1) throw InputError("sketchnav recognise: --top-k must be >= 1");
  const lm::LandmarkModel model = lm::LandmarkModel::load(args.get("model"));
  // Search indexes are built up front so per-image times are steady-state frame times.
  const auto tb = std::chrono::steady_clock::now();
  model.buildIndexes();
  const double index_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - tb).count();
  Runner runner{model, {}, args.getInt("windows"), nullptr, {}, false, {}, {}, nullptr};
  // Frame SIFT settings: the model's frame_* limits, overridable with landmarks.frame.* (e.g.
  // bench/recognition/fast.json) without retraining.
  runner.frame_features = model.params().frameFeatures();
  applyConfig(runner.frame_features, g.config, "landmarks.frame");
  applyConfig(runner.params, g.config, "landmarks.recognition");
  if (args.flagSet("no-verify")) runner.params.verify = false;
  if (runner.windows < 0) throw InputError("sketchnav recognise: --windows must be >= 0");
  runner.with_match = args.flagSet("match");
  applyConfig(runner.match_params, g.config, "landmarks.match");
  if (!args.get("frame").empty()) {
    int w = 0, h = 0;
    char x = 0;
    if (std::sscanf(args.get("frame").c_str(), "%d%c%d", &w, &x, &h) != 3 || x != 'x' || w < 32 ||
        h < 32)
      throw InputError("sketchnav recognise: --frame expects WxH, e.g. 640x480");
    runner.frame_size = cv::Size(w, h);
  }
  const lm::ObjectnessParams objectness = lm::objectnessParamsFrom(g.config);
  g.config.requireAllUsed();
  if (runner.windows > 0) runner.objectness = std::make_unique<lm::Objectness>(objectness);

  std::ofstream details;
  if (!args.get("details").empty()) {
    details.open(args.get("details"));
    if (!details) throw InputError(args.get("details") + ": cannot write --details file");
    runner.details = &details;
  }
  if (!args.get("plot").empty()) {
    // Checked before the evaluation, so a mistyped path does not cost the figures of a long run.
    const std::filesystem::path plot(args.get("plot"));
    const auto parent = plot.has_parent_path() ? plot.parent_path() : std::filesystem::path(".");
    if (plot.extension() != ".png")
      throw InputError("sketchnav recognise: --plot '" + plot.string() + "' must end in .png");
    if (!std::filesystem::is_directory(parent))
      throw InputError("sketchnav recognise: --plot folder '" + parent.string() +
                       "' does not exist");
  }
  if (!args.get("eval").empty()) {
    if (!args.get("annotate").empty())
      throw InputError("sketchnav recognise: --annotate is for IMAGE..., not --eval");
    return evaluate(runner, args.get("eval"), index_ms, g, args.get("plot"));
  }
  if (!args.get("plot").empty())
    throw InputError("sketchnav recognise: --plot needs --eval DIR (it draws the evaluation)");

  const std::string annotate_dir = args.get("annotate");
  int annotated = 0;
  if (!annotate_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(annotate_dir, ec);
    if (ec)
      throw InputError("sketchnav recognise: cannot create --annotate folder '" + annotate_dir +
                       "': " + ec.message());
  }
  Json out = Json::array();
  int unreadable = 0;
  for (const auto& path : args.positional()) {
    // Regular files only (a FIFO would block), the header's pixel count bounded before decoding.
    cv::Mat img;
    try {
      img = runner.prepare(readImageFile(path, "sketchnav recognise: image"));
      if (img.empty())
        throw InputError("sketchnav recognise: image '" + path + "': empty after resizing");
    } catch (const InputError& e) {
      if (args.positional().size() == 1) throw;
      log::warn("recognise", "skipping unreadable image", {{"file", path}, {"error", e.what()}});
      ++unreadable;
      continue;
    }
    double ms = 0;
    lm::MatchResult m;
    const auto res = runner.run(img, top_k, ms, nullptr, annotate_dir.empty() ? nullptr : &m);
    if (!annotate_dir.empty()) {
      char name[32];
      std::snprintf(name, sizeof name, "%03d_", ++annotated);
      const std::string file = (std::filesystem::path(annotate_dir) /
                                (name + std::filesystem::path(path).stem().string() + ".png"))
                                   .string();
      if (!cv::imwrite(file, annotate(img, res, m)))
        throw RuntimeError("sketchnav recognise: cannot write '" + file + "'");
    }
    Json cands = Json::array();
    for (const auto& r : res)
      cands.push_back({{"class", r.class_name},
                       {"score", r.score},
                       {"inliers", r.inliers},
                       {"verified", r.verified},
                       {"evidence", r.evidence},
                       {"votes", r.votes},
                       {"bow_probability", r.bow_probability},
                       {"colour_probability", r.colour_probability},
                       {"colour_rescued", r.colour_rescued},
                       {"appearance", r.appearance},
                       {"rejected", r.rejected},
                       {"window", {r.window.x, r.window.y, r.window.width, r.window.height}}});
    const bool rejected = res.empty() || res.front().rejected;
    out.push_back({{"image", path},
                   {"class", rejected ? Json(nullptr) : Json(res.front().class_name)},
                   {"candidates", cands},
                   {"ms", ms}});
    if (!g.json) {
      std::cout << path << ": " << (rejected ? "none of these" : res.front().class_name) << "\n";
      for (const auto& r : res)
        std::printf("  %-40s score %.3f  inliers %3d  bow p %.3f  colour p %.3f%s\n",
                    r.class_name.c_str(), r.score, r.inliers, r.bow_probability,
                    r.colour_probability,
                    r.rejected && r.verified ? "  (verified; the sibling check chose another class)"
                    : r.rejected             ? "  (not verified)"
                    : r.colour_rescued       ? "  (not verified; votes and colour agree)"
                                             : "");
    }
  }
  if (g.json) printJson({{"results", out}, {"unreadable", unreadable}, {"mode", modeJson(runner)}});
  return unreadable ? 1 : 0;
}

const CommandRegistration reg("recognise",
                              "classify images with a landmark model; --eval DIR prints accuracy",
                              runRecognise);
}  // namespace
}  // namespace sketchnav::app
