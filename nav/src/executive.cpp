#include "sketchnav/nav/executive.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include "sketchnav/core/config.h"
#include "sketchnav/core/log.h"
#include "sketchnav/nav/command_arbiter.h"
#include "sketchnav/nav/goal_checker.h"
#include "sketchnav/nav/progress_checker.h"

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
  require(dock_m >= 0, "nav.dock_m", "must be >= 0");
  require(detour_ahead_m > 0.5 && detour_ahead_m <= 10, "nav.detour_ahead_m",
          "must be in (0.5, 10] m");
  require(replan_s > 0, "nav.replan_s", "must be > 0");
  require(same_class_gate_m >= 0, "nav.same_class_gate_m", "must be >= 0 (0 = off)");
  require(final_look_range_m >= 0, "nav.final_look_range_m", "must be >= 0 (0 = off)");
  require(final_look_s > 0, "nav.final_look_s", "must be > 0");
  require(fit_fixes == 0 || fit_fixes >= 3, "nav.fit_fixes", "must be 0 (off) or >= 3");
  require(fit_min_span_m >= 0, "nav.fit_min_span_m", "must be >= 0");
  require(fit_max_scale_change >= 0 && fit_max_scale_change < 1, "nav.fit_max_scale_change",
          "must be in [0, 1)");
  require(fit_local_gain >= 0 && fit_local_gain <= 1, "nav.fit_local_gain", "must be in [0, 1]");
  require(fit_outlier_m >= 0, "nav.fit_outlier_m", "must be >= 0 (0 = keep every fix)");
  require(stuck_s > 0, "nav.stuck_s", "must be > 0");
  require(goal_settle_m >= 0, "nav.goal_settle_m", "must be >= 0");
  require(goal_settle_s > 0, "nav.goal_settle_s", "must be > 0");
  require(stuck_m >= 0, "nav.stuck_m", "must be >= 0");
  require(recover_m > 0, "nav.recover_m", "must be > 0");
  require(recover_s > 0, "nav.recover_s", "must be > 0");
  require(look_range_m >= 0, "nav.look_range_m", "must be >= 0");
  require(look_max_bearing_deg > 0 && look_max_bearing_deg <= 180, "nav.look_max_bearing_deg",
          "must be in (0, 180]");
  require(look_bearing_deg > 0 && look_bearing_deg <= 90, "nav.look_bearing_deg",
          "must be in (0, 90]");
  require(side_look_s >= 0, "nav.side_look_s", "must be >= 0 (0 = off)");
  require(side_look_range_m > 0, "nav.side_look_range_m", "must be > 0");
  require(side_look_min_range_m >= 0 && side_look_min_range_m < side_look_range_m,
          "nav.side_look_min_range_m", "must be in [0, nav.side_look_range_m)");
  require(side_look_margin_deg >= 0 && side_look_margin_deg < 90, "nav.side_look_margin_deg",
          "must be in [0, 90)");
  require(side_look_max_bearing_deg > 0 && side_look_max_bearing_deg <= 180,
          "nav.side_look_max_bearing_deg", "must be in (0, 180]");
}

NavSettings navSettingsFrom(const Config& c) {
  NavSettings s;
  applyConfig(s.exec, c, "nav");
  applyConfig(s.sections, c, "nav.sections");
  applyConfig(s.select, c, "nav.select");
  applyConfig(s.locate, c, "nav.locate");
  applyConfig(s.avoid, c, "nav.avoid");
  applyConfig(s.safety, c, "nav.safety");
  applyConfig(s.laser_odometry, c, "nav.laser_odometry");
  applyConfig(s.planner, c, "nav.planner");
  applyConfig(s.movers, c, "nav.movers");
  applyConfig(s.goal_door, c, "nav.goal_door");
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
          {"failure", toString(failure)},
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
          {"full_passes", full_passes},
          {"tracked_detections", tracked_detections},
          {"avoidance_manoeuvres", avoidance_manoeuvres},
          {"recoveries", recoveries},
          {"detours", detours},
          {"yields", yields},
          {"laser_odometry",
           {{"scans", laser_odometry.scans},
            {"aligned", laser_odometry.aligned},
            {"rejected", laser_odometry.rejected},
            {"keyframes", laser_odometry.keyframes},
            {"degenerate", laser_odometry.degenerate},
            {"wheel_disagree", laser_odometry.wheel_disagree},
            {"moving_share", laser_odometry.moving_share},
            {"ms_mean", laser_odometry.ms_mean}}},
          {"timing", timing.toJson(time_s)}};
}

json LoopTiming::toJson(double time_s) const {
  auto rate = [&](int n) {
    return json{{"n", n},
                {"clock", time_s > 0 ? n / time_s : 0.0},
                {"wall", wall_s > 0 ? n / wall_s : 0.0}};
  };
  return {{"time_s", time_s},
          {"wall_s", wall_s},
          {"rates_hz",
           {{"camera_frames", rate(frames)},
            {"perception_frames", rate(perception_frames)},
            {"full_passes", rate(full_passes)},
            {"tracked_frames", rate(tracked_frames)},
            {"servo_updates", rate(servo_updates)},
            {"control_ticks", rate(ticks)}}},
          {"latency_ms",
           {{"grab_to_command", grab_to_command_ms.toJson()},
            {"perception", perception_ms.toJson()},
            {"objectness", objectness_ms.toJson()},
            {"features", features_ms.toJson()},
            {"match", match_ms.toJson()},
            {"track", track_ms.toJson()}}}};
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
  // Where it was last seen (odometry frame): the ray's origin and direction, and its point
  // when it had a range. While it is being tracked, detections are matched against this, not
  // against where the sketch puts it.
  Eigen::Vector2d last_origin{0, 0};
  double last_world_bearing = 0, last_point_range = 0;
  std::vector<Sighting> sightings;  // within fix range, for locateLandmark()
  bool side_looked = false;         // a look to the side was spent on it (once per landmark)
};
}  // namespace

struct Executive::Impl {
  SectionTracker tracker;
  GoalChecker goal_checker;
  Devices dev;
  Perception& perception;
  NavSettings s;
  ExecutiveObserver* obs;
  servo::TurnLaw law;
  ObstacleAvoider avoider;
  SafetySupervisor safety;
  LaserOdometry lodo;
  LocalPlanner planner;
  MoverTracker movers;
  // The grid as it was 1.5-3 s ago, for the mover tracker (a person's own trace is not in it).
  LocalPlanner grid_before, grid_snap;
  double snap_t = -1e300;
  bool yielding = false;
  int yields = 0;

