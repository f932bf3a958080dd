// sketchnav sim: render a world view, drive the simulator open-loop, or draw a world's map.
#include <opencv2/imgcodecs.hpp>

#include <chrono>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "cli.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/input_file.h"
#include "sketchnav/core/log.h"
#include "sketchnav/core/paths.h"
#include "sketchnav/hw/pose.h"
#include "sketchnav/sim/map_render.h"
#include "sketchnav/sim/simulator.h"
#include "sketchnav/sim/world.h"

namespace fs = std::filesystem;

namespace sketchnav::app {
namespace {

std::vector<double> numbers(const std::string& text, size_t n, const std::string& option) {
  std::vector<double> out;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      size_t used = 0;
      out.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw InputError("sketchnav sim: " + option + " expects " + std::to_string(n) +
                       " comma-separated numbers, got '" + text + "'");
    }
  }
  if (out.size() != n)
    throw InputError("sketchnav sim: " + option + " expects " + std::to_string(n) +
                     " comma-separated numbers, got '" + text + "'");
  return out;
}

// "-o FILE" is accepted as a synonym of "--output FILE".
std::vector<std::string> withLongOutput(std::vector<std::string> argv) {
  for (auto& a : argv)
    if (a == "-o") a = "--output";
  return argv;
}

sim::SimParams simParams(const GlobalOptions& g) {
  sim::SimParams p;
  applyConfig(p, g.config, "sim");
  return p;
}

double cpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

Json poseJson(const hw::Pose2D& p) {
  return {{"x", p.x}, {"y", p.y}, {"theta", p.theta}};
}

std::string outputFile(const Args& args, const std::string& def_name) {
  if (args.has("output") && !args.get("output").empty()) {
    // An explicit -o names a file in an existing folder: no parent folders are created.
    requireOutputFile(args.get("output"), "sketchnav sim: -o");
    return args.get("output");
  }
  return (fs::path(makeOutputDir(args.get("out"))) / def_name).string();
}

int runRender(const std::vector<std::string>& argv, GlobalOptions& g) {
  Args args("sim render", "render one camera view of a world",
            "[--world lab|FILE] [--pose x,y,theta] [-o view.png]");
  args.option("world", "world: lab, a name in share/worlds, or a world file", "lab")
      .option("pose", "robot pose x,y,theta in the world frame [m, m, rad] (default: the start)")
      .option("time", "simulated time [s] (pedestrian positions, lighting)", "0")
      .option("output", "output image (-o); default <out>/view.png")
      .option("out", "output folder when -o is not given (default runs/<timestamp>)")
      .flag("clean", "no pixel noise / blur / brightness jitter");
  if (!args.parse(withLongOutput(argv))) return 0;
  auto sim =
      std::make_unique<sim::Simulator>(sim::loadWorldByName(args.get("world")), simParams(g));
  hw::Pose2D pose = sim->world().start;
  if (args.has("pose") && !args.get("pose").empty()) {
    const auto v = numbers(args.get("pose"), 3, "--pose");
    pose = {v[0], v[1], v[2]};
  }
  const auto t0 = std::chrono::steady_clock::now();
  const cv::Mat img = sim->renderView(pose, args.getDouble("time"), !args.flagSet("clean"));
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  const std::string file = outputFile(args, "view.png");
  if (!cv::imwrite(file, img)) throw RuntimeError("cannot write '" + file + "'");
  const Json out = {{"world", sim->world().name}, {"pose", poseJson(pose)}, {"file", file},
                    {"width", img.cols},          {"height", img.rows},     {"render_ms", ms}};
  if (g.json)
    printJson(out);
  else
    std::cout << "wrote " << file << " (" << img.cols << "x" << img.rows << ", " << std::fixed
              << std::setprecision(2) << ms << " ms)\n";
  return 0;
}

