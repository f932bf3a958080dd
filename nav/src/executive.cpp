#include "sketchnav/nav/executive.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "sketchnav/core/config.h"
#include "sketchnav/core/log.h"

namespace sketchnav::nav {

using nlohmann::json;

void ExecutiveParams::validate() const {
  require(tick_s > 0.001 && tick_s <= 0.2, "nav.tick_s", "must be in (0.001, 0.2] s");
  require(camera_period_s > 0 && camera_period_s <= 2, "nav.camera_period_s",
          "must be in (0, 2] s");
  require(v_cruise > 0 && v_cruise <= 2, "nav.v_cruise", "must be in (0, 2] m/s");
  require(k_heading > 0, "nav.k_heading", "must be > 0");
  require(max_w > 0 && max_w <= 5, "nav.max_w", "must be in (0, 5] rad/s");
  require(turn_in_place_deg > 0 && turn_in_place_deg <= 180, "nav.turn_in_place_deg",
          "must be in (0, 180]");
  require(max_time_s > 0, "nav.max_time_s", "must be > 0");
  require(section_time_factor >= 1, "nav.section_time_factor", "must be >= 1");
  require(section_time_extra_s >= 0, "nav.section_time_extra_s", "must be >= 0");
  require(approach_m > 0 && approach_m <= max_approach_m, "nav.approach_m",
          "must be in (0, max_approach_m]");
  require(servo_hold_s >= 0, "nav.servo_hold_s", "must be >= 0");
  require(lost_after_s > 0, "nav.lost_after_s", "must be > 0");
  require(miss_slack_m >= 0, "nav.miss_slack_m", "must be >= 0");
  require(reanchor_gain >= 0 && reanchor_gain <= 1, "nav.reanchor_gain", "must be in [0, 1]");
  require(end_blocked_m >= 0, "nav.end_blocked_m", "must be >= 0");
  require(realign_gain >= 0 && realign_gain <= 1, "nav.realign_gain", "must be in [0, 1]");
  require(realign_baseline_m >= 0, "nav.realign_baseline_m", "must be >= 0");
  require(perception_period_s >= 0, "nav.perception_period_s", "must be >= 0");
  require(attend_bearing_deg > 0 && attend_bearing_deg <= 180, "nav.attend_bearing_deg",
          "must be in (0, 180]");
  require(attend_range_m > 0, "nav.attend_range_m", "must be > 0");
  require(max_missed_in_row >= 0, "nav.max_missed_in_row", "must be >= 0");
  require(goal_stop_s >= 0, "nav.goal_stop_s", "must be >= 0");
}

NavSettings navSettingsFrom(const Config& c) {
  NavSettings s;
  applyConfig(s.exec, c, "nav");
  applyConfig(s.sections, c, "nav.sections");
  applyConfig(s.select, c, "nav.select");
  applyConfig(s.avoid, c, "nav.avoid");
  applyConfig(s.safety, c, "nav.safety");
  applyConfig(s.servo, c, "servo");
  return s;
}

const char* toString(RunStatus s) {
  switch (s) {
    case RunStatus::Running:
      return "running";
    case RunStatus::Succeeded:
      return "succeeded";
    case RunStatus::Failed:
      return "failed";
    default:
      return "idle";
  }
}

json ExecutiveSummary::toJson() const {
  json lms = json::array();
  for (const auto& l : landmarks)
    lms.push_back({{"id", l.id},
                   {"class", l.class_name},
                   {"section", l.section},
                   {"state", l.state},
                   {"frames_seen", l.frames_seen},
                   {"max_inliers", l.max_inliers}});
  return {{"status", toString(status)},
          {"reason", reason},
          {"time_s", time_s},
          {"odom_path_m", odom_path_m},
          {"sections_done", sections_done},
          {"sections", sections},
          {"landmarks", lms},
          {"frames", frames},
          {"frames_processed", frames_processed},
          {"perception_ms_mean", perception_ms_mean},
          {"perception_ms_max", perception_ms_max},
          {"objectness_ms_mean", objectness_ms_mean},
          {"features_ms_mean", features_ms_mean},
          {"match_ms_mean", match_ms_mean},
          {"avoidance_manoeuvres", avoidance_manoeuvres}};
}

namespace {
enum class LmState { Pending, Tracking, Passed, Missed };
const char* lmName(LmState s) {
  switch (s) {
    case LmState::Tracking:
      return "tracking";
    case LmState::Passed:
      return "passed";
    case LmState::Missed:
      return "missed";
    default:
      return "pending";
  }
}
struct LmTrack {
  LmState state = LmState::Pending;
  int frames_seen = 0, max_inliers = 0;
  double last_seen = -1e300, last_range = 0, last_bearing = 0;
};
}  // namespace

struct Executive::Impl {
  SectionTracker tracker;
  Devices dev;
  Perception& perception;
  NavSettings s;
  ExecutiveObserver* obs;
  servo::TurnLaw law;
  ObstacleAvoider avoider;
  SafetySupervisor safety;

