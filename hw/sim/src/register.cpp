#include "sketchnav/sim/register.h"

#include <mutex>

#include "sketchnav/core/config.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/log.h"
#include "sketchnav/sim/simulator.h"

namespace sketchnav::sim {
namespace {

// Thin device handles that keep the shared Simulator alive and forward to its devices.
class CameraHandle final : public hw::Camera {
 public:
  CameraHandle(std::shared_ptr<Simulator> s, std::string uri)
      : s_(std::move(s)), uri_(std::move(uri)) {}
  hw::GrabStatus grab(hw::Frame& f, double timeout_s) override {
    return s_->camera().grab(f, timeout_s);
  }
  hw::Intrinsics intrinsics() const override { return s_->camera().intrinsics(); }
  hw::DeviceStats stats() const override { return s_->camera().stats(); }
  std::string uri() const override { return uri_; }

 private:
  std::shared_ptr<Simulator> s_;
  std::string uri_;
};

class BaseHandle final : public hw::Base {
 public:
  BaseHandle(std::shared_ptr<Simulator> s, std::string uri)
      : s_(std::move(s)), uri_(std::move(uri)) {}
  void command(double v, double w) override { s_->base().command(v, w); }
  void stop() noexcept override { s_->base().stop(); }
  bool odometry(hw::Odometry& o) override { return s_->base().odometry(o); }
  bool ok() const override { return s_->base().ok(); }
  hw::DeviceStats stats() const override { return s_->base().stats(); }
  std::string uri() const override { return uri_; }

 private:
  std::shared_ptr<Simulator> s_;
  std::string uri_;
};

class RangeHandle final : public hw::RangeSensor {
 public:
  RangeHandle(std::shared_ptr<Simulator> s, bool laser, std::string uri)
      : s_(std::move(s)), laser_(laser), uri_(std::move(uri)) {}
  bool read(hw::RangeScan& out) override { return dev().read(out); }
  hw::DeviceStats stats() const override { return dev().stats(); }
  std::string uri() const override { return uri_; }

 private:
  hw::RangeSensor& dev() const { return laser_ ? s_->laser() : s_->sonar(); }
  std::shared_ptr<Simulator> s_;
  bool laser_;
  std::string uri_;
};

}  // namespace

std::shared_ptr<Simulator> simulatorFor(const std::string& text, hw::DeviceContext& ctx) {
  const Uri uri = Uri::parse(text);
  if (uri.scheme != "sim") throw InputError("'" + text + "' is not a sim:// URI");
  if (uri.authority.empty() && uri.path.empty())
    throw InputError("'" + text + "': say which world, e.g. sim://lab or sim:///path/world.json");
  const std::string key = "sim:" + uri.authority + uri.path;
  if (auto it = ctx.shared.find(key); it != ctx.shared.end()) {
    auto sim = std::any_cast<std::shared_ptr<Simulator>>(it->second);
    ctx.clock = sim->clock();
    return sim;
  }
  World world = uri.authority.empty() ? loadWorld(uri.path) : loadWorldByName(uri.authority);
  SimParams params;
  applyConfig(params, ctx.config, "sim");
  if (uri.hasParam("seed")) {
    const int seed = uri.paramInt("seed", 1);
    if (seed < 0) throw InputError("'" + text + "': seed must be >= 0");
    params.seed = static_cast<std::uint64_t>(seed);
  }
  if (uri.hasParam("realtime")) params.realtime = uri.param("realtime", "0") != "0";
  auto sim = std::make_shared<Simulator>(std::move(world), params);
  log::info("sim", "simulator created", {{"uri", text}, {"seed", std::to_string(params.seed)}});
  ctx.shared[key] = sim;
  ctx.clock = sim->clock();
  return sim;
}

void registerDrivers() {
  static std::once_flag once;
  std::call_once(once, [] {
    auto& r = hw::Registry::instance();
    r.addCamera("sim",
                [](const Uri& u, hw::DeviceContext& ctx) -> std::unique_ptr<hw::Camera> {
                  return std::make_unique<CameraHandle>(simulatorFor(u.text, ctx), u.text);
                },
                {"seed", "realtime"});
    r.addBase("sim",
              [](const Uri& u, hw::DeviceContext& ctx) -> std::unique_ptr<hw::Base> {
                return std::make_unique<BaseHandle>(simulatorFor(u.text, ctx), u.text);
              },
              {"seed", "realtime"});
    r.addRange("sim",
               [](const Uri& u, hw::DeviceContext& ctx) -> std::unique_ptr<hw::RangeSensor> {
                 const std::string sensor = u.param("sensor", "laser");
                 if (sensor != "laser" && sensor != "sonar")
                   throw InputError("'" + u.text + "': sensor must be laser or sonar, got '" +
                                    sensor + "'");
                 return std::make_unique<RangeHandle>(simulatorFor(u.text, ctx), sensor == "laser",
                                                      u.text);
               },
               {"sensor", "seed", "realtime"});
  });
}

}  // namespace sketchnav::sim