int runMap(const std::vector<std::string>& argv, GlobalOptions& g) {
  Args args("sim map", "draw a world's top-down map", "[--world lab|FILE] [-o map.png]");
  args.option("world", "world: lab, a name in share/worlds, or a world file", "lab")
      .option("scale", "pixels per metre", "40")
      .option("output", "output image (-o); default <out>/map.png")
      .option("out", "output folder when -o is not given (default runs/<timestamp>)");
  if (!args.parse(withLongOutput(argv))) return 0;
  const double scale = args.getDouble("scale");
  if (!(scale >= 5 && scale <= 400))
    throw InputError("sketchnav sim map: --scale must be in [5, 400]");
  const sim::World w = sim::loadWorldByName(args.get("world"));
  sim::MapCanvas canvas(w, scale);
  const std::string file = outputFile(args, "map.png");
  canvas.save(file);
  if (g.json)
    printJson({{"world", w.name},
               {"file", file},
               {"width", canvas.image().cols},
               {"height", canvas.image().rows}});
  else
    std::cout << "wrote " << file << "\n";
  return 0;
}

int runDrive(const std::vector<std::string>& argv, GlobalOptions& g) {
  Args args("sim drive", "drive the simulator open-loop with a constant command",
            "--cmd v,w --seconds T [--world lab|FILE] [--camera-hz 10] [--frames DIR]");
  args.option("world", "world: lab, a name in share/worlds, or a world file", "lab")
      .option("cmd", "constant command v,w [m/s, rad/s]", "0.3,0")
      .option("seconds", "simulated duration [s]", "10")
      .option("camera-hz", "camera frame rate [Hz] (0 = no camera)", "10")
      .option("frames", "save the rendered frames as PNGs in DIR (otherwise discarded)")
      .option("seed", "random seed (default: sim.seed)")
      .option("out", "output folder for trajectory.csv / trajectory.png (default runs/<timestamp>)")
      .flag("realtime", "run at wall-clock speed instead of as fast as possible");
  if (!args.parse(argv)) return 0;
  const auto cmd = numbers(args.get("cmd"), 2, "--cmd");
  const double seconds = args.getDouble("seconds");
  const double cam_hz = args.getDouble("camera-hz");
  if (!(seconds > 0 && seconds <= 36000))
    throw InputError("sketchnav sim drive: --seconds must be in (0, 36000]");
  if (!(cam_hz >= 0 && cam_hz <= 200))
    throw InputError("sketchnav sim drive: --camera-hz must be in [0, 200]");
  sim::SimParams p = simParams(g);
  p.camera_hz = cam_hz;
  p.realtime = args.flagSet("realtime");
  if (args.has("seed") && !args.get("seed").empty()) {
    const int s = args.getInt("seed");
    if (s < 0) throw InputError("sketchnav sim drive: --seed must be >= 0");
    p.seed = static_cast<std::uint64_t>(s);
  }
  const std::string frames_dir = args.has("frames") ? args.get("frames") : "";
  if (!frames_dir.empty()) fs::create_directories(frames_dir);
  const std::string out_dir = makeOutputDir(args.get("out"));

  sim::Simulator sim(sim::loadWorldByName(args.get("world")), p);
  auto clock = sim.clock();
  const double laser_hz = sim.world().laser.rate_hz, sonar_hz = sim.world().sonar.rate_hz;
  const double loop_hz = std::max({cam_hz, laser_hz, sonar_hz});
  const auto wall0 = std::chrono::steady_clock::now();
  const double cpu0 = cpuSeconds();
  sim.base().command(cmd[0], cmd[1]);
  hw::Frame frame;
  hw::RangeScan scan;
  std::uint64_t frames = 0;
  double next_cam = 0;
  const long steps = static_cast<long>(std::floor(seconds * loop_hz + 1e-9));
  for (long k = 0; k <= steps; ++k) {
    const double t = k / loop_hz;
    clock->sleepUntil(t);
    if (cam_hz > 0 && t + 1e-9 >= next_cam) {
      if (sim.camera().grab(frame, 1.0) == hw::GrabStatus::Ok) {
        ++frames;
        if (!frames_dir.empty()) {
          std::ostringstream name;
          name << "frame_" << std::setw(5) << std::setfill('0') << frame.seq << ".png";
          cv::imwrite((fs::path(frames_dir) / name.str()).string(), frame.image);
        }
      }
      next_cam += 1.0 / cam_hz;
    }
    sim.laser().read(scan);
    sim.sonar().read(scan);
    if (sim.collided()) break;
    if (k % std::max(1L, static_cast<long>(10 * loop_hz)) == 0 && !g.json)
      std::cerr << "\rt = " << std::fixed << std::setprecision(1) << t << " s" << std::flush;
  }
  if (!g.json) std::cerr << "\n";
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  const double cpu = cpuSeconds() - cpu0;
  const auto st = sim.stats();
  const auto traj = sim.trajectory();

  std::ofstream csv((fs::path(out_dir) / "trajectory.csv").string());
  csv << "t,x,y,theta,odom_x,odom_y,odom_theta,v,w\n";
  for (const auto& s : traj)
    csv << s.t << ',' << s.truth.x << ',' << s.truth.y << ',' << s.truth.theta << ',' << s.odom.x
        << ',' << s.odom.y << ',' << s.odom.theta << ',' << s.v << ',' << s.w << '\n';
  sim::MapCanvas canvas(sim.world(), 40);
  std::vector<hw::Pose2D> truth, odom_world;
  for (const auto& s : traj) {
    truth.push_back(s.truth);
    odom_world.push_back(hw::composePose(sim.world().start, s.odom));
  }
  canvas.drawPoses(odom_world, cv::Scalar(200, 120, 0), true, 1);
  canvas.drawPoses(truth, cv::Scalar(0, 0, 0), true, 2);
  canvas.drawRobot(sim.truePose(), sim.world().robot.radius, cv::Scalar(0, 0, 200));
  canvas.drawLegend(
      {{"true trajectory", cv::Scalar(0, 0, 0)}, {"odometry", cv::Scalar(200, 120, 0)}});
  canvas.save((fs::path(out_dir) / "trajectory.png").string());

  const double sim_t = clock->now();
  Json out = {{"world", sim.world().name},
              {"seed", p.seed},
              {"command", {{"v", cmd[0]}, {"w", cmd[1]}}},
              {"sim_seconds", sim_t},
              {"final_pose", poseJson(sim.truePose())},
              {"odometry_pose", poseJson(sim.odometryPose())},
              {"distance", st.distance},
              {"collisions", sim.collided() ? 1 : 0},
              {"collision_with", sim.collided() ? Json(sim.collisionWith()) : Json(nullptr)},
              {"min_clearance", sim.minClearance()},
              {"frames_rendered", st.frames_rendered},
              {"laser_scans", st.laser_scans},
              {"sonar_scans", st.sonar_scans},
              {"render_ms_per_frame",
               st.frames_rendered ? 1000.0 * st.render_seconds / st.frames_rendered : 0.0},
              {"wall_seconds", wall},
              {"realtime_factor", wall > 0 ? sim_t / wall : 0.0},
              {"cpu_seconds", cpu},
              {"realtime_factor_cpu", cpu > 0 ? sim_t / cpu : 0.0},
              {"out", out_dir}};
  if (g.json) {
    printJson(out);
  } else {
    std::cout << out.dump(2) << "\n";
  }
  return 0;
}

