#include "sketchnav/sim/simulator.h"

#include <mrpt/kinematics/CVehicleSimul_DiffDriven.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <mutex>
#include <random>
#include <thread>

#include "geometry.h"
#include "renderer.h"
#include "sketchnav/core/config.h"
#include "sketchnav/core/log.h"
#include "sketchnav/hw/pose.h"

namespace sketchnav::sim {

using hw::composePose;
using hw::inversePose;

void SimParams::validate() const {
  require(substep >= 1e-4 && substep <= 0.1, "sim.substep", "must be in [0.0001, 0.1] s");
  require(camera_hz >= 0 && camera_hz <= 200, "sim.camera_hz", "must be in [0, 200] Hz");
  require(image_noise_std >= 0 && image_noise_std < 100, "sim.image_noise_std",
          "must be in [0, 100)");
  require(blur_sigma >= 0 && blur_sigma < 20, "sim.blur_sigma", "must be in [0, 20) px");
  require(brightness_jitter >= 0 && brightness_jitter < 1, "sim.brightness_jitter",
          "must be in [0, 1)");
  require(v_max > 0 && v_max < 10, "sim.v_max", "must be in (0, 10) m/s");
  require(w_max > 0 && w_max < 20, "sim.w_max", "must be in (0, 20) rad/s");
  require(acc_max > 0, "sim.acc_max", "must be > 0");
  require(alpha_max > 0, "sim.alpha_max", "must be > 0");
  require(odom_slip_std >= 0 && odom_slip_std < 1, "sim.odom_slip_std", "must be in [0, 1)");
  require(odom_turn_slip_std >= 0 && odom_turn_slip_std < 1, "sim.odom_turn_slip_std",
          "must be in [0, 1)");
  require(std::abs(odom_scale_error) < 0.5, "sim.odom_scale_error", "must be in (-0.5, 0.5)");
  require(std::abs(odom_drift) < 1, "sim.odom_drift", "must be in (-1, 1) rad/m");
  require(range_noise_scale >= 0 && range_noise_scale < 100, "sim.range_noise_scale",
          "must be in [0, 100)");
  require(record_period >= 0, "sim.record_period", "must be >= 0");
  require(pedestrian_keep_behind_m >= 0 && pedestrian_keep_behind_m <= 5,
          "sim.pedestrian_keep_behind_m", "must be in [0, 5] m (0 = off)");
}

namespace {

// CPU time of the calling thread: render cost measured this way does not depend on how
// loaded the machine is.
double threadCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

/// MRPT's differential-drive kinematics, stepped once per substep. MRPT integrates in
/// "firmware" periods and, with its default 0.5 ms period, a 10 ms step runs 20 or 21 periods
/// depending on rounding (a few % too much motion). With the period set to the substep and a
/// call of half a substep, each call is exactly one period (checked by the tests).
class Vehicle : public mrpt::kinematics::CVehicleSimul_DiffDriven {
 public:
  explicit Vehicle(double substep) : substep_(substep) { m_firmware_control_period = substep; }
  void step() { simulateOneTimeStep(0.5 * substep_); }

