// sketchnav tune: sweep the turn-radius gain (servo.lambda, or another setting) over simulated
// scenarios x seeds; table + plot + a recommended value. --offline: the same gains applied to
// the per-frame offsets of replay CSVs (no simulation).
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>

#include "cli.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/paths.h"
#include "sketchnav/run/experiments.h"
#include "sketchnav/run/plot.h"
#include "sketchnav/run/run.h"
#include "sketchnav/run/scenario.h"
#include "sketchnav/servo/turn_law.h"

namespace sketchnav::app {
using run::drawLinePlot;
using run::plotColor;
using run::PlotSpec;
namespace fs = std::filesystem;
namespace {

struct Row {
  double value = 0;
  int trials = 0, successes = 0;
  double time_s = NAN, deviation_m = NAN, oscillation = NAN, min_clearance_m = NAN;
};

double mean(const std::vector<double>& v) {
  double s = 0;
  int n = 0;
  for (double x : v)
    if (std::isfinite(x)) s += x, ++n;
  return n ? s / n : NAN;
}

std::vector<double> parseValues(const std::vector<std::string>& items, const std::string& opt) {
  std::vector<double> out;
  for (const auto& s : items) {
    try {
      size_t used = 0;
      out.push_back(std::stod(s, &used));
      if (used != s.size()) throw std::invalid_argument(s);
    } catch (...) {
      throw InputError("--" + opt + ": '" + s + "' is not a number");
    }
  }
  if (out.empty()) throw InputError("--" + opt + ": give at least one value");
  return out;
}

/// The documented rule (doc/replay-and-tune.md): the highest success rate; among the values
/// within one trial of it, the least oscillation (sign changes of w per metre); ties -> the
/// shorter mean time to goal.
size_t recommend(const std::vector<Row>& rows) {
  double best_rate = -1;
  int trials = 1;
  for (const auto& r : rows) {
    best_rate = std::max(best_rate, r.trials ? double(r.successes) / r.trials : 0.0);
    trials = std::max(trials, r.trials);
  }
  size_t pick = 0;
  bool have = false;
  for (size_t i = 0; i < rows.size(); ++i) {
    const auto& r = rows[i];
    const double rate = r.trials ? double(r.successes) / r.trials : 0.0;
    if (rate + 1.0 / trials + 1e-9 < best_rate) continue;
    auto key = [](const Row& x) {
      return std::make_pair(std::isfinite(x.oscillation) ? x.oscillation : 1e9,
                            std::isfinite(x.time_s) ? x.time_s : 1e9);
    };
    if (!have || key(r) < key(rows[pick])) pick = i, have = true;
  }
  return pick;
}

std::string f2(double v, int dec = 2) {
  if (!std::isfinite(v)) return "-";
  char b[32];
  std::snprintf(b, sizeof b, "%.*f", dec, v);
  return b;
}

void writePlot(const std::string& path, const std::string& param, const std::vector<Row>& rows,
               double rec) {
  std::vector<double> x;
  std::vector<double> rate, time, dev, osc, clr;
  for (const auto& r : rows) {
    x.push_back(r.value);
    rate.push_back(r.trials ? 100.0 * r.successes / r.trials : NAN);
    time.push_back(r.time_s);
    dev.push_back(r.deviation_m);
    osc.push_back(r.oscillation);
    clr.push_back(r.min_clearance_m);
  }
  PlotSpec a{"success rate", param, "success [%]", 420, 280, 0, 100, rec};
  PlotSpec b{"time to goal (successful trials)", param, "time [s]", 420, 280, NAN, NAN, rec};
  PlotSpec c{"path deviation / min clearance", param, "[m]", 420, 280, 0, NAN, rec};
  PlotSpec d{"oscillation", param, "sign changes of w per m", 420, 280, 0, NAN, rec};
  const cv::Mat pa = drawLinePlot(a, {{"success rate", x, rate, plotColor(0)}});
  const cv::Mat pb = drawLinePlot(b, {{"mean time to goal", x, time, plotColor(1)}});
  const cv::Mat pc = drawLinePlot(
      c, {{"mean deviation", x, dev, plotColor(2)}, {"min clearance", x, clr, plotColor(3)}});
  const cv::Mat pd = drawLinePlot(d, {{"oscillation", x, osc, plotColor(4)}});
  cv::Mat top, bottom, all;
  cv::hconcat(pa, pb, top);
  cv::hconcat(pc, pd, bottom);
  cv::vconcat(top, bottom, all);
  cv::imwrite(path, all);
}

/// Offline mode: apply each gain to the per-frame offsets of replay CSVs.
int runOffline(const std::vector<std::string>& files, const std::vector<double>& values,
               const std::string& out, GlobalOptions& g) {
  std::vector<double> x_t, errors;  // errors holds x_d
  std::vector<std::string> expected;
  for (const auto& f : files) {
    std::ifstream in(f);
    if (!in) throw InputError("--offline " + f + ": cannot read");
    std::string line;
    std::getline(in, line);
    if (line.rfind("frame,file,windows,class,inliers,x_t,x_d,error", 0) != 0)
      throw InputError("--offline " + f + ": not a replay.csv (sketchnav replay output)");
    while (std::getline(in, line)) {
      std::vector<std::string> c;
      std::string cell;
      std::istringstream ls(line);
      while (std::getline(ls, cell, ',')) c.push_back(cell);
      if (c.size() < 11 || c[5].empty() || c[6].empty()) continue;  // landmark not found
      x_t.push_back(std::stod(c[5]));
      errors.push_back(std::stod(c[6]));  // x_d
      expected.push_back(c[10]);
    }
  }
  if (errors.empty()) throw InputError("--offline: no frame with a detection in the given CSVs");
  const servo::TurnLawParams base = servo::turnLawParamsFrom(g.config);
  g.config.requireAllUsed();
  Json rows = Json::array();
  std::printf("%-8s %8s %10s %10s %12s %10s\n", "lambda", "frames", "mean|w|", "saturated",
              "w sign chg", "agreement");
  std::vector<double> xs, mw, sat;
  for (double v : values) {
    servo::TurnLawParams p = base;
    p.lambda = v;
    p.validate();
    const servo::TurnLaw law(p);
    double sum_w = 0;
    int saturated = 0, changes = 0, last = 0, agree = 0, with_truth = 0;
    for (size_t i = 0; i < errors.size(); ++i) {
      const auto c = law.compute(x_t[i], errors[i]);
      sum_w += std::abs(c.w);
      saturated += c.saturated;
      const int sg = c.w > 1e-3 ? 1 : c.w < -1e-3 ? -1 : 0;
      if (sg && last && sg != last) ++changes;
      if (sg) last = sg;
      if (!expected[i].empty()) ++with_truth, agree += expected[i] == servo::toString(c.state);
    }
    const double n = static_cast<double>(errors.size());
    std::printf("%-8.3g %8zu %10.3f %9.0f%% %12d %10s\n", v, errors.size(), sum_w / n,
                100.0 * saturated / n, changes,
                with_truth ? (f2(100.0 * agree / with_truth, 1) + "%").c_str() : "-");
    rows.push_back({{"lambda", v},
                    {"frames", errors.size()},
                    {"mean_abs_w", sum_w / n},
                    {"saturated_fraction", saturated / n},
                    {"w_sign_changes", changes},
                    {"agreement", with_truth ? Json(double(agree) / with_truth) : Json(nullptr)}});
    xs.push_back(v), mw.push_back(sum_w / n), sat.push_back(saturated / n);
  }
  PlotSpec s{"offline: yaw rate over replayed frames", "servo.lambda", "", 640, 400, 0, NAN, NAN};
  cv::imwrite(out + "/tune-offline.png",
              drawLinePlot(s, {{"mean |w| [rad/s]", xs, mw, plotColor(0)},
                               {"saturated fraction", xs, sat, plotColor(1)}}));
  const Json j = {{"mode", "offline"}, {"rows", rows}, {"out_dir", out}};
  std::ofstream(out + "/tune.json") << j.dump(2) << "\n";
  if (g.json)
    printJson(j);
  else
    std::cout << "plot: " << out << "/tune-offline.png\n";
  return 0;
}

int runTune(const std::vector<std::string>& argv, GlobalOptions& g) {
  Args args("tune", "sweep the turn-radius gain over scenarios; table + plot",
            "[--lambda 0.2,0.4,...] [--scenarios a,b] [--seeds N] [--jobs J] [--out DIR]\n"
            "       sketchnav tune --offline replay.csv[,...] [--lambda ...]");
  args.option("lambda", "values to try (of --param)", "0.2,0.4,0.8,1.2,1.6")
      .option("param", "the setting swept", "servo.lambda")
      .option("scenarios", "experiment variants to run (see `sketchnav experiments --list`)",
              "exp3-8")
      .option("seeds", "seeded trials per scenario and value", "3")
      .option("seed", "first seed (trial k uses S + k; the same sketches for every value)", "1")
      .option("jobs", "runs in parallel (child processes)", "2")
      .option("max-time", "give up each run after this many simulated seconds")
      .option("model", "landmark model (.slm); default: the demo set's cached model")
      .option("out", "output folder (default: runs/<UTC timestamp>)")
      .option("offline", "comma separated replay.csv files: apply the gains to their offsets");
  if (!args.parse(argv)) return 0;
  const std::vector<double> values = parseValues(args.getList("lambda"), "lambda");
  const std::string param = args.get("param");
  if (param.empty() || param.find('=') != std::string::npos)
    throw InputError("--param must be a setting name such as servo.lambda");
  if (!args.get("offline").empty()) {
    const std::string out = makeOutputDir(args.get("out"));
    return runOffline(args.getList("offline"), values, out, g);
  }
  const int seeds = args.getInt("seeds"), jobs = args.getInt("jobs"), seed0 = args.getInt("seed");
  if (seeds < 1 || seeds > 1000) throw InputError("--seeds must be in 1..1000");
  if (jobs < 1 || jobs > 64) throw InputError("--jobs must be in 1..64");
  if (seed0 < 0) throw InputError("--seed must be >= 0");
  double max_time = 0;
  if (!args.get("max-time").empty()) {
    max_time = args.getDouble("max-time");
    if (!(max_time > 0)) throw InputError("--max-time must be positive");
  }
  std::vector<run::Variant> scen;
  for (const auto& n : args.getList("scenarios")) scen.push_back(run::makeVariant(n));
  const run::SketchNoise noise = run::sketchNoiseFrom(g.config);
  // The runs' settings (every run setting; the runs apply them again): a typo fails here, and
  // --param must name one of them.
  const run::RunSettings settings = run::runSettingsFrom(g.config);
  g.config.requireAllUsedExcept(run::driverSettingPrefixes());
  {
    const auto known = g.config.knownKeys();
    if (std::find(known.begin(), known.end(), param) == known.end())
      throw InputError("--param: unknown setting '" + param + "' (did you mean '" +
                       closestKey(param, known) + "'?)");
  }
  const std::string out = makeOutputDir(args.get("out"));
  const std::string model = run::ensureModel(args.get("model"), true, settings.train);
  const std::string config_file = run::writeBatchConfig(g.config, out);
  std::vector<run::ScenarioSpec> specs;
  std::vector<size_t> value_of;
  for (size_t si = 0; si < scen.size(); ++si) {
    const auto& v = scen[si];
    const std::string sdir = out + "/" + v.name;
    const std::string wf = run::writeVariantWorld(v, sdir);
    for (int k = 0; k < seeds; ++k) {
      const int seed = seed0 + k;
      const std::string sk = sdir + "/sketch-" + std::to_string(seed) + ".json";
      run::writeVariantSketch(v, noise, seed, sk);
      for (size_t vi = 0; vi < values.size(); ++vi) {
        run::ScenarioSpec s;
        std::ostringstream val;
        val << values[vi];
        s.label = v.name + " " + param + "=" + val.str() + " seed " + std::to_string(seed);
        s.world_file = wf;
        s.sketch_file = sk;
        s.seed = seed;
        s.model = model;
        s.config_file = config_file;
        s.sets = {param + "=" + val.str()};
        s.max_time_s = max_time;
        s.out_dir = sdir + "/" + param + "=" + val.str() + "/seed-" + std::to_string(seed);
        specs.push_back(s);
        value_of.push_back(vi);
      }
    }
  }
  std::cerr << "tune: " << values.size() << " values x " << scen.size() << " scenarios x " << seeds
            << " seeds = " << specs.size() << " runs, " << jobs << " in parallel; outputs in "
            << out << "\n";
  const auto results = run::runScenarios(specs, jobs, true);

  std::vector<Row> rows(values.size());
  for (size_t vi = 0; vi < values.size(); ++vi) {
    std::vector<double> t, d, o, c;
    Row& r = rows[vi];
    r.value = values[vi];
    for (size_t i = 0; i < specs.size(); ++i) {
      if (value_of[i] != vi) continue;
      const auto& x = results[i];
      ++r.trials;
      if (x.success) ++r.successes, t.push_back(x.time_s);
      if (x.ran)
        d.push_back(x.deviation_mean_m), o.push_back(x.oscillation_per_m),
            c.push_back(x.min_clearance_m);
    }
    r.time_s = mean(t);
    r.deviation_m = mean(d);
    r.oscillation = mean(o);
    r.min_clearance_m = c.empty() ? NAN : *std::min_element(c.begin(), c.end());
  }
  const size_t rec = recommend(rows);
  std::ostringstream table, csv;
  table << param << "  runs  success  time[s]  deviation[m]  oscillation[/m]  min clearance[m]\n";
  csv << "value,runs,successes,success_rate,mean_time_s,mean_deviation_m,oscillation_per_m,"
         "min_clearance_m\n";
  Json jrows = Json::array();
  auto jn = [](double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); };
  for (const auto& r : rows) {
    const double rate = r.trials ? double(r.successes) / r.trials : 0.0;
    char b[300];
    std::snprintf(b, sizeof b, "%-12.4g %4d  %5.0f %%  %7s  %12s  %15s  %16s\n", r.value, r.trials,
                  100 * rate, f2(r.time_s, 1).c_str(), f2(r.deviation_m).c_str(),
                  f2(r.oscillation).c_str(), f2(r.min_clearance_m).c_str());
    table << b;
    csv << r.value << ',' << r.trials << ',' << r.successes << ',' << rate << ',' << f2(r.time_s, 3)
        << ',' << f2(r.deviation_m, 4) << ',' << f2(r.oscillation, 4) << ','
        << f2(r.min_clearance_m, 4) << '\n';
    jrows.push_back({{"value", r.value},
                     {"runs", r.trials},
                     {"successes", r.successes},
                     {"success_rate", rate},
                     {"mean_time_s", jn(r.time_s)},
                     {"mean_deviation_m", jn(r.deviation_m)},
                     {"oscillation_per_m", jn(r.oscillation)},
                     {"min_clearance_m", jn(r.min_clearance_m)}});
  }
  std::ofstream(out + "/tune.csv") << csv.str();
  writePlot(out + "/tune.png", param, rows, rows[rec].value);
  const Json j = {{"param", param},
                  {"rows", jrows},
                  {"recommended", rows[rec].value},
                  {"rule",
                   "highest success rate; within one trial of it, least oscillation; "
                   "then shortest time"},
                  {"out_dir", out}};
  std::ofstream(out + "/tune.json") << j.dump(2) << "\n";
  if (g.json) {
    printJson(j);
  } else {
    std::cout << table.str() << "recommended " << param << " = " << rows[rec].value
              << " (highest success rate; within one trial of it, least oscillation; then "
                 "shortest time)\nplot: "
              << out << "/tune.png\n";
  }
  return 0;
}

const CommandRegistration reg("tune", "sweep the turn-radius gain over scenarios; table + plot",
                              runTune);
}  // namespace
}  // namespace sketchnav::app
