#include "sketchnav/nav/landmark_stage.h"

#include <cmath>

#include "sketchnav/core/config.h"
#include "sketchnav/nav/sections.h"

namespace sketchnav::nav {

void SelectParams::validate() const {
  require(bearing_gate_deg > 0 && bearing_gate_deg <= 180, "nav.select.bearing_gate_deg",
          "must be in (0, 180]");
  require(range_gate_rel > 0, "nav.select.range_gate_rel", "must be > 0");
  require(range_gate_min_m >= 0, "nav.select.range_gate_min_m", "must be >= 0");
  require(bearing_sigma_deg > 0, "nav.select.bearing_sigma_deg", "must be > 0");
  require(range_sigma_m > 0, "nav.select.range_sigma_m", "must be > 0");
}

int selectCandidate(const std::vector<Candidate>& cands, const std::string& class_name, double pb,
                    double pr, const SelectParams& p) {
  const double deg = M_PI / 180;
  int best = -1;
  double best_cost = 0;
  for (size_t i = 0; i < cands.size(); ++i) {
    const auto& c = cands[i];
    if (!c.detection || c.detection->class_name != class_name) continue;
    const double db = std::abs(wrapAngle(c.detection->bearing - pb));
    if (db > p.bearing_gate_deg * deg) continue;
    double cost = db / (p.bearing_sigma_deg * deg);
    if (c.range_m > 0 && pr > 0) {
      const double dr = std::abs(c.range_m - pr);
      if (dr > std::max(p.range_gate_min_m, p.range_gate_rel * pr)) continue;
      cost += dr / p.range_sigma_m;
    }
    if (best < 0 || cost < best_cost - 1e-9 ||
        (std::abs(cost - best_cost) <= 1e-9 &&
         c.detection->inliers > cands[best].detection->inliers)) {
      best = static_cast<int>(i);
      best_cost = cost;
    }
  }
  return best;
}

}  // namespace sketchnav::nav