 private:
  double substep_;
};

}  // namespace

PedestrianState pedestrianAt(const Pedestrian& p, double t) {
  PedestrianState st;
  st.name = p.name;
  st.radius = p.radius;
  std::vector<Vec2> pts = p.path;
  if (p.loop) pts.push_back(p.path.front());
  double len = 0;
  for (size_t i = 1; i < pts.size(); ++i) len += (pts[i] - pts[i - 1]).norm();
  double s = p.phase + p.speed * t;
  double dir = 1.0;
  if (p.loop) {
    s = std::fmod(s, len);
    if (s < 0) s += len;
  } else {
    s = std::fmod(s, 2 * len);
    if (s < 0) s += 2 * len;
    if (s > len) {
      s = 2 * len - s;
      dir = -1.0;
    }
  }
  for (size_t i = 1; i < pts.size(); ++i) {
    const Vec2 seg = pts[i] - pts[i - 1];
    const double l = seg.norm();
    if (s <= l || i + 1 == pts.size()) {
      const Vec2 u = l > 0 ? Vec2(seg / l) : Vec2(1, 0);
      st.position = pts[i - 1] + std::min(s, l) * u;
      st.velocity = dir * p.speed * u;
      return st;
    }
    s -= l;
  }
  st.position = pts.back();
  return st;
}

// ---------------------------------------------------------------------------------------
struct Simulator::Impl {
  Simulator& sim;
  const World& world;
  const SimParams& params;
  std::recursive_mutex mutex;
  std::shared_ptr<hw::SimClock> clock = std::make_shared<hw::SimClock>();
  Vehicle vehicle;
  std::mt19937_64 rng_motion, rng_camera, rng_range;
  std::unique_ptr<Renderer> renderer;
  geom::Solids solids;

  double t_state = 0.0;
  double cmd_v = 0, cmd_w = 0;  // last command (clamped to the limits)
  double v = 0, w = 0;          // actual velocities (after acceleration limits)
  hw::Pose2D odom;
  bool collided = false;
  std::string collided_with;
  double min_clearance = geom::kInf;
  double min_clearance_people = geom::kInf;
  // Per pedestrian: how long it has waited behind the robot so far [s] (it is where its path
  // puts it at t - waited), and whether it is waiting now.
  std::vector<double> waited;
  std::vector<char> waiting;
  double clearance = geom::kInf;
  double distance = 0;
  std::vector<TrajectorySample> trajectory;
  double next_record = 0;
  SimStats stats;
  // Realtime pacing
  static constexpr double kPacedMaxLag = 0.1;  // [s] backlog a paced run may catch up at once
  bool wall_started = false;
  std::chrono::steady_clock::time_point wall0;
  double sim0 = 0;

  class Camera;
  class Base;
  class Range;
  std::unique_ptr<hw::Camera> camera_dev;
  std::unique_ptr<hw::Base> base_dev;
  std::unique_ptr<hw::RangeSensor> laser_dev, sonar_dev;

  Impl(Simulator& s, const World& w, const SimParams& p)
      : sim(s),
        world(w),
        params(p),
        vehicle(p.substep),
        rng_motion(p.seed * 1000003ULL + 1),
        rng_camera(p.seed * 1000003ULL + 2),
        rng_range(p.seed * 1000003ULL + 3),
        waited(w.pedestrians.size(), 0.0),
        waiting(w.pedestrians.size(), 0) {}

  hw::Pose2D gt() const {
    const auto& p = vehicle.getCurrentGTPose();
    return {p.x, p.y, p.phi};
  }

  std::vector<PedestrianState> pedestriansAt(double t) const {
    std::vector<PedestrianState> out;
    for (size_t i = 0; i < world.pedestrians.size(); ++i) {
      out.push_back(pedestrianAt(world.pedestrians[i], t - waited[i]));
      if (waiting[i]) out.back().velocity.setZero();
    }
    return out;
  }

  // Who waits behind the robot (at `robot`, driving at `speed` [m/s]) over the step to t_next
  // (SimParams::pedestrian_keep_behind_m).
  void updateWaits(const hw::Pose2D& robot, double speed, double t_next, double dt) {
    const double keep = params.pedestrian_keep_behind_m;
    const Vec2 c(robot.x, robot.y), heading(std::cos(robot.theta), std::sin(robot.theta));
    for (size_t i = 0; i < world.pedestrians.size(); ++i) {
      waiting[i] = 0;
      if (keep <= 0) continue;
      const auto& p = world.pedestrians[i];
      const PedestrianState st = pedestrianAt(p, t_next - waited[i]);  // walking on
      const double walk = st.velocity.norm();
      const Vec2 d = c - st.position;  // to the robot
      const double dist = d.norm();
      if (walk < 1e-9 || dist < 1e-9) continue;
      const Vec2 u = st.velocity / walk;
      const double reach = p.radius + world.robot.radius;
      const double along = d.dot(u);
      const bool in_way = along > 0 && (d - along * u).norm() < reach + 0.1;
      const bool at_its_back = heading.dot(-d) < 0;
      const bool driving_at = speed * heading.dot(-d / dist) > 0.05;
      if (in_way && at_its_back && !driving_at && dist - reach < keep) {
        waited[i] += dt;
        waiting[i] = 1;
      }
    }
  }