int runSim(const std::vector<std::string>& argv, GlobalOptions& g) {
  const std::string usage =
      "sketchnav sim render|drive|map [options]\n"
      "  render  render one camera view:  --world lab|FILE --pose x,y,theta -o view.png\n"
      "  drive   drive open-loop:         --world lab --cmd v,w --seconds T [--camera-hz 10] "
      "[--frames DIR]\n"
      "  map     draw the top-down map:   --world lab|FILE -o map.png\n"
      "`sketchnav sim <action> --help` lists each action's options. Simulator settings:\n"
      "--set sim.<field>=value (see doc/simulator.md).\n";
  if (argv.empty() || argv[0] == "--help" || argv[0] == "-h") {
    std::cout << usage;
    return argv.empty() ? 2 : 0;
  }
  const std::vector<std::string> rest(argv.begin() + 1, argv.end());
  // The simulator's settings are the only ones sim takes: a typo fails before any work.
  simParams(g);
  g.config.requireAllUsed();
  if (argv[0] == "render") return runRender(rest, g);
  if (argv[0] == "drive") return runDrive(rest, g);
  if (argv[0] == "map") return runMap(rest, g);
  throw InputError("sketchnav sim: unknown action '" + argv[0] + "' (render, drive or map)");
}

const CommandRegistration reg("sim", "render a world view / step the simulator", runSim);
}  // namespace
}  // namespace sketchnav::app
