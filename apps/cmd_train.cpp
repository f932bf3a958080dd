// sketchnav train: build a landmark model (.slm) from a folder of class folders.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <iostream>

#include <unistd.h>

#include "cli.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/input_file.h"
#include "sketchnav/landmarks/model.h"

namespace sketchnav::app {
namespace {

int runTrain(const std::vector<std::string>& argv_in, GlobalOptions& g) {
  Args args("train", "build a landmark model (.slm) from a folder of class folders",
            "--landmarks DIR -o MODEL [--vocabulary N] [--plain-sift] [--seed S]");
  args.option("landmarks", "landmark set: a folder of class folders (a class = a leaf folder)")
      .option("output", "model file to write (also -o)")
      .option("vocabulary", "visual words (default: landmarks.train.vocabulary_size, 1000)")
      .option("max-features", "SIFT keypoints per photo (default 500)")
      .option("seed", "seed for sampling and k-means (default 1)")
      .option("exclude", "comma-separated class names to leave out (rejection experiments)")
      .flag("plain-sift", "use plain SIFT descriptors instead of RootSIFT (for comparisons)");
  std::vector<std::string> argv;
  for (size_t i = 0; i < argv_in.size(); ++i)
    argv.push_back(argv_in[i] == "-o" ? "--output" : argv_in[i]);
  if (!args.parse(argv)) return 0;
  if (args.get("landmarks").empty())
    throw InputError("sketchnav train: --landmarks DIR is required");
  if (args.get("output").empty()) throw InputError("sketchnav train: -o MODEL is required");
  // Checked before training: outputs go only to regular or new files in existing folders.
  requireOutputFile(args.get("output"), "sketchnav train: -o");

  landmarks::ModelParams p;
  applyConfig(p, g.config, "landmarks.train");
  g.config.requireAllUsed();
  if (!args.get("vocabulary").empty()) p.vocabulary_size = args.getInt("vocabulary");
  if (!args.get("max-features").empty()) p.features.max_features = args.getInt("max-features");
  if (!args.get("seed").empty()) p.seed = args.getInt("seed");
  if (args.flagSet("plain-sift")) p.features.root_sift = false;
  p.validate();

  const auto t0 = std::chrono::steady_clock::now();
  std::string last_stage;
  // On a terminal one line is rewritten in place; into a log file (not a terminal) a carriage
  // return per photo would pile hundreds of updates onto one line, so a line is written per
  // tenth of each stage instead.
  const bool tty = isatty(STDERR_FILENO) != 0;
  int last_tenth = -1;
  auto progress = [&](const std::string& stage, int done, int total) {
    if (g.json && !g.verbose) return;
    const bool new_stage = stage != last_stage;
    if (tty) {
      if (new_stage && !last_stage.empty()) std::cerr << "\n";
      last_stage = stage;
      std::cerr << "\rtrain: " << stage << " " << done << "/" << total << std::flush;
      return;
    }
    const int tenth = total > 0 ? 10 * done / total : 10;
    if (!new_stage && tenth == last_tenth) return;
    last_stage = stage;
    last_tenth = tenth;
    std::cerr << "train: " << stage << " " << done << "/" << total << "\n" << std::flush;
  };
  landmarks::LandmarkModel m =
      landmarks::trainModel(args.get("landmarks"), p, progress, args.getList("exclude"));
  if (tty && !last_stage.empty() && !(g.json && !g.verbose)) std::cerr << "\n";
  m.save(args.get("output"));
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  // Per class: its photos and keypoints, and what would make it weak (the photos a user has to
  // retake are easier to find here than in recognition figures later).
  constexpr int kFewPhotos = 3;
  const int few_keypoints = std::max(20, p.features.max_features / 4);
  Json per_class = Json::object();
  int weak = 0;
  for (size_t c = 0; c < m.classes().size(); ++c) {
    const auto& ids = m.photosOfClass(static_cast<int>(c));
    int kmin = 1 << 30, ksum = 0;
    for (int id : ids) {
      const int k = static_cast<int>(m.photos()[id].keypoints.size());
      kmin = std::min(kmin, k), ksum += k;
    }
    const int n = static_cast<int>(ids.size());
    const double kmean = n ? static_cast<double>(ksum) / n : 0.0;
    Json warn = Json::array();
    if (n < kFewPhotos) warn.push_back("few photos: add views from other angles and distances");
    if (kmean < few_keypoints)
      warn.push_back("few keypoints: little texture in view; photograph it closer or fuller");
    weak += warn.empty() ? 0 : 1;
    per_class[m.classes()[c]] = {{"photos", n},
                                 {"keypoints_mean", kmean},
                                 {"keypoints_min", n ? kmin : 0},
                                 {"warnings", warn}};
  }
  Json j = {{"model", args.get("output")},
            {"classes", m.classes().size()},
            {"photos", m.photos().size()},
            {"words", m.vocabulary().size()},
            {"descriptor", p.features.root_sift ? "RootSIFT" : "SIFT"},
            {"seconds", secs},
            {"excluded", args.getList("exclude")},
            {"params", paramsToJson(p)},
            {"weak_classes", weak},
            {"per_class", per_class}};
  if (g.json) {
    printJson(j);
  } else {
    std::cout << "model      " << args.get("output") << "\nclasses    " << m.classes().size()
              << "\nphotos     " << m.photos().size() << "\nwords      " << m.vocabulary().size()
              << "\ndescriptor " << j["descriptor"].get<std::string>() << "\nseconds    " << secs
              << "\n\n";
    std::printf("%-40s %6s %15s  %s\n", "class", "photos", "keypoints mean", "(min)");
    for (const auto& [name, pc] : per_class.items()) {
      std::string w;
      for (const auto& x : pc["warnings"]) w += "  " + x.get<std::string>();
      std::printf("%-40s %6d %15.0f  (%d)%s\n", name.c_str(), pc["photos"].get<int>(),
                  pc["keypoints_mean"].get<double>(), pc["keypoints_min"].get<int>(), w.c_str());
    }
    if (weak > 0)
      std::printf("\n%d class%s may be recognised poorly (see the notes above)\n", weak,
                  weak == 1 ? "" : "es");
  }
  return 0;
}

const CommandRegistration reg("train",
                              "build a landmark model (.slm) from a folder of class folders",
                              runTrain);
}  // namespace
}  // namespace sketchnav::app
