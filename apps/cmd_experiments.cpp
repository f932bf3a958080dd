// sketchnav experiments: the paper's experiments 2-4 in simulation, N trials each; report.
// Variants are generated from the lab world (run/experiments.h); every trial draws its own
// sketch (sketch noise) and runs with its own simulator seed (odometry / sensor noise).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <sstream>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "cli.h"
#include "sketchnav/core/config.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/paths.h"
#include "sketchnav/mapsketch/io.h"
#include "sketchnav/mapsketch/route.h"
#include "sketchnav/nav/executive.h"
#include "sketchnav/run/experiments.h"
#include "sketchnav/run/judge.h"
#include "sketchnav/run/run.h"
#include "sketchnav/run/scenario.h"
#include "sketchnav/run/summary.h"
#include "sketchnav/sim/map_render.h"
#include "sketchnav/sim/world.h"

namespace sketchnav::app {
namespace fs = std::filesystem;
namespace {

struct VariantStats {
  int trials = 0, successes = 0;
  // Trials whose sketch alone puts the goal outside the goal region: the navigation's refit to
  // every landmark fixed exactly (summary diagnostics.sketch_goal_error_m) misses it.
  int sketch_limited = 0, sketch_known = 0;
  double time_sum = 0;
  std::vector<run::TrialFailure> failures;  // of the failed trials
};

// The share of `n` seeded sketches of `v` (seeds seed0, seed0 + 1, ...: the trials' sketches
// first) whose goal, refitted with every sketched landmark fixed exactly (sketchGoalErrorM),
// lands inside the goal region: the success rate a robot with perfect perception and odometry
// reaches with the navigation's refit. Measured on many sketches, not only the trials', so a
// variant's aim can be judged against what its drawing errors allow.
double sketchCeiling(const run::Variant& v, const run::SketchNoise& noise, int seed0, int n,
                     const Config& config) {
  const sim::World world = sim::worldFromJson(v.world, v.name, resourceDir());
  mapsketch::RouteParams rp;
  applyConfig(rp, config, "route");
  const double outlier_m = nav::navSettingsFrom(config).exec.fit_outlier_m;
  int inside = 0;
  for (int k = 0; k < n; ++k) {
    try {
      const auto route = mapsketch::toRoute(
          mapsketch::sketchFromJson(run::variantSketch(v, noise, seed0 + k)), rp);
      const auto e = run::sketchGoalErrorM(world, route, outlier_m);
      inside += e && *e <= world.goal.radius;
    } catch (const InputError&) {
      // A sketch that gives no route cannot be followed: it counts as outside.
    }
  }
  return n > 0 ? static_cast<double>(inside) / n : NAN;
}

void drawVariantFigure(const std::string& path, const run::Variant& v,
                       const std::vector<const run::ScenarioResult*>& trials) {
  const sim::World world = sim::worldFromJson(v.world, v.name, resourceDir());
  sim::MapCanvas canvas(world, 40.0, 0.5, true);
  canvas.drawPolyline(v.drawn_path, {0, 0, 0}, false, 2);
  for (const auto* r : trials)
    if (!r->trajectory.empty())
      canvas.drawPoses(r->trajectory,
                       r->success ? cv::Scalar(40, 150, 40) : cv::Scalar(30, 30, 210), true, 2);
  canvas.drawStart(v.drawn_path.front());
  canvas.drawGoal({world.goal.centre.x(), world.goal.centre.y()}, world.goal.radius);
  // A title band above the map and a legend band below it (the map fills its canvas).
  const cv::Mat& map = canvas.image();
  cv::Mat fig(map.rows + 52, map.cols, CV_8UC3, cv::Scalar(255, 255, 255));
  map.copyTo(fig(cv::Rect(0, 28, map.cols, map.rows)));
  cv::putText(fig, v.name + ": " + v.description, {8, 19}, cv::FONT_HERSHEY_SIMPLEX, 0.45,
              {0, 0, 0}, 1, cv::LINE_AA);
  int x = 8;
  const int y = fig.rows - 9;
  const std::vector<std::pair<std::string, cv::Scalar>> legend = {
      {"sketched path (as intended)", {0, 0, 0}},
      {"trajectory, success", {40, 150, 40}},
      {"trajectory, failure", {30, 30, 210}}};
  for (size_t i = 0; i < legend.size(); ++i) {
    for (int u = 0; u < 28; u += (i ? 9 : 28))
      cv::line(fig, {x + u, y - 4}, {x + std::min(28, u + (i ? 5 : 28)), y - 4}, legend[i].second,
               2);
    cv::putText(fig, legend[i].first, {x + 34, y}, cv::FONT_HERSHEY_SIMPLEX, 0.42, {0, 0, 0}, 1,
                cv::LINE_AA);
    x += 34 + 12 +
         cv::getTextSize(legend[i].first, cv::FONT_HERSHEY_SIMPLEX, 0.42, 1, nullptr).width;
  }
  cv::putText(fig, "stars: landmarks", {x, y}, cv::FONT_HERSHEY_SIMPLEX, 0.42, {90, 90, 90}, 1,
              cv::LINE_AA);
  if (!cv::imwrite(path, fig)) throw RuntimeError("cannot write " + path);
}

int runExperiments(const std::vector<std::string>& argv, GlobalOptions& g) {
  Args args("experiments", "the paper's experiments 2-4 in simulation, N trials each; report",
            "[--trials N] [--variants a,b] [--out DIR] [--jobs J] [--seed S] [--max-time T]");
  args.option("trials", "trials per variant (each: its own sketch noise and simulator seed)", "10")
      .option("variants", "comma separated variant names (default: all 13)")
      .option("out", "output folder (default: runs/<UTC timestamp>)")
      .option("jobs", "trials run in parallel (child processes)", "2")
      .option("seed", "first seed; trial k of every variant uses seed S + k", "1")
      .option("model", "landmark model (.slm); default: the demo set's cached model")
      .option("ceiling",
              "sketches per variant for the sketch ceiling: the success rate perfect "
              "perception and odometry would reach with these drawing errors from the "
              "landmarks alone, without the goal doorway (0 = skip)",
              "2000")
      .option("max-time",
              "give up each trial after this many simulated seconds "
              "(default: nav.max_time_s)")
      .flag("list", "print the variant names and descriptions and exit");
  if (!args.parse(argv)) return 0;
  if (args.flagSet("list")) {
    for (const auto& n : run::variantNames())
      std::cout << n << "\t" << run::makeVariant(n).description << "\n";
    return 0;
  }
  const int trials = args.getInt("trials");
  const int jobs = args.getInt("jobs");
  const int seed0 = args.getInt("seed");
  if (trials < 1 || trials > 10000) throw InputError("--trials must be in 1..10000");
  if (jobs < 1 || jobs > 64) throw InputError("--jobs must be in 1..64");
  if (seed0 < 0) throw InputError("--seed must be >= 0");
  const int ceiling_n = args.getInt("ceiling");
  if (ceiling_n < 0 || ceiling_n > 1000000) throw InputError("--ceiling must be in 0..1000000");
  double max_time = 0;
  if (!args.get("max-time").empty()) {
    max_time = args.getDouble("max-time");
    if (!(max_time > 0)) throw InputError("--max-time must be positive");
  }
  std::vector<std::string> names =
      args.get("variants").empty() ? run::variantNames() : args.getList("variants");
  std::vector<run::Variant> variants;
  for (const auto& n : names) variants.push_back(run::makeVariant(n));  // InputError on unknown
  const run::SketchNoise noise = run::sketchNoiseFrom(g.config);
  // The trials' settings (every run setting; the trials apply them again): a typo fails here.
  const run::RunSettings settings = run::runSettingsFrom(g.config);
  g.config.requireAllUsedExcept(run::driverSettingPrefixes());

  const std::string out = makeOutputDir(args.get("out"));
  const std::string model = run::ensureModel(args.get("model"), true, settings.train);
  const std::string config_file = run::writeBatchConfig(g.config, out);

  std::vector<run::ScenarioSpec> specs;
  for (size_t vi = 0; vi < variants.size(); ++vi) {
    const run::Variant& v = variants[vi];
    const std::string vdir = out + "/" + v.name;
    const std::string wf = run::writeVariantWorld(v, vdir);
    for (int k = 0; k < trials; ++k) {
      run::ScenarioSpec s;
      s.seed = seed0 + k;
      s.label = v.name + " #" + std::to_string(k + 1);
      s.world_file = wf;
      s.out_dir = vdir + "/trial-" + std::to_string(k + 1);
      fs::create_directories(s.out_dir);
      s.sketch_file = s.out_dir + "/sketch.json";
      run::writeVariantSketch(v, noise, s.seed, s.sketch_file);
      s.model = model;
      s.config_file = config_file;
      s.max_time_s = max_time;
      specs.push_back(s);
    }
  }
  std::cerr << "experiments: " << variants.size() << " variants x " << trials << " trials, " << jobs
            << " in parallel; outputs in " << out << "\n";
  std::vector<double> ceiling(variants.size(), NAN);
  if (ceiling_n > 0) {
    std::cerr << "experiments: sketch ceiling over " << ceiling_n << " sketches per variant\n";
    for (size_t vi = 0; vi < variants.size(); ++vi)
      ceiling[vi] = sketchCeiling(variants[vi], noise, seed0, ceiling_n, g.config);
  }
  const auto results = run::runScenarios(specs, jobs, true);

  // --- aggregate, figures, report ---------------------------------------------------------
  Json jv = Json::object();
  std::ostringstream md;
  md << "# sketchnav experiments (paper's experiments 2-4, simulated)\n\n"
     << "Command: `sketchnav experiments --trials " << trials << " --variants ";
  for (size_t i = 0; i < names.size(); ++i) md << (i ? "," : "") << names[i];
  md << " --seed " << seed0 << (max_time > 0 ? " --max-time " + args.get("max-time") : "")
     << "`  \nGenerated " << utcTimestamp() << ". Each trial: its own hand-drawn-like sketch "
     << "(landmark boxes sigma " << noise.landmark_sigma_m << " m, distances sigma "
     << noise.distance_sigma * 100 << " % rounded to " << noise.distance_round_m
     << " m, guide-line corners sigma " << noise.path_sigma_m
     << " m) and its own simulator seed (odometry slip, drift, image and range noise). "
     << "Success = inside the goal region without a collision (simulator ground truth). "
     << "Mean time over successful trials. *Sketch-limited*: trials whose sketch alone puts the "
     << "goal outside the goal region: the navigation's refit of the sketch, with every sketched "
     << "landmark fixed exactly where it is, maps the drawn goal that far off (perfect "
     << "perception and odometry would still fail those with this refit). *Sketch ceiling*: the "
     << "same judged on " << ceiling_n << " sketches of the variant (the trials' first): the "
     << "success rate perfect perception and odometry would reach with these drawing errors "
     << "and this refit. "
     << (noise.goal_doorway
             ? "The sketches say the goal is the doorway in front of it (goal_place): a robot "
               "that finds the door with its laser is not bound by either figure."
             : "The sketches give the goal as a bare point (experiments.sketch.goal_doorway "
               "off).")
     << "\n\n"
     << "| variant | trials | successes | success rate | mean time [s] | sketch-limited | "
        "sketch ceiling | failures |\n"
     << "|---|---:|---:|---:|---:|---:|---:|---|\n";
  std::ostringstream figs;
  std::ostringstream table;
  table << "variant                   trials  success  rate    mean time [s]  sketch-limited  "
           "ceiling\n";
  for (size_t vi = 0; vi < variants.size(); ++vi) {
    const run::Variant& v = variants[vi];
    VariantStats st;
    const double goal_radius =
        v.world.contains("goal") ? v.world["goal"].value("radius", 0.5) : 0.5;
    std::vector<const run::ScenarioResult*> rs;
    for (size_t i = 0; i < specs.size(); ++i) {
      if (specs[i].label.rfind(v.name + " #", 0) != 0) continue;
      const auto& r = results[i];
      rs.push_back(&r);
      ++st.trials;
      // (A trial without a summary has none.)
      const auto diag = r.ran ? run::RunSummary::fromJson(r.summary).diagnostics : std::nullopt;
      if (diag && diag->sketch_goal_error_m) {
        ++st.sketch_known;
        st.sketch_limited += *diag->sketch_goal_error_m > goal_radius;
      }
      if (r.success) {
        ++st.successes;
        st.time_sum += r.time_s;
      } else {
        st.failures.push_back(run::trialFailure(r.failure, r.reason, r.summary));
      }
    }
    const double rate = st.trials ? static_cast<double>(st.successes) / st.trials : 0.0;
    const double mean_t = st.successes ? st.time_sum / st.successes : NAN;
    jv[v.name] = {
        {"trials", st.trials},
        {"successes", st.successes},
        {"success_rate", rate},
        {"mean_time_s", std::isfinite(mean_t) ? Json(mean_t) : Json(nullptr)},
        {"sketch_limited", st.sketch_known ? Json(st.sketch_limited) : Json(nullptr)},
        {"sketch_ceiling", std::isfinite(ceiling[vi]) ? Json(ceiling[vi]) : Json(nullptr)}};
    char buf[300];
    const std::string limited = st.sketch_known ? std::to_string(st.sketch_limited) : "-";
    char ceil_s[16] = "-";
    if (std::isfinite(ceiling[vi]))
      std::snprintf(ceil_s, sizeof ceil_s, "%.1f %%", 100 * ceiling[vi]);
    // Built as a string: the failure list has no length limit (a fixed buffer cut a row of
    // five failures, and the next row ran into it).
    std::snprintf(buf, sizeof buf, "| %s | %d | %d | %.0f %% | %s | %s | %s | ", v.name.c_str(),
                  st.trials, st.successes, 100 * rate,
                  std::isfinite(mean_t)
                      ? (std::to_string(static_cast<int>(std::lround(mean_t)))).c_str()
                      : "-",
                  limited.c_str(), ceil_s);
    md << buf << run::summariseFailures(st.failures) << " |\n";
    std::snprintf(buf, sizeof buf, "%-25s %6d  %7d  %5.0f %%  %-13s  %-14s  %s\n", v.name.c_str(),
                  st.trials, st.successes, 100 * rate,
                  std::isfinite(mean_t) ? std::to_string(mean_t).substr(0, 6).c_str() : "-",
                  limited.c_str(), ceil_s);
    table << buf;
    const std::string png = v.name + ".png";
    try {
      drawVariantFigure(out + "/" + png, v, rs);
      figs << "### " << v.name << "\n\n"
           << v.description << ".\n\n![" << v.name << "](" << png << ")\n\n";
    } catch (const std::exception& e) {
      figs << "### " << v.name << "\n\n(figure failed: " << e.what() << ")\n\n";
    }
  }
  md << "\nFigures: landmarks (stars), start (dot), goal (double circle), the guide line as the "
        "user meant it (solid; each trial's sketch adds its own drawing errors), the true "
        "trajectories (dashed; green success, red failure). Per-trial runs (summary.json, "
        "telemetry.csv, trajectory.png, sketch.json) are in `<variant>/trial-<k>/`.\n\n"
     << figs.str();
  std::ofstream(out + "/report.md") << md.str();
  const Json result = {{"trials", trials}, {"variants", jv}, {"out_dir", out}};
  std::ofstream(out + "/experiments.json") << result.dump(2) << "\n";
  if (g.json) {
    printJson(result);
  } else {
    std::cout << table.str() << "report: " << out << "/report.md\n";
  }
  bool any_ran = false;
  for (const auto& r : results) any_ran = any_ran || r.ran;
  return any_ran ? 0 : 1;
}

const CommandRegistration reg("experiments",
                              "the paper's experiments 2-4 in simulation, N trials each; report",
                              runExperiments);
}  // namespace
}  // namespace sketchnav::app
