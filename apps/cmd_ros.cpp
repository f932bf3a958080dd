// sketchnav ros sim|nav: the simulator as a ROS robot, and the navigation as a ROS node
// (doc/ros.md). `ros nav` is `sketchnav run` on ros:// devices: the same executive, fed from
// ROS topics, commanding cmd_vel.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>

#include <opencv2/imgproc.hpp>

#include "cli.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/log.h"
#include "sketchnav/core/paths.h"
#include "sketchnav/nav/events.h"
#include "sketchnav/nav/sections.h"
#include "sketchnav/ros/bag.h"
#include "sketchnav/ros/node.h"
#include "sketchnav/ros/outputs.h"
#include "sketchnav/ros/route_server.h"
#include "sketchnav/ros/sim_bridge.h"
#include "sketchnav/run/run.h"
#include "sketchnav/servo/turn_law.h"

namespace sketchnav::app {
namespace {

// ROS remappings and special arguments (`from:=to`, `__name:=x`) go to ros::init.
std::vector<std::string> splitRosArgs(const std::vector<std::string>& argv,
                                      std::vector<std::string>& ros_args) {
  std::vector<std::string> rest;
  for (const auto& a : argv) (a.find(":=") != std::string::npos ? ros_args : rest).push_back(a);
  return rest;
}

// The node's ROS parameters (~nav/v_cruise ...) under the command line's --config / --set.
Config mergedSettings(GlobalOptions& g) {
  Config c = ros::privateParams();
  for (const auto& k : g.config.keys()) {
    c.set(k, g.config.at(k));
    g.config.markUsed(k);  // checked (strictly) through the merged settings
  }
  return c;
}

int runSim(const std::vector<std::string>& argv0, GlobalOptions& g) {
  std::vector<std::string> ros_args;
  const auto argv = splitRosArgs(argv0, ros_args);
  Args args("ros sim",
            "the built-in simulator as a ROS robot: camera, odometry + tf, laser, sonar, "
            "ground truth and /clock; drives from cmd_vel",
            "[--world NAME|FILE] [--seed N] [--rate R] [--max-time S] [--no-hold] [--lockstep] "
            "[from:=to ...]");
  args.option("world", "a world name in share/worlds or a .world.json file", "lab")
      .option("seed", "simulator seed", "1")
      .option("rate", "simulated seconds per wall second (0 = as fast as possible)", "1")
      .option("step", "publishing step [s, simulated]: /clock, odom, tf", "0.02")
      .option("cmd-timeout", "a cmd_vel older than this [s, simulated] is replaced by zero", "0.5")
      .option("max-time", "end after this many simulated seconds (default: run until stopped)")
      .flag("no-hold", "start simulated time at once (default: hold it at 0 until a cmd_vel)")
      .flag("lockstep",
            "step only when the navigation (ros nav with ros.lockstep=true) has answered: "
            "time stands while it perceives, as in sketchnav run");
  if (!args.parse(argv)) return 0;
  ros::SimBridgeOptions o;
  o.world = args.get("world");
  o.seed = args.getInt("seed");
  if (o.seed < 0) throw InputError("sketchnav ros sim: --seed must be >= 0");
  o.rate = args.getDouble("rate");
  o.step_s = args.getDouble("step");
  o.cmd_timeout_s = args.getDouble("cmd-timeout");
  if (!(o.cmd_timeout_s > 0)) throw InputError("sketchnav ros sim: --cmd-timeout must be > 0");
  if (!args.get("max-time").empty()) o.max_time_s = args.getDouble("max-time");
  o.hold_until_cmd = !args.flagSet("no-hold");
  o.lockstep = args.flagSet("lockstep");
  ros::init("sketchnav_sim", ros_args, 10.0);
  o.config = mergedSettings(g);
  Json s;
  try {
    s = ros::runSimBridge(o);
  } catch (...) {
    ros::shutdown();
    throw;
  }
  ros::shutdown();
  if (g.json) {
    printJson(s);
  } else {
    std::printf("ros sim: t %.1f s, %s, %.2f m from the goal%s\n", s["t"].get<double>(),
                s["at_goal"].get<bool>() ? "at the goal" : "not at the goal",
                s["distance_to_goal_m"].get<double>(),
                s["collided"].get<bool>()
                    ? (", collided with " + s["collision_with"].get<std::string>()).c_str()
                    : "");
  }
  return 0;
}

// The node's view of the route for the feedback, /diagnostics and rviz (outputs.h).
struct RouteView {
  ros::NavOutputs* out = nullptr;
  ros::RouteServer* server = nullptr;
  hw::Pose2D pose;
  double stamp = 0;
  std::string mode, landmark;
  int ticks = 0;