  RunStatus status = RunStatus::Idle;
  FailureCode failure = FailureCode::None;
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
  double objn_sum = 0, feat_sum = 0, match_sum = 0;  // over every processed frame
  int full_passes = 0, tracked_detections = 0;
  // Loop rates and latency budget (LoopTiming): counts, and samples added as they happen
  // (no lock: the executive runs on one thread).
  using WallClock = std::chrono::steady_clock;
  WallClock::time_point wall0, wall_last, grab_wall;
  double grab_lag_ms = 0;  // [ms] run clock from the frame's stamp to the grab's return
  int ticks = 0, tracked_frames = 0, servo_updates = 0;
  PercentileAccumulator grab_to_command_ms, perception_ms, objectness_ms, features_ms, match_ms,
      track_ms;
  std::vector<std::vector<LmTrack>> tracks;  // per section, per expected landmark
  servo::TurnCommand servo_cmd;
  double servo_t = -1e300, servo_bearing = 0;
  std::vector<std::string> missed_ids;
  double last_perception_t = -1e300;
  bool sectionBlocked_ = false;
  // Stuck recovery: where the robot was stuck_s ago, and an escape under way.
  ProgressChecker progress_checker;
  bool recovering = false;
  double rec_dir = 0, rec_t0 = 0;  // escape heading (odometry frame), start time
  hw::Pose2D rec_from;
  int recoveries = 0;
  // Planned detour (or docking path) being followed, when it was planned and to where.
  PlannedPath detour;
  double detour_t = -1e300;
  Eigen::Vector2d detour_goal{1e300, 1e300};
  bool detouring = false;
  bool moving_seen = false;  // the current manoeuvre has seen something come towards the robot
  bool in_lane = false;      // a walker's lane covered the robot at the last step
  // Final look: at the goal, a landmark never seen (too far so far) is looked for before
  // arriving. Which one, since when, whether it had been missed, whether the look is over.
  int fl_k = -1, fl_i = -1;
  double fl_t = 0;
  bool fl_was_missed = false;
  bool fl_done = false;
  bool final_looking = false;  // this tick
  // Look to the side (ExecutiveParams::side_look_s): for which landmark, since when.
  bool side_looking = false;
  int sl_k = -1, sl_i = -1;
  double sl_t = 0;
  double half_fov = 0;  // [rad] the camera's half horizontal field of view
  int detours = 0;
  SettleChecker settle_checker;
  Eigen::Vector2d fix_route{0, 0}, fix_odom{0, 0};       // last trusted fix (start, then landmarks)
  std::vector<Eigen::Vector2d> fixes_route, fixes_odom;  // every fix, the start first
  std::vector<std::string> fixes_class;                  // class of each ("" for the start)
  std::vector<Eigen::Matrix2d> fixes_info;               // how well each was seen [1/m^2]
  // Across-ray unit normal of a bearing-only fix (placed only across its rays; its point
  // along them means nothing), zero for the others.
  std::vector<Eigen::Vector2d> fixes_across;
  // Goal doorway (route goal_place): stopping points of the doorways seen near the goal
  // (odometry frame, newest last); the goal put on one is tracker.goalOdom().
  std::vector<Eigen::Vector2d> door_stops;

  Impl(mapsketch::Route r, Devices d, Perception& p, NavSettings st, ExecutiveObserver* o)
      : tracker(std::move(r), st.sections),
        goal_checker(st.sections.goal_radius_m),
        dev(d),
        perception(p),
        s(st),
        obs(o),
        law(st.servo),
        avoider(st.avoid),
        safety(st.safety),
        lodo(st.laser_odometry),
        planner(st.planner),
        movers(st.movers),
        grid_before(st.planner),
        grid_snap(st.planner),
        progress_checker(st.exec.stuck_s, st.exec.stuck_m),
        settle_checker(st.exec.goal_settle_m, st.exec.goal_settle_s) {
    s.exec.validate();
    s.select.validate();
    s.locate.validate();
    s.goal_door.validate();
    if (!dev.base || !dev.clock) throw std::logic_error("Executive: base and clock are required");
    if (!dev.camera) s.safety.require_camera = false, safety = SafetySupervisor(s.safety);
    if (dev.ranges.empty()) s.safety.require_range = false, safety = SafetySupervisor(s.safety);
    scans.resize(dev.ranges.size());
    scan_stamps.assign(dev.ranges.size(), -1e300);
    if (dev.camera) K = dev.camera->intrinsics();
    if (dev.camera) half_fov = std::atan2(0.5 * K.width, K.fx);
    for (const auto& sec : tracker.route().sections) tracks.emplace_back(sec.landmarks.size());
    if (s.avoid.approach_needs_free_floor)
      avoider.setMovedInTest(
          [this](const Eigen::Vector2d& p) { return grid_before.seenFreeAround(p); });
  }

  void event(EventData d) {
    if (obs) obs->onEvent(NavEvent{now - t0, std::move(d)});
  }
  void succeed(const std::string& why) { finish(RunStatus::Succeeded, FailureCode::None, why); }
  // A failure rule about the way to the goal cannot fire once the goal is reached
  // (GoalChecker): the run goes on and ends as it does at the goal.
  void fail(FailureCode code, const std::string& why) {
    if (status == RunStatus::Running && have_pose && GoalChecker::overrules(code) &&
        goal_checker.reached(tracker, pose)) {
      log::info("nav", "at the goal: not failing for the way there", {{"rule", why}});
      return;
    }
    finish(RunStatus::Failed, code, why);
  }
  void finish(RunStatus st, FailureCode code, const std::string& why) {
    dev.base->stop();
    if (status != RunStatus::Running) return;
    status = st;
    failure = code;
    reason = why;
    if (st == RunStatus::Succeeded)
      event(event::Arrived{why});
    else
      event(event::Failed{code, why});
    if (st == RunStatus::Succeeded)
      log::info("nav", why);
    else
      log::warn("nav", why);
  }

