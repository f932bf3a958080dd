// Simulator benchmarks: camera render time in the lab world, laser/sonar scan time, ViSP's
// vpImageSimulator per-plane cost (the reason for our own rasteriser), and the real-time
// factor of a drive with a 640x480 camera at 10 Hz plus laser and sonar.
#include <benchmark/benchmark.h>
#include <visp3/core/vpImage.h>
#include <visp3/robot/vpImageSimulator.h>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>

#include <chrono>
#include <cmath>
#include <ctime>

#include "sketchnav/sim/simulator.h"
#include "sketchnav/sim/world.h"

using namespace sketchnav;

namespace {

// Poses along the lab route (world frame), looking where a robot following it would look.
const std::vector<hw::Pose2D> kRoute = {{0.8, 10.1, -0.35}, {2.5, 11.3, 0.0},   {5.0, 11.3, -1.0},
                                        {6.6, 8.8, -1.4},   {7.0, 6.5, 0.0},    {11.0, 6.5, 0.0},
                                        {14.0, 6.5, 0.0},   {16.6, 6.5, -1.45}, {17.0, 3.4, -0.8},
                                        {9.0, 6.5, 3.1416}, {4.0, 4.0, 2.3},    {12.0, 10.0, -2.0}};

sim::SimParams quietParams() {
  sim::SimParams p;
  p.record_period = 0;
  return p;
}

void BM_RenderLabView(benchmark::State& state) {
  cv::setNumThreads(1);
  sim::Simulator s(sim::labWorld(), quietParams());
  size_t i = 0;
  for (auto _ : state) {
    cv::Mat img = s.renderView(kRoute[i++ % kRoute.size()], 0.0, state.range(0) != 0);
    benchmark::DoNotOptimize(img.data);
  }
  state.SetLabel(state.range(0) ? "with noise" : "clean");
}
BENCHMARK(BM_RenderLabView)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_LaserScan(benchmark::State& state) {
  sim::World w = sim::labWorld();
  w.laser.rate_hz = 1000;  // a new scan on every read below
  sim::Simulator s(w, quietParams());
  hw::RangeScan scan;
  double t = 0;
  for (auto _ : state) {
    t += 0.001;
    s.advanceTo(t);
    s.laser().read(scan);
    benchmark::DoNotOptimize(scan.ranges.data());
  }
}
BENCHMARK(BM_LaserScan)->Unit(benchmark::kMicrosecond);

void BM_SonarScan(benchmark::State& state) {
  sim::World w = sim::labWorld();
  w.sonar.rate_hz = 1000;
  sim::Simulator s(w, quietParams());
  hw::RangeScan scan;
  double t = 0;
  for (auto _ : state) {
    t += 0.001;
    s.advanceTo(t);
    s.sonar().read(scan);
    benchmark::DoNotOptimize(scan.ranges.data());
  }
}
BENCHMARK(BM_SonarScan)->Unit(benchmark::kMicrosecond);

// One textured plane (a 198x198 landmark photo, 0.5 m wide, 1.5 m ahead) with ViSP.
void BM_VispImageSimulatorPlane(benchmark::State& state) {
  const sim::World w = sim::labWorld();
  vpImage<vpRGBa> tex;
  {
    cv::Mat m = cv::imread(w.landmarks[0].texture);
    tex.resize(m.rows, m.cols);
    for (int r = 0; r < m.rows; ++r)
      for (int c = 0; c < m.cols; ++c) {
        const auto p = m.at<cv::Vec3b>(r, c);
        tex[r][c] = vpRGBa(p[2], p[1], p[0]);
      }
  }
  vpImageSimulator sim(vpImageSimulator::COLORED);
  vpColVector X[4];
  const double h = 0.25;
  const double corners[4][2] = {{-h, -h}, {h, -h}, {h, h}, {-h, h}};
  for (int k = 0; k < 4; ++k) {
    X[k].resize(3);
    X[k][0] = corners[k][0];
    X[k][1] = corners[k][1];
    X[k][2] = 0;
  }
  sim.init(tex, X);
  sim.setInterpolationType(vpImageSimulator::BILINEAR_INTERPOLATION);
  vpCameraParameters cam(554.3, 554.3, 319.5, 239.5);
  vpHomogeneousMatrix cMo(0.1, 0.05, 1.5, 0.1, 0.2, 0.0);
  vpImage<vpRGBa> img(480, 640, vpRGBa(128, 128, 128));
  for (auto _ : state) {
    sim.setCameraPosition(cMo);
    sim.getImage(img, cam);
    benchmark::DoNotOptimize(img.bitmap);
  }
}
BENCHMARK(BM_VispImageSimulatorPlane)->Unit(benchmark::kMillisecond);

// A 60 s drive on a 1.5 m circle in the open north-east part of room B:
// camera 10 Hz + laser + sonar. Reports the real-time factor (simulated seconds per second of
// this thread's CPU time, i.e. on one core, independent of other load on the machine) and per
// wall second.
double threadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

void BM_DriveRealtimeFactor(benchmark::State& state) {
  cv::setNumThreads(1);
  const sim::World w = sim::labWorld();
  double sim_s = 0, wall_s = 0, cpu_s = 0, frames = 0, render_s = 0;
  for (auto _ : state) {
    sim::SimParams p = quietParams();
    p.camera_hz = 10;
    sim::Simulator s(w, p);
    s.setTruePose({15.5, 8.7, 0.0});
    auto clock = s.clock();
    hw::Frame f;
    hw::RangeScan scan;
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = threadCpuSeconds();
    for (int k = 0; k <= 600; ++k) {
      const double t = 0.1 * k;
      clock->sleepUntil(t);
      s.base().command(0.3, 0.2);
      s.camera().grab(f, 1.0);
      s.laser().read(scan);
      s.sonar().read(scan);
    }
    cpu_s += threadCpuSeconds() - c0;
    if (s.collided()) state.SkipWithError("the benchmark drive collided");
    wall_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    sim_s += clock->now();
    const auto st = s.stats();
    frames += static_cast<double>(st.frames_rendered);
    render_s += st.render_seconds;
  }
  state.counters["realtime_factor_cpu"] = sim_s / cpu_s;
  state.counters["realtime_factor_wall"] = sim_s / wall_s;
  state.counters["ms_per_frame"] = 1000.0 * render_s / frames;
  state.counters["cpu_ms_per_sim_second"] = 1000.0 * cpu_s / sim_s;
}
BENCHMARK(BM_DriveRealtimeFactor)->Unit(benchmark::kMillisecond)->Iterations(2);

}  // namespace

BENCHMARK_MAIN();