  /// Distance from the robot's body (disc) to the nearest solid or pedestrian; < 0 = overlap.
  /// `people` (when given): lowered to the distance to the nearest pedestrian's body.
  double clearanceAt(const hw::Pose2D& pose, double t, std::string* what,
                     double* people = nullptr) const {
    const Vec2 c(pose.x, pose.y);
    const double r = world.robot.radius;
    double best = geom::kInf;
    for (const auto& p : solids.polys) {
      const double d = geom::signedDistance(c, p) - r;
      if (d < best) {
        best = d;
        if (what) *what = p.name;
      }
    }
    for (const auto& k : solids.circles) {
      const double d = (c - k.c).norm() - k.r - r;
      if (d < best) {
        best = d;
        if (what) *what = k.name;
      }
    }
    for (const auto& st : pedestriansAt(t)) {
      const double d = (c - st.position).norm() - st.radius - r;
      if (people) *people = std::min(*people, d);
      if (d < best) {
        best = d;
        if (what) *what = st.name;
      }
    }
    return best;
  }

  void record() {
    if (params.record_period <= 0 || t_state + 1e-9 < next_record) return;
    trajectory.push_back({t_state, gt(), odom, v, w});
    next_record += params.record_period;
  }

  void stepOnce(double dt) {
    const double t_next = t_state + dt;
    if (collided) {
      v = w = 0;
    } else {
      v += std::clamp(cmd_v - v, -params.acc_max * dt, params.acc_max * dt);
      w += std::clamp(cmd_w - w, -params.alpha_max * dt, params.alpha_max * dt);
    }
    const hw::Pose2D prev = gt();
    updateWaits(prev, v, t_next, dt);
    vehicle.movementCommand(v, w);
    vehicle.step();
    const hw::Pose2D now = gt();
    std::string what;
    clearance = clearanceAt(now, t_next, &what, &min_clearance_people);
    min_clearance = std::min(min_clearance, clearance);
    if (clearance < 0) {
      if (!collided) {
        collided = true;
        collided_with = what;
        log::warn("sim", "collision",
                  {{"with", what},
                   {"t", std::to_string(t_next)},
                   {"x", std::to_string(now.x)},
                   {"y", std::to_string(now.y)}});
      }
      vehicle.setCurrentGTPose({prev.x, prev.y, prev.theta});
      vehicle.movementCommand(0, 0);
      v = w = cmd_v = cmd_w = 0;
    } else {
      // Odometry: the true wheel increments with random slip (a random walk whose variance
      // grows with the distance / angle, so it does not depend on the substep) and
      // systematic errors (wheel scale, heading drift per metre).
      const hw::Pose2D inc = composePose(inversePose(prev), now);
      std::normal_distribution<double> g(0.0, 1.0);
      const double ds = std::hypot(inc.x, inc.y);
      const double dth = inc.theta;
      hw::Pose2D m = inc;
      m.x *= 1 + params.odom_scale_error;
      m.y *= 1 + params.odom_scale_error;
      m.x += params.odom_slip_std * std::sqrt(ds) * g(rng_motion) * (inc.x < 0 ? -1 : 1);
      m.theta = dth + params.odom_turn_slip_std * std::sqrt(std::abs(dth)) * g(rng_motion) +
                params.odom_drift * ds;
      odom = composePose(odom, m);
      distance += std::hypot(now.x - prev.x, now.y - prev.y);
    }
    t_state = t_next;
    record();
  }