  RunStatus status = RunStatus::Idle;
  std::string reason;
  double t0 = 0, now = 0, next_tick = 0, section_t0 = 0, done_t = -1;
  hw::Pose2D pose;
  bool have_pose = false;
  double odom_stamp = -1e300, path_m = 0;
  std::vector<hw::RangeScan> scans;
  std::vector<double> scan_stamps;
  hw::Intrinsics K;
  double frame_stamp = -1e300;
  int frames = 0, processed = 0, manoeuvres = 0, missed_in_row = 0;
  double perc_sum = 0, perc_max = 0, objn_sum = 0, feat_sum = 0, match_sum = 0;
  std::vector<std::vector<LmTrack>> tracks;  // per section, per expected landmark
  servo::TurnCommand servo_cmd;
  double servo_t = -1e300, servo_bearing = 0;
  std::vector<std::string> missed_ids;
  double last_perception_t = -1e300;
  bool sectionBlocked_ = false;
  Eigen::Vector2d fix_route{0, 0}, fix_odom{0, 0};  // last trusted fix (start, then landmarks)

  Impl(mapsketch::Route r, Devices d, Perception& p, NavSettings st, ExecutiveObserver* o)
      : tracker(std::move(r), st.sections),
        dev(d),
        perception(p),
        s(st),
        obs(o),
        law(st.servo),
        avoider(st.avoid),
        safety(st.safety) {
    s.exec.validate();
    s.select.validate();
    if (!dev.base || !dev.clock) throw std::logic_error("Executive: base and clock are required");
    if (!dev.camera) s.safety.require_camera = false, safety = SafetySupervisor(s.safety);
    if (dev.ranges.empty()) s.safety.require_range = false, safety = SafetySupervisor(s.safety);
    scans.resize(dev.ranges.size());
    scan_stamps.assign(dev.ranges.size(), -1e300);
    if (dev.camera) K = dev.camera->intrinsics();
    for (const auto& sec : tracker.route().sections) tracks.emplace_back(sec.landmarks.size());
  }

  void event(json e) {
    e["t"] = now - t0;
    if (obs) obs->onEvent(e);
  }
  void finish(RunStatus st, const std::string& why) {
    dev.base->stop();
    if (status != RunStatus::Running) return;
    status = st;
    reason = why;
    event({{"type", st == RunStatus::Succeeded ? "arrived" : "failed"}, {"reason", why}});
    if (st == RunStatus::Succeeded)
      log::info("nav", why);
    else
      log::warn("nav", why);
  }

