// Matching range of LandmarkPerception in the lab simulation, without and with the foveal
// second look (PerceptionParams fovea_*). For each of the lab world's landmarks, a robot at
// each distance along the landmark's normal (and `--angle` degrees off it) facing the landmark
// (turned `--turn` degrees away) renders one frame (default noise); perception is asked for the
// landmark's class with a hint: its true bearing and range, perturbed by `--hint-bearing`
// degrees and `--hint-range` (relative). Prints, per setting and distance, how many landmarks
// were recognised, the time per frame, and false detections when another landmark's class is
// hinted at it. `--world` takes another world's landmarks and textures; `--set` changes the
// "on" side's settings, `--base-set` the "off" side's (so two settings can be compared with the
// fovea off on both: `--set fovea=false --set frame_max_side=640`). Not a timed test: run by
// hand, e.g.
//   bench_perception --angle 0,40 --dist 2,3,4,5,6
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

#include "sketchnav/core/paths.h"
#include "sketchnav/landmarks/model.h"
#include "sketchnav/nav/perception.h"
#include "sketchnav/sim/simulator.h"
#include "sketchnav/sim/world.h"

namespace {
using namespace sketchnav;

std::vector<double> list(const std::string& s) {
  std::vector<double> v;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) v.push_back(std::stod(item));
  return v;
}

struct Options {
  std::vector<double> angles{0, 40};                     // [deg] off the landmark's normal
  std::vector<double> dists{1, 2, 3, 4, 5, 6, 7};        // [m] camera to landmark
  double turn_deg = 0;                                   // robot heading away from the landmark
  double hint_bearing_deg = 0;                           // hint error
  double hint_range = 0;                                 // relative hint range error
  std::string model;                                     // .slm (default: trained/cached)
  std::string frames_dir;                                // save rendered frames here
  std::vector<std::pair<std::string, std::string>> set;  // nav.perception overrides (fovea on)
  std::vector<std::pair<std::string, std::string>> base_set;  // ... of the baseline (fovea off)
  std::string world = "lab";  // a name in share/worlds or a .world.json file
  bool verbose = false;
};

// Applies "name=value" to the PerceptionParams field bound as `name`.
struct Setter {
  std::string name, value;
  bool done = false;
  void operator()(const char* n, bool& v) {
    if (name == n) v = value == "true" || value == "1", done = true;
  }
  void operator()(const char* n, int& v) {
    if (name == n) v = std::stoi(value), done = true;
  }
  void operator()(const char* n, double& v) {
    if (name == n) v = std::stod(value), done = true;
  }
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << a << " needs a value\n";
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--angle")
      o.angles = list(next());
    else if (a == "--dist")
      o.dists = list(next());
    else if (a == "--turn")
      o.turn_deg = std::stod(next());
    else if (a == "--hint-bearing")
      o.hint_bearing_deg = std::stod(next());
    else if (a == "--hint-range")
      o.hint_range = std::stod(next());
    else if (a == "--model")
      o.model = next();
    else if (a == "--frames")
      o.frames_dir = next();
    else if (a == "--world")
      o.world = next();
    else if (a == "--set" || a == "--base-set") {
      const std::string kv = next();
      const auto eq = kv.find('=');
      if (eq == std::string::npos) {
        std::cerr << a << " expects name=value\n";
        std::exit(2);
      }
      (a == "--set" ? o.set : o.base_set).emplace_back(kv.substr(0, eq), kv.substr(eq + 1));
    } else if (a == "-v")
      o.verbose = true;
    else {
      std::cerr << "usage: bench_perception [--angle 0,40] [--dist 1,2,...] [--turn DEG]\n"
                   "  [--hint-bearing DEG] [--hint-range REL] [--model FILE.slm] [--frames DIR] "
                   "[--set fovea_x=V]... [--base-set x=V]... [--world NAME|FILE] [-v]\n";
      std::exit(a == "--help" ? 0 : 2);
    }
  }
  return o;
}

struct Cell {
  int n = 0, found = 0, fovea_found = 0, looks = 0, wrong = 0;
  double normal_ms = 0, fovea_ms = 0, bearing_err_deg = 0;
};

}  // namespace

