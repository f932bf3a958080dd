#include "sketchnav/run/experiments.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <random>

#include "sketchnav/core/error.h"
#include "sketchnav/core/paths.h"
#include "sketchnav/mapsketch/route.h"

namespace sketchnav::run {
namespace {

using V2 = Eigen::Vector2d;

// The guide line of the lab sketch (share/sketches/lab.sketch.json simplified, in world
// metres): start at the left door of room A, along room A, down to the walkway, across room B
// and down to the right door.
const std::vector<V2> kBasePath = {{0.8, 10.1}, {6.0, 10.5}, {6.8, 9.8}, {7.5, 6.5},
                                   {16.0, 6.2}, {17.0, 5.6}, {17.4, 2.6}};
// Experiment 2, redrawn guide lines. (c): fewer, straighter strokes; (d): a wobblier line
// with more corners. Both keep >= 0.4 m from furniture, as a person drawing over the room would.
const std::vector<V2> kRedrawnC = {{0.8, 10.1}, {6.5, 10.4}, {7.3, 6.4}, {16.6, 6.3}, {17.4, 2.6}};
const std::vector<V2> kRedrawnD = {{0.8, 10.1}, {2.0, 10.7}, {4.5, 10.9}, {6.6, 10.4},
                                   {7.0, 8.2},  {7.8, 6.6},  {10.5, 6.6}, {13.0, 6.0},
                                   {16.0, 6.0}, {17.0, 4.6}, {17.4, 2.6}};

const std::vector<std::string> kNames = {"exp2-moved-a",
                                         "exp2-moved-b",
                                         "exp2-redrawn-c",
                                         "exp2-redrawn-d",
                                         "exp3-8",
                                         "exp3-6",
                                         "exp3-4",
                                         "exp3-4-uneven",
                                         "exp4-repeated-a",
                                         "exp4-repeated-b",
                                         "exp4-static-obstacle",
                                         "exp4-pedestrian-left",
                                         "exp4-pedestrian-right"};

Json& landmarkById(Json& world, const std::string& id) {
  for (auto& l : world["landmarks"])
    if (l.value("id", "") == id) return l;
  throw RuntimeError("lab world has no landmark " + id);
}

void moveLandmark(Json& world, const std::string& id, double x, double y, double yaw_deg = 1e9) {
  Json& l = landmarkById(world, id);
  l["position"] = {x, y};
  if (yaw_deg < 1e8) l["yaw_deg"] = yaw_deg;
}

void keepLandmarks(Json& world, const std::vector<std::string>& keep) {
  Json out = Json::array();
  for (const auto& l : world["landmarks"])
    if (std::find(keep.begin(), keep.end(), l.value("id", "")) != keep.end()) out.push_back(l);
  world["landmarks"] = out;
}

void setClass(Json& world, const std::string& id, const std::string& cls) {
  Json& l = landmarkById(world, id);
  l["class"] = cls;
  l["texture"] = "textures/" + cls + "/" + cls + "_Iconic.jpg";
  l.erase("back_texture");
}

Json pedestrian(const std::string& name, V2 a, V2 b) {
  return {{"name", name},  {"path", {{a.x(), a.y()}, {b.x(), b.y()}}},
          {"speed", 0.4},  {"loop", false},
          {"phase", 0.0},  {"radius", 0.25},
          {"height", 1.7}, {"color", {60, 60, 170}}};
}

std::vector<std::string> idsOf(const Json& world) {
  std::vector<std::string> ids;
  for (const auto& l : world["landmarks"]) ids.push_back(l.value("id", ""));
  return ids;
}

V2 toCanvas(const V2& w) {
  return {32.0 + 52.0 * w.x(), 698.0 - 52.0 * w.y()};
}

// The distance from `goal` to the centre of the nearest open door within 1.5 m, rounded to
// 0.1 m as a person would say it; none without such a door.
std::optional<double> goalDoorStandoff(const Json& world, const V2& goal) {
  std::optional<double> best;
  for (const auto& d : world.value("doors", Json::array())) {
    if (!d.value("open", true)) continue;
    const V2 a(d["from"][0].get<double>(), d["from"][1].get<double>());
    const V2 b(d["to"][0].get<double>(), d["to"][1].get<double>());
    const double dist = (0.5 * (a + b) - goal).norm();
    if (dist <= 1.5 && (!best || dist < *best)) best = dist;
  }
  if (best) best = std::round(*best * 10) / 10;
  return best;
}

}  // namespace

void SketchNoise::validate() const {
  require(landmark_sigma_m >= 0 && landmark_sigma_m < 5, "experiments.sketch.landmark_sigma_m",
          "must be in [0, 5) m");
  require(distance_sigma >= 0 && distance_sigma < 1, "experiments.sketch.distance_sigma",
          "must be in [0, 1)");
  require(distance_round_m >= 0 && distance_round_m <= 5, "experiments.sketch.distance_round_m",
          "must be in [0, 5] m");
  require(path_sigma_m >= 0 && path_sigma_m < 2, "experiments.sketch.path_sigma_m",
          "must be in [0, 2) m");
  require(jitter_px >= 0 && jitter_px < 20, "experiments.sketch.jitter_px",
          "must be in [0, 20) px");
}

const std::vector<std::string>& variantNames() {
  return kNames;
}

Variant makeVariant(const std::string& name) {
  if (std::find(kNames.begin(), kNames.end(), name) == kNames.end()) {
    std::string known;
    for (const auto& n : kNames) known += (known.empty() ? "" : ", ") + n;
    throw InputError("unknown experiment variant '" + name + "' (known: " + known + ")");
  }
  Variant v;
  v.name = name;
  {
    const std::string path = resourcePath("worlds/lab.world.json");
    std::ifstream in(path);
    if (!in) throw RuntimeError("cannot read " + path);
    v.world = Json::parse(in);
  }
  v.world["name"] = "lab/" + name;
  v.drawn_path = kBasePath;
  Json& w = v.world;
  if (name == "exp2-moved-a") {
    // Positions on the faces of the same furniture as in the lab world (a landmark inside a
    // bench would be invisible, which is another experiment).
    v.description = "L1, L5, L7 slid 0.9-1.0 m along their furniture";
    moveLandmark(w, "L1", 3.7, 9.62, 120);  // humidifier table: left end -> top face
    moveLandmark(w, "L5", 12.7, 7.56);      // test bench front face, 1 m to the right
    moveLandmark(w, "L7", 14.6, 5.49);      // lab bench top face, 1 m to the left
  } else if (name == "exp2-moved-b") {
    v.description = "L2, L8 moved 0.4 m; L6 to the lab bench (other side of the path)";
    moveLandmark(w, "L2", 7.43, 10.5);      // cabinet A face, 0.4 m down
    moveLandmark(w, "L6", 13.8, 5.35, 90);  // trash can -> lab bench top face
    moveLandmark(w, "L8", 17.1, 0.6);       // cabinet B face, 0.4 m left
  } else if (name == "exp2-redrawn-c") {
    v.description = "guide line redrawn with fewer, straighter strokes (4 sections)";
    v.drawn_path = kRedrawnC;
  } else if (name == "exp2-redrawn-d") {
    v.description = "guide line redrawn wobblier, with 10 corners";
    v.drawn_path = kRedrawnD;
  } else if (name == "exp3-8") {
    v.description = "all eight landmarks (the lab as in experiment 1)";
  } else if (name == "exp3-6") {
    v.description = "six landmarks, evenly spread (L2 and L6 removed)";
    keepLandmarks(w, {"L1", "L3", "L4", "L5", "L7", "L8"});
  } else if (name == "exp3-4") {
    v.description = "four landmarks, evenly spread (L1, L3, L5, L7)";
    keepLandmarks(w, {"L1", "L3", "L5", "L7"});
  } else if (name == "exp3-4-uneven") {
    v.description = "four landmarks, all before room B (L1-L4): room B on odometry alone";
    keepLandmarks(w, {"L1", "L2", "L3", "L4"});
  } else if (name == "exp4-repeated-a") {
    v.description = "eight landmarks, L2, L5, L8 all Arla-Standard-Milk (spread out)";
    for (const char* id : {"L2", "L5", "L8"}) setClass(w, id, "Arla-Standard-Milk");
  } else if (name == "exp4-repeated-b") {
    v.description = "eight landmarks, L5, L6, L7 all Bravo-Orange-Juice (consecutive)";
    for (const char* id : {"L5", "L6", "L7"}) setClass(w, id, "Bravo-Orange-Juice");
  } else if (name == "exp4-static-obstacle") {
    v.description = "a 0.6 x 0.6 m box on the guide line in room B (12.0, 6.35)";
    w["obstacles"].push_back({{"name", "static obstacle"},
                              {"shape", "box"},
                              {"centre", {12.0, 6.35}},
                              {"size", {0.6, 0.6}},
                              {"height", 1.0},
                              {"color", {40, 140, 200}}});
  } else if (name == "exp4-pedestrian-left") {
    v.description = "a pedestrian at 0.4 m/s, 0.7 m left of the line in room B";
    w["pedestrians"].push_back(pedestrian("pedestrian left", {16.0, 6.95}, {10.5, 6.95}));
  } else if (name == "exp4-pedestrian-right") {
    v.description = "a pedestrian at 0.4 m/s, 0.7 m right of the line in room B";
    w["pedestrians"].push_back(pedestrian("pedestrian right", {16.0, 5.6}, {10.5, 5.6}));
  }
  // The user puts the robot down facing along the first stroke of the guide line (the
  // executive assumes so), not at the lab file's default heading.
  const V2 d0 = v.drawn_path[1] - v.drawn_path[0];
  w["start"] = {{"x", v.drawn_path[0].x()},
                {"y", v.drawn_path[0].y()},
                {"yaw_deg", std::atan2(d0.y(), d0.x()) * 180.0 / M_PI}};
  v.sketched = idsOf(w);
  return v;
}

Json makeSketch(const Variant& v, const SketchNoise& noise, std::uint64_t seed) {
  noise.validate();
  std::mt19937_64 rng(seed * 0x9E3779B97F4A7C15ull + 0x5eedull);
  std::normal_distribution<double> n01(0.0, 1.0);
  auto gauss2 = [&](double s) { return V2(s * n01(rng), s * n01(rng)); };

  // Guide line: corners misplaced (not start / goal: the user knows those), then drawn as many
  // jittery points 5 px apart.
  std::vector<V2> corners = v.drawn_path;
  for (size_t i = 1; i + 1 < corners.size(); ++i) corners[i] += gauss2(noise.path_sigma_m);
  Json path = Json::array();
  for (size_t i = 0; i + 1 < corners.size(); ++i) {
    const V2 a = toCanvas(corners[i]), b = toCanvas(corners[i + 1]);
    const int n = std::max(1, static_cast<int>((b - a).norm() / 5.0));
    for (int k = 0; k < n; ++k) {
      const V2 p = a + (b - a) * (static_cast<double>(k) / n) + gauss2(noise.jitter_px);
      path.push_back({std::round(p.x() * 10) / 10, std::round(p.y() * 10) / 10});
    }
  }
  const V2 goal_px = toCanvas(corners.back());
  path.push_back({goal_px.x(), goal_px.y()});
  const V2 start_px = toCanvas(corners.front());

  // Landmarks in route order, each box where the user remembers it, distances from the
  // previous one (start for the first) as estimated by a person: off by a factor, rounded.
  struct L {
    std::string id, cls;
    V2 pos;
    double s;
  };
  std::vector<L> ls;
  for (const auto& l : v.world["landmarks"]) {
    const std::string id = l.value("id", "");
    if (std::find(v.sketched.begin(), v.sketched.end(), id) == v.sketched.end()) continue;
    const V2 p(l["position"][0].get<double>(), l["position"][1].get<double>());
    ls.push_back({id, l.value("class", ""), p, mapsketch::closestOnPolyline(p, v.drawn_path).arc});
  }
  std::stable_sort(ls.begin(), ls.end(), [](const L& a, const L& b) { return a.s < b.s; });
  Json lms = Json::array();
  V2 prev = v.drawn_path.front();
  for (const auto& l : ls) {
    const V2 c = toCanvas(l.pos + gauss2(noise.landmark_sigma_m));
    double d = (l.pos - prev).norm() * std::exp(noise.distance_sigma * n01(rng));
    if (noise.distance_round_m > 0)
      d = std::max(noise.distance_round_m,
                   std::round(d / noise.distance_round_m) * noise.distance_round_m);
    prev = l.pos;
    const double w = 60, h = 40;  // a furniture-sized box, as in the lab sketch
    lms.push_back(
        {{"id", l.id},
         {"class", l.cls},
         {"rect",
          {{"x", std::round(c.x() - w / 2)}, {"y", std::round(c.y() - h / 2)}, {"w", w}, {"h", h}}},
         {"distance_m", d}});
  }
  Json sketch = {
      {"format", 1},
      {"name", "experiment " + v.name + " (generated, seed " + std::to_string(seed) + ")"},
      {"notes", "Generated by sketchnav experiments from the lab world: " + v.description +
                    ". Canvas u = 32 + 52 x, v = 698 - 52 y plus sketch noise."},
      {"canvas", {{"width", 1000}, {"height", 720}}},
      {"landmarks", lms},
      {"path", path},
      {"start", {start_px.x(), start_px.y()}},
      {"goal", {goal_px.x(), goal_px.y()}}};
  if (noise.goal_doorway)
    if (const auto standoff = goalDoorStandoff(v.world, v.drawn_path.back()))
      sketch["goal_place"] = {{"kind", "doorway"}, {"standoff_m", *standoff}};
  return sketch;
}

SketchNoise sketchNoiseFrom(const Config& config) {
  SketchNoise noise;
  applyConfig(noise, config, "experiments.sketch");
  return noise;
}

std::string writeVariantWorld(const Variant& v, const std::string& dir) {
  std::filesystem::create_directories(dir);
  const std::string path = dir + "/" + v.name + ".world.json";
  std::ofstream(path) << v.world.dump(1) << "\n";
  return path;
}

Json variantSketch(const Variant& v, const SketchNoise& noise, int seed) {
  const auto it = std::find(kNames.begin(), kNames.end(), v.name);
  const std::uint64_t variant_index = static_cast<std::uint64_t>(it - kNames.begin());
  return makeSketch(v, noise, static_cast<std::uint64_t>(seed) * 101 + variant_index);
}

void writeVariantSketch(const Variant& v, const SketchNoise& noise, int seed,
                        const std::string& path) {
  std::ofstream(path) << variantSketch(v, noise, seed).dump(1) << "\n";
}

TrialFailure trialFailure(const std::string& code, const std::string& reason, const Json& summary) {
  TrialFailure f{code, reason, ""};
  if (code == "short_of_goal" && summary.contains("distance_to_goal_m") &&
      summary["distance_to_goal_m"].is_number()) {
    char b[32];
    std::snprintf(b, sizeof b, "%.2f", summary["distance_to_goal_m"].get<double>());
    f.detail = b;
  } else if (code == "collision") {
    f.detail = summary.value("collision_with", "");
  }
  return f;
}

std::string summariseFailures(const std::vector<TrialFailure>& failures) {
  static const std::vector<std::pair<std::string, std::string>> kLabels = {
      {"collision", "collision"},
      {"short_of_goal", "stopped short of the goal [m]"},
      {"lost", "lost (landmarks in a row not found)"},
      {"timeout", "timeout"},
      {"no_progress", "no progress in a section"},
      {"safety_stop", "safety stop"},
      {"stopped", "stopped"},
      {"crashed", "run crashed"},
      {"no_summary", "no summary"}};
  struct Kind {
    std::string key;  // the code, or for a trial without one its reason
    int count = 0;
    std::vector<std::string> details;
  };
  std::vector<Kind> kinds;
  for (const auto& f : failures) {
    const std::string key = f.code.empty() ? f.reason : f.code;
    auto it = std::find_if(kinds.begin(), kinds.end(), [&](const Kind& k) { return k.key == key; });
    if (it == kinds.end()) it = kinds.insert(kinds.end(), Kind{key, 0, {}});
    ++it->count;
    if (!f.detail.empty()) it->details.push_back(f.detail);
  }
  std::string out;
  for (const auto& k : kinds) {
    std::string label = k.key;
    for (const auto& [code, words] : kLabels)
      if (code == k.key) label = words;
    out += (out.empty() ? "" : "; ") + std::to_string(k.count) + "x " + label;
    if (k.details.empty()) continue;
    out += " (";
    for (size_t i = 0; i < k.details.size(); ++i) out += (i ? ", " : "") + k.details[i];
    out += ")";
  }
  return out;
}

std::string writeBatchConfig(const Config& config, const std::string& out) {
  // The runs' settings: every key but the batch's own ("experiments.*").
  Config runs;
  for (const auto& k : config.keys())
    if (k.rfind("experiments.", 0) != 0) runs.set(k, config.at(k));
  const Json j = runs.toJson();
  if (j.empty()) return "";
  const std::string path = out + "/config.json";
  std::ofstream(path) << j.dump(2) << "\n";
  return path;
}

}  // namespace sketchnav::run