  // Median laser range (laser preferred over the wide sonar cones) along a robot-frame bearing.
  double rangeAt(double bearing) const {
    std::vector<double> r;
    for (int pass = 0; pass < 2 && r.empty(); ++pass)
      for (const auto& sc : scans) {
        const bool laser = sc.kind == hw::RangeScan::Kind::Laser;
        if ((pass == 0) != laser) continue;
        const double tol = laser ? 2.5 * M_PI / 180 : 0.5 * sc.beam_width;
        for (size_t i = 0; i < std::min(sc.angles.size(), sc.ranges.size()); ++i) {
          if (sc.ranges[i] >= sc.max_range || sc.ranges[i] < sc.min_range) continue;
          const double x = sc.mount.x + sc.ranges[i] * std::cos(sc.angles[i]);
          const double y = sc.mount.y + sc.ranges[i] * std::sin(sc.angles[i]);
          if (std::abs(wrapAngle(std::atan2(y, x) - bearing)) <= tol) r.push_back(std::hypot(x, y));
        }
      }
    if (r.empty()) return 0;
    std::nth_element(r.begin(), r.begin() + r.size() / 2, r.end());
    return r[r.size() / 2];
  }

  void markMissed(int sec, int i) {
    auto& tr = tracks[sec][i];
    const auto& lm = tracker.route().sections[sec].landmarks[i];
    tr.state = LmState::Missed;
    ++missed_in_row;
    missed_ids.push_back(lm.id);
    event({{"type", "landmark_missed"},
           {"id", lm.id},
           {"class", lm.class_name},
           {"section", sec},
           {"seen_before", tr.frames_seen > 0}});
    log::warn("nav", "landmark not seen, continuing on odometry",
              {{"id", lm.id}, {"class", lm.class_name}});
    if (missed_in_row > s.exec.max_missed_in_row) {
      std::string ids;
      for (size_t k = missed_ids.size() - missed_in_row; k < missed_ids.size(); ++k)
        ids += (ids.empty() ? "" : ", ") + missed_ids[k];
      finish(RunStatus::Failed, "lost: " + std::to_string(missed_in_row) +
                                    " landmarks in a row not found (" + ids + ")");
    }
  }