int main(int argc, char** argv) {
  const Options o = parse(argc, argv);
  cv::setNumThreads(1);  // the navigation loop's budget: one core
  std::string model_file = o.model;
  auto model = std::make_shared<landmarks::LandmarkModel>();
  if (model_file.empty()) {
    const char* home = std::getenv("HOME");
    const std::string dir = std::string(home && *home ? home : "/tmp") + "/.cache/sketchnav";
    std::filesystem::create_directories(dir);
    model_file = dir + "/bench-perception.slm";
    std::cerr << "model: " << model_file << " (trained from share/landmarks when missing)\n";
    *model = landmarks::loadOrTrainModel(resourcePath("landmarks"), model_file,
                                         landmarks::ModelParams{});
  } else {
    *model = landmarks::LandmarkModel::load(model_file);
  }
  model->buildIndexes();

  sim::Simulator simr(sim::loadWorldByName(o.world));
  const auto& world = simr.world();
  const hw::Intrinsics K = world.camera.intrinsics();
  nav::PerceptionParams off, on;
  off.camera_yaw = on.camera_yaw = world.camera.yaw;
  off.fovea = false;
  on.fovea = true;  // the comparison is the look against none, whatever the default
  for (const auto* sets : {&o.set, &o.base_set})
    for (const auto& [k, v] : *sets) {
      Setter st{k, v};
      (sets == &o.set ? on : off).bind(st);
      if (!st.done) {
        std::cerr << (sets == &o.set ? "--set" : "--base-set") << ": no nav.perception field '" << k
                  << "'\n";
        return 2;
      }
    }
  on.validate();
  off.validate();
  nav::LandmarkPerception p_off(model, off), p_on(model, on);
  if (!o.frames_dir.empty()) std::filesystem::create_directories(o.frames_dir);

  std::printf("hint: bearing %+.1f deg, range %+.0f %%; robot turned %+.1f deg\n",
              o.hint_bearing_deg, 100 * o.hint_range, o.turn_deg);
  std::printf("%6s %6s | %-24s | %-34s | %s\n", "angle", "dist", "fovea off: found  ms",
              "fovea on: found (by fovea) looks", "fovea ms/look  |bearing err| deg  false");
  for (const double ang : o.angles) {
    for (const double dist : o.dists) {
      Cell c0, c1;
      std::string per_lm;
      for (const auto& lm : world.landmarks) {
        // Camera `dist` from the landmark along its normal rotated by `ang`; robot facing it.
        const double dir = lm.yaw + ang * M_PI / 180;
        const double cxw = lm.position.x() + dist * std::cos(dir);
        const double cyw = lm.position.y() + dist * std::sin(dir);
        const double heading =
            std::atan2(lm.position.y() - cyw, lm.position.x() - cxw) + o.turn_deg * M_PI / 180;
        const hw::Pose2D pose{cxw - world.camera.x * std::cos(heading),
                              cyw - world.camera.x * std::sin(heading), heading};
        hw::Frame f;
        f.image = simr.renderView(pose, 0.0, true);
        // True bearing/range of the landmark's centre from the robot (the camera position).
        const double dx = lm.position.x() - cxw, dy = lm.position.y() - cyw;
        const double true_bearing = std::remainder(std::atan2(dy, dx) - heading, 2 * M_PI);
        const double true_range = std::hypot(dx, dy);
        const std::vector<nav::LookFor> look = {{lm.class_name,
                                                 true_bearing + o.hint_bearing_deg * M_PI / 180,
                                                 true_range * (1 + o.hint_range)}};
        const auto r0 = p_off.observe(f, K, look);
        const auto r1 = p_on.observe(f, K, look);
        // Another landmark's class hinted at this one: any detection of it is false.
        const std::string& other =
            world.landmarks[(&lm - &world.landmarks[0] + 1) % world.landmarks.size()].class_name;
        std::vector<nav::LookFor> wrong_look = look;
        wrong_look[0].class_name = other;
        for (const auto& d : p_on.observe(f, K, wrong_look).detections)
          c1.wrong += d.class_name == other;
        int inliers = 0;
        auto has = [&](const nav::Observation& ob, double* bearing) {
          for (const auto& d : ob.detections)
            if (d.class_name == lm.class_name) {
              if (bearing) *bearing = d.bearing;
              inliers = d.inliers;
              return true;
            }
          return false;
        };
        const bool f0 = has(r0, nullptr);
        double b1 = 0;
        const bool f1 = has(r1, &b1);
        ++c0.n, ++c1.n;
        c0.found += f0;
        c1.found += f1;
        c1.fovea_found += f1 && !f0;
        c0.normal_ms += r0.timing.total_ms;
        c1.normal_ms += r1.timing.total_ms - r1.timing.fovea_ms;
        if (r1.timing.fovea_looks > 0) {
          c1.looks += r1.timing.fovea_looks;
          c1.fovea_ms += r1.timing.fovea_ms;
        }
        if (f1 && !f0) c1.bearing_err_deg += std::abs(b1 - true_bearing) * 180 / M_PI;
        per_lm += f1 ? (f0 ? "N" : "F") : "-";
        if (!o.frames_dir.empty()) {
          char name[128];
          std::snprintf(name, sizeof name, "/%s_a%02.0f_d%.1f.png", lm.id.c_str(), ang, dist);
          cv::imwrite(o.frames_dir + name, f.image);
        }
        if (o.verbose)
          std::fprintf(stderr,
                       "%s %s a=%.0f d=%.1f: off %d on %d (%d inliers; looks %d, %.1f ms)\n",
                       lm.id.c_str(), lm.class_name.c_str(), ang, dist, f0, f1, inliers,
                       r1.timing.fovea_looks, r1.timing.fovea_ms);
      }
      std::printf("%6.0f %6.1f | %5d/%d %12.1f   | %5d/%d (%d) %14d   | %8.1f %12.2f %7d   %s\n",
                  ang, dist, c0.found, c0.n, c0.normal_ms / c0.n, c1.found, c1.n, c1.fovea_found,
                  c1.looks, c1.looks ? c1.fovea_ms / c1.looks : 0.0,
                  c1.fovea_found ? c1.bearing_err_deg / c1.fovea_found : 0.0, c1.wrong,
                  per_lm.c_str());
      std::fflush(stdout);
    }
  }
  std::printf(
      "false: detections of another landmark's class hinted at this one (fovea on)\n"
      "per landmark L1..L8: N = normal pass, F = fovea only, - = not recognised\n");
  return 0;
}