  void advanceTo(double t) {
    const double dt = params.substep;
    while (t_state + dt <= t + 1e-9) stepOnce(dt);
    if (clock->now() < t) clock->sleepUntil(t);
    if (params.realtime) {
      if (!wall_started) {
        wall_started = true;
        wall0 = std::chrono::steady_clock::now();
        sim0 = t_state;
      }
      const auto due = wall0 + std::chrono::duration_cast<std::chrono::nanoseconds>(
                                   std::chrono::duration<double>(t_state - sim0));
      // Simulated time stands still while the loop computes (a long perception pass, the
      // first one building the model's indexes), so a paced run falls behind the wall clock.
      // It catches up by at most kPacedMaxLag: the rest of the backlog is dropped (the origin
      // moves on) instead of being run at full speed, which would show the user a world
      // faster than real time for as long as the stall lasted.
      const auto late = std::chrono::steady_clock::now() - due;
      const auto max_lag = std::chrono::duration_cast<std::chrono::steady_clock::duration>(
          std::chrono::duration<double>(kPacedMaxLag));
      if (late > max_lag) wall0 += late - max_lag;
      std::this_thread::sleep_until(due);
    }
  }
  void sync() { advanceTo(clock->now()); }

  hw::RangeScan laserScan() {
    const auto& L = world.laser;
    hw::RangeScan s;
    s.kind = hw::RangeScan::Kind::Laser;
    s.min_range = static_cast<float>(L.min_range);
    s.max_range = static_cast<float>(L.max_range);
    s.mount = {L.x, L.y, L.yaw};
    s.stamp = t_state;
    const hw::Pose2D sp = composePose(gt(), s.mount);
    const auto peds = pedestriansAt(t_state);
    const double fov = L.fov_deg * M_PI / 180, res = L.resolution_deg * M_PI / 180;
    const bool full = L.fov_deg >= 360 - 1e-9;
    const int n = static_cast<int>(std::floor(fov / res + 1e-9)) + (full ? 0 : 1);
    std::normal_distribution<double> g(0.0, L.noise_std * params.range_noise_scale);
    for (int i = 0; i < n; ++i) {
      const double a = -0.5 * fov + i * res;
      const double r = castRay(sp, a, peds, L.max_range);
      s.angles.push_back(static_cast<float>(wrapAngle(L.yaw + a)));
      s.ranges.push_back(noisy(r, L.min_range, L.max_range, g));
    }
    return s;
  }

  hw::RangeScan sonarScan() {
    const auto& S = world.sonar;
    hw::RangeScan s;
    s.kind = hw::RangeScan::Kind::Sonar;
    s.min_range = static_cast<float>(S.min_range);
    s.max_range = static_cast<float>(S.max_range);
    s.beam_width = static_cast<float>(S.beam_width_deg * M_PI / 180);
    s.stamp = t_state;
    const auto peds = pedestriansAt(t_state);
    std::normal_distribution<double> g(0.0, S.noise_std * params.range_noise_scale);
    for (const auto& b : S.beams) {
      // A sonar reports the closest echo inside its cone: the minimum over a fan of rays.
      const hw::Pose2D bp = composePose(gt(), {b.x, b.y, b.yaw});
      double r = geom::kInf;
      const int rays = 9;
      for (int k = 0; k < rays; ++k) {
        const double a = (k / double(rays - 1) - 0.5) * s.beam_width;
        r = std::min(r, castRay(bp, a, peds, S.max_range));
      }
      // The scan has one mount, the robot's centre, for the whole ring: a range is reported
      // from there, i.e. with the transducer's offset along its axis added (reporting it
      // from the rim made every echo look 0.2 m closer than it is).
      const double off = b.x * std::cos(b.yaw) + b.y * std::sin(b.yaw);
      s.angles.push_back(static_cast<float>(b.yaw));
      s.ranges.push_back(r >= S.max_range || r + off >= S.max_range
                             ? static_cast<float>(S.max_range)
                             : noisy(r + off, S.min_range, S.max_range, g));
    }
    return s;
  }

