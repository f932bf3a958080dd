// sketchnav scenarios: generate seeded worlds with human-like sketches (scenario_gen.h) and,
// with --run, the benchmark over them: success (ground truth), goal error, clearance to people
// and to furniture, time, per family and per drawing-error kind, and the sketch ceiling of
// each scenario (doc/experiments.md "Generated scenarios").
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>

#include "cli.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/paths.h"
#include "sketchnav/mapsketch/io.h"
#include "sketchnav/mapsketch/route.h"
#include "sketchnav/nav/executive.h"
#include "sketchnav/run/judge.h"
#include "sketchnav/run/run.h"
#include "sketchnav/run/run_folder.h"
#include "sketchnav/run/scenario.h"
#include "sketchnav/run/scenario_gen.h"
#include "sketchnav/sim/simulator.h"
#include "sketchnav/sim/world.h"

namespace sketchnav::app {
using run::GeneratedScenario;
using run::generateScenario;
using run::scenarioFamilies;
using run::sketchErrorKinds;
using run::writeScenario;
namespace fs = std::filesystem;
namespace {

using V2 = Eigen::Vector2d;

double boxDistance(const sim::Obstacle& o, const V2& p) {
  if (o.shape == sim::Obstacle::Shape::Cylinder) return (p - o.centre).norm() - o.radius;
  const V2 d = p - o.centre;
  const double c = std::cos(o.yaw), s = std::sin(o.yaw);
  const V2 l(c * d.x() + s * d.y(), -s * d.x() + c * d.y());
  const V2 q(std::abs(l.x()) - o.size_x / 2, std::abs(l.y()) - o.size_y / 2);
  const double out = V2(std::max(q.x(), 0.0), std::max(q.y(), 0.0)).norm();
  return out + std::min(std::max(q.x(), q.y()), 0.0);
}

// From a run's telemetry (true poses over time): the closest the robot's body came to a
// person and to a piece of furniture, the share of ticks in each executive mode, and how often
// the robot reversed a turn on the spot.
struct Telemetry {
  double people_m = NAN, obstacles_m = NAN;
  std::map<std::string, double> mode_share;
  // Ticks whose yaw-rate command (|w| > 0.3 rad/s) has the opposite sign of the previous such
  // command of the same stand (|v| <= 0.05 m/s throughout): a robot swinging left and right on
  // the spot instead of turning one way (doc/experiments.md "Dodge directions seen, not guessed").
  int turn_reversals = 0;
};

Telemetry readTelemetry(const std::string& dir, const sim::World& w) {
  Telemetry t;
  std::map<std::string, int> modes;
  int rows = 0;
  int last_turn = 0;  // sign of the last turn on the spot
  double people = INFINITY, obst = INFINITY;
  for (const run::TelemetryRecord& r : run::readTelemetryCsv(dir + "/telemetry.csv")) {
    // A row without the true pose (no simulator) or cut before its mode (a killed run).
    if (!r.truth || r.mode.empty()) continue;
    const V2 p(r.truth->x, r.truth->y);
    for (const auto& ped : w.pedestrians) {
      const auto st = sim::pedestrianAt(ped, r.t);
      people = std::min(people, (st.position - p).norm() - st.radius - w.robot.radius);
    }
    for (const auto& o : w.obstacles) obst = std::min(obst, boxDistance(o, p) - w.robot.radius);
    ++modes[r.mode];
    ++rows;
    if (std::abs(r.v_cmd) > 0.05) {
      last_turn = 0;  // driving: a new stand starts afresh
    } else if (std::abs(r.w_cmd) > 0.3) {
      const int sign = r.w_cmd > 0 ? 1 : -1;
      t.turn_reversals += last_turn == -sign;
      last_turn = sign;
    }
  }
  if (std::isfinite(people)) t.people_m = people;
  if (std::isfinite(obst)) t.obstacles_m = obst;
  for (const auto& [m, n] : modes) t.mode_share[m] = rows ? static_cast<double>(n) / rows : 0;
  return t;
}

// How often each executive event happened in a run (events.jsonl): which behaviours a run
// leaned on, the input for a failure's "why".
Json eventCounts(const std::string& dir) {
  std::map<std::string, int> n;
  std::ifstream in(dir + "/events.jsonl");
  for (std::string line; std::getline(in, line);) {
    try {
      ++n[Json::parse(line).value("type", "?")];
    } catch (const std::exception&) {
    }
  }
  return n;
}

Json numOrNull(double x) {
  return std::isfinite(x) ? Json(x) : Json(nullptr);
}

struct Agg {
  int n = 0, ok = 0, allowed = 0, allowed_ok = 0, collisions = 0, exec_ok = 0, reversals = 0;
  double goal_err_sum = 0, time_ok_sum = 0;
  double people_min = INFINITY, obst_min = INFINITY;
  void add(const Json& r) {
    ++n;
    const bool s = r.value("success", false);
    ok += s;
    exec_ok += r.value("executive_success", false);
    collisions += r.value("collided", false);
    reversals += r.value("turn_reversals", 0);
    if (r["sketch_allows_success"].is_boolean() && r["sketch_allows_success"].get<bool>()) {
      ++allowed;
      allowed_ok += s;
    }
    if (r["goal_error_m"].is_number()) goal_err_sum += r["goal_error_m"].get<double>();
    if (s && r["time_s"].is_number()) time_ok_sum += r["time_s"].get<double>();
    if (r["clearance_people_m"].is_number())
      people_min = std::min(people_min, r["clearance_people_m"].get<double>());
    if (r["clearance_obstacles_m"].is_number())
      obst_min = std::min(obst_min, r["clearance_obstacles_m"].get<double>());
  }
  Json toJson() const {
    return {{"scenarios", n},
            {"successes", ok},
            {"success_rate", n ? static_cast<double>(ok) / n : 0.0},
            {"executive_successes", exec_ok},
            {"sketch_allows", allowed},
            {"successes_where_sketch_allows", allowed_ok},
            {"success_rate_where_sketch_allows",
             allowed ? Json(static_cast<double>(allowed_ok) / allowed) : Json(nullptr)},
            {"collisions", collisions},
            {"turn_reversals", reversals},
            {"mean_goal_error_m", n ? Json(goal_err_sum / n) : Json(nullptr)},
            {"mean_time_s_of_successes", ok ? Json(time_ok_sum / ok) : Json(nullptr)},
            {"min_clearance_people_m", numOrNull(people_min)},
            {"min_clearance_obstacles_m", numOrNull(obst_min)}};
  }
  std::string row(const std::string& label) const {
    char b[400];
    auto f2 = [](double x) {
      char s[32];
      if (std::isfinite(x))
        std::snprintf(s, sizeof s, "%.2f", x);
      else
        std::snprintf(s, sizeof s, "-");
      return std::string(s);
    };
    std::snprintf(b, sizeof b, "| %s | %d | %d (%.0f %%) | %d / %d | %d | %s | %s | %s | %s | %d |",
                  label.c_str(), n, ok, n ? 100.0 * ok / n : 0.0, allowed_ok, allowed, exec_ok,
                  f2(n ? goal_err_sum / n : NAN).c_str(), f2(people_min).c_str(),
                  f2(obst_min).c_str(), f2(ok ? time_ok_sum / ok : NAN).c_str(), collisions);
    return b;
  }
};

int runScenariosCmd(const std::vector<std::string>& argv, GlobalOptions& g) {
  Args args("scenarios",
            "generate seeded worlds with human-like sketches; --run: the benchmark over them",
            "--generate N [--families corridor,hall,office,mixed] [--seed S] [--out DIR] [--run] "
            "[--jobs J] [--max-time T] | --regression [--run] ...");
  args.option("generate", "how many scenarios (scenario k: family k mod families, seed S + k)")
      .option("families", "comma separated families", "corridor,hall,office,mixed")
      .option("seed", "first seed", "1")
      .option("out", "output folder (default: runs/<UTC timestamp>)")
      .flag("regression",
            "the fixed regression set: dev seeds 1-48, all four families (12 each); instead of "
            "--generate / --seed / --families")
      .flag("run", "run every scenario in simulation and report the benchmark")
      .flag("reuse", "with --run: keep runs already in <out>/runs/<name>/summary.json")
      .option("jobs", "runs in parallel (child processes)", "2")
      .option("model", "landmark model (.slm); default: the demo set's cached model")
      .option("landmarks",
              "landmark set folder the landmarks' classes are drawn from (default: the demo "
              "set; with another set give --model trained on it)")
      .option("max-time", "give up each run after this many simulated seconds", "300");
  if (!args.parse(argv)) return 0;
  const bool regression = args.flagSet("regression");
  if (regression && !args.get("generate").empty())
    throw InputError("--regression is a fixed set: give it without --generate");
  if (!regression && args.get("generate").empty()) throw InputError("--generate N is required");
  // The regression set: scenarios 0..47 from seed 1 over the four families (development seeds,
  // doc/experiments.md); the held-out range is never part of it.
  const int n = regression ? 48 : args.getInt("generate");
  const int seed0 = regression ? 1 : args.getInt("seed");
  const int jobs = args.getInt("jobs");
  if (n < 1 || n > 100000) throw InputError("--generate must be in 1..100000");
  if (seed0 < 0) throw InputError("--seed must be >= 0");
  if (jobs < 1 || jobs > 64) throw InputError("--jobs must be in 1..64");
  const double max_time = args.getDouble("max-time");
  if (!(max_time > 0)) throw InputError("--max-time must be positive");
  const auto families = regression ? std::vector<std::string>{"corridor", "hall", "office", "mixed"}
                                   : args.getList("families");
  for (const auto& f : families)
    if (std::find(scenarioFamilies().begin(), scenarioFamilies().end(), f) ==
        scenarioFamilies().end())
      throw InputError("--families: unknown family '" + f +
                       "' (known: corridor, hall, office, mixed)");
  if (families.empty()) throw InputError("--families must name at least one family");
  const std::string landmark_dir =
      args.get("landmarks").empty() ? resourcePath("landmarks") : args.get("landmarks");
  const auto classes = mapsketch::landmarkClasses(landmark_dir);
  const bool run = args.flagSet("run");
  if (run) {
    run::runSettingsFrom(g.config);
    g.config.requireAllUsedExcept(run::driverSettingPrefixes());
  }
  const std::string out = makeOutputDir(args.get("out"));

  // --- generate ------------------------------------------------------------------------------
  Json index = Json::array();
  std::vector<GeneratedScenario> scen;
  const double outlier_m = nav::navSettingsFrom(g.config).exec.fit_outlier_m;
  for (int k = 0; k < n; ++k) {
    const std::string& fam = families[static_cast<size_t>(k) % families.size()];
    GeneratedScenario s = generateScenario(fam, static_cast<std::uint64_t>(seed0 + k), classes);
    writeScenario(s, out);
    // The sketch ceiling of this scenario: where the navigation's refit puts the goal with
    // every sketched landmark fixed exactly (sketchGoalErrorM).
    const sim::World w = sim::worldFromJson(s.world, s.name, resourceDir());
    const auto route = mapsketch::toRoute(mapsketch::sketchFromJson(s.sketch, s.name));
    const auto e = run::sketchGoalErrorM(w, route, outlier_m);
    Json kinds = Json::array();
    for (const auto& er : s.errors) kinds.push_back(er.kind);
    index.push_back({{"name", s.name},
                     {"family", s.family},
                     {"seed", s.seed},
                     {"route_length_m", s.meta["route_length_m"]},
                     {"landmarks", s.meta["landmarks_world"]},
                     {"people", s.meta["people"].size()},
                     {"obstacle_in_the_way", s.meta["obstacle_in_the_way"]},
                     {"errors", kinds},
                     {"sketch_goal_error_m", e ? Json(*e) : Json(nullptr)},
                     {"warnings", s.warnings.size()}});
    scen.push_back(std::move(s));
  }
  std::ofstream(out + "/scenarios.json")
      << Json({{"seed", seed0}, {"families", families}, {"scenarios", index}}).dump(1) << "\n";
  if (!run) {
    if (g.json) {
      printJson({{"out_dir", out}, {"scenarios", index}});
    } else {
      for (const auto& x : index) {
        std::string kinds;
        for (const auto& k : x["errors"])
          kinds += (kinds.empty() ? "" : ",") + k.get<std::string>();
        std::printf("%-14s %6.1f m  %2d landmarks  %d people  errors: %s\n",
                    x["name"].get<std::string>().c_str(), x["route_length_m"].get<double>(),
                    x["landmarks"].get<int>(), static_cast<int>(x["people"].get<size_t>()),
                    kinds.empty() ? "none" : kinds.c_str());
      }
      std::cout << "wrote " << n << " scenarios to " << out << "\n";
    }
    return 0;
  }

  // --- benchmark -----------------------------------------------------------------------------
  const std::string model =
      run::ensureModel(args.get("model"), true, run::runSettingsFrom(g.config).train);
  std::string config_file;
  if (!g.config.keys().empty()) {
    config_file = out + "/config.json";
    std::ofstream(config_file) << g.config.toJson().dump(2) << "\n";
  }
  std::vector<run::ScenarioSpec> specs;
  std::vector<size_t> spec_of;  // scenario index of each spec
  for (size_t i = 0; i < scen.size(); ++i) {
    const std::string dir = out + "/runs/" + scen[i].name;
    if (args.flagSet("reuse") && fs::exists(dir + "/summary.json")) continue;
    fs::create_directories(dir);
    run::ScenarioSpec sp;
    sp.label = scen[i].name;
    sp.world_file = out + "/" + scen[i].name + ".world.json";
    sp.sketch_file = out + "/" + scen[i].name + ".sketch.json";
    sp.seed = static_cast<int>(scen[i].seed);
    sp.model = model;
    sp.config_file = config_file;
    sp.max_time_s = max_time;
    sp.out_dir = dir;
    specs.push_back(sp);
    spec_of.push_back(i);
  }
  std::cerr << "scenarios: running " << specs.size() << " of " << scen.size() << ", " << jobs
            << " in parallel; outputs in " << out << "/runs\n";
  run::runScenarios(specs, jobs, true);

  Json rows = Json::array();
  Agg all;
  std::map<std::string, Agg> by_family, by_kind;
  for (size_t i = 0; i < scen.size(); ++i) {
    const auto& s = scen[i];
    const std::string dir = out + "/runs/" + s.name;
    Json r = {{"name", s.name}, {"family", s.family}};
    Json kinds = Json::array();
    for (const auto& e : s.errors) kinds.push_back(e.kind);
    r["errors"] = kinds;
    const run::ScenarioResult res = run::readRunFolder(dir);
    const Json& sm = res.summary;
    const sim::World w = sim::worldFromJson(s.world, s.name, resourceDir());
    r["ran"] = res.ran;
    r["success"] = res.ran && sm.value("success", false);
    r["executive_success"] = sm.value("executive_success", false);
    r["reason"] = res.ran ? sm.value("reason", "") : "the run produced no summary";
    r["collided"] = sm.value("collided", false);
    r["goal_error_m"] =
        sm.contains("distance_to_goal_m") ? sm["distance_to_goal_m"] : Json(nullptr);
    r["time_s"] = sm.contains("time_s") ? sm["time_s"] : Json(nullptr);
    r["min_clearance_m"] = sm.contains("min_clearance_m") ? sm["min_clearance_m"] : Json(nullptr);
    const Telemetry t = readTelemetry(dir, w);
    // The simulator's own figure (every step, people's waits included); from the telemetry's
    // rows for run folders written before it reported one.
    r["clearance_people_m"] = sm.contains("min_clearance_people_m") ? sm["min_clearance_people_m"]
                                                                    : numOrNull(t.people_m);
    r["clearance_obstacles_m"] = numOrNull(t.obstacles_m);
    r["mode_share"] = t.mode_share;
    r["turn_reversals"] = t.turn_reversals;
    r["events"] = eventCounts(dir);
    const Json diag = sm.value("diagnostics", Json::object());
    r["sketch_goal_error_m"] = diag.contains("sketch_goal_error_m")
                                   ? diag["sketch_goal_error_m"]
                                   : index[i]["sketch_goal_error_m"];
    r["sketch_allows_success"] = r["sketch_goal_error_m"].is_number()
                                     ? Json(r["sketch_goal_error_m"].get<double>() <= w.goal.radius)
                                     : Json(nullptr);
    r["odometry_error_m"] =
        diag.contains("odometry_error_m") ? diag["odometry_error_m"] : Json(nullptr);
    r["landmarks_recognised"] =
        sm.contains("landmarks_recognised") ? sm["landmarks_recognised"].size() : 0;
    r["landmarks"] = w.landmarks.size();
    r["route_length_m"] = s.meta["route_length_m"];
    rows.push_back(r);
    all.add(r);
    by_family[s.family].add(r);
    for (const auto& e : s.errors) by_kind[e.kind].add(r);
    if (s.errors.empty()) by_kind["(none)"].add(r);
  }
  Json jf = Json::object(), jk = Json::object();
  for (const auto& [f, a] : by_family) jf[f] = a.toJson();
  for (const auto& [k, a] : by_kind) jk[k] = a.toJson();
  const Json result = {{"seed", seed0},       {"scenarios", n},  {"families", families},
                       {"all", all.toJson()}, {"by_family", jf}, {"by_error_kind", jk},
                       {"runs", rows},        {"out_dir", out},  {"max_time_s", max_time}};
  std::ofstream(out + "/benchmark.json") << result.dump(1) << "\n";
  std::ostringstream md;
  md << "| set | scenarios | success | success where the sketch allows | executive "
        "success | mean goal error [m] | min gap to people [m] | min gap to furniture [m] | "
        "mean time of successes [s] | collisions "
        "|\n|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n"
     << all.row("all") << "\n";
  for (const auto& [f, a] : by_family) md << a.row(f) << "\n";
  for (const auto& k : sketchErrorKinds())
    if (by_kind.count(k)) md << by_kind[k].row("with " + k) << "\n";
  if (by_kind.count("(none)")) md << by_kind["(none)"].row("no drawing error") << "\n";
  md << "\n| scenario | success | reason | goal error [m] | sketch goal error [m] | odometry "
        "error [m] | landmarks seen | ticks avoiding | errors |\n"
        "|---|---|---|---:|---:|---:|---:|---:|---|\n";
  for (const auto& r : rows) {
    std::string kinds;
    for (const auto& k : r["errors"]) kinds += (kinds.empty() ? "" : ", ") + k.get<std::string>();
    char b[64] = "-", c[64] = "-";
    if (r["goal_error_m"].is_number())
      std::snprintf(b, sizeof b, "%.2f", r["goal_error_m"].get<double>());
    if (r["sketch_goal_error_m"].is_number())
      std::snprintf(c, sizeof c, "%.2f", r["sketch_goal_error_m"].get<double>());
    md << "| " << r["name"].get<std::string>() << " | " << (r["success"].get<bool>() ? "yes" : "no")
       << " | " << r["reason"].get<std::string>() << " | " << b << " | " << c << " | ";
    if (r["odometry_error_m"].is_number())
      md << std::round(r["odometry_error_m"].get<double>() * 100) / 100;
    else
      md << "-";
    const double avoid = r["mode_share"].value("avoid", 0.0) + r["mode_share"].value("detour", 0.0);
    md << " | " << r["landmarks_recognised"].get<size_t>() << "/" << r["landmarks"].get<size_t>()
       << " | " << std::lround(100 * avoid) << " % | " << kinds << " |\n";
  }
  std::ofstream(out + "/benchmark.md") << md.str();
  if (g.json)
    printJson(result);
  else
    std::cout << md.str() << "report: " << out << "/benchmark.md\n";
  return 0;
}

const CommandRegistration reg(
    "scenarios", "generate seeded worlds with human-like sketches; --run: the benchmark over them",
    runScenariosCmd);
}  // namespace
}  // namespace sketchnav::app