  void tick() {
    now = dev.clock->now();
    // --- sensors -----------------------------------------------------------------------
    hw::Odometry o;
    if (dev.base->odometry(o) && o.stamp > odom_stamp) {
      odom_stamp = o.stamp;
      safety.odometry(o.stamp);
      if (have_pose) path_m += std::hypot(o.pose.x - pose.x, o.pose.y - pose.y);
      pose = o.pose;
      have_pose = true;
    }
    for (size_t i = 0; i < dev.ranges.size(); ++i) {
      hw::RangeScan sc;
      if (dev.ranges[i]->read(sc) && sc.stamp > scan_stamps[i]) {
        scan_stamps[i] = sc.stamp;
        safety.rangeScan(sc.stamp);
        scans[i] = std::move(sc);
      }
    }
    hw::Frame frame;
    bool have_frame = false;
    if (dev.camera && now + 1e-9 >= frame_stamp + s.exec.camera_period_s - 0.5 * s.exec.tick_s) {
      const auto st = dev.camera->grab(frame, 0.5 * s.exec.tick_s);
      if (st == hw::GrabStatus::Ok && frame.stamp > frame_stamp && !frame.image.empty()) {
        frame_stamp = frame.stamp;
        safety.cameraFrame(frame.stamp);
        have_frame = true;
        ++frames;
      }
      now = dev.clock->now();  // a simulated camera may have advanced time to its frame
    }
    // --- safety ------------------------------------------------------------------------
    const auto st = safety.check(now, dev.base->ok());
    if (!st.ok()) {
      dev.base->stop();
      event({{"type", "fault"}, {"fault", toString(st.fault)}, {"reason", st.reason}});
      finish(RunStatus::Failed, "safety stop: " + st.reason);
      return;
    }
    if (now - t0 > s.exec.max_time_s) {
      finish(RunStatus::Failed, "timeout: route not completed in " +
                                    std::to_string(static_cast<int>(s.exec.max_time_s)) + " s");
      return;
    }
    // --- sections ----------------------------------------------------------------------
    const int before = tracker.current();
    // A landmark of this section being servoed on says more about where the section ends than
    // odometry does: hold the section open until it is passed (or lost, or far overshot).
    bool hold = false;
    if (!tracker.finished()) {
      const int k0 = tracker.current();
      for (const auto& t : tracks[k0])
        hold |= t.state == LmState::Tracking && now - t.last_seen <= s.exec.servo_hold_s + 0.5;
      if (hold && tracker.progress(pose).remaining_m < -s.exec.miss_slack_m) hold = false;
    }
    if (!hold && tracker.update(pose) > 0) closeSections(before);
    if (status != RunStatus::Running) return;
    if (tracker.finished()) {
      finish(RunStatus::Succeeded, "reached the end of the route");
      return;
    }
    const auto& sec = tracker.section();
    const int k = tracker.current();
    const double budget =
        s.exec.section_time_factor * sec.length_m / s.exec.v_cruise + s.exec.section_time_extra_s;
    if (now - section_t0 > budget) {
      finish(RunStatus::Failed, "section " + std::to_string(k + 1) + "/" +
                                    std::to_string(tracker.count()) + ": no progress after " +
                                    std::to_string(static_cast<int>(budget)) + " s");
      return;
    }
    const auto prog = tracker.progress(pose);

    // --- landmark stage ------------------------------------------------------------------
    // The landmark to attend to: the first one of this section not yet passed or missed, or
    // else the first of the next section (a landmark just past a guide point is often in
    // view before that section starts).
    int lk = -1, li = -1;
    for (int kk = k; kk < std::min(k + 2, tracker.count()) && li < 0; ++kk) {
      const auto& ss = tracker.route().sections[kk];
      for (size_t i = 0; i < ss.landmarks.size(); ++i) {
        auto& t = tracks[kk][i];
        if (t.state == LmState::Passed || t.state == LmState::Missed) continue;
        if (kk == k && prog.along_m > ss.landmarks[i].along_m + s.exec.miss_slack_m &&
            t.state == LmState::Pending) {
          markMissed(kk, static_cast<int>(i));
          if (status != RunStatus::Running) return;
          continue;
        }
        lk = kk;
        li = static_cast<int>(i);
        break;
      }
      if (kk == k && li < 0) continue;
      if (kk > k) break;
    }
    const mapsketch::ExpectedLandmark* lm =
        li >= 0 ? &tracker.route().sections[lk].landmarks[li] : nullptr;
    LmTrack* tr = li >= 0 ? &tracks[lk][li] : nullptr;
    double servo_error = std::numeric_limits<double>::quiet_NaN();
    const Polar pred = lm ? polarFrom(pose, tracker.toOdom(lm->position_m)) : Polar{};
    const bool attend = lm && (tr->state == LmState::Tracking ||
                               (std::abs(pred.bearing) <= s.exec.attend_bearing_deg * M_PI / 180 &&
                                pred.range <= s.exec.attend_range_m));
    if (attend && have_frame && now - last_perception_t >= s.exec.perception_period_s - 1e-6) {
      last_perception_t = now;
      const auto ob = perception.observe(frame, K, {lm->class_name});
      ++processed;
      perc_sum += ob.timing.total_ms;
      perc_max = std::max(perc_max, ob.timing.total_ms);
      objn_sum += ob.timing.objectness_ms;
      feat_sum += ob.timing.features_ms;
      match_sum += ob.timing.match_ms;
      std::vector<Candidate> cands;
      for (const auto& d : ob.detections) cands.push_back({&d, rangeAt(d.bearing)});
      const int ci = selectCandidate(cands, lm->class_name, pred.bearing, pred.range, s.select);
      if (ci >= 0) {
        const auto& d = *cands[ci].detection;
        const double range = cands[ci].range_m;
        if (tr->state != LmState::Tracking)
          event({{"type", "landmark_seen"},
                 {"id", lm->id},
                 {"class", lm->class_name},
                 {"section", lk},
                 {"inliers", d.inliers},
                 {"bearing_deg", d.bearing * 180 / M_PI},
                 {"range_m", range},
                 {"predicted_bearing_deg", pred.bearing * 180 / M_PI},
                 {"predicted_range_m", pred.range},
                 {"candidates", cands.size()}});
        tr->state = LmState::Tracking;
        ++tr->frames_seen;
        tr->max_inliers = std::max(tr->max_inliers, d.inliers);
        tr->last_seen = now;
        tr->last_range = range;
        tr->last_bearing = d.bearing;
        const double depth = range > 0 ? range * std::cos(d.bearing) : 0;
        servo_cmd = law.compute(d.x_t, d.x_d, depth);
        servo_t = now;
        servo_bearing = d.bearing;
        if (range > 0 && range <= passDistance(lk, *lm)) passLandmark(lk, li, true);
      }
    }
    if (tr && tr->state == LmState::Tracking && now - tr->last_seen > s.exec.lost_after_s) {
      // Out of view when already close (it slid out of the side of the image): passed.
      if (tr->last_range > 0 && tr->last_range <= passDistance(lk, *lm) + 1.0) {
        passLandmark(lk, li, false);
      } else {
        tr->state = LmState::Pending;
        event({{"type", "landmark_lost"}, {"id", lm->id}, {"section", lk}});
      }
    }

    // --- command -------------------------------------------------------------------------
    double v, w, target_bearing;
    std::string mode = "follow", turn = "Straight";
    const bool servoing =
        tr && tr->state == LmState::Tracking && now - servo_t <= s.exec.servo_hold_s;
    if (servoing) {
      v = servo_cmd.v;
      w = servo_cmd.w;
      target_bearing = servo_bearing;
      servo_error = servo_cmd.error;
      turn = servo::toString(servo_cmd.state);
      mode = "servo";
    } else {
      const Polar la = polarFrom(pose, tracker.lookahead(pose));
      target_bearing = la.bearing;
      w = std::clamp(s.exec.k_heading * la.bearing, -s.exec.max_w, s.exec.max_w);
      v = std::abs(la.bearing) > s.exec.turn_in_place_deg * M_PI / 180
              ? 0.0
              : s.exec.v_cruise * std::max(0.2, std::cos(la.bearing));
      turn = std::abs(la.bearing) < 0.05 ? "Straight" : (la.bearing > 0 ? "Left" : "Right");
    }
    // Side of the next landmark, for the avoidance's rotation direction.
    DodgeSide side = DodgeSide::None;
    if (lm) {
      if (lm->side == mapsketch::Side::Left) side = DodgeSide::Left;
      if (lm->side == mapsketch::Side::Right) side = DodgeSide::Right;
      if (lm->side == mapsketch::Side::Ahead) {
        const Polar p = polarFrom(pose, tracker.toOdom(lm->position_m));
        side = p.bearing >= target_bearing ? DodgeSide::Left : DodgeSide::Right;
      }
    }
    double front = 0;
    if (!dev.ranges.empty()) {
      const auto av = avoider.step(scans, target_bearing, side, pose.theta, s.exec.v_cruise, now);
      front = av.front_free_m;
      if (av.started) {
        ++manoeuvres;
        event({{"type", "avoid_start"},
               {"side", toString(av.side)},
               {"original_heading_deg", av.original_heading * 180 / M_PI},
               {"front_free_m", av.front_free_m},
               {"section", k}});
      }
      if (av.ended) event({{"type", "avoid_end"}, {"side", toString(av.side)}});
      if (av.active) {
        v = av.v;
        w = av.w;
        mode = "avoid";
        turn = std::abs(w) < 0.05 ? "Straight" : (w > 0 ? "Left" : "Right");
      } else {
        v = avoider.capSpeed(scans, v);
      }
    }
    // An end point that cannot be reached (the sketch put it in or against an obstacle): when
    // the robot is dodging within end_blocked_m of it, the section is done.
    bool end_blocked = false;
    if (mode == "avoid" && prog.to_end_m <= s.exec.end_blocked_m && !sectionBlocked_) {
      // Blocked means the range sensors see something at or before the end point itself.
      const Polar pe = polarFrom(pose, tracker.toOdom(sec.end_m));
      const double r = rangeAt(pe.bearing);
      end_blocked = r > 0 && r < pe.range + s.avoid.robot_radius_m + 0.1;
    }
    if (end_blocked) {
      sectionBlocked_ = true;
      event({{"type", "end_blocked"}, {"section", k}, {"to_end_m", prog.to_end_m}});
      tracker.advance();
      closeSections(k);
      if (status != RunStatus::Running) return;
      if (tracker.finished()) {
        finish(RunStatus::Succeeded, "reached the end of the route (end point blocked, " +
                                         std::to_string(prog.to_end_m).substr(0, 4) + " m away)");
        return;
      }
    }
    w = std::clamp(w, -s.exec.max_w, s.exec.max_w);
    dev.base->command(v, w);
    if (obs) {
      TelemetryRow row;
      row.t = now - t0;
      row.odom = pose;
      row.v_cmd = v;
      row.w_cmd = w;
      row.servo_error = servo_error;
      row.mode = mode;
      row.turn = turn;
      row.section = k;
      row.landmark = lm ? lm->id : "";
      row.front_free_m = front;
      obs->onTick(row);
    }
  }