  float noisy(double r, double rmin, double rmax, std::normal_distribution<double>& g) {
    if (r >= rmax) return static_cast<float>(rmax);
    if (g.stddev() > 0) r += g(rng_range);
    return static_cast<float>(std::clamp(r, rmin, std::nextafter(rmax, 0.0)));
  }

  double castRay(const hw::Pose2D& from, double rel, const std::vector<PedestrianState>& peds,
                 double max_range) const {
    const Vec2 o(from.x, from.y);
    const Vec2 d(std::cos(from.theta + rel), std::sin(from.theta + rel));
    double best = max_range;
    for (const auto& p : solids.polys) best = std::min(best, geom::rayPolygon(o, d, p));
    for (const auto& c : solids.circles) best = std::min(best, geom::rayCircle(o, d, c.c, c.r));
    for (const auto& p : peds) best = std::min(best, geom::rayCircle(o, d, p.position, p.radius));
    return best;
  }
};

// ---------------------------------------------------------------------------------------
class Simulator::Impl::Camera final : public hw::Camera {
 public:
  explicit Camera(Impl& s) : s_(s), k_(s.world.camera.intrinsics()) {}
  hw::GrabStatus grab(hw::Frame& frame, double timeout_s) override {
    std::lock_guard<std::recursive_mutex> lock(s_.mutex);
    const double hz = s_.params.camera_hz;
    double now = s_.clock->now();
    if (hz > 0) {
      const long tick = static_cast<long>(std::floor(now * hz + 1e-9));
      if (tick <= last_tick_) {
        // Like a real camera, block until the next frame: here that advances simulated time.
        const double t_frame = (last_tick_ + 1) / hz;
        if (t_frame - now > timeout_s) {
          s_.advanceTo(now + timeout_s);
          return hw::GrabStatus::Timeout;
        }
        s_.clock->sleepUntil(t_frame);
        now = s_.clock->now();
        last_tick_ = last_tick_ + 1;
      } else {
        last_tick_ = tick;
      }
    }
    s_.advanceTo(now);
    const double t0 = threadCpuSeconds();
    s_.renderer->render(s_.gt(), s_.t_state, s_.pedestriansAt(s_.t_state), true, s_.rng_camera,
                        frame.image);
    s_.stats.render_seconds += threadCpuSeconds() - t0;
    ++s_.stats.frames_rendered;
    frame.stamp = now;
    frame.seq = seq_++;
    frame.source = "sim";
    ++stats_.received;
    return hw::GrabStatus::Ok;
  }
  hw::Intrinsics intrinsics() const override { return k_; }
  hw::DeviceStats stats() const override { return stats_; }
  std::string uri() const override { return "sim://" + s_.world.name; }

