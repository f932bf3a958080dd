#pragma once
// Builds small routes by hand for the nav unit tests (no sketch file needed).
#include <cmath>
#include <string>
#include <vector>

#include "sketchnav/mapsketch/route.h"

namespace sketchnav::nav::test {

struct LmSpec {
  int section;
  std::string id, class_name;
  Eigen::Vector2d pos;
  mapsketch::Side side = mapsketch::Side::Ahead;
};

inline mapsketch::Route makeRoute(const std::vector<Eigen::Vector2d>& pts,
                                  const std::vector<LmSpec>& lms = {}) {
  mapsketch::Route r;
  r.guide_points_m = pts;
  r.start_m = pts.front();
  r.goal_m = pts.back();
  double prev = 0;
  for (size_t i = 0; i + 1 < pts.size(); ++i) {
    mapsketch::PathSection s;
    s.index = static_cast<int>(i);
    s.start_m = pts[i];
    s.end_m = pts[i + 1];
    const Eigen::Vector2d d = s.end_m - s.start_m;
    s.length_m = d.norm();
    s.heading_rad = std::atan2(d.y(), d.x());
    s.heading_change_rad = i == 0 ? 0 : s.heading_rad - prev;
    prev = s.heading_rad;
    r.total_length_m += s.length_m;
    r.sections.push_back(s);
  }
  r.start_heading_rad = r.sections.front().heading_rad;
  int order = 0;
  for (const auto& l : lms) {
    auto& s = r.sections[l.section];
    mapsketch::ExpectedLandmark e;
    e.id = l.id;
    e.class_name = l.class_name;
    e.order = order++;
    e.side = l.side;
    e.position_m = l.pos;
    const Eigen::Vector2d d = (s.end_m - s.start_m).normalized();
    e.along_m = (l.pos - s.start_m).dot(d);
    e.range_m = std::abs(d.x() * (l.pos - s.start_m).y() - d.y() * (l.pos - s.start_m).x());
    s.landmarks.push_back(e);
  }
  r.scale_m_per_px = 0.01;
  return r;
}

}  // namespace sketchnav::nav::test