  void tick(const nav::TelemetryRow& r) {
    pose = r.odom;
    stamp = ros::clock()->now();
    mode = nav::toString(r.mode);
    landmark = r.landmark;
    out->pose(r.odom.x, r.odom.y, r.odom.theta, stamp);
  }
  void step(const nav::Executive& ex) {
    const auto& st = ex.sections();
    const int cur = st.current(), n = st.count();
    // Distance left: to the current section's end, then the later sections end to end.
    double left = 0;
    Eigen::Vector2d from(pose.x, pose.y);
    for (int k = std::min(cur, n); k < n; ++k) {
      const Eigen::Vector2d e = st.endOdom(k);
      left += (e - from).norm();
      from = e;
    }
    ros::RouteFeedback f;
    f.section = std::min(cur, n) + 1;
    f.sections = n;
    f.distance_left_m = left;
    f.mode = mode;
    f.landmark = landmark;
    if (server) server->feedback(f);
    char b[96];
    std::snprintf(b, sizeof b, "running section %d/%d, %.1f m left", f.section, n, left);
    out->status(b);
    // The route and the landmarks as now aligned to odometry, every 0.5 s (10 ticks).
    if (ticks++ % 10 != 0) return;
    const auto& route = st.route();
    std::vector<std::pair<double, double>> pts;
    if (!route.guide_points_m.empty()) {
      const Eigen::Vector2d p0 = st.toOdom(route.guide_points_m.front());
      pts.push_back({p0.x(), p0.y()});
    }
    for (int k = 0; k < n; ++k) {
      const Eigen::Vector2d e = st.endOdom(k);
      pts.push_back({e.x(), e.y()});
    }
    out->route(pts, stamp);
    std::map<std::string, std::string> state;
    for (const auto& l : ex.summary().landmarks) state[l.id] = l.state;
    std::vector<ros::LandmarkMark> marks;
    for (const auto& sec : route.sections)
      for (const auto& lm : sec.landmarks) {
        const Eigen::Vector2d q = st.toOdom(lm.position_m);
        marks.push_back({lm.id, state.count(lm.id) ? state[lm.id] : "pending", q.x(), q.y()});
      }
    out->landmarks(marks, stamp);
  }
};

// The frame perception examined with what it found (detection windows, class, inliers).
cv::Mat annotate(const hw::Frame& f, const nav::Observation& obs) {
  cv::Mat img = f.image.clone();
  // The windows examined, thin and grey beneath the detections: where perception looked.
  for (const auto& w : obs.windows) cv::rectangle(img, w, cv::Scalar(160, 160, 160), 1);
  for (const auto& d : obs.detections) {
    const cv::Scalar c = d.tracked           ? cv::Scalar(255, 160, 0)
                         : d.recognised_only ? cv::Scalar(0, 200, 255)
                                             : cv::Scalar(0, 220, 0);
    cv::rectangle(img, d.window, c, 2);
    char b[96];
    std::snprintf(b, sizeof b, "%s %d%s", d.class_name.c_str(), d.inliers,
                  d.tracked ? " (tracked)" : "");
    cv::putText(img, b, {d.window.x, std::max(12, d.window.y - 4)}, cv::FONT_HERSHEY_SIMPLEX, 0.45,
                c, 1, cv::LINE_AA);
  }
  char b[96];
  std::snprintf(b, sizeof b, "%d windows, %.0f ms", obs.timing.windows, obs.timing.total_ms);
  cv::putText(img, b, {6, img.rows - 8}, cv::FONT_HERSHEY_SIMPLEX, 0.45, {255, 255, 255}, 1,
              cv::LINE_AA);
  return img;
}

int runNav(const std::vector<std::string>& argv0, GlobalOptions& g) {
  std::vector<std::string> ros_args;
  const auto argv = splitRosArgs(argv0, ros_args);
  Args args("ros nav",
            "the navigation as a ROS node: camera, odometry, scan and sonar from topics, "
            "cmd_vel out; routes started and cancelled through the action ~route (or ~start / "
            "~cancel); every setting also a ROS parameter (~nav/v_cruise = nav.v_cruise)",
            "[--sketch FILE [--exit-on-result]] [--model FILE] [--max-time S] [--out DIR] "
            "[from:=to ...]");
  args.option("sketch", "the hand-drawn map (.sketch.json): start this route at once")
      .option("model",
              "landmark model (.slm) for goals that name none; default: the demo set, "
              "trained once and cached")
      .option("landmarks", "landmark set folder to train the model from (default: share/landmarks)")
      .option("cache-dir", "where trained models are cached (default: ~/.cache/sketchnav)")
      .option("max-time",
              "give up a route after this many seconds of ROS time (default: "
              "nav.max_time_s)")
      .option("out",
              "also write summary.json, events.jsonl, telemetry.csv here (one folder a "
              "route)")
      .flag("exit-on-result",
            "with --sketch: exit when that route ends (0 success, 1 not) "
            "instead of waiting for goals");
  if (!args.parse(argv)) return 0;
  const bool once = args.flagSet("exit-on-result");
  if (once && args.get("sketch").empty())
    throw InputError("sketchnav ros nav: --exit-on-result needs --sketch FILE");
  ros::init("sketchnav_nav", ros_args, 10.0);
  Json summary;
  bool last_success = false;
  try {
    Config c = mergedSettings(g);
    ros::RosParams rp;
    applyConfig(rp, c, "ros");
    // Every setting checked before anything waits for a topic: a typo fails at once.
    const run::RunSettings rs = run::runSettingsFrom(c);
    c.requireAllUsedExcept(run::driverSettingPrefixes());
    ros::startWatchdog(rp);
    // The executive grabs a frame once nav.camera_period_s - tick_s / 2 has passed since the
    // last: such a frame wakes the control loop instead of waiting for its next tick.
    ros::wakeOnFrames(rp.wake_on_frame && !rp.lockstep
                          ? rs.nav.exec.camera_period_s - 0.5 * rs.nav.exec.tick_s
                          : -1.0);
    ros::registerDrivers();
    // The executive's own staleness limits on ROS time: ros.stale_timeout_s unless set.
    for (const char* k :
         {"nav.safety.camera_timeout_s", "nav.safety.range_timeout_s", "nav.safety.odom_timeout_s"})
      if (!c.has(k)) c.set(k, rp.stale_timeout_s);
    if (!ros::waitForTime(rp.wait_s))
      throw RuntimeError("ROS time is not valid after " + std::to_string(rp.wait_s) +
                         " s: /use_sim_time is set but nothing publishes /clock");
    // The camera mount from tf (REP 105 base frame -> the image's optical frame).
    std::string camera_frame;
    if (rp.camera_mount_from_tf) {
      camera_frame = ros::imageFrame(rp.image_topic, rp.wait_s, rp.image_transport);
      CameraMount m;
      if (!camera_frame.empty() && ros::lookupCameraMount(rp.base_frame, camera_frame, 2.0, m)) {
        if (!c.has("robot.camera.x_m")) c.set("robot.camera.x_m", m.x_m);
        if (!c.has("robot.camera.z_m")) c.set("robot.camera.z_m", m.z_m);
        if (!c.has("robot.camera.yaw")) c.set("robot.camera.yaw", m.yaw);
        if (!c.has("robot.camera.pitch")) c.set("robot.camera.pitch", m.pitch);
        char b[160];
        std::snprintf(b, sizeof b, "x %.3f m, z %.3f m, yaw %.1f deg, pitch %.1f deg", m.x_m, m.z_m,
                      m.yaw * 180 / M_PI, m.pitch * 180 / M_PI);
        log::info("ros", "camera mount from tf", {{"frame", camera_frame}, {"mount", b}});
      } else {
        log::warn("ros",
                  "no tf from the base frame to the camera: the camera mount settings "
                  "keep their values",
                  {{"base_frame", rp.base_frame}, {"camera_frame", camera_frame}});
      }
    }
    ros::JsonPublisher events("~events", false, 100), state("~state", false, 10),
        result("~result", true, 1);
    ros::NavOutputs outputs(rp.odom_frame);
    std::unique_ptr<ros::RouteServer> server;
    if (!once) server = std::make_unique<ros::RouteServer>("route");
    // Odometry from nav_msgs/Odometry, or from tf odom -> base_link (REP 105).
    const std::string base_uri =
        "ros://base?cmd_vel=" + rp.cmd_vel_topic +
        (rp.odom_source == "tf" ? "&tf=" + rp.odom_frame : "&odom=" + rp.odom_topic);

    // One route: the goal's sketch and model (else --model) on the ros:// devices.
    auto runGoal = [&](const ros::RouteGoal& goal) -> Json {
      if (goal.sketch.empty()) throw InputError("the goal names no sketch file");
      ros::resetFault();  // a new goal after a safety stop may move the robot again
      ros::release();     // ... or after a cancelled or preempted one
      RouteView view;
      view.out = &outputs;
      view.server = server.get();
      run::RunOptions o;
      o.sketch = goal.sketch;
      o.model = goal.model.empty() ? args.get("model") : goal.model;
      o.landmark_dir = args.get("landmarks");
      o.cache_dir = args.get("cache-dir");
      if (!args.get("max-time").empty()) o.max_time_s = args.getDouble("max-time");
      o.robot = base_uri;
      o.camera = "ros://camera?topic=" + rp.image_topic + "&info=" + rp.camera_info_topic +
                 "&transport=" + rp.image_transport;
      if (!rp.scan_topic.empty()) o.laser = "ros://laser?topic=" + rp.scan_topic;
      if (!rp.sonar_topic.empty()) o.sonar = "ros://sonar?topic=" + rp.sonar_topic;
      o.config = c;
      o.out_dir = args.get("out").empty() ? "" : makeOutputDir(args.get("out"));
      o.progress = true;
      o.on_event = [&](const nav::NavEvent& e) {
        // The route starts: one command, so a simulator holding its time at 0 starts too.
        if (e.as<nav::event::Start>()) ros::sendZeroCommand();
        events.publish(e.toJson());
      };
      o.on_tick = [&](const nav::TelemetryRow& r) {
        view.tick(r);
        state.publish({{"t", r.t},
                       {"section", r.section},
                       {"mode", nav::toString(r.mode)},
                       {"turn", servo::toString(r.turn)},
                       {"landmark", r.landmark},
                       {"v", r.v_cmd},
                       {"w", r.w_cmd},
                       {"servo_error", std::isfinite(r.servo_error) ? Json(r.servo_error) : Json()},
                       {"odom", {r.odom.x, r.odom.y, r.odom.theta}},
                       {"front_free_m", r.front_free_m}});
      };
      o.after_step = [&](const nav::Executive& ex) { view.step(ex); };
      o.on_observation = [&](const hw::Frame& f, const nav::Observation& obs) {
        ros::noteObservation(f.seq);
        if (outputs.wantImage()) outputs.image(annotate(f, obs), f.stamp, camera_frame);
      };
      o.stop_requested = [&] { return (server && server->cancelRequested()) || !ros::ok(); };
      log::info("ros", "route started", {{"sketch", o.sketch}, {"from", goal.source}});
      outputs.status("starting " + o.sketch);
      Json s = run::runNavigation(o);
      const std::string f = ros::fault();
      s["ros"] = {{"fault", f},
                  {"signal", ros::signalReceived()},
                  {"base", base_uri},
                  {"settings", paramsToJson(rp)},
                  {"goal_from", goal.source},
                  {"latency", ros::latencySummary()}};
      // A fault while the route ran failed it (the base reported it lost); say what it was.
      if (!f.empty() && !s["success"].get<bool>()) {
        s["reason"] = "safety stop: " + f;
        s["failure"] = "safety_stop";
      }
      if (server && server->cancelRequested() && !s["success"].get<bool>()) {
        s["failure"] = "cancelled";
        s["reason"] = "cancelled: the goal was cancelled or preempted";
      }
      return s;
    };
    auto finish = [&](const Json& s) {
      result.publish(s);
      if (!server) return;
      ros::RouteResult r;
      r.success = s.value("success", false);
      r.failure = s.value("failure", r.success ? "" : "error");
      r.reason = s.value("reason", "");
      r.sections_done = s.value("sections_done", 0);
      r.sections = s.value("sections", 0);
      r.summary = s;
      server->finish(r);
      outputs.status((r.success ? "idle (last route succeeded: " : "idle (last route failed: ") +
                     r.reason + ")");
    };

    ros::RouteGoal goal{args.get("sketch"), args.get("model"), "command line"};
    bool have = !goal.sketch.empty();
    while (ros::ok()) {
      if (!have) {
        have = server && server->waitGoal(goal, 0.2);
        continue;
      }
      have = false;
      Json s;
      try {
        s = runGoal(goal);
      } catch (const std::exception& e) {
        if (once) throw;
        // A bad goal (unreadable sketch, a model that does not load, a device that does not
        // open) fails that goal; the node waits for the next.
        ros::sendZeroCommand();
        log::error("ros", std::string("goal failed before the route ran: ") + e.what());
        s = {{"success", false},
             {"failure", "error"},
             {"reason", e.what()},
             {"sections_done", 0},
             {"sections", 0}};
      }
      summary = s;
      last_success = s.value("success", false);
      finish(s);
      if (once) break;
    }
  } catch (...) {
    ros::shutdown();
    throw;
  }
  ros::shutdown();
  if (!once) return 0;
  if (g.json) {
    printJson(summary);
  } else {
    std::cout << (summary["success"].get<bool>() ? "success" : "FAILED") << ": "
              << summary["reason"].get<std::string>() << "\n"
              << "time " << summary["time_s"].get<double>() << " s, sections "
              << summary["sections_done"].get<int>() << "/" << summary["sections"].get<int>()
              << ", odometry path " << summary["odom_path_m"].get<double>() << " m\n";
  }
  return last_success ? 0 : 1;
}

int runRos(const std::vector<std::string>& argv, GlobalOptions& g) {
  const std::string usage =
      "usage: sketchnav ros sim [options]   the simulator as a ROS robot\n"
      "       sketchnav ros nav [options]   the navigation as a ROS node\n"
      "(`sketchnav ros sim --help`, doc/ros.md)\n";
  if (argv.empty() || argv[0] == "--help" || argv[0] == "-h") {
    std::cout << usage;
    return argv.empty() ? 2 : 0;
  }
  const std::vector<std::string> rest(argv.begin() + 1, argv.end());
  if (argv[0] == "sim") return runSim(rest, g);
  if (argv[0] == "nav") return runNav(rest, g);
  throw InputError("sketchnav ros: unknown subcommand '" + argv[0] + "' (sim or nav)");
}

// bag:// cameras for every subcommand that opens a camera URI (replay --frames, probe, run).
const struct BagDriver {
  BagDriver() { ros::registerBagDriver(); }
} bag_driver;

const CommandRegistration reg("ros",
                              "ROS 1: the simulator as a ROS robot (ros sim), the navigation as "
                              "a ROS node (ros nav)",
                              runRos);
}  // namespace
}  // namespace sketchnav::app