  // Turn state for telemetry from a signed bearing or yaw rate.
  static servo::Turn turnOf(double x) {
    return std::abs(x) < 0.05 ? servo::Turn::Straight
                              : (x > 0 ? servo::Turn::Left : servo::Turn::Right);
  }
  // Head for a robot-frame bearing: yaw rate proportional to it; forward speed slowed by its
  // cosine (times `scale`), and zero above turn_in_place_deg (turn on the spot first).
  void headFor(double bearing, double scale, double& v, double& w) const {
    w = std::clamp(s.exec.k_heading * bearing, -s.exec.max_w, s.exec.max_w);
    v = std::abs(bearing) > s.exec.turn_in_place_deg * M_PI / 180
            ? 0.0
            : s.exec.v_cruise * std::max(0.2, std::cos(bearing)) * scale;
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

  // `counts`: towards "lost: N in a row". A landmark left behind one that was passed after it
  // does not count: the robot knows where it is.
  void markMissed(int sec, int i, bool counts = true) {
    auto& tr = tracks[sec][i];
    const auto& lm = tracker.route().sections[sec].landmarks[i];
    tr.state = LmState::Missed;
    if (counts) ++missed_in_row;
    missed_ids.push_back(lm.id);
    event(event::LandmarkMissed{lm.id, lm.class_name, sec, tr.frames_seen > 0});
    log::warn("nav", "landmark not seen, continuing on odometry",
              {{"id", lm.id}, {"class", lm.class_name}});
    if (missed_in_row > s.exec.max_missed_in_row) {
      std::string ids;
      for (size_t k = missed_ids.size() - missed_in_row; k < missed_ids.size(); ++k)
        ids += (ids.empty() ? "" : ", ") + missed_ids[k];
      fail(FailureCode::Lost, "lost: " + std::to_string(missed_in_row) +
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
      const hw::Pose2D p = lodo.wheel(o.pose, o.stamp);
      if (have_pose) path_m += std::hypot(p.x - pose.x, p.y - pose.y);
      pose = p;
      have_pose = true;
    }
    std::vector<size_t> fresh;
    for (size_t i = 0; i < dev.ranges.size(); ++i) {
      hw::RangeScan sc;
      if (dev.ranges[i]->read(sc) && sc.stamp > scan_stamps[i]) {
        scan_stamps[i] = sc.stamp;
        safety.rangeScan(sc.stamp);
        if (have_pose) lodo.scan(sc);
        scans[i] = std::move(sc);
        fresh.push_back(i);
      }
    }
    if (have_pose) pose = lodo.pose();
    if (have_pose) {
      for (size_t i : fresh) {
        movers.update(pose, scans[i], grid_before);
        planner.insert(pose, scans[i]);
        lookForGoalDoor(scans[i]);
      }
      // The avoider follows walkers the tracker finds (avoidance.h), so the grid of a few
      // seconds ago is kept whenever the tracker runs.
      if (now - snap_t >= 1.5) {
        grid_before = std::move(grid_snap);
        grid_snap = planner.snapshot();
        snap_t = now;
      }
    }
    hw::Frame frame;
    bool have_frame = false;
    bool perceived = false;  // perception looked at `frame` this tick
    if (dev.camera && now + 1e-9 >= frame_stamp + s.exec.camera_period_s - 0.5 * s.exec.tick_s) {
      const auto st = dev.camera->grab(frame, 0.5 * s.exec.tick_s);
      if (st == hw::GrabStatus::Ok && frame.stamp > frame_stamp && !frame.image.empty()) {
        frame_stamp = frame.stamp;
        safety.cameraFrame(frame.stamp);
        have_frame = true;
        ++frames;
      }
      now = dev.clock->now();  // a simulated camera may have advanced time to its frame
      if (have_frame) {
        grab_wall = WallClock::now();
        grab_lag_ms = (now - frame.stamp) * 1e3;
      }
    }
    // --- safety ------------------------------------------------------------------------
    const auto st = safety.check(now, dev.base->ok());
    if (!st.ok()) {
      dev.base->stop();
      std::string reason = st.reason;
      // The base says why it is not ok (a link timeout, or a gate closed because the camera
      // was lost): "base link lost" alone would send the user to the wrong device.
      if (st.fault == Fault::BaseLinkLost) {
        const std::string why = dev.base->stats().last_error;
        if (!why.empty()) reason += ": " + why;
      }
      event(event::Fault{toString(st.fault), reason});
      fail(FailureCode::SafetyStop, "safety stop: " + reason);
      return;
    }
    if (now - t0 > s.exec.max_time_s) {
      fail(FailureCode::Timeout, "timeout: route not completed in " +
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
      for (size_t i = 0; i < tracks[k0].size(); ++i) {
        const auto& t = tracks[k0][i];
        if (k0 == fl_k && static_cast<int>(i) == fl_i && !fl_done) continue;  // final look's
        hold |= t.state == LmState::Tracking && now - t.last_seen <= s.exec.servo_hold_s + 0.5;
      }
      if (hold && tracker.progress(pose).remaining_m < -s.exec.miss_slack_m) hold = false;
    }
    // A final look under way continues whichever way it started (at the goal, or settled near
    // it): it holds the route open and turns the robot.
    final_looking = fl_k >= 0 && !fl_done && finalLook();
    // At the goal: a landmark of the last section that was seen moves the goal when it is
    // passed (re-fit), so pass it first and judge arrival against the corrected goal.
    if (!hold && !tracker.finished() && tracker.current() + 1 == tracker.count() &&
        tracker.progress(pose).to_end_m <= s.sections.goal_radius_m) {
      const int kl = tracker.current();
      for (size_t i = 0; i < tracks[kl].size() && status == RunStatus::Running; ++i) {
        const auto st = tracks[kl][i].state;
        if (st == LmState::Tracking || (st == LmState::Pending && tracks[kl][i].frames_seen > 0))
          passLandmark(kl, static_cast<int>(i), false);
      }
      if (status != RunStatus::Running) return;
      if (!final_looking) final_looking = finalLook();
    }
    hold |= final_looking;
    if (!hold && tracker.update(pose) > 0) closeSections(before);
    if (status != RunStatus::Running) return;
    if (tracker.finished()) {
      succeed("reached the end of the route");
      return;
    }
    const auto& sec = tracker.section();
    const int k = tracker.current();
    const double budget =
        s.exec.section_time_factor * sec.length_m / s.exec.v_cruise + s.exec.section_time_extra_s;
    if (now - section_t0 > budget) {
      fail(FailureCode::NoProgress, "section " + std::to_string(k + 1) + "/" +
                                        std::to_string(tracker.count()) + ": no progress after " +
                                        std::to_string(static_cast<int>(budget)) + " s");
      return;
    }
    const auto prog = tracker.progress(pose);

    // --- landmark stage ------------------------------------------------------------------
    // Attended landmarks: the first one of this section not yet passed or missed (or else the
    // first of the next section: a landmark just past a guide point is often in view before
    // that section starts), and the one after it. The robot servos on the first only; the
    // second is looked for in the same frames because it often comes into view while the
    // first is still expected (two landmarks a few metres apart on opposite sides of the path)
    // and is too close to be recognised by the time the first is passed.
    struct Attended {
      int k, i;
      const mapsketch::ExpectedLandmark* lm;
      LmTrack* tr;
      Polar pred;
      bool attend;
    };
    std::vector<Attended> att;
    if (final_looking) {
      const auto& l = tracker.route().sections[fl_k].landmarks[fl_i];
      const Polar p = polarFrom(pose, tracker.toOdom(l.position_m));
      const bool a = std::abs(p.bearing) <= s.exec.attend_bearing_deg * M_PI / 180;
      att.push_back({fl_k, fl_i, &l, &tracks[fl_k][fl_i], p, a});
    }
    for (int kk = k; !final_looking && kk < std::min(k + 2, tracker.count()) && att.size() < 2;
         ++kk) {
      const auto& ss = tracker.route().sections[kk];
      for (size_t i = 0; i < ss.landmarks.size() && att.size() < 2; ++i) {
        auto& t = tracks[kk][i];
        if (t.state == LmState::Passed || t.state == LmState::Missed) continue;
        if (!fl_done && kk == fl_k && static_cast<int>(i) == fl_i) continue;  // final look's
        if (kk == k &&
            prog.along_m > ss.landmarks[i].along_m * tracker.scale() + s.exec.miss_slack_m &&
            t.state == LmState::Pending) {
          // Recognised earlier but lost from view before it was close: the robot did see it,
          // so it is passed (a sighting says the route is right), not missed.
          if (t.frames_seen > 0)
            passLandmark(kk, static_cast<int>(i), false);
          else
            markMissed(kk, static_cast<int>(i));
          if (status != RunStatus::Running) return;
          continue;
        }
        const auto& l = ss.landmarks[i];
        const Polar p = polarFrom(pose, tracker.toOdom(l.position_m));
        const bool a = t.state == LmState::Tracking ||
                       (std::abs(p.bearing) <= s.exec.attend_bearing_deg * M_PI / 180 &&
                        p.range <= s.exec.attend_range_m);
        att.push_back({kk, static_cast<int>(i), &l, &t, p, a});
      }
    }
    const mapsketch::ExpectedLandmark* lm = att.empty() ? nullptr : att[0].lm;
    LmTrack* tr = att.empty() ? nullptr : att[0].tr;
    double servo_error = std::numeric_limits<double>::quiet_NaN();
    const Polar pred = att.empty() ? Polar{} : att[0].pred;
    std::vector<std::string> classes;
    for (const auto& x : att)
      if (x.attend && std::find(classes.begin(), classes.end(), x.lm->class_name) == classes.end())
        classes.push_back(x.lm->class_name);
    if (!classes.empty() && have_frame &&
        now - last_perception_t >= s.exec.perception_period_s - 1e-6) {
      last_perception_t = now;
      // Where the sketch puts each attended landmark is handed to perception, which takes a
      // foveal second look there (a full-resolution, upscaled crop) if the normal pass
      // misses it (~35 ms then): a landmark 3-6 m away is small. (When far sightings were
      // dropped this bought nothing: landmarks recognised twice as far away, goal no better.)
      Observation ob;
      if ((final_looking && s.exec.final_look_fovea) || s.exec.fovea_hints) {
        std::vector<LookFor> look;
        for (const auto& x : att)
          if (x.attend) look.push_back({x.lm->class_name, x.pred.bearing, x.pred.range});
        ob = perception.observe(frame, K, look);
      } else {
        ob = perception.observe(frame, K, classes);
      }
      ++processed;
      perceived = true;
      const PerceptionTiming& pt = ob.timing;
      perception_ms.add(pt.total_ms);
      if (pt.full_pass) {
        objectness_ms.add(pt.objectness_ms);
        features_ms.add(pt.features_ms);
        match_ms.add(pt.match_ms);
      }
      if (pt.track_steps > 0) track_ms.add(pt.track_ms);
      tracked_frames += pt.tracked > 0 ? 1 : 0;
      full_passes += ob.timing.full_pass ? 1 : 0;
      tracked_detections += ob.timing.tracked;
      objn_sum += ob.timing.objectness_ms;
      feat_sum += ob.timing.features_ms;
      match_sum += ob.timing.match_ms;
      std::vector<Candidate> all;
      // A detection that recognition found but no photo verified is placed by a looser match:
      // its bearing is good enough to steer and to fix by, but a laser return along it may be
      // a neighbour of the landmark, so it is taken for its bearing alone.
      for (const auto& d : ob.detections)
        all.push_back({&d, d.recognised_only ? 0.0 : rangeAt(d.bearing)});
      std::vector<bool> used(all.size(), false);
      // A landmark being tracked is expected where it was last seen, and its detection is not
      // another landmark's (landmark_stage.h: claimedByTracked).
      std::vector<Expected> expect(att.size());
      for (size_t n = 0; n < att.size(); ++n) {
        const LmTrack& t = *att[n].tr;
        expect[n].class_name = att[n].lm->class_name;
        expect[n].tracked = t.state == LmState::Tracking;
        expect[n].where =
            expect[n].tracked
                ? expectedFromTrack(pose, t.last_origin, t.last_world_bearing, t.last_point_range)
                : att[n].pred;
        // A track followed by its bearing alone says nothing of the range: the sketch's
        // prediction still gates a measured one (else the first laser return along the bearing,
        // an obstacle in front, would be taken for the landmark).
        if (expect[n].tracked && expect[n].where.range <= 0)
          expect[n].where.range = att[n].pred.range;
      }
      for (size_t n = 0; n < att.size() && status == RunStatus::Running; ++n) {
        auto& x = att[n];
        if (!x.attend) continue;
        // A detection already given to the landmark before (same class) is not this one.
        std::vector<Candidate> cands;
        std::vector<size_t> idx;
        for (size_t c = 0; c < all.size(); ++c)
          if (!used[c] && !atEarlierFix(x.lm->class_name, *all[c].detection, all[c].range_m) &&
              !claimedByTracked(all[c], n, expect))
            cands.push_back(all[c]), idx.push_back(c);
        SelectParams sp = s.select;
        if (sp.unique_class_bearing_only && classCount(x.lm->class_name) == 1)
          sp.bearing_only_gate_deg = sp.bearing_gate_deg;
        const int ci = selectCandidate(cands, x.lm->class_name, expect[n].where.bearing,
                                       expect[n].where.range, sp);
        if (ci < 0) continue;
        used[idx[ci]] = true;
        const auto& d = *cands[ci].detection;
        // Taken for its bearing alone when its measured range is another object's.
        const bool range_dropped = !rangeAgrees(cands[ci].range_m, expect[n].where.range, sp);
        const double range = range_dropped ? 0.0 : cands[ci].range_m;
        LmTrack& t = *x.tr;
        if (t.state != LmState::Tracking)
          event(event::LandmarkSeen{x.lm->id, x.lm->class_name, x.k, d.inliers,
                                    d.bearing * 180 / M_PI, range, x.pred.bearing * 180 / M_PI,
                                    x.pred.range, range_dropped, cands.size(), n == 0});
        t.state = LmState::Tracking;
        ++t.frames_seen;
        t.max_inliers = std::max(t.max_inliers, d.inliers);
        t.last_seen = now;
        t.last_range = range;
        t.last_bearing = d.bearing;
        t.last_origin = {pose.x, pose.y};
        t.last_world_bearing = pose.theta + d.bearing;
        t.last_point_range = range;
        // Far ranges may be something else along the bearing; the bearing still helps.
        const bool far = range > fixRange();
        // Fixes rest on verified geometry: the bearings of recognised-only detections are
        // noisier by a few degrees, which a triangulation from nearly parallel rays turns into
        // metres; they still steer the servo and keep the track.
        if (!d.recognised_only && (!far || s.exec.fit_bearing_only)) {
          if (t.sightings.size() >= 80) t.sightings.erase(t.sightings.begin());
          Sighting sg{
              {pose.x, pose.y}, pose.theta + d.bearing, far ? 0.0 : range, far ? range : 0.0};
          sg.elevation = d.elevation;
          sg.camera_along_m = s.servo.camera_x_m * std::cos(d.bearing);
          sg.photo = d.photo;
          t.sightings.push_back(sg);
        }
        if (n == 0) {
          const double depth = range > 0 ? range * std::cos(d.bearing) : 0;
          servo_cmd = law.compute(d.x_t, d.x_d, depth);
          ++servo_updates;
          servo_t = now;
          servo_bearing = d.bearing;
          if (range > 0 && range <= passDistance(x.k, *x.lm)) passLandmark(x.k, x.i, true);
        }
      }
    }
    for (auto& x : att) {
      if (status != RunStatus::Running) return;
      LmTrack& t = *x.tr;
      if (t.state != LmState::Tracking || now - t.last_seen <= s.exec.lost_after_s) continue;
      // Out of view when already close (it slid out of the side of the image): passed.
      if (atLandmark(x.k, *x.lm, t.last_range)) {
        passLandmark(x.k, x.i, false);
      } else {
        t.state = LmState::Pending;
        event(event::LandmarkLost{x.lm->id, x.k});
      }
    }
    if (status != RunStatus::Running) return;

    // --- command -------------------------------------------------------------------------
    // Each behaviour that applies proposes a command; the arbiter's priority list decides
    // (command_arbiter.h). The proposals below come lowest priority first.
    CommandArbiter arb;
    double target_bearing;
    bool looking = false;
    const bool servoing =
        tr && tr->state == LmState::Tracking && now - servo_t <= s.exec.servo_hold_s;
    if (servoing) {
      target_bearing = servo_bearing;
      servo_error = servo_cmd.error;
      arb.propose(Behaviour::Servo, {servo_cmd.v, servo_cmd.w, servo_cmd.state});
    } else {
      const Polar la = polarFrom(pose, tracker.lookahead(pose));
      target_bearing = la.bearing;
      // Not seen yet and near: keep it in view (see ExecutiveParams::look_range_m).
      if (lm && tr->state == LmState::Pending && pred.range <= s.exec.look_range_m &&
          pred.range > s.exec.approach_m &&
          std::abs(pred.bearing) <= s.exec.look_max_bearing_deg * M_PI / 180) {
        const double m = s.exec.look_bearing_deg * M_PI / 180;
        target_bearing = std::clamp(target_bearing, pred.bearing - m, pred.bearing + m);
        looking = target_bearing != la.bearing;
      }
      Command c;
      headFor(target_bearing, 1.0, c.v, c.w);
      c.turn = turnOf(target_bearing);
      arb.propose(looking ? Behaviour::Look : Behaviour::Follow, c);
    }
    // Side of the next landmark, for the avoidance's rotation direction.
    // When the robot is already at the attended landmark, the obstacle is most likely the
    // furniture it stands on, and dodging round to its side leads away from the route: the
    // landmark that matters then is the one after it.
    const mapsketch::ExpectedLandmark* next_lm = lm;
    if (lm && att.size() > 1 && pred.range <= passDistance(att[0].k, *lm) + 1.0)
      next_lm = att[1].lm;
    DodgeSide side = DodgeSide::None;
    if (next_lm) {
      if (next_lm->side == mapsketch::Side::Left) side = DodgeSide::Left;
      if (next_lm->side == mapsketch::Side::Right) side = DodgeSide::Right;
      if (next_lm->side == mapsketch::Side::Ahead) {
        const Polar p = polarFrom(pose, tracker.toOdom(next_lm->position_m));
        side = p.bearing >= target_bearing ? DodgeSide::Left : DodgeSide::Right;
      }
    }
    // Docking: close to the goal with a free straight line to it, drive there directly. The
    // goal is a place, often near a wall or in a doorway, and the avoider would keep dodging
    // the wall behind it; the speed is still capped by the clearance ahead.
    // Without a free straight line (a goal in a doorway: the line grazes the door frame), a
    // path planned on the grid leads there, or as near as the robot fits.
    bool docking = false;
    if (k + 1 == tracker.count() && prog.to_end_m <= s.exec.dock_m && !dev.ranges.empty()) {
      const Eigen::Vector2d goal = tracker.endOdom(k);
      const Polar pg = polarFrom(pose, goal);
      const double free =
          corridorFree(scanPoints(scans), pg.bearing,
                       s.avoid.robot_radius_m + s.avoid.corridor_margin_m, s.avoid.max_range_m);
      double bearing = pg.bearing, left = pg.range;
      bool ok = free >= pg.range;
      if (!ok && s.exec.detour) {
        const double b = planTowards(goal);
        // Only a short way round: a long one means the estimate sits behind a wall.
        if (std::isfinite(b) && detour.length_m <= s.exec.dock_m + 1.5) {
          ok = true;
          bearing = b;
          left =
              std::max(0.0, detour.length_m -
                                (detour.points.front() - Eigen::Vector2d(pose.x, pose.y)).norm());
        }
      }
      if (ok) {
        docking = true;
        if (avoider.active()) {
          avoider.reset();
          endDetour("docking");
          event(event::AvoidEnd{DodgeSide::None, true});
        }
        target_bearing = bearing;
        Command c;
        headFor(bearing, std::clamp(left / 0.6, 0.3, 1.0), c.v, c.w);  // slow in the last 0.6 m
        c.turn = turnOf(bearing);
        arb.propose(Behaviour::Dock, c);
      }
    }
    // Stuck recovery: the reactive layers can livelock (boxed in between furniture, the route
    // behind an obstacle the dodge went round the wrong way), turning on the spot. Not having
    // moved stuck_m in stuck_s, the robot drives recover_m towards the most open direction
    // (ties to the route side), then resumes.
    if (!recovering && !docking && !dev.ranges.empty() && progress_checker.due(now)) {
      const bool stuck = progress_checker.stuck(pose, now);
      if (stuck) {
        const auto pts = scanPoints(scans);
        const double hwid = s.avoid.robot_radius_m + s.avoid.corridor_margin_m;
        double best = -1e9, best_a = 0;
        for (int i = 0; i < 36; ++i) {
          const double a = wrapAngle(i * M_PI / 18);
          const double free = corridorFree(pts, a, hwid, s.avoid.max_range_m);
          const double score = std::min(free, s.exec.recover_m + 0.5) -
                               0.3 * std::abs(wrapAngle(a - target_bearing));
          if (free >= 0.5 && score > best) best = score, best_a = a;
        }
        if (best > -1e9) {
          recovering = true;
          ++recoveries;
          rec_dir = wrapAngle(pose.theta + best_a);
          rec_t0 = now;
          rec_from = pose;
          if (avoider.active()) avoider.reset();
          event(event::RecoverStart{best_a * 180 / M_PI});
          log::warn("nav", "stuck: driving clear before resuming",
                    {{"direction_deg", std::to_string(static_cast<int>(best_a * 180 / M_PI))}});
        }
      }
    }
    if (recovering) {
      const double a = wrapAngle(rec_dir - pose.theta);
      const double w = std::clamp(s.avoid.k_heading * a, -s.exec.max_w, s.exec.max_w);
      const double v = std::abs(a) > 0.35 ? 0.0 : avoider.capSpeed(scans, 0.7 * s.exec.v_cruise);
      arb.propose(Behaviour::Recover, {v, w, turnOf(w)});
      const bool blocked = std::abs(a) <= 0.35 && v <= 0;
      if (std::hypot(pose.x - rec_from.x, pose.y - rec_from.y) >= s.exec.recover_m ||
          now - rec_t0 > s.exec.recover_s || blocked) {
        recovering = false;
        progress_checker.reset(pose, now);
        event(event::RecoverEnd{});
      }
    }
    double front = 0;
    bool dodging = false;  // an avoidance manoeuvre (reactive or planned) is under way
    if (docking || recovering) {
      endDetour(docking ? "docking" : "recovering");
      if (docking) arb.setWinnerSpeed(avoider.capSpeed(scans, arb.winner().v));
    } else if (!dev.ranges.empty()) {
      avoider.setPose(pose);
      for (const auto& m : movers.walkers()) avoider.offerWalker(m.position, m.velocity);
      const auto av = avoider.step(scans, target_bearing, side, pose.theta, s.exec.v_cruise, now);
      front = av.front_free_m;
      if (av.in_lane && !in_lane) event(event::WalkerLane{av.walker_pos, av.walker_vel, k});
      in_lane = av.in_lane;
      if (av.started) {
        ++manoeuvres;
        event(event::AvoidStart{av.side, av.original_heading * 180 / M_PI, av.front_free_m, k});
        // Dodging something right at the landmark being servoed on: it stands on or against
        // that furniture, and this is as close as the robot gets. Passing it now keeps the
        // servo from steering back into the furniture after the dodge (a robot circled the
        // lab bench its landmark was on).
        if (tr && lm && tr->state == LmState::Tracking && atLandmark(att[0].k, *lm, tr->last_range))
          passLandmark(att[0].k, att[0].i, false);
      }
      if (av.ended) {
        if (!s.exec.detour_hold) endDetour("avoid ended");
        event(event::AvoidEnd{av.side});
      }
      if (av.active) {
        dodging = true;
        // Something standing still: follow a way round planned on the grid, back to the route
        // a few metres on. Something coming towards the robot (a person) is left to the
        // reactive dodge, whose rules step out of its way.
        // Once something has come towards the robot in this manoeuvre it stays reactive: the
        // approach estimate drops while the robot backs off and turns, and a plan through
        // the grid's picture of the person then led a robot straight into them.
        if (av.started) moving_seen = false;
        // A walker's lane too: a detour planned on the grid ignores the lane, and one drove an
        // exp4-pedestrian-left robot along it into the walker.
        moving_seen |= av.approach_speed >= 0.25 || av.in_lane;
        double b = std::numeric_limits<double>::quiet_NaN();
        if (s.exec.detour && !moving_seen)
          b = planTowards(tracker.lookahead(pose, s.exec.detour_ahead_m));
        if (std::isfinite(b)) {
          if (!detouring) {
            detouring = true;
            ++detours;
            event(event::DetourStart{detour.length_m, detour.goal, detour.goal_moved, k});
          }
          arb.propose(Behaviour::Detour, detourCommand(b));
        } else {
          endDetour(moving_seen ? "coming towards the robot" : "no way found");
          arb.propose(Behaviour::Avoid, {av.v, av.w, turnOf(av.w)});
        }
      } else {
        bool held = false;
        if (s.exec.detour_hold && detouring && !servoing) {
          // The avoider has let go (the corridor towards the route is free release_m ahead),
          // but round a box or through a door that is before the robot is past it: heading
          // back to the route from here drives into the same obstacle again. The detour is
          // followed until the straight line to the route point it leads to is clear.
          const Eigen::Vector2d to = tracker.lookahead(pose, s.exec.detour_ahead_m);
          const double hwid = s.avoid.robot_radius_m + s.avoid.corridor_margin_m;
          const double b = planTowards(to);
          if (planner.segmentClear({pose.x, pose.y}, to, hwid)) {
            endDetour("route clear");
          } else if (!std::isfinite(b)) {
            endDetour("no way found");
          } else {
            dodging = held = true;
            arb.propose(Behaviour::Detour, detourCommand(b));
          }
        } else if (servoing) {
          endDetour("servoing");
        }
        if (!held) arb.setWinnerSpeed(avoider.capSpeed(scans, arb.winner().v));
      }
    } else {
      endDetour("no range data");
    }
    sideLook(att.empty() ? nullptr : &att[0], docking || recovering, dodging && moving_seen, arb);
    // An end point that cannot be reached (the sketch put it in or against an obstacle): when
    // the robot is dodging within end_blocked_m of it, the section is done.
    bool end_blocked = false;
    // The goal counts as blocked only when the robot cannot get within 0.6 m of it.
    const double blocked_m =
        k + 1 == tracker.count() ? std::min(0.6, s.exec.end_blocked_m) : s.exec.end_blocked_m;
    if (dodging && prog.to_end_m <= blocked_m && !sectionBlocked_) {
      // Blocked means the range sensors see something at or before the end point itself.
      const Polar pe = polarFrom(pose, tracker.endOdom(k));
      const double r = rangeAt(pe.bearing);
      // For the goal, only an obstacle the robot could not stand next to the point for: a goal
      // half a metre from a wall is reachable and must be reached.
      const bool last = k + 1 == tracker.count();
      end_blocked = r > 0 && r < pe.range + s.avoid.robot_radius_m + (last ? -0.05 : 0.1);
    }
    // Near the goal but no longer getting closer (the estimate sits where the robot cannot
    // stand, e.g. against a door frame): the best it can do is where it is.
    // A final look turns on the spot by design, and the landmark it finds moves the goal: the
    // clock starts again when it ends. (Counted, it settled an exp2-redrawn-d robot 0.21 m
    // short of its estimate, driving towards it at 0.1 m/s.)
    const bool goal_settled =
        settle_checker.update(k + 1 == tracker.count(), prog.to_end_m, now, final_looking);
    // (No final look from here: a robot settled short of the goal is usually beside furniture,
    // and the looks taken from there fixed L7 by laser ranges to the bench under it, 0.6-0.9 m
    // off, which moved the goal the wrong way: 2 of 52 experiment trials lost.)
    if (goal_settled) {
      event(event::GoalSettled{prog.to_end_m});
      tracker.advance();
      closeSections(k);
      if (status != RunStatus::Running) return;
      succeed("reached the end of the route (could not get closer than " +
              std::to_string(prog.to_end_m).substr(0, 4) + " m)");
      return;
    }
    if (end_blocked) {
      sectionBlocked_ = true;
      event(event::EndBlocked{k, prog.to_end_m});
      tracker.advance();
      closeSections(k);
      if (status != RunStatus::Running) return;
      if (tracker.finished()) {
        succeed("reached the end of the route (end point blocked, " +
                std::to_string(prog.to_end_m).substr(0, 4) + " m away)");
        return;
      }
    }
    // Walking people: keep out of their lanes (movers.h). In one: step out sideways (backing
    // only slowly and with room behind); about to enter one: wait, turning is harmless.
    if (s.movers.enabled && !dev.ranges.empty() && status == RunStatus::Running) {
      // It advises on the command that would drive otherwise, and may keep its yaw rate.
      const Command cur = arb.winner();
      const auto adv = movers.advise(pose, cur.v, cur.w, s.exec.k_heading, s.exec.v_cruise);
      if (adv.active) {
        Command c = cur;
        if (!adv.in_lane) {
          c.v = 0;
        } else if (adv.v >= 0) {
          c.v = avoider.capSpeed(scans, adv.v);
          c.w = adv.w;
        } else {
          const double hwid = s.avoid.robot_radius_m + s.avoid.corridor_margin_m;
          c.v = corridorFree(scanPoints(scans), M_PI, hwid, s.avoid.max_range_m) > 0.5
                    ? -s.avoid.reverse_speed
                    : 0.0;
          c.w = adv.w;
        }
        c.turn = turnOf(c.w);
        arb.propose(Behaviour::Yield, c);
        if (!yielding) {
          yielding = true;
          ++yields;
          event(event::YieldStart{adv.in_lane, adv.clearance_m, adv.mover.position,
                                  adv.mover.velocity, pose});
        }
      } else if (yielding) {
        yielding = false;
        event(event::YieldEnd{});
      }
    }
    if (final_looking && fl_k >= 0) {
      // Turn on the spot to where the sketch puts the landmark (perception attends it once it
      // is within attend_bearing_deg).
      const auto& l = tracker.route().sections[fl_k].landmarks[fl_i];
      const double b = polarFrom(pose, tracker.toOdom(l.position_m)).bearing;
      const double w = std::abs(b) < 0.1 ? 0.0 : s.exec.k_heading * b;
      arb.propose(Behaviour::FinalLook, {0.0, w, turnOf(w)});
    }
    // Behind someone walking the same way, whatever drives: keep the following gap.
    if (!dev.ranges.empty() && arb.winner().v > 0)
      arb.setWinnerSpeed(movers.followSpeed(pose, arb.winner().v));
    const Command& cmd = arb.winner();
    const Mode mode = modeOf(arb.winning());
    const servo::Turn turn = cmd.turn;
    const double v = cmd.v;
    const double w = std::clamp(cmd.w, -s.exec.max_w, s.exec.max_w);
    dev.base->command(v, w);
    if (perceived)
      grab_to_command_ms.add(
          grab_lag_ms +
          std::chrono::duration<double, std::milli>(WallClock::now() - grab_wall).count());
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

  // Looking to the side (ExecutiveParams::side_look_s): starts when the attended landmark `a`
  // (never seen, no look spent on it) is predicted outside the camera's view and within
  // range; ends when it is seen, is no longer the attended one, or the budget is spent.
  // While it lasts it proposes a turn on the spot towards it, except while the robot is
  // busy elsewhere (`busy`: docking or recovering, no look starts) or dodging something that
  // comes towards it (`give_way`: the dodge drives; the clock still runs).
  template <class A>
  void sideLook(const A* a, bool busy, bool give_way, CommandArbiter& arb) {
    const auto& p = s.exec;
    const double max_b = p.side_look_max_bearing_deg * M_PI / 180;
    if (side_looking) {
      const LmTrack& t = tracks[sl_k][sl_i];
      const bool same = a && a->k == sl_k && a->i == sl_i;
      const bool seen = t.frames_seen > 0;
      if (seen || !same || final_looking || now - sl_t > p.side_look_s ||
          std::abs(a->pred.bearing) > max_b) {
        side_looking = false;
        event(event::SideLookEnd{tracker.route().sections[sl_k].landmarks[sl_i].id, seen,
                                 now - sl_t});
        // Standing still to look is not being stuck.
        progress_checker.reset(pose, now);
      }
    } else if (a && dev.camera && p.side_look_s > 0 && !busy && !final_looking &&
               a->tr->state == LmState::Pending && a->tr->frames_seen == 0 && !a->tr->side_looked) {
      const double b = std::abs(a->pred.bearing);
      if (b > half_fov - p.side_look_margin_deg * M_PI / 180 && b <= max_b &&
          a->pred.range <= p.side_look_range_m && a->pred.range >= p.side_look_min_range_m) {
        side_looking = true;
        sl_k = a->k;
        sl_i = a->i;
        sl_t = now;
        a->tr->side_looked = true;
        event(event::SideLookStart{a->lm->id, a->k, a->pred.bearing * 180 / M_PI, a->pred.range});
      }
    }
    if (side_looking && !give_way) {
      const double w = std::clamp(p.k_heading * a->pred.bearing, -p.max_w, p.max_w);
      arb.propose(Behaviour::SideLook, {0.0, w, turnOf(w)});
    }
  }

  // A doorway goal (mapsketch::GoalPlace): while the sketch's goal is within look_m, each laser
  // scan's doorways whose stopping point lies within search_m of it are sightings; once
  // min_scans of the recent ones agree within agree_m, their mean is the goal (and keeps being
  // refined as the robot comes closer and sees the jambs better).
  void lookForGoalDoor(const hw::RangeScan& sc) {
    const auto& place = tracker.route().goal_place;
    if (!s.goal_door.enabled || place.kind != mapsketch::GoalPlace::Kind::Doorway ||
        sc.kind != hw::RangeScan::Kind::Laser || tracker.finished())
      return;
    const Eigen::Vector2d here(pose.x, pose.y);
    const Eigen::Vector2d drawn = tracker.toOdom(tracker.route().goal_m);
    if ((drawn - here).norm() > s.goal_door.look_m) return;
    const Doorway* best = nullptr;
    Eigen::Vector2d best_stop;
    double best_d = s.goal_door.search_m;
    const auto doors = findDoorways(sc, pose, s.goal_door);
    for (const auto& d : doors) {
      const Eigen::Vector2d stop = d.centre + place.standoff_m * d.normal;
      const double dist = (stop - drawn).norm();
      if (dist <= best_d) best = &d, best_d = dist, best_stop = stop;
    }
    if (!best) return;
    door_stops.push_back(best_stop);
    if (door_stops.size() > 30) door_stops.erase(door_stops.begin());
    Eigen::Vector2d sum(0, 0);
    int n = 0;
    for (const auto& p : door_stops)
      if ((p - best_stop).norm() <= s.goal_door.agree_m) sum += p, ++n;
    if (n < s.goal_door.min_scans) return;
    const Eigen::Vector2d goal = sum / n;
    if (!tracker.goalOdom()) {
      event(event::GoalDoor{best->centre, best->width_m, goal, (goal - drawn).norm(),
                            place.standoff_m, n});
      log::info("nav", "goal doorway found",
                {{"width_m", std::to_string(best->width_m).substr(0, 4)},
                 {"moved_m", std::to_string((goal - drawn).norm()).substr(0, 4)}});
    }
    tracker.setGoalOdom(goal);
  }

  // Bearing [rad, robot frame] of the carrot on a path planned to `goal` (odometry frame),
  // replanned every replan_s or when the goal moved; NaN when there is no way there.
  double planTowards(const Eigen::Vector2d& goal) {
    if (now - detour_t >= s.exec.replan_s - 1e-9 || (goal - detour_goal).norm() > 0.3) {
      detour = planner.plan({pose.x, pose.y}, goal);
      detour_t = now;
      detour_goal = goal;
    }
    if (!detour.found) return std::numeric_limits<double>::quiet_NaN();
    const Eigen::Vector2d c =
        LocalPlanner::carrot(detour, {pose.x, pose.y}, planner.params().carrot_m);
    return polarFrom(pose, c).bearing;
  }
  // Along a planned detour: towards bearing `b` [rad, robot frame] of its carrot, the speed
  // capped by the clearance ahead.
  Command detourCommand(double b) {
    Command c;
    headFor(b, 1.0, c.v, c.w);
    c.v = avoider.capSpeed(scans, c.v);
    c.turn = turnOf(c.w);
    return c;
  }
  void endDetour(const char* reason) {
    if (!detouring) return;
    detouring = false;
    event(event::DetourEnd{reason});
  }

  // At the goal: whether to stay and look for a never-seen landmark of the last section within
  // final_look_range_m (starts the look on the first call, ends it when the landmark is seen
  // or after final_look_s).
  bool finalLook() {
    if (fl_done || tracker.finished() || s.exec.final_look_range_m <= 0) return false;
    if (fl_k < 0) {
      // Any section's: a landmark a few metres before the goal was often missed on the way
      // (out of recognition range, or out of view) and is within range from the goal.
      double best = s.exec.final_look_range_m;
      for (int kl = 0; kl < tracker.count(); ++kl)
        for (size_t i = 0; i < tracks[kl].size(); ++i) {
          const auto& t = tracks[kl][i];
          if (t.frames_seen > 0 || (t.state != LmState::Pending && t.state != LmState::Missed))
            continue;
          const auto& l = tracker.route().sections[kl].landmarks[i];
          const double r = polarFrom(pose, tracker.toOdom(l.position_m)).range;
          if (r <= best) best = r, fl_k = kl, fl_i = static_cast<int>(i);
        }
      if (fl_k < 0) {
        fl_done = true;
        return false;
      }
      fl_t = now;
      fl_was_missed = tracks[fl_k][fl_i].state == LmState::Missed;
      tracks[fl_k][fl_i].state = LmState::Pending;  // a missed one is looked for again
      const auto& l = tracker.route().sections[fl_k].landmarks[fl_i];
      event(event::FinalLookStart{l.id, best});
    }
    const auto& t = tracks[fl_k][fl_i];
    const bool seen = t.frames_seen > 0;
    // Seen: a few frames for its bearings to cross (the fix), then passed.
    const bool enough = t.frames_seen >= 3 || t.state == LmState::Passed;
    if (enough || now - fl_t > s.exec.final_look_s) {
      fl_done = true;
      const auto& l = tracker.route().sections[fl_k].landmarks[fl_i];
      event(event::FinalLookEnd{l.id, seen});
      if (t.state == LmState::Tracking || (t.state == LmState::Pending && seen))
        passLandmark(fl_k, fl_i, false);
      else if (t.state == LmState::Pending && fl_was_missed)
        tracks[fl_k][fl_i].state = LmState::Missed;  // as it was (counted then)
      else if (t.state == LmState::Pending)
        markMissed(fl_k, fl_i);
      return false;
    }
    return true;
  }

  // Whether a detection of `cls` is where an earlier landmark of that class was fixed (the
  // same object seen again, not the next one of a repeated class): its ranged point within
  // same_class_gate_m of that fix, or without a usable range, its ray passing within half that.
  bool atEarlierFix(const std::string& cls, const Detection& d, double range) const {
    const Eigen::Vector2d o(pose.x, pose.y);
    const Eigen::Vector2d dir(std::cos(pose.theta + d.bearing), std::sin(pose.theta + d.bearing));
    for (size_t j = 1; j < fixes_odom.size(); ++j) {
      if (fixes_class[j] != cls || !fixes_across[j].isZero()) continue;
      const Eigen::Vector2d v = fixes_odom[j] - o;
      if (range > 0 && range <= fixRange()) {
        if ((o + range * dir - fixes_odom[j]).norm() < s.exec.same_class_gate_m) return true;
      } else if (v.dot(dir) > 0 &&
                 std::abs(dir.x() * v.y() - dir.y() * v.x()) < 0.5 * s.exec.same_class_gate_m) {
        return true;
      }
    }
    return false;
  }

  // Sightings further than this are not ranged fixes (the laser along the bearing may hit
  // something else that far out).
  double fixRange() const { return s.exec.max_approach_m + 1.5; }

  // How many landmarks of the sketch have this class.
  int classCount(const std::string& cls) const {
    int n = 0;
    for (const auto& sec : tracker.route().sections)
      for (const auto& l : sec.landmarks) n += l.class_name == cls;
    return n;
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
  // A measured range within a metre of the pass distance: the robot is at the landmark (one
  // that slid out of view there was passed; the furniture being dodged there is its own).
  bool atLandmark(int k, const mapsketch::ExpectedLandmark& lm, double range) const {
    return range > 0 && range <= passDistance(k, lm) + 1.0;
  }

  void passLandmark(int k, int i, bool seen_close) {
    auto& tr = tracks[k][i];
    const auto& lm = tracker.route().sections[k].landmarks[i];
    tr.state = LmState::Passed;
    // Passed out of order (the one after the attended landmark was seen first): every earlier
    // landmark still pending is behind the robot now.
    for (int kk = 0; kk <= k; ++kk)
      for (int ii = 0; ii < (kk < k ? static_cast<int>(tracks[kk].size()) : i); ++ii)
        if (tracks[kk][ii].state == LmState::Pending) {
          if (tracks[kk][ii].frames_seen > 0)
            tracks[kk][ii].state = LmState::Passed;
          else
            markMissed(kk, ii, false);
        }
    missed_in_row = 0;
    event::LandmarkPassed e;
    e.id = lm.id;
    e.class_name = lm.class_name;
    e.section = k;
    e.range_m = tr.last_range;
    e.frames_seen = tr.frames_seen;
    e.in_view = seen_close;
    // Where the landmark really is (odometry frame: its bearings crossed, and the ranges that
    // agree) vs where the sketch puts it: refit or rotate the route, then shift it, each by
    // its gain. A landmark that slid out of view when close was seen as well as one passed in
    // view, and the last landmark before the goal is often passed that way.
    LandmarkFix lf = locateLandmark(tr.sightings, s.locate);
    if (lf.ok && lf.bearing_only && !(s.exec.fit_bearing_only && s.exec.fit_weighted))
      lf.ok = false;  // (an equal-weight fit would take its nominal point as exact)
    // Across the rays of a bearing-only fix (the newest sighting's).
    Eigen::Vector2d across = Eigen::Vector2d::Zero();
    if (lf.ok && lf.bearing_only) {
      const double a = tr.sightings.back().direction;
      across = {-std::sin(a), std::cos(a)};
    }
    // Located where an earlier landmark of the same class was (a bearing-only one: its rays
    // pass there): the sightings were of that one.
    for (size_t j = 1; lf.ok && j < fixes_odom.size(); ++j) {
      if (fixes_class[j] != lm.class_name || !fixes_across[j].isZero()) continue;
      const Eigen::Vector2d v = fixes_odom[j] - lf.position;
      if (lf.bearing_only ? std::abs(across.dot(v)) < 0.5 * s.exec.same_class_gate_m
                          : v.norm() < s.exec.same_class_gate_m) {
        lf.ok = false;
        e.fix_rejected = "where an earlier " + lm.class_name + " was";
      }
    }
    if (lf.ok) {
      const Eigen::Vector2d seen = lf.position;
      auto& fx = e.fix.emplace();
      fx.method = lf.bearing_only ? "bearing only" : lf.triangulated ? "bearings" : "ranges";
      fx.rays = lf.rays;
      fx.ranges_used = lf.ranges_used;
      fx.height_ranges = lf.height_ranges;
      fx.height_sigma_m = lf.height_sigma_m;
      fx.ranges_dropped = lf.ranges_dropped;
      for (const auto& q : tr.sightings)
        fx.sightings.push_back({q.origin.x(), q.origin.y(), q.direction, q.range_m});
      // A bearing-only fix says nothing along its rays: only the across part shifts anything.
      auto toward = [&](const Eigen::Vector2d& d) -> Eigen::Vector2d {
        return lf.bearing_only ? Eigen::Vector2d(across * across.dot(d)) : d;
      };
      // Shift the route `gain` of the way to the fix, as the route stands then.
      auto reanchorOn = [&](double gain) {
        const Eigen::Vector2d at = tracker.toOdom(lm.position_m);
        tracker.reanchor(lm.position_m, at + toward(seen - at), gain);
      };
      const Eigen::Vector2d shift = toward(seen - tracker.toOdom(lm.position_m));
      fixes_route.push_back(lm.position_m);
      fixes_odom.push_back(seen);
      fixes_info.push_back(lf.information);
      fixes_class.push_back(lm.class_name);
      fixes_across.push_back(across);
      // With enough fixes spread far enough: refit rotation, scale and translation to the
      // last fit_fixes of them (the start counts as one) by least squares, then pull the route
      // fit_local_gain of the way to this one (0 by default, see executive.h).
      const size_t n = std::min<size_t>(fixes_route.size(), std::max(0, s.exec.fit_fixes));
      std::vector<size_t> idx;  // the fixes fitted: the last n (and the start, if asked)
      if (s.exec.fit_keep_start && fixes_route.size() > n) idx.push_back(0);
      for (size_t j = fixes_route.size() - n; j < fixes_route.size(); ++j) idx.push_back(j);
      std::vector<Eigen::Vector2d> fr, fo;
      for (size_t j : idx) fr.push_back(fixes_route[j]), fo.push_back(fixes_odom[j]);
      double span = 0;
      for (const auto& a : fr)
        for (const auto& b : fr) span = std::max(span, (a - b).norm());
      if (n >= 3 && span >= s.exec.fit_min_span_m) {
        SectionTracker::Fit f;
        if (s.exec.fit_weighted) {
          WeightedFitParams wp;
          wp.outlier_m = s.exec.fit_outlier_m;
          wp.max_scale_change = s.exec.fit_max_scale_change;
          std::vector<WeightedFix> wf;
          for (size_t j : idx) wf.push_back({fixes_route[j], fixes_odom[j], fixes_info[j], j == 0});
          f = tracker.fitSimilarityWeighted(wf, wp);
        } else {
          f = tracker.fitSimilarity(fr, fo, s.exec.fit_max_scale_change, s.exec.fit_outlier_m);
        }
        // Not towards the newest fix when the fit found it an outlier.
        if (f.used.empty() || f.used.back()) reanchorOn(s.exec.fit_local_gain);
        fx.fit = event::LandmarkPassed::Refit{f.rotation * 180 / M_PI, tracker.scale(), f.rms,
                                              idx.size(), f.dropped};
      } else {
        const double rot = lf.bearing_only
                               ? 0.0
                               : tracker.realign(lm.position_m, seen, fix_route, fix_odom,
                                                 s.exec.realign_gain, s.exec.realign_baseline_m);
        reanchorOn(s.exec.reanchor_gain);
        fx.realign =
            event::LandmarkPassed::Realign{rot * 180 / M_PI, shift.norm() * s.exec.reanchor_gain};
      }
      fx.disagreement_m = shift.norm();
      // Both ends of the fix, for judging the sketch's and the estimator's errors offline.
      fx.route = lm.position_m;
      fx.odom = seen;
      if (!lf.bearing_only) {  // the anchor of the next realign: a point, not a ray
        fix_route = lm.position_m;
        fix_odom = seen;
      }
    }
    event(std::move(e));
    log::info("nav", "landmark passed", {{"id", lm.id}, {"class", lm.class_name}});
  }

  void closeSections(int from) {
    for (int k = from; k < tracker.current() && status == RunStatus::Running; ++k) {
      for (size_t i = 0; i < tracks[k].size(); ++i) {
        auto& tr = tracks[k][i];
        if (tr.state == LmState::Tracking || (tr.state == LmState::Pending && tr.frames_seen > 0))
          passLandmark(k, static_cast<int>(i), false);
        else if (tr.state == LmState::Pending)
          markMissed(k, static_cast<int>(i));
        if (status != RunStatus::Running) return;
      }
      // Where the (re-anchored) route put the end point, and the robot: for judging the sketch.
      const Eigen::Vector2d end = tracker.endOdom(k);
      event(event::SectionDone{k, tracker.count(), end, pose});
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
  I.progress_checker.reset(hw::Pose2D{}, I.t0);
  I.fix_route = I.tracker.route().start_m;
  I.fix_odom = I.tracker.toOdom(I.fix_route);
  I.fixes_route = {I.fix_route};
  I.fixes_odom = {I.fix_odom};
  I.fixes_class = {""};
  I.fixes_info = {Eigen::Matrix2d::Identity() / (0.05 * 0.05)};  // the start: where it is put
  I.fixes_across = {Eigen::Vector2d::Zero()};
  I.safety.start(I.t0);
  I.wall0 = I.wall_last = Impl::WallClock::now();
  // Room for a whole run's samples up front: no reallocation inside the loop.
  const double frames_max = I.s.exec.max_time_s / I.s.exec.camera_period_s + 1;
  const auto n = static_cast<size_t>(std::min(frames_max, 65536.0));
  for (auto* a : {&I.grab_to_command_ms, &I.perception_ms, &I.objectness_ms, &I.features_ms,
                  &I.match_ms, &I.track_ms})
    a->reserve(n);
  I.status = RunStatus::Running;
  I.event(event::Start{I.tracker.count(), I.tracker.route().total_length_m});
}

void Executive::step() {
  auto& I = *impl_;
  if (I.status != RunStatus::Running) return;
  ++I.ticks;
  try {
    I.tick();
  } catch (const std::exception& e) {
    I.dev.base->stop();
    I.event(event::Fault{"exception", e.what()});
    I.fail(FailureCode::SafetyStop, std::string("safety stop: exception: ") + e.what());
  } catch (...) {
    I.dev.base->stop();
    I.fail(FailureCode::SafetyStop, "safety stop: unknown exception");
  }
  I.wall_last = Impl::WallClock::now();
}

void Executive::stop(const std::string& reason) {
  impl_->fail(FailureCode::Stopped, reason);
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
  s.failure = I.failure;
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
    s.perception_ms_mean = I.perception_ms.mean();
    s.objectness_ms_mean = I.objn_sum / I.processed;
    s.features_ms_mean = I.feat_sum / I.processed;
    s.match_ms_mean = I.match_sum / I.processed;
  }
  if (!I.perception_ms.empty()) s.perception_ms_max = I.perception_ms.max();
  s.full_passes = I.full_passes;
  s.tracked_detections = I.tracked_detections;
  LoopTiming& lt = s.timing;
  lt.ticks = I.ticks;
  lt.frames = I.frames;
  lt.perception_frames = I.processed;
  lt.full_passes = I.full_passes;
  lt.tracked_frames = I.tracked_frames;
  lt.servo_updates = I.servo_updates;
  lt.wall_s = std::chrono::duration<double>(I.wall_last - I.wall0).count();
  lt.grab_to_command_ms = I.grab_to_command_ms.summary();
  lt.perception_ms = I.perception_ms.summary();
  lt.objectness_ms = I.objectness_ms.summary();
  lt.features_ms = I.features_ms.summary();
  lt.match_ms = I.match_ms.summary();
  lt.track_ms = I.track_ms.summary();
  s.avoidance_manoeuvres = I.manoeuvres;
  s.recoveries = I.recoveries;
  s.detours = I.detours;
  s.yields = I.yields;
  s.laser_odometry = I.lodo.stats();
  return s;
}

}  // namespace sketchnav::nav