  // Range at which a servoed landmark counts as passed: its lateral distance from the path,
  // or, for a landmark ahead beyond the section's end (on the wall the route turns at), its
  // sketched distance from that end, so that re-anchoring on it puts the end where the robot is.
  double passDistance(int k, const mapsketch::ExpectedLandmark& lm) const {
    const auto& sec = tracker.route().sections[k];
    double d = lm.range_m;
    if (lm.side == mapsketch::Side::Ahead && lm.along_m >= sec.length_m)
      d = (lm.position_m - sec.end_m).norm();
    return std::clamp(d, s.exec.approach_m, s.exec.max_approach_m);
  }

  void passLandmark(int k, int i, bool seen_close) {
    auto& tr = tracks[k][i];
    const auto& lm = tracker.route().sections[k].landmarks[i];
    tr.state = LmState::Passed;
    missed_in_row = 0;
    json e = {{"type", "landmark_passed"}, {"id", lm.id},
              {"class", lm.class_name},    {"section", k},
              {"range_m", tr.last_range},  {"frames_seen", tr.frames_seen}};
    if (seen_close) {
      // Where the landmark really is (odometry frame) vs where the sketch puts it: rotate the
      // route about the last trusted fix, then shift it, each by its gain.
      const double b = pose.theta + tr.last_bearing;
      const Eigen::Vector2d seen(pose.x + tr.last_range * std::cos(b),
                                 pose.y + tr.last_range * std::sin(b));
      const double rot = tracker.realign(lm.position_m, seen, fix_route, fix_odom,
                                         s.exec.realign_gain, s.exec.realign_baseline_m);
      const Eigen::Vector2d shift = seen - tracker.toOdom(lm.position_m);
      tracker.reanchor(lm.position_m, seen, s.exec.reanchor_gain);
      e["realign_deg"] = rot * 180 / M_PI;
      e["reanchor_m"] = shift.norm() * s.exec.reanchor_gain;
      fix_route = lm.position_m;
      fix_odom = seen;
    }
    event(e);
    log::info("nav", "landmark passed", {{"id", lm.id}, {"class", lm.class_name}});
  }

