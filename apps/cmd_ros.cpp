// sketchnav ros sim|nav: the simulator as a ROS robot, and the navigation as a ROS node
// (doc/ros.md). `ros nav` is `sketchnav run` on ros:// devices: the same executive, fed from
// ROS topics, commanding cmd_vel.
#include <cmath>
#include <cstdio>
#include <iostream>

#include "cli.h"
#include "run_harness.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/log.h"
#include "sketchnav/core/paths.h"
#include "sketchnav/ros/bag.h"
#include "sketchnav/ros/node.h"
#include "sketchnav/ros/sim_bridge.h"

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
            "[--world NAME|FILE] [--seed N] [--rate R] [--max-time S] [--no-hold] [from:=to ...]");
  args.option("world", "a world name in share/worlds or a .world.json file", "lab")
      .option("seed", "simulator seed", "1")
      .option("rate", "simulated seconds per wall second (0 = as fast as possible)", "1")
      .option("step", "publishing step [s, simulated]: /clock, odom, tf", "0.02")
      .option("cmd-timeout", "a cmd_vel older than this [s, simulated] is replaced by zero", "0.5")
      .option("max-time", "end after this many simulated seconds (default: run until stopped)")
      .flag("no-hold", "start simulated time at once (default: hold it at 0 until a cmd_vel)");
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

