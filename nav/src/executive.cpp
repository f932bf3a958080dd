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

namespace {
// Backing out when wedged (Recovery::startBack): the trail must run straight back within this
// [m] of the line (the robot reversing straight stays on the floor it came over), and the point
// backed out to lie within this [rad] of straight behind.
constexpr double kTrailTolerance_m = 0.1;
constexpr double kBackOutCone_rad = M_PI / 3;
}  // namespace

void ExecutiveParams::validate() const {
  DriveParams::validate();
  LandmarkTrackerParams::validate();
  RouteAnchorParams::validate();
  LookParams::validate();
  SideLookParams::validate();
  FinalLookParams::validate();
  RecoverParams::validate();
  DockParams::validate();
  DetourParams::validate();
  require(tick_s > 0.001 && tick_s <= 0.2, "nav.tick_s", "must be in (0.001, 0.2] s");
  require(camera_period_s > 0 && camera_period_s <= 2, "nav.camera_period_s",
          "must be in (0, 2] s");
  require(max_time_s > 0, "nav.max_time_s", "must be > 0");
  require(section_time_factor >= 1, "nav.section_time_factor", "must be >= 1");
  require(section_time_extra_s >= 0, "nav.section_time_extra_s", "must be >= 0");
  require(servo_hold_s >= 0, "nav.servo_hold_s", "must be >= 0");
  require(end_blocked_m >= 0, "nav.end_blocked_m", "must be >= 0");
  require(perception_period_s >= 0, "nav.perception_period_s", "must be >= 0");
  require(goal_stop_s >= 0, "nav.goal_stop_s", "must be >= 0");
  require(goal_settle_m >= 0, "nav.goal_settle_m", "must be >= 0");
  require(goal_settle_s > 0, "nav.goal_settle_s", "must be > 0");
  require(section_settle_frac >= 0 && section_settle_frac <= 1, "nav.section_settle_frac",
          "must be in [0, 1]");
  require(section_settle_s > 0, "nav.section_settle_s", "must be > 0 s");
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
  s.servo = servo::turnLawParamsFrom(c);
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
  YieldBehaviour yield;

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
  int frames = 0, processed = 0, manoeuvres = 0;
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
  LandmarkTracker landmarks;  // per section, per expected landmark: pending ... passed
  servo::TurnCommand servo_cmd;
  double servo_t = -1e300, servo_bearing = 0;
  double last_perception_t = -1e300;
  bool sectionBlocked_ = false;
  // Stuck recovery: where the robot was stuck_s ago, and an escape under way.
  ProgressChecker progress_checker;
  Recovery recovery;
  bool looked = false;  // the last stuck test started a recovery that only turns to look
  Trail trail;          // the robot's last metres of path (backing out when wedged)
  Docking docker;
  Detour detour;         // a planned way round (or docking's path)
  bool in_lane = false;  // a walker's lane covered the robot at the last step
  FollowBehaviour follow;
  // Final look: at the goal, a landmark never seen (too far so far) is looked for before
  // arriving.
  FinalLook final_look;
  bool final_looking = false;  // this tick
  SideLook side_look;          // (its camera's field of view is known once the camera is)
  SettleChecker settle_checker;
  SectionSettleChecker section_settle;  // an intermediate end the robot cannot get near
  RouteAnchor anchor;                   // the fixes and the refit / realign policy
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
        yield(st.avoid.reverse_speed),
        landmarks(tracker.route(), st.exec),
        progress_checker(st.exec.stuck_s, st.exec.stuck_m),
        recovery(st.exec, st.avoid.k_heading, st.exec.max_w),
        docker(st.exec),
        detour(st.exec, st.exec),
        follow(st.exec, st.exec, st.exec.approach_m),
        final_look(st.exec, st.exec.k_heading),
        side_look(st.exec, 0.0, st.exec.k_heading, st.exec.max_w),
        settle_checker(st.exec.goal_settle_m, st.exec.goal_settle_s),
        section_settle(st.exec.section_settle_frac, st.exec.end_blocked_m,
                       st.exec.section_settle_s),
        anchor(st.exec) {
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
    // The camera's half horizontal field of view.
    if (dev.camera)
      side_look = SideLook(s.exec, std::atan2(0.5 * K.width, K.fx), s.exec.k_heading, s.exec.max_w);
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

  // A landmark missed: reported, and the run fails when too many were missed in a row
  // (LandmarkTracker::miss).
  void reportMiss(const LandmarkTracker::Miss& m) {
    event(m.event);
    log::warn("nav", "landmark not seen, continuing on odometry",
              {{"id", m.event.id}, {"class", m.event.class_name}});
    if (m.lost) fail(FailureCode::Lost, *m.lost);
  }
  // `counts`: towards "lost: N in a row" (LandmarkTracker::miss).
  void markMissed(int sec, int i, bool counts = true) {
    reportMiss(landmarks.miss(sec, i, counts));
  }

  // What one control tick carries from one stage to the next (tick()).
  struct Tick {
    hw::Frame frame;
    bool have_frame = false;  // a new camera frame this tick
    bool perceived = false;   // perception looked at `frame` this tick
    int k = -1;               // the current section
    const mapsketch::PathSection* sec = nullptr;
    SectionProgress prog;
    std::vector<AttendedLandmark> att;                // the attended landmarks, first served
    const mapsketch::ExpectedLandmark* lm = nullptr;  // the first of them (null: none)
    const LandmarkTrack* tr = nullptr;                // and its track
    Polar pred;                                       // where the sketch puts it
    double servo_error = std::numeric_limits<double>::quiet_NaN();
    CommandArbiter arb;  // the behaviours' proposals
    bool servoing = false;
    bool docking = false;
    bool dodging = false;              // an avoidance manoeuvre (reactive or planned) is under way
    double front = 0;                  // [m] free length ahead (telemetry)
    double target_bearing = 0;         // [rad] where following (or the servo, or docking) heads
    DodgeSide side = DodgeSide::None;  // the avoidance's rotation direction
    std::vector<Mover> walkers;        // the mover tracker's walkers
    SideLook::Outcome sl;
  };

  // One control tick, in the order of doc/navigation.md: the sensors, the safety checks, the
  // route's sections, the landmark stage, the behaviours' proposals, the ends of sections, and
  // the command. A stage that ends the run (or has nothing left to do this tick) returns false.
  void tick() {
    now = dev.clock->now();
    Tick t;
    readSensors(t);
    if (!checkSafety()) return;
    if (!sectionStage(t)) return;
    if (!landmarkStage(t)) return;
    proposeDrive(t);
    proposeAvoidance(t);
    proposeSideLook(t);
    if (!sectionEnds(t)) return;
    command(t);
  }

  // Odometry, range scans (the movers, the grid, the goal doorway) and a camera frame when one
  // is due.
  void readSensors(Tick& t) {
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
    // Backing out runs back along the trail; it is cut there when the back-out ends.
    if (have_pose && !(recovery.active() && recovery.backing())) trail.add({pose.x, pose.y});
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
    hw::Frame& frame = t.frame;
    bool& have_frame = t.have_frame;
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
  }

  // The safety supervisor and the run's time limit; false: the run has ended.
  bool checkSafety() {
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
      return false;
    }
    if (now - t0 > s.exec.max_time_s) {
      fail(FailureCode::Timeout, "timeout: route not completed in " +
                                     std::to_string(static_cast<int>(s.exec.max_time_s)) + " s");
      return false;
    }
    return true;
  }

  // Section bookkeeping: holds, arrival, the section's time budget; false: the run has ended.
  bool sectionStage(Tick& t) {
    const int before = tracker.current();
    // A landmark of this section being servoed on says more about where the section ends than
    // odometry does: hold the section open until it is passed (or lost, or far overshot).
    bool hold = false;
    if (!tracker.finished()) {
      const int k0 = tracker.current();
      const int fi = final_look.target().second;  // not the final look's landmark
      hold = landmarks.holdsSection(k0, now, s.exec.servo_hold_s + 0.5,
                                    final_look.isTarget(k0, fi) ? fi : -1);
      if (hold && tracker.progress(pose).remaining_m < -s.exec.miss_slack_m) hold = false;
    }
    // A final look under way continues whichever way it started (at the goal, or settled near
    // it): it holds the route open and turns the robot.
    final_looking = final_look.underWay() && finalLook();
    // At the goal: a landmark of the last section that was seen moves the goal when it is
    // passed (re-fit), so pass it first and judge arrival against the corrected goal.
    if (!hold && !tracker.finished() && tracker.current() + 1 == tracker.count() &&
        tracker.progress(pose).to_end_m <= s.sections.goal_radius_m) {
      const int kl = tracker.current();
      for (size_t i = 0; i < landmarks.tracks()[kl].size() && status == RunStatus::Running; ++i) {
        const auto& t = landmarks.track(kl, static_cast<int>(i));
        if (t.state == LandmarkState::Tracking ||
            (t.state == LandmarkState::Pending && t.frames_seen > 0))
          passLandmark(kl, static_cast<int>(i), false);
      }
      if (status != RunStatus::Running) return false;
      if (!final_looking) final_looking = finalLook();
    }
    hold |= final_looking;
    if (!hold && tracker.update(pose) > 0) closeSections(before);
    if (status != RunStatus::Running) return false;
    if (tracker.finished()) {
      succeed("reached the end of the route");
      return false;
    }
    const auto& sec = tracker.section();
    const int k = tracker.current();
    const double budget =
        s.exec.section_time_factor * sec.length_m / s.exec.v_cruise + s.exec.section_time_extra_s;
    if (now - section_t0 > budget) {
      fail(FailureCode::NoProgress, "section " + std::to_string(k + 1) + "/" +
                                        std::to_string(tracker.count()) + ": no progress after " +
                                        std::to_string(static_cast<int>(budget)) + " s");
      return false;
    }
    const auto prog = tracker.progress(pose);
    t.k = k;
    t.sec = &sec;
    t.prog = prog;
    return true;
  }

  // The attended landmarks, perception on the frame, association, the servo law, passes and
  // misses; false: the run has ended.
  bool landmarkStage(Tick& t) {
    const int k = t.k;
    const SectionProgress& prog = t.prog;
    const hw::Frame& frame = t.frame;
    const bool have_frame = t.have_frame;
    bool& perceived = t.perceived;
    // Attended landmarks: the first one of this section not yet passed or missed (or else the
    // first of the next section: a landmark just past a guide point is often in view before
    // that section starts), and the one after it. The robot servos on the first only; the
    // second is looked for in the same frames because it often comes into view while the
    // first is still expected (two landmarks a few metres apart on opposite sides of the path)
    // and is too close to be recognised by the time the first is passed.
    std::vector<AttendedLandmark>& att = t.att;
    if (final_looking) {
      const auto [fk, fi] = final_look.target();
      const auto& l = landmarks.landmark(fk, fi);
      const Polar p = polarFrom(pose, tracker.toOdom(l.position_m));
      const bool a = std::abs(p.bearing) <= s.exec.attend_bearing_deg * M_PI / 180;
      att.push_back({fk, fi, p, a});
    }
    for (int kk = k; !final_looking && kk < std::min(k + 2, tracker.count()) && att.size() < 2;
         ++kk) {
      const auto& ss = tracker.route().sections[kk];
      for (size_t i = 0; i < ss.landmarks.size() && att.size() < 2; ++i) {
        const auto& t = landmarks.track(kk, static_cast<int>(i));
        if (t.state == LandmarkState::Passed || t.state == LandmarkState::Missed) continue;
        if (final_look.isTarget(kk, static_cast<int>(i))) continue;  // the final look's
        if (kk == k &&
            prog.along_m > ss.landmarks[i].along_m * tracker.scale() + s.exec.miss_slack_m &&
            t.state == LandmarkState::Pending) {
          // Recognised earlier but lost from view before it was close: the robot did see it,
          // so it is passed (a sighting says the route is right), not missed.
          if (t.frames_seen > 0)
            passLandmark(kk, static_cast<int>(i), false);
          else
            markMissed(kk, static_cast<int>(i));
          if (status != RunStatus::Running) return false;
          continue;
        }
        const auto& l = ss.landmarks[i];
        const Polar p = polarFrom(pose, tracker.toOdom(l.position_m));
        const bool a = t.state == LandmarkState::Tracking ||
                       (std::abs(p.bearing) <= s.exec.attend_bearing_deg * M_PI / 180 &&
                        p.range <= s.exec.attend_range_m);
        att.push_back({kk, static_cast<int>(i), p, a});
      }
    }
    const mapsketch::ExpectedLandmark* lm =
        att.empty() ? nullptr : &landmarks.landmark(att[0].k, att[0].i);
    const LandmarkTrack* tr = att.empty() ? nullptr : &landmarks.track(att[0].k, att[0].i);
    const Polar pred = att.empty() ? Polar{} : att[0].pred;
    std::vector<std::string> classes;
    for (const auto& x : att) {
      const std::string& cls = landmarks.landmark(x.k, x.i).class_name;
      if (x.attend && std::find(classes.begin(), classes.end(), cls) == classes.end())
        classes.push_back(cls);
    }
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
          if (x.attend)
            look.push_back({landmarks.landmark(x.k, x.i).class_name, x.pred.bearing, x.pred.range});
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
      const std::vector<Expected> expect = landmarks.expectations(att, pose);
      for (size_t n = 0; n < att.size() && status == RunStatus::Running; ++n) {
        const auto& x = att[n];
        if (!x.attend) continue;
        const auto got = landmarks.associate(att, n, expect, all, used, anchor, s.select, pose, now,
                                             s.servo.camera_x_m, s.exec.fit_bearing_only);
        if (!got) continue;
        if (got->seen) event(*got->seen);
        if (n == 0) {
          const Detection& d = *got->detection;
          const double range = got->range_m;
          const double depth = range > 0 ? range * std::cos(d.bearing) : 0;
          servo_cmd = law.compute(d.x_t, d.x_d, depth);
          ++servo_updates;
          servo_t = now;
          servo_bearing = d.bearing;
          if (range > 0 && range <= landmarks.passDistance(x.k, x.i)) passLandmark(x.k, x.i, true);
        }
      }
    }
    for (const auto& x : att) {
      if (status != RunStatus::Running) return false;
      switch (landmarks.checkUnseen(x.k, x.i, now)) {
        case LandmarkTracker::Unseen::AtIt:  // slid out of the side of the image when close
          passLandmark(x.k, x.i, false);
          break;
        case LandmarkTracker::Unseen::LostToView:
          event(event::LandmarkLost{landmarks.landmark(x.k, x.i).id, x.k});
          break;
        case LandmarkTracker::Unseen::No:
          break;
      }
    }
    t.lm = lm;
    t.tr = tr;
    t.pred = pred;
    return status == RunStatus::Running;
  }

  // Route following or the servo, and docking at the goal (t.arb); the target bearing and the
  // side to dodge to for the stages after.
  void proposeDrive(Tick& t) {
    const int k = t.k;
    const SectionProgress& prog = t.prog;
    const std::vector<AttendedLandmark>& att = t.att;
    const mapsketch::ExpectedLandmark* const lm = t.lm;
    const LandmarkTrack* const tr = t.tr;
    const Polar& pred = t.pred;
    double& servo_error = t.servo_error;
    // Each behaviour that applies proposes a command; the arbiter's priority list decides
    // (command_arbiter.h). The proposals below come lowest priority first.
    CommandArbiter& arb = t.arb;
    double& target_bearing = t.target_bearing;
    t.servoing = tr && tr->state == LandmarkState::Tracking && now - servo_t <= s.exec.servo_hold_s;
    const bool servoing = t.servoing;
    if (servoing) {
      target_bearing = servo_bearing;
      servo_error = servo_cmd.error;
      arb.propose(Behaviour::Servo, {servo_cmd.v, servo_cmd.w, servo_cmd.state});
    } else {
      // Following the route; a landmark not seen yet and near is kept in view (LookParams).
      const bool unseen = lm && tr->state == LandmarkState::Pending;
      const auto f = follow.propose(polarFrom(pose, tracker.lookahead(pose)).bearing,
                                    unseen ? &pred : nullptr);
      target_bearing = f.target_bearing;
      arb.propose(f.behaviour, f.command);
    }
    // Side of the next landmark, for the avoidance's rotation direction.
    // When the robot is already at the attended landmark, the obstacle is most likely the
    // furniture it stands on, and dodging round to its side leads away from the route: the
    // landmark that matters then is the one after it.
    const mapsketch::ExpectedLandmark* next_lm = lm;
    if (lm && att.size() > 1 && pred.range <= landmarks.passDistance(att[0].k, att[0].i) + 1.0)
      next_lm = &landmarks.landmark(att[1].k, att[1].i);
    DodgeSide& side = t.side;
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
    bool& docking = t.docking;
    if (k + 1 == tracker.count() && docker.near(prog.to_end_m) && !dev.ranges.empty()) {
      const Eigen::Vector2d goal = tracker.endOdom(k);
      const Polar pg = polarFrom(pose, goal);
      const double free =
          corridorFree(scanPoints(scans), pg.bearing,
                       s.avoid.robot_radius_m + s.avoid.corridor_margin_m, s.avoid.max_range_m);
      std::function<std::optional<Docking::WayRound>()> plan;
      if (s.exec.detour)
        plan = [&]() -> std::optional<Docking::WayRound> {
          const double b = detour.planTowards(planner, pose, goal, now);
          if (!std::isfinite(b)) return std::nullopt;
          const PlannedPath& way = detour.path();
          const double from_start = (way.points.front() - Eigen::Vector2d(pose.x, pose.y)).norm();
          return Docking::WayRound{b, way.length_m, std::max(0.0, way.length_m - from_start)};
        };
      if (const auto d = docker.propose(pg, free, plan, s.exec)) {
        docking = true;
        if (avoider.active()) {
          avoider.reset();
          endDetour("docking");
          event(event::AvoidEnd{DodgeSide::None, true});
        }
        target_bearing = d->bearing;
        arb.propose(Behaviour::Dock, d->command);
      }
    }
  }

  // Walkers' lanes, recovery when stuck, the avoider and its detours (t.arb).
  void proposeAvoidance(Tick& t) {
    const int k = t.k;
    const std::vector<AttendedLandmark>& att = t.att;
    const mapsketch::ExpectedLandmark* const lm = t.lm;
    const LandmarkTrack* const tr = t.tr;
    CommandArbiter& arb = t.arb;
    const double target_bearing = t.target_bearing;
    const DodgeSide side = t.side;
    const bool servoing = t.servoing, docking = t.docking;
    double& front = t.front;
    bool& dodging = t.dodging;
    t.walkers = movers.walkers();  // for the avoider and the side look
    const std::vector<Mover>& walkers = t.walkers;
    // A walker coming at the robot whose lane covers it: stepping out of the lane is the
    // dodge's, which a recovery would keep from running (a robot driving clear of a corner
    // drove into the lane of a person walking at it and stood there until they walked into it).
    bool walker_lane = false;
    for (const auto& m : walkers)
      walker_lane |= avoider.walkerLaneCovers({pose.x, pose.y}, m.position, m.velocity);
    if (walker_lane && !dev.ranges.empty()) {
      if (recovery.active()) {
        recovery.stop();
        event(event::RecoverEnd{});
      }
      progress_checker.reset(pose, now);  // giving way is not being stuck
    }
    // Stuck (ProgressChecker): drive clear towards the most open direction (Recovery).
    if (!recovery.active() && !docking && !dev.ranges.empty() && !walker_lane &&
        progress_checker.due(now)) {
      const bool stuck = progress_checker.stuck(pose, now);
      if (stuck) {
        const double hwid = s.avoid.robot_radius_m + s.avoid.corridor_margin_m;
        const auto pts = scanPoints(scans);
        auto dir = recovery.openDirection(
            pts, hwid, s.avoid.max_range_m, target_bearing,
            [&](double a, double len) { return avoider.sweptSeenFree(a, len); });
        // Nothing known free, but a way out the laser has not seen (behind the robot): turn
        // to see it, then choose again (recover_look). Once: what is still unseen after a look
        // waits for the next stuck window, so a robot boxed in does not turn round and round.
        bool look = false;
        if (!dir && !looked && s.exec.recover_look) {
          dir = recovery.openDirection(pts, hwid, s.avoid.max_range_m, target_bearing);
          look = dir.has_value();
        }
        looked = look;
        if (dir) {
          const auto started = recovery.start(*dir, pose, now, look);
          if (avoider.active()) avoider.reset();
          event(started);
          log::warn(
              "nav",
              look ? "stuck: turning to see a way out" : "stuck: driving clear before resuming",
              {{"direction_deg", std::to_string(static_cast<int>(*dir * 180 / M_PI))}});
        } else if (s.exec.recover_back_m > 0) {
          // Wedged: no way out the laser sees, and behind it is blind. The robot came over the
          // floor behind it: back out along that, when the trail runs straight back.
          const Eigen::Vector2d at(pose.x, pose.y);
          if (const auto to = trail.backOut(at, s.exec.recover_back_m, kTrailTolerance_m)) {
            const double b = wrapAngle(std::atan2(to->y() - at.y(), to->x() - at.x()) - pose.theta);
            if (std::abs(wrapAngle(b - M_PI)) <= kBackOutCone_rad) {
              const auto started = recovery.startBack(*to, pose, now);
              if (avoider.active()) avoider.reset();
              event(started);
              log::warn("nav", "stuck with no way out in view: backing out along the trail",
                        {{"m", std::to_string(s.exec.recover_back_m)}});
            }
          }
        }
      }
    }
    if (recovery.active()) {
      const auto r = recovery.step(pose, now, avoider.capSpeed(scans, 0.7 * s.exec.v_cruise));
      arb.propose(Behaviour::Recover, r.command);
      if (r.ended) {
        // After a look, or backing out, the way out is chosen at once: with the laser's view of
        // it, or with the room backing made.
        if (recovery.backing()) trail.backTo({pose.x, pose.y});
        if (recovery.looking() || recovery.backing())
          progress_checker.expire(pose, now);
        else
          progress_checker.reset(pose, now);
        event(event::RecoverEnd{});
      }
    }
    if (docking || recovery.active()) {
      if (!dev.ranges.empty()) avoider.observe(scans, pose);
      endDetour(docking ? "docking" : "recovering");
      if (docking) arb.setWinnerSpeed(avoider.capSpeed(scans, arb.winner().v));
    } else if (!dev.ranges.empty()) {
      avoider.setPose(pose);
      for (const auto& m : walkers) avoider.offerWalker(m.position, m.velocity);
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
        if (tr && lm && tr->state == LandmarkState::Tracking &&
            landmarks.atLandmark(att[0].k, att[0].i, tr->last_range))
          passLandmark(att[0].k, att[0].i, false);
      }
      if (av.ended) {
        if (!s.exec.detour_hold) endDetour("avoid ended");
        event(event::AvoidEnd{av.side});
      }
      const auto cap = [&](double v) { return avoider.capSpeed(scans, v); };
      if (av.active) {
        dodging = true;
        // Something standing still: a way round planned on the grid; something coming
        // towards the robot (a person) or a walker's lane: the reactive dodge (Detour).
        const auto d = detour.whileDodging(
            av, planner, pose, tracker.lookahead(pose, s.exec.detour_ahead_m), now, k, cap);
        if (d.started) event(*d.started);
        if (d.ended) event(*d.ended);
        if (d.command)
          arb.propose(Behaviour::Detour, *d.command);
        else
          arb.propose(Behaviour::Avoid, {av.v, av.w, turnOf(av.w)});
      } else {
        const auto d =
            detour.afterDodge(planner, pose, tracker.lookahead(pose, s.exec.detour_ahead_m), now,
                              servoing, s.avoid.robot_radius_m + s.avoid.corridor_margin_m, cap);
        if (d.ended) event(*d.ended);
        if (d.command) {
          dodging = true;
          arb.propose(Behaviour::Detour, *d.command);
        } else {
          arb.setWinnerSpeed(cap(arb.winner().v));
        }
      }
    } else {
      endDetour("no range data");
    }
  }

  // Looking to the side for a landmark predicted out of view (t.arb, t.sl).
  void proposeSideLook(Tick& t) {
    const std::vector<AttendedLandmark>& att = t.att;
    CommandArbiter& arb = t.arb;
    const bool docking = t.docking, dodging = t.dodging;
    const std::vector<Mover>& walkers = t.walkers;
    // Looking to the side for a landmark predicted out of view (SideLook). A look stands the
    // robot still: none starts, and one under way gives way, near a walking person
    // (side_look_walker_m) or in their lane.
    bool walker_near = in_lane || yield.active();
    for (const auto& m : walkers)
      walker_near |=
          (m.position - Eigen::Vector2d(pose.x, pose.y)).norm() <= s.exec.side_look_walker_m;
    t.sl = side_look.update(landmarks, att.empty() ? nullptr : &att[0], now, dev.camera != nullptr,
                            docking || recovery.active() || walker_near, final_looking,
                            (dodging && detour.movingSeen()) || walker_near, pose.theta);
    const auto& sl = t.sl;
    if (sl.ended) {
      event(*sl.ended);
      progress_checker.reset(pose, now);  // standing still to look is not being stuck
    }
    if (sl.started) event(*sl.started);
    if (sl.command) arb.propose(Behaviour::SideLook, *sl.command);
  }

  // Ends that cannot be reached, a settled goal or section; false: the run has ended.
  bool sectionEnds(Tick& t) {
    const int k = t.k;
    const mapsketch::PathSection& sec = *t.sec;
    const SectionProgress& prog = t.prog;
    const bool servoing = t.servoing, dodging = t.dodging;
    const SideLook::Outcome& sl = t.sl;
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
      if (status != RunStatus::Running) return false;
      succeed("reached the end of the route (could not get closer than " +
              std::to_string(prog.to_end_m).substr(0, 4) + " m)");
      return false;
    }
    // An intermediate end the robot cannot get near, blocked or not in view (the corner drawn
    // beyond the corridor's wall): the section is done where the robot came closest.
    const bool section_settled =
        section_settle.update(sec.length_m, prog.to_end_m, now,
                              servoing || sl.command.has_value() || yield.active()) &&
        k + 1 < tracker.count() && !end_blocked;
    if (section_settled) {
      event(event::SectionSettled{k, prog.to_end_m});
      tracker.advance();
      closeSections(k);
      if (status != RunStatus::Running) return false;
    }
    if (end_blocked) {
      sectionBlocked_ = true;
      event(event::EndBlocked{k, prog.to_end_m});
      tracker.advance();
      closeSections(k);
      if (status != RunStatus::Running) return false;
      if (tracker.finished()) {
        succeed("reached the end of the route (end point blocked, " +
                std::to_string(prog.to_end_m).substr(0, 4) + " m away)");
        return false;
      }
    }
    return true;
  }

  // Walking people, the final look and the following gap have the last word; the command is
  // sent and the tick's telemetry row written.
  void command(Tick& t) {
    const int k = t.k;
    const mapsketch::ExpectedLandmark* const lm = t.lm;
    CommandArbiter& arb = t.arb;
    const bool perceived = t.perceived;
    const double servo_error = t.servo_error, front = t.front;
    // Walking people: keep out of their lanes (movers.h). In one: step out sideways (backing
    // only slowly and with room behind); about to enter one: wait, turning is harmless. With
    // lane keeping off, still the waiting, for walkers only (the tracker's walkers, not every
    // mover; stepping out of a walker's lane is the avoider's): whatever drives does not take
    // the robot into one. (A dodge that ended as the walker's track dropped out for a scan
    // handed the robot back to the route, which crossed the lane 1 m in front of them.)
    if (!dev.ranges.empty() && status == RunStatus::Running) {
      // It advises on the command that would drive otherwise, and may keep its yaw rate.
      const Command cur = arb.winner();
      const auto adv = s.movers.enabled
                           ? movers.advise(pose, cur.v, cur.w, s.exec.k_heading, s.exec.v_cruise)
                           : movers.holdShortOfWalkerLanes(pose, cur.v, cur.w);
      const auto y = yield.update(
          adv, cur, pose, [&](double v) { return avoider.capSpeed(scans, v); },
          [&] {
            const double hwid = s.avoid.robot_radius_m + s.avoid.corridor_margin_m;
            return corridorFree(scanPoints(scans), M_PI, hwid, s.avoid.max_range_m);
          });
      if (y.command) arb.propose(Behaviour::Yield, *y.command);
      if (y.started) event(*y.started);
      if (y.ended) event(*y.ended);
    }
    if (final_looking) {
      // Turn on the spot to where the sketch puts the landmark (perception attends it once it
      // is within attend_bearing_deg).
      const auto [fk, fi] = final_look.target();
      const auto& l = landmarks.landmark(fk, fi);
      arb.propose(Behaviour::FinalLook,
                  final_look.command(polarFrom(pose, tracker.toOdom(l.position_m)).bearing));
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

  void endDetour(const char* reason) {
    if (const auto e = detour.end(reason)) event(*e);
  }

  // At the goal: whether to stay and look for a never-seen landmark of the last section within
  // final_look_range_m (starts the look on the first call, ends it when the landmark is seen
  // or after final_look_s).
  bool finalLook() {
    const auto o = final_look.step(landmarks, tracker, pose, now);
    if (o.started) event(*o.started);
    if (o.ended) event(*o.ended);
    const auto [fk, fi] = final_look.target();
    if (o.verdict == FinalLook::Verdict::Pass)
      passLandmark(fk, fi, false);
    else if (o.verdict == FinalLook::Verdict::Miss)
      markMissed(fk, fi);
    return o.looking;
  }

  void passLandmark(int k, int i, bool seen_close) {
    // Every earlier landmark still pending is behind the robot now (LandmarkTracker::pass).
    for (const auto& m : landmarks.pass(k, i)) reportMiss(m);
    const auto& tr = landmarks.track(k, i);
    const auto& lm = landmarks.landmark(k, i);
    event::LandmarkPassed e;
    e.id = lm.id;
    e.class_name = lm.class_name;
    e.section = k;
    e.range_m = tr.last_range;
    e.frames_seen = tr.frames_seen;
    e.in_view = seen_close;
    // Where the landmark really is vs where the sketch puts it: the route anchor refits or
    // rotates the route, then shifts it (route_anchor.h). A landmark that slid out of view when
    // close was seen as well as one passed in view, and the last landmark before the goal is
    // often passed that way.
    auto c = anchor.correct(tracker, lm.position_m, lm.class_name, tr.sightings, s.locate);
    e.fix_rejected = std::move(c.rejected);
    e.fix = std::move(c.fix);
    event(std::move(e));
    log::info("nav", "landmark passed", {{"id", lm.id}, {"class", lm.class_name}});
  }

  void closeSections(int from) {
    for (int k = from; k < tracker.current() && status == RunStatus::Running; ++k) {
      for (size_t i = 0; i < landmarks.tracks()[k].size(); ++i) {
        const auto& tr = landmarks.track(k, static_cast<int>(i));
        if (tr.state == LandmarkState::Tracking ||
            (tr.state == LandmarkState::Pending && tr.frames_seen > 0))
          passLandmark(k, static_cast<int>(i), false);
        else if (tr.state == LandmarkState::Pending)
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
    section_settle.restart(now);
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
  I.section_settle.restart(I.t0);
  I.progress_checker.reset(hw::Pose2D{}, I.t0);
  I.anchor.start(I.tracker);
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
  for (size_t k = 0; k < I.landmarks.tracks().size(); ++k)
    for (size_t i = 0; i < I.landmarks.tracks()[k].size(); ++i) {
      const auto& lm = I.tracker.route().sections[k].landmarks[i];
      const auto& tr = I.landmarks.tracks()[k][i];
      s.landmarks.push_back({lm.id, lm.class_name, static_cast<int>(k), toString(tr.state),
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
  s.recoveries = I.recovery.count();
  s.detours = I.detour.count();
  s.yields = I.yield.count();
  s.laser_odometry = I.lodo.stats();
  return s;
}

}  // namespace sketchnav::nav