  void closeSections(int from) {
    for (int k = from; k < tracker.current() && status == RunStatus::Running; ++k) {
      for (size_t i = 0; i < tracks[k].size(); ++i) {
        auto& tr = tracks[k][i];
        if (tr.state == LmState::Tracking)
          passLandmark(k, static_cast<int>(i), false);
        else if (tr.state == LmState::Pending)
          markMissed(k, static_cast<int>(i));
        if (status != RunStatus::Running) return;
      }
      event({{"type", "section_done"}, {"section", k}, {"of", tracker.count()}});
      log::info("nav", "section " + std::to_string(k + 1) + "/" + std::to_string(tracker.count()) +
                           " done");
    }
    section_t0 = now;
    sectionBlocked_ = false;
  }
};

Executive::Executive(mapsketch::Route route, Devices devices, Perception& perception,
                     NavSettings settings, ExecutiveObserver* observer)
    : impl_(std::make_unique<Impl>(std::move(route), devices, perception, settings, observer)) {}
Executive::~Executive() {
  if (impl_ && impl_->dev.base) impl_->dev.base->stop();
}

void Executive::start() {
  auto& I = *impl_;
  I.t0 = I.now = I.dev.clock->now();
  I.next_tick = I.t0;
  I.section_t0 = I.t0;
  I.fix_route = I.tracker.route().start_m;
  I.fix_odom = I.tracker.toOdom(I.fix_route);
  I.safety.start(I.t0);
  I.status = RunStatus::Running;
  I.event({{"type", "start"},
           {"sections", I.tracker.count()},
           {"route_length_m", I.tracker.route().total_length_m}});
}

void Executive::step() {
  auto& I = *impl_;
  if (I.status != RunStatus::Running) return;
  try {
    I.tick();
  } catch (const std::exception& e) {
    I.dev.base->stop();
    I.event({{"type", "fault"}, {"fault", "exception"}, {"reason", e.what()}});
    I.finish(RunStatus::Failed, std::string("safety stop: exception: ") + e.what());
  } catch (...) {
    I.dev.base->stop();
    I.finish(RunStatus::Failed, "safety stop: unknown exception");
  }
}

void Executive::stop(const std::string& reason) {
  impl_->finish(RunStatus::Failed, reason);
  impl_->dev.base->stop();
}

bool Executive::done() const {
  return impl_->status == RunStatus::Succeeded || impl_->status == RunStatus::Failed;
}

ExecutiveSummary Executive::run() {
  auto& I = *impl_;
  if (I.status == RunStatus::Idle) start();
  while (!done()) {
    I.next_tick += I.s.exec.tick_s;
    I.dev.clock->sleepUntil(I.next_tick);
    step();
  }
  return summary();
}

const SectionTracker& Executive::sections() const {
  return impl_->tracker;
}

ExecutiveSummary Executive::summary() const {
  const auto& I = *impl_;
  ExecutiveSummary s;
  s.status = I.status;
  s.reason = I.reason;
  s.time_s = I.now - I.t0;
  s.odom_path_m = I.path_m;
  s.sections = I.tracker.count();
  s.sections_done = std::min(I.tracker.current(), s.sections);
  for (size_t k = 0; k < I.tracks.size(); ++k)
    for (size_t i = 0; i < I.tracks[k].size(); ++i) {
      const auto& lm = I.tracker.route().sections[k].landmarks[i];
      const auto& tr = I.tracks[k][i];
      s.landmarks.push_back({lm.id, lm.class_name, static_cast<int>(k), lmName(tr.state),
                             tr.frames_seen, tr.max_inliers});
    }
  s.frames = I.frames;
  s.frames_processed = I.processed;
  if (I.processed > 0) {
    s.perception_ms_mean = I.perc_sum / I.processed;
    s.objectness_ms_mean = I.objn_sum / I.processed;
    s.features_ms_mean = I.feat_sum / I.processed;
    s.match_ms_mean = I.match_sum / I.processed;
  }
  s.perception_ms_max = I.perc_max;
  s.avoidance_manoeuvres = I.manoeuvres;
  return s;
}

}  // namespace sketchnav::nav