 private:
  Impl& s_;
  hw::Intrinsics k_;
  long last_tick_ = -1;
  std::uint64_t seq_ = 0;
  hw::DeviceStats stats_;
};

class Simulator::Impl::Base final : public hw::Base {
 public:
  explicit Base(Impl& s) : s_(s) {}
  void command(double v, double w) override {
    std::lock_guard<std::recursive_mutex> lock(s_.mutex);
    s_.sync();  // the previous command held until now
    if (s_.collided) return;
    if (!std::isfinite(v) || !std::isfinite(w)) {
      log::warn("sim", "non-finite velocity command ignored; stopping");
      v = w = 0;
    }
    s_.cmd_v = std::clamp(v, -s_.params.v_max, s_.params.v_max);
    s_.cmd_w = std::clamp(w, -s_.params.w_max, s_.params.w_max);
    ++stats_.received;
  }
  void stop() noexcept override {
    try {
      std::lock_guard<std::recursive_mutex> lock(s_.mutex);
      s_.sync();
      s_.cmd_v = s_.cmd_w = 0;
    } catch (...) {
      s_.cmd_v = s_.cmd_w = 0;
    }
  }
  bool odometry(hw::Odometry& out) override {
    std::lock_guard<std::recursive_mutex> lock(s_.mutex);
    s_.sync();
    out.pose = s_.odom;
    out.v = s_.v;
    out.w = s_.w;
    out.stamp = s_.t_state;
    return true;
  }
  bool ok() const override {
    std::lock_guard<std::recursive_mutex> lock(s_.mutex);
    return !s_.collided;
  }
  hw::DeviceStats stats() const override {
    std::lock_guard<std::recursive_mutex> lock(s_.mutex);
    hw::DeviceStats st = stats_;
    if (s_.collided) st.last_error = "collision with '" + s_.collided_with + "'";
    return st;
  }
  std::string uri() const override { return "sim://" + s_.world.name; }

 private:
  Impl& s_;
  hw::DeviceStats stats_;
};

class Simulator::Impl::Range final : public hw::RangeSensor {
 public:
  Range(Impl& s, bool laser) : s_(s), laser_(laser) {}
  bool read(hw::RangeScan& out) override {
    std::lock_guard<std::recursive_mutex> lock(s_.mutex);
    s_.sync();
    const bool enabled = laser_ ? s_.world.laser.enabled : s_.world.sonar.enabled;
    if (!enabled) return false;
    const double hz = laser_ ? s_.world.laser.rate_hz : s_.world.sonar.rate_hz;
    const long tick = static_cast<long>(std::floor(s_.t_state * hz + 1e-9));
    if (tick > last_tick_) {
      last_tick_ = tick;
      scan_ = laser_ ? s_.laserScan() : s_.sonarScan();
      ++(laser_ ? s_.stats.laser_scans : s_.stats.sonar_scans);
      ++stats_.received;
    }
    out = scan_;
    return true;
  }
  hw::DeviceStats stats() const override { return stats_; }
  std::string uri() const override {
    return "sim://" + s_.world.name + (laser_ ? "" : "?sensor=sonar");
  }

