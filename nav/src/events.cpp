#include "sketchnav/nav/events.h"

#include <cmath>

namespace sketchnav::nav {

using nlohmann::json;

const char* toString(Mode m) {
  switch (m) {
    case Mode::Follow:
      return "follow";
    case Mode::Look:
      return "look";
    case Mode::Servo:
      return "servo";
    case Mode::Dock:
      return "dock";
    case Mode::Recover:
      return "recover";
    case Mode::Avoid:
      return "avoid";
    case Mode::Detour:
      return "detour";
    case Mode::Yield:
      return "yield";
  }
  return "follow";
}

const char* toString(FailureCode c) {
  switch (c) {
    case FailureCode::None:
      return "";
    case FailureCode::SafetyStop:
      return "safety_stop";
    case FailureCode::Timeout:
      return "timeout";
    case FailureCode::NoProgress:
      return "no_progress";
    case FailureCode::Lost:
      return "lost";
    case FailureCode::Stopped:
      return "stopped";
  }
  return "";
}

namespace {

json xy(const Eigen::Vector2d& p) {
  return {p.x(), p.y()};
}
json xyt(const hw::Pose2D& p) {
  return {p.x, p.y, p.theta};
}
double rounded(double v, double scale) {
  return std::round(v * scale) / scale;
}

// One overload per event: its type string and its fields. The field names and value types are
// the events.jsonl format (an int stays an int, a double a double: 0 and 0.0 differ there).
struct Writer {
  json& j;
  const char* operator()(const event::Start& e) {
    j["sections"] = e.sections;
    j["route_length_m"] = e.route_length_m;
    return "start";
  }
  const char* operator()(const event::Arrived& e) {
    j["reason"] = e.reason;
    return "arrived";
  }
  const char* operator()(const event::Failed& e) {
    j["reason"] = e.reason;
    return "failed";
  }
  const char* operator()(const event::Fault& e) {
    j["fault"] = e.fault;
    j["reason"] = e.reason;
    return "fault";
  }
  const char* operator()(const event::LandmarkSeen& e) {
    j["id"] = e.id;
    j["class"] = e.class_name;
    j["section"] = e.section;
    j["inliers"] = e.inliers;
    j["bearing_deg"] = e.bearing_deg;
    j["range_m"] = e.range_m;
    j["predicted_bearing_deg"] = e.predicted_bearing_deg;
    j["predicted_range_m"] = e.predicted_range_m;
    j["range_dropped"] = e.range_dropped;
    j["candidates"] = e.candidates;
    j["attended_first"] = e.attended_first;
    return "landmark_seen";
  }
  const char* operator()(const event::LandmarkLost& e) {
    j["id"] = e.id;
    j["section"] = e.section;
    return "landmark_lost";
  }
  const char* operator()(const event::LandmarkMissed& e) {
    j["id"] = e.id;
    j["class"] = e.class_name;
    j["section"] = e.section;
    j["seen_before"] = e.seen_before;
    return "landmark_missed";
  }
  const char* operator()(const event::LandmarkPassed& e) {
    j["id"] = e.id;
    j["class"] = e.class_name;
    j["section"] = e.section;
    j["range_m"] = e.range_m;
    j["frames_seen"] = e.frames_seen;
    j["in_view"] = e.in_view;
    if (e.fix_rejected) j["fix_rejected"] = *e.fix_rejected;
    if (e.fix) {
      const auto& f = *e.fix;
      j["fix_method"] = f.method;
      j["fix_rays"] = f.rays;
      j["fix_ranges_used"] = f.ranges_used;
      j["fix_height_ranges"] = f.height_ranges;
      if (f.height_ranges > 0) j["fix_height_sigma_m"] = f.height_sigma_m;
      j["fix_gated_ranges"] = f.gated_ranges;
      j["fix_ranges_dropped"] = f.ranges_dropped;
      json rays = json::array();
      for (const auto& q : f.sightings)
        rays.push_back(
            {rounded(q[0], 1000), rounded(q[1], 1000), rounded(q[2], 10000), rounded(q[3], 1000)});
      j["sightings"] = rays;
      if (f.fit) {
        j["fit_rotation_deg"] = f.fit->rotation_deg;
        j["fit_scale"] = f.fit->scale;
        j["fit_rms_m"] = f.fit->rms_m;
        j["fit_fixes"] = f.fit->fixes;
        j["fit_dropped"] = f.fit->dropped;
      }
      if (f.realign) {
        j["realign_deg"] = f.realign->realign_deg;
        j["reanchor_m"] = f.realign->reanchor_m;
      }
      j["disagreement_m"] = f.disagreement_m;
      j["fix_route"] = xy(f.route);
      j["fix_odom"] = xy(f.odom);
    }
    return "landmark_passed";
  }
  const char* operator()(const event::SectionDone& e) {
    j["section"] = e.section;
    j["of"] = e.of;
    j["end_odom"] = xy(e.end_odom);
    j["pose_odom"] = xyt(e.pose_odom);
    return "section_done";
  }
  const char* operator()(const event::AvoidStart& e) {
    j["side"] = toString(e.side);
    j["original_heading_deg"] = e.original_heading_deg;
    j["front_free_m"] = e.front_free_m;
    j["section"] = e.section;
    return "avoid_start";
  }
  const char* operator()(const event::AvoidEnd& e) {
    j["side"] = toString(e.side);
    if (e.docking) j["docking"] = true;
    return "avoid_end";
  }
  const char* operator()(const event::WalkerLane& e) {
    j["walker_odom"] = xy(e.walker_odom);
    j["walker_velocity"] = xy(e.walker_velocity);
    j["section"] = e.section;
    return "walker_lane";
  }
  const char* operator()(const event::DetourStart& e) {
    j["length_m"] = e.length_m;
    j["goal_odom"] = xy(e.goal_odom);
    j["goal_moved"] = e.goal_moved;
    j["section"] = e.section;
    return "detour_start";
  }
  const char* operator()(const event::DetourEnd& e) {
    j["reason"] = e.reason;
    return "detour_end";
  }
  const char* operator()(const event::RecoverStart& e) {
    j["direction_deg"] = e.direction_deg;
    j["look"] = e.look;
    if (e.back) j["back"] = true;  // absent when not backing: the older form of the event
    return "recover_start";
  }
  const char* operator()(const event::RecoverEnd&) { return "recover_end"; }
  const char* operator()(const event::GoalSettled& e) {
    j["to_end_m"] = e.to_end_m;
    return "goal_settled";
  }
  const char* operator()(const event::EndBlocked& e) {
    j["section"] = e.section;
    j["to_end_m"] = e.to_end_m;
    return "end_blocked";
  }
  const char* operator()(const event::SectionSettled& e) {
    j["section"] = e.section;
    j["to_end_m"] = e.to_end_m;
    return "section_settled";
  }
  const char* operator()(const event::YieldStart& e) {
    j["in_lane"] = e.in_lane;
    j["clearance_m"] = e.clearance_m;
    j["mover_odom"] = xy(e.mover_odom);
    j["mover_velocity"] = xy(e.mover_velocity);
    j["pose_odom"] = xyt(e.pose_odom);
    return "yield_start";
  }
  const char* operator()(const event::YieldEnd&) { return "yield_end"; }
  const char* operator()(const event::GoalDoor& e) {
    j["centre_odom"] = xy(e.centre_odom);
    j["width_m"] = e.width_m;
    j["goal_odom"] = xy(e.goal_odom);
    j["moved_m"] = e.moved_m;
    j["standoff_m"] = e.standoff_m;
    j["sightings"] = e.sightings;
    return "goal_door";
  }
  const char* operator()(const event::FinalLookStart& e) {
    j["id"] = e.id;
    j["range_m"] = e.range_m;
    return "final_look_start";
  }
  const char* operator()(const event::FinalLookEnd& e) {
    j["id"] = e.id;
    j["seen"] = e.seen;
    return "final_look_end";
  }
  const char* operator()(const event::SideLookStart& e) {
    j["id"] = e.id;
    j["section"] = e.section;
    j["bearing_deg"] = e.bearing_deg;
    j["range_m"] = e.range_m;
    return "side_look_start";
  }
  const char* operator()(const event::SideLookEnd& e) {
    j["id"] = e.id;
    j["seen"] = e.seen;
    j["duration_s"] = e.duration_s;
    return "side_look_end";
  }
};

}  // namespace

const char* NavEvent::type() const {
  json scratch = json::object();
  return std::visit(Writer{scratch}, data);
}

json NavEvent::toJson() const {
  json j = json::object();
  j["type"] = std::visit(Writer{j}, data);
  j["t"] = t;
  return j;
}

}  // namespace sketchnav::nav
