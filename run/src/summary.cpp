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
    for (auto [key, field] : {std::pair{"goal_estimate_error_m", &dg.goal_estimate_error_m},
                              std::pair{"sketch_goal_error_m", &dg.sketch_goal_error_m}})
      if (d.contains(key) && d[key].is_number()) *field = d[key].get<double>();
    r.diagnostics = dg;
  }
  return r;
}

}  // namespace sketchnav::run