 private:
  Impl& s_;
  bool laser_;
  long last_tick_ = -1;
  hw::RangeScan scan_;
  hw::DeviceStats stats_;
};

// ---------------------------------------------------------------------------------------
Simulator::Simulator(World world, SimParams params)
    : world_(std::move(world)), params_(std::move(params)) {
  params_.validate();
  impl_ = std::make_unique<Impl>(*this, world_, params_);
  impl_->solids = geom::buildSolids(world_);
  impl_->renderer = std::make_unique<Renderer>(world_, params_);
  impl_->vehicle.setDelayModelParams(0.0, 0.0);
  impl_->vehicle.setOdometryErrors(false);
  impl_->vehicle.setCurrentGTPose({world_.start.x, world_.start.y, world_.start.theta});
  impl_->clearance = impl_->clearanceAt(world_.start, 0.0, nullptr);
  impl_->min_clearance = impl_->clearance;
  impl_->record();
  impl_->camera_dev = std::make_unique<Impl::Camera>(*impl_);
  impl_->base_dev = std::make_unique<Impl::Base>(*impl_);
  impl_->laser_dev = std::make_unique<Impl::Range>(*impl_, true);
  impl_->sonar_dev = std::make_unique<Impl::Range>(*impl_, false);
  log::debug("sim", "simulator ready",
             {{"world", world_.name},
              {"seed", std::to_string(params_.seed)},
              {"faces", std::to_string(impl_->renderer->staticFaceCount())}});
}

Simulator::Simulator(World world, SimParams params, std::uint64_t seed)
    : Simulator(std::move(world), [&] {
        params.seed = seed;
        return params;
      }()) {}

Simulator::~Simulator() = default;

hw::Camera& Simulator::camera() {
  return *impl_->camera_dev;
}
hw::Base& Simulator::base() {
  return *impl_->base_dev;
}
hw::RangeSensor& Simulator::laser() {
  return *impl_->laser_dev;
}
hw::RangeSensor& Simulator::sonar() {
  return *impl_->sonar_dev;
}
std::shared_ptr<hw::SimClock> Simulator::clock() const {
  return impl_->clock;
}

void Simulator::advanceTo(double t) {
  std::lock_guard<std::recursive_mutex> lock(impl_->mutex);
  impl_->advanceTo(t);
}
void Simulator::sync() {
  std::lock_guard<std::recursive_mutex> lock(impl_->mutex);
  impl_->sync();
}
hw::Pose2D Simulator::truePose() {
  std::lock_guard<std::recursive_mutex> lock(impl_->mutex);
  impl_->sync();
  return impl_->gt();
}
hw::Pose2D Simulator::odometryPose() {
  std::lock_guard<std::recursive_mutex> lock(impl_->mutex);
  impl_->sync();
  return impl_->odom;
}
bool Simulator::collided() {
  std::lock_guard<std::recursive_mutex> lock(impl_->mutex);
  impl_->sync();
  return impl_->collided;
}
std::string Simulator::collisionWith() {
  std::lock_guard<std::recursive_mutex> lock(impl_->mutex);
  impl_->sync();
  return impl_->collided_with;
}
double Simulator::minClearance() {
  std::lock_guard<std::recursive_mutex> lock(impl_->mutex);
  impl_->sync();
  return impl_->min_clearance;
}
double Simulator::minClearancePeople() {
  std::lock_guard<std::recursive_mutex> lock(impl_->mutex);
  impl_->sync();
  return impl_->min_clearance_people;
}
double Simulator::clearance() {
  std::lock_guard<std::recursive_mutex> lock(impl_->mutex);
  impl_->sync();
  return impl_->clearance;
}
std::vector<PedestrianState> Simulator::pedestrians() {
  std::lock_guard<std::recursive_mutex> lock(impl_->mutex);
  impl_->sync();
  return impl_->pedestriansAt(impl_->t_state);
}
std::vector<TrajectorySample> Simulator::trajectory() {
  std::lock_guard<std::recursive_mutex> lock(impl_->mutex);
  impl_->sync();
  return impl_->trajectory;
}
SimStats Simulator::stats() {
  std::lock_guard<std::recursive_mutex> lock(impl_->mutex);
  impl_->sync();
  SimStats s = impl_->stats;
  s.distance = impl_->distance;
  return s;
}
bool Simulator::atGoal() {
  const hw::Pose2D p = truePose();
  return (Vec2(p.x, p.y) - world_.goal.centre).norm() <= world_.goal.radius;
}

cv::Mat Simulator::renderView(const hw::Pose2D& wMr, double t, bool degrade) {
  std::lock_guard<std::recursive_mutex> lock(impl_->mutex);
  cv::Mat out;
  std::mt19937_64 rng(params_.seed * 31 + static_cast<std::uint64_t>(std::llround(t * 1000)));
  impl_->renderer->render(wMr, t, impl_->pedestriansAt(t), degrade, rng, out);
  return out;
}

void Simulator::setTruePose(const hw::Pose2D& wMr) {
  std::lock_guard<std::recursive_mutex> lock(impl_->mutex);
  impl_->sync();
  impl_->vehicle.setCurrentGTPose({wMr.x, wMr.y, wMr.theta});
  impl_->vehicle.movementCommand(0, 0);
  impl_->v = impl_->w = impl_->cmd_v = impl_->cmd_w = 0;
  impl_->collided = false;
  impl_->collided_with.clear();
  impl_->clearance = impl_->clearanceAt(wMr, impl_->t_state, nullptr);
}

}  // namespace sketchnav::sim
