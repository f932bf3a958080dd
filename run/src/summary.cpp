#include "sketchnav/run/summary.h"

namespace sketchnav::run {
namespace {

// A number figure, or `def` when it is missing or not a number (e.g. null: no clearance on a
// real robot).
double number(const Json& j, const char* key, double def) {
  return j.contains(key) && j[key].is_number() ? j[key].get<double>() : def;
}

}  // namespace

RunSummary RunSummary::fromJson(const Json& s) {
  RunSummary r;
  r.json = s;
  r.success = s.value("success", false);
  r.executive_success = s.contains("executive_success") && s["executive_success"].is_boolean() &&
                        s["executive_success"].get<bool>();
  r.reason = s.value("reason", "");
  r.failure = s.value("failure", "");
  r.time_s = number(s, "time_s", 0);
  r.wall_time_s = number(s, "wall_time_s", 0);
  r.real_time_factor = number(s, "real_time_factor", 0);
  r.path_length_m = number(s, "path_length_m", 0);
  r.min_clearance_m = number(s, "min_clearance_m", NAN);
  r.min_clearance_people_m = number(s, "min_clearance_people_m", NAN);
  if (s.contains("deviation_m") && s["deviation_m"].is_object()) {
    r.deviation_mean_m = number(s["deviation_m"], "mean", NAN);
    r.deviation_max_m = number(s["deviation_m"], "max", NAN);
  }
  if (s.contains("diagnostics") && s["diagnostics"].is_object()) {
    const Json& d = s["diagnostics"];
    Diagnostics dg;
    dg.odometry_error_m = number(d, "odometry_error_m", 0);
    dg.odometry_heading_error_deg = number(d, "odometry_heading_error_deg", 0);
    if (d.contains("goal_estimate_world") && d["goal_estimate_world"].is_array() &&
        d["goal_estimate_world"].size() == 2 && d["goal_estimate_world"][0].is_number() &&
        d["goal_estimate_world"][1].is_number())
      dg.goal_estimate_world = {d["goal_estimate_world"][0].get<double>(),
                                d["goal_estimate_world"][1].get<double>()};
    for (auto [key, field] : {std::pair{"goal_estimate_error_m", &dg.goal_estimate_error_m},
                              std::pair{"sketch_goal_error_m", &dg.sketch_goal_error_m}})
      if (d.contains(key) && d[key].is_number()) *field = d[key].get<double>();
    r.diagnostics = dg;
  }
  return r;
}

Json RunSummary::toJson() const {
  const auto orNull = [](double x) { return std::isnan(x) ? Json(nullptr) : Json(x); };
  Json s = {{"success", success},
            {"executive_success", executive_success},
            {"reason", reason},
            {"failure", failure},
            {"time_s", time_s},
            {"wall_time_s", wall_time_s},
            {"real_time_factor", real_time_factor},
            {"path_length_m", path_length_m},
            {"min_clearance_m", orNull(min_clearance_m)},
            {"min_clearance_people_m", orNull(min_clearance_people_m)}};
  s["deviation_m"] =
      std::isnan(deviation_mean_m) && std::isnan(deviation_max_m)
          ? Json(nullptr)
          : Json{{"mean", orNull(deviation_mean_m)}, {"max", orNull(deviation_max_m)}};
  if (diagnostics) {
    const Diagnostics& dg = *diagnostics;
    Json d = {{"odometry_error_m", dg.odometry_error_m},
              {"odometry_heading_error_deg", dg.odometry_heading_error_deg}};
    if (dg.goal_estimate_error_m) d["goal_estimate_error_m"] = *dg.goal_estimate_error_m;
    if (dg.goal_estimate_world)
      d["goal_estimate_world"] = {(*dg.goal_estimate_world)[0], (*dg.goal_estimate_world)[1]};
    if (dg.sketch_goal_error_m) d["sketch_goal_error_m"] = *dg.sketch_goal_error_m;
    s["diagnostics"] = d;
  }
  return s;
}

}  // namespace sketchnav::run