int runNav(const std::vector<std::string>& argv0, GlobalOptions& g) {
  std::vector<std::string> ros_args;
  const auto argv = splitRosArgs(argv0, ros_args);
  Args args("ros nav",
            "the navigation as a ROS node: camera, odometry, scan and sonar from topics, "
            "cmd_vel out; every setting also a ROS parameter (~nav/v_cruise = nav.v_cruise)",
            "--sketch FILE [--model FILE] --exit-on-result [--max-time S] [--out DIR] "
            "[from:=to ...]");
  args.option("sketch", "the hand-drawn map (.sketch.json)")
      .option("model", "landmark model (.slm); default: the demo set, trained once and cached")
      .option("landmarks", "landmark set folder to train the model from (default: share/landmarks)")
      .option("cache-dir", "where trained models are cached (default: ~/.cache/sketchnav)")
      .option("max-time", "give up after this many seconds of ROS time (default: nav.max_time_s)")
      .option("out", "also write summary.json, events.jsonl, telemetry.csv here")
      .flag("exit-on-result", "start the route at once and exit when it ends (0 success, 1 not)");
  if (!args.parse(argv)) return 0;
  if (args.get("sketch").empty()) throw InputError("sketchnav ros nav: --sketch FILE is required");
  if (!args.flagSet("exit-on-result"))
    throw InputError(
        "sketchnav ros nav: --exit-on-result is required: the goal / cancel action server is "
        "not built yet (doc/ros.md)");
  ros::init("sketchnav_nav", ros_args, 10.0);
  Json summary;
  try {
    Config c = mergedSettings(g);
    ros::RosParams rp;
    applyConfig(rp, c, "ros");
    // Every setting checked before anything waits for a topic: a typo fails at once.
    runSettingsFrom(c);
    c.requireAllUsedExcept(driverSettingPrefixes());
    ros::startWatchdog(rp);
    ros::registerDrivers();
    // The executive's own staleness limits on ROS time: ros.stale_timeout_s unless set.
    for (const char* k :
         {"nav.safety.camera_timeout_s", "nav.safety.range_timeout_s", "nav.safety.odom_timeout_s"})
      if (!c.has(k)) c.set(k, rp.stale_timeout_s);
    if (!ros::waitForTime(rp.wait_s))
      throw RuntimeError("ROS time is not valid after " + std::to_string(rp.wait_s) +
                         " s: /use_sim_time is set but nothing publishes /clock");
    // The camera mount from tf (REP 105 base frame -> the image's optical frame).
    if (rp.camera_mount_from_tf) {
      const std::string frame = ros::imageFrame(rp.image_topic, rp.wait_s);
      ros::CameraMount m;
      if (!frame.empty() && ros::lookupCameraMount(rp.base_frame, frame, 2.0, m)) {
        if (!c.has("servo.camera_x_m")) c.set("servo.camera_x_m", m.x);
        if (!c.has("servo.camera_z_m")) c.set("servo.camera_z_m", m.z);
        if (!c.has("nav.perception.camera_yaw")) c.set("nav.perception.camera_yaw", m.yaw);
        if (!c.has("nav.perception.camera_pitch")) c.set("nav.perception.camera_pitch", m.pitch);
        char b[160];
        std::snprintf(b, sizeof b, "x %.3f m, z %.3f m, yaw %.1f deg, pitch %.1f deg", m.x, m.z,
                      m.yaw * 180 / M_PI, m.pitch * 180 / M_PI);
        log::info("ros", "camera mount from tf", {{"frame", frame}, {"mount", b}});
      } else {
        log::warn("ros",
                  "no tf from the base frame to the camera: the camera mount settings "
                  "keep their values",
                  {{"base_frame", rp.base_frame}, {"camera_frame", frame}});
      }
    }
    ros::JsonPublisher events("~events", false, 100), state("~state", false, 10),
        result("~result", true, 1);
    RunOptions o;
    o.sketch = args.get("sketch");
    o.model = args.get("model");
    o.landmark_dir = args.get("landmarks");
    o.cache_dir = args.get("cache-dir");
    if (!args.get("max-time").empty()) o.max_time_s = args.getDouble("max-time");
    o.robot = "ros://base?cmd_vel=" + rp.cmd_vel_topic + "&odom=" + rp.odom_topic;
    o.camera = "ros://camera?topic=" + rp.image_topic + "&info=" + rp.camera_info_topic;
    if (!rp.scan_topic.empty()) o.laser = "ros://laser?topic=" + rp.scan_topic;
    if (!rp.sonar_topic.empty()) o.sonar = "ros://sonar?topic=" + rp.sonar_topic;
    o.config = c;
    o.out_dir = args.get("out").empty() ? "" : makeOutputDir(args.get("out"));
    o.progress = true;
    o.on_event = [&](const nav::NavEvent& ev) {
      const Json e = ev.toJson();
      // The route starts: one command, so a simulator holding its time at 0 starts too.
      if (e.value("type", "") == "start") ros::sendZeroCommand();
      events.publish(e);
    };
    o.on_tick = [&](const nav::TelemetryRow& r) {
      state.publish({{"t", r.t},
                     {"section", r.section},
                     {"mode", r.mode},
                     {"turn", r.turn},
                     {"landmark", r.landmark},
                     {"v", r.v_cmd},
                     {"w", r.w_cmd},
                     {"servo_error", std::isfinite(r.servo_error) ? Json(r.servo_error) : Json()},
                     {"odom", {r.odom.x, r.odom.y, r.odom.theta}},
                     {"front_free_m", r.front_free_m}});
    };
    summary = runNavigation(o);
    const std::string f = ros::fault();
    summary["ros"] = {{"fault", f}, {"signal", ros::signalReceived()}};
    // A fault while the route ran failed it (the base reported it lost); say what it was.
    if (!f.empty() && !summary["success"].get<bool>()) {
      summary["reason"] = "safety stop: " + f;
    }
    result.publish(summary);
  } catch (...) {
    ros::shutdown();
    throw;
  }
  ros::shutdown();
  if (g.json) {
    printJson(summary);
  } else {
    std::cout << (summary["success"].get<bool>() ? "success" : "FAILED") << ": "
              << summary["reason"].get<std::string>() << "\n"
              << "time " << summary["time_s"].get<double>() << " s, sections "
              << summary["sections_done"].get<int>() << "/" << summary["sections"].get<int>()
              << ", odometry path " << summary["odom_path_m"].get<double>() << " m\n";
  }
  return summary["success"].get<bool>() ? 0 : 1;
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
