// sketchnav propose: objectness windows for images; --eval VOCDIR prints a recall table for
// our method and the baselines, all measured in the same run.
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <unistd.h>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>

#include "cli.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/image_file.h"
#include "sketchnav/core/log.h"
#include "sketchnav/core/paths.h"
#include "sketchnav/landmarks/baselines.h"
#include "sketchnav/landmarks/objectness.h"
#include "sketchnav/landmarks/voc.h"

namespace sketchnav::app {
namespace {
namespace fs = std::filesystem;
using namespace sketchnav::landmarks;

// Our method behind the benchmark's interface.
class Ours : public ProposalMethod {
 public:
  Ours(std::string name, ObjectnessParams p) : name_(std::move(name)), obj_(std::move(p)) {}
  std::string name() const override { return name_; }
  std::vector<cv::Rect> propose(const cv::Mat& bgr, int max_windows) override {
    std::vector<cv::Rect> out;
    for (const auto& w : obj_.propose(bgr, max_windows)) out.push_back(w.box);
    return out;
  }

 private:
  std::string name_;
  Objectness obj_;
};

std::string defaultBingDir(const std::string& voc_dir) {
  const fs::path beside = fs::path(voc_dir).parent_path() / "bing-model";
  if (fs::is_directory(beside)) return beside.string();
  if (const char* env = std::getenv("SKETCHNAV_DATA"); env && *env)
    return (fs::path(env) / "bing-model").string();
  return beside.string();
}

std::unique_ptr<ProposalMethod> makeMethod(const std::string& name, const ObjectnessParams& p,
                                           const std::string& bing_dir,
                                           const std::string& scratch) {
  if (name == "ours") return std::make_unique<Ours>(name, p);
  if (name == "ccs" || name == "scs") {
    ObjectnessParams q = p;
    q.use_ccs = name == "ccs";
    q.use_scs = name == "scs";
    q.use_edgeboxes = false;  // one method alone
    return std::make_unique<Ours>(name, q);
  }
  if (name == "bing") return makeBing(bing_dir, scratch);
  if (name == "selective-search" || name == "selective-search-as-returned" ||
      name == "selective-search-random") {
    static std::shared_ptr<void> run = makeSelectiveSearchRun();  // one SS run per image
    const SsOrder order = name == "selective-search"          ? SsOrder::Reversed
                          : name == "selective-search-random" ? SsOrder::Random
                                                              : SsOrder::AsReturned;
    return makeSelectiveSearchFast(order, run);
  }
  if (name == "edgeboxes") return makeEdgeBoxesSobel();
  if (name == "sliding-window") return makeSlidingWindow();
  throw InputError("sketchnav propose: --methods: unknown method '" + name +
                   "' (ours, ccs, scs, bing, selective-search, selective-search-as-returned, "
                   "selective-search-random, edgeboxes, sliding-window)");
}

std::string fmt(double v, int prec = 3) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(prec) << v;
  return s.str();
}

int runEval(const Args& args, GlobalOptions& g, const ObjectnessParams& params) {
  const std::string dir = args.get("eval");
  std::vector<int> budgets;
  for (const auto& s : args.getList("windows")) {
    char* end = nullptr;
    const long v = std::strtol(s.c_str(), &end, 10);
    if (s.empty() || *end || v <= 0 || v > 100000)
      throw InputError("sketchnav propose: --windows: '" + s + "' is not a positive count");
    budgets.push_back(static_cast<int>(v));
  }
  if (budgets.empty()) throw InputError("sketchnav propose: --windows is empty");
  std::vector<std::string> names = args.getList("methods");
  if (names.empty()) throw InputError("sketchnav propose: --methods is empty");
  const int max_images = args.getInt("max-images");
  auto images = readVocDataset(dir);
  // --part: a fixed split for tuning on one half and reporting on the other. The images are in
  // readVocDataset's order (ImageSets list, else ids sorted by name); first-half = the first
  // ⌊n/2⌋ of them, second-half = the rest.
  const std::string part = args.get("part");
  if (part == "first-half")
    images.resize(images.size() / 2);
  else if (part == "second-half")
    images.erase(images.begin(), images.begin() + static_cast<long>(images.size() / 2));
  else if (part != "all")
    throw InputError("sketchnav propose: --part: '" + part +
                     "' is not one of all, first-half, second-half");
  if (max_images > 0 && static_cast<int>(images.size()) > max_images) images.resize(max_images);
  const std::string bing_dir = args.has("bing-model") && !args.get("bing-model").empty()
                                   ? args.get("bing-model")
                                   : defaultBingDir(dir);
  const std::string scratch =
      (fs::temp_directory_path() / ("sketchnav-bing-" + std::to_string(::getpid()))).string();
  std::vector<std::unique_ptr<ProposalMethod>> methods;
  for (const auto& n : names) methods.push_back(makeMethod(n, params, bing_dir, scratch));

  std::vector<ProposalMethod*> ptrs;
  for (auto& m : methods) ptrs.push_back(m.get());
  const EvalResult r =
      evaluateProposals(images, ptrs, budgets, [](int i, int n, const std::string& id) {
        std::cerr << "propose: image " << (i + 1) << "/" << n << " " << id << "\n";
      });
  std::error_code ec;
  fs::remove_all(scratch, ec);

  Json j = {{"dataset", dir},
            {"images", r.images},
            {"objects", r.objects},
            {"skipped_images", r.skipped},
            {"part", part},
            {"windows", budgets},
            {"methods", Json::object()}};
  j["params"] = paramsToJson(params);
  j["params"]["ccs"] = paramsToJson(params.ccs);
  j["params"]["scs"] = paramsToJson(params.scs);
  for (const auto& m : r.methods) {
    Json mj = {{"recall", Json::object()}, {"ar", Json::object()}, {"mabo", Json::object()}};
    for (int b : budgets) {
      const auto& e = m.at.at(b);
      const std::string k = std::to_string(b);
      mj["recall"][k] = {{"0.5", e.recall(0.5)}, {"0.7", e.recall(0.7)}};
      mj["ar"][k] = e.averageRecall();
      mj["mabo"][k] = e.mabo();
    }
    mj["ms_mean"] = m.msMean();
    mj["ms_median"] = m.msMedian();
    mj["cpu_ms_mean"] = m.cpuMsMean();
    mj["cpu_ms_median"] = m.cpuMsMedian();
    j["methods"][m.name] = mj;
  }
  if (g.json) {
    printJson(j);
  } else {
    std::cout << "dataset " << dir << ": " << r.images << " images, " << r.objects << " objects"
              << (r.skipped.empty() ? "" : ", " + std::to_string(r.skipped.size()) + " skipped")
              << "\n";
    std::cout << std::left << std::setw(18) << "method" << std::setw(8) << "windows" << std::setw(9)
              << "R@0.5" << std::setw(9) << "R@0.7" << std::setw(9) << "AR" << std::setw(9)
              << "MABO" << std::setw(10) << "ms mean" << std::setw(11) << "ms median"
              << "cpu ms mean\n";
    for (const auto& m : r.methods)
      for (int b : budgets) {
        const auto& e = m.at.at(b);
        std::cout << std::left << std::setw(18) << m.name << std::setw(8) << b << std::setw(9)
                  << fmt(e.recall(0.5)) << std::setw(9) << fmt(e.recall(0.7)) << std::setw(9)
                  << fmt(e.averageRecall()) << std::setw(9) << fmt(e.mabo()) << std::setw(10)
                  << fmt(m.msMean(), 1) << std::setw(11) << fmt(m.msMedian(), 1)
                  << fmt(m.cpuMsMean(), 1) << "\n";
      }
  }
  return r.images > 0 ? 0 : 1;
}

int runImage(const Args& args, GlobalOptions& g, const ObjectnessParams& params) {
  const std::string path = args.positional().front();
  // Regular files only (a FIFO would block), the header's pixel count bounded before decoding.
  const cv::Mat img = readImageFile(path, "sketchnav propose: image");
  const int n = args.getInt("windows");
  if (n <= 0) throw InputError("sketchnav propose: --windows must be a positive count");
  const int draw = std::min(n, args.getInt("draw"));
  const Objectness obj(params);
  const int64 t0 = cv::getTickCount();
  const auto wins = obj.propose(img, n);
  const double ms = 1000.0 * (cv::getTickCount() - t0) / cv::getTickFrequency();
  std::string out = args.get("output");
  if (out.empty())
    out = (fs::path(makeOutputDir(args.get("out"))) /
           (fs::path(path).stem().string() + "_windows.png"))
              .string();
  cv::Mat vis = img.clone();
  for (int i = std::min<int>(draw, static_cast<int>(wins.size())) - 1; i >= 0; --i) {
    const auto& w = wins[i];
    const cv::Scalar colour = w.source == Window::CCS     ? cv::Scalar(0, 0, 255)
                              : w.source == Window::SCS   ? cv::Scalar(255, 128, 0)
                              : w.source == Window::Edges ? cv::Scalar(0, 200, 255)
                                                          : cv::Scalar(0, 200, 0);
    cv::rectangle(vis, w.box, colour, i < 5 ? 2 : 1);
  }
  if (!cv::imwrite(out, vis)) throw RuntimeError("sketchnav propose: cannot write " + out);
  if (g.json) {
    Json j = {{"image", path}, {"width", img.cols}, {"height", img.rows},
              {"ms", ms},      {"output", out},     {"windows", Json::array()}};
    for (const auto& w : wins)
      j["windows"].push_back({{"x", w.box.x},
                              {"y", w.box.y},
                              {"width", w.box.width},
                              {"height", w.box.height},
                              {"score", w.score},
                              {"source", toString(w.source)}});
    printJson(j);
  } else {
    std::cout << wins.size() << " windows in " << fmt(ms, 1) << " ms; top " << draw << " drawn to "
              << out << " (red CCS, blue SCS, green both, orange EdgeBoxes)\n";
    for (size_t i = 0; i < std::min<size_t>(wins.size(), 10); ++i)
      std::cout << "  " << wins[i].box.x << "," << wins[i].box.y << " " << wins[i].box.width << "x"
                << wins[i].box.height << " score " << fmt(wins[i].score) << " "
                << toString(wins[i].source) << "\n";
  }
  return 0;
}

int runPropose(const std::vector<std::string>& argv0, GlobalOptions& g) {
  std::vector<std::string> argv = argv0;
  for (auto& a : argv)
    if (a == "-o") a = "--output";
  Args args("propose", "objectness windows for images; --eval VOCDIR prints a recall table",
            "IMAGE [-o out.png] [--windows N] | --eval VOCDIR [--methods LIST] [--windows LIST]");
  args.positionals("IMAGE", "image to propose windows for (not with --eval)", 0, 1)
      .option("output", "(-o) PNG with the top windows drawn (default: <out>/<image>_windows.png)")
      .option("out", "output directory (default runs/<timestamp>/)")
      .option("windows", "window count (IMAGE) or comma-separated budgets (--eval)", "")
      .option("draw", "how many of the top windows to draw", "20")
      .option("eval", "VOC-layout folder to evaluate on")
      .option("methods",
              "comma-separated: ours, ccs, scs, bing, selective-search (read reversed), "
              "selective-search-as-returned, selective-search-random, edgeboxes, sliding-window",
              "ours,ccs,scs,bing,selective-search,edgeboxes,sliding-window")
      .option("part",
              "all, first-half or second-half of the images in list/sorted-name order "
              "(a fixed dev / held-out split)",
              "all")
      .option("max-images", "evaluate only the first N images (0 = all)", "0")
      .option("bing-model", "BING model folder (default: <VOCDIR>/../bing-model)");
  if (!args.parse(argv)) return 0;
  ObjectnessParams params = objectnessParamsFrom(g.config);
  g.config.requireAllUsed();
  const bool eval = args.has("eval") && !args.get("eval").empty();
  if (eval == !args.positional().empty())
    throw InputError("sketchnav propose: give either IMAGE or --eval VOCDIR");
  if (eval) {
    Args& a = args;
    if (a.get("windows").empty()) a.option("windows", "", "10,100,1000");
    return runEval(a, g, params);
  }
  if (args.get("windows").empty()) args.option("windows", "", "100");
  return runImage(args, g, params);
}

const CommandRegistration reg("propose",
                              "objectness windows for images; --eval VOCDIR prints a recall table",
                              runPropose);
}  // namespace
}  // namespace sketchnav::app
