#include "sketchnav/sim/register.h"

#include <mutex>

#include "sketchnav/core/config.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/log.h"
#include "sketchnav/hw/forwarding.h"
#include "sketchnav/sim/simulator.h"

namespace sketchnav::sim {
namespace {

// Thin device handles onto the shared Simulator's devices: each keeps the Simulator alive (an
// aliasing shared_ptr) and reports the URI it was opened with; every other call forwards.
template <class Forwarding, class Device>
class Handle final : public Forwarding {
 public:
  Handle(const std::shared_ptr<Simulator>& s, Device& device, std::string uri)
      : Forwarding(std::shared_ptr<Device>(s, &device)), uri_(std::move(uri)) {}
  std::string uri() const override { return uri_; }

 private:
  std::string uri_;
};
using CameraHandle = Handle<hw::ForwardingCamera, hw::Camera>;
using BaseHandle = Handle<hw::ForwardingBase, hw::Base>;
using RangeHandle = Handle<hw::ForwardingRangeSensor, hw::RangeSensor>;

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
                  auto sim = simulatorFor(u.text, ctx);
                  return std::make_unique<CameraHandle>(sim, sim->camera(), u.text);
                },
                {"seed", "realtime"});
    r.addBase("sim",
              [](const Uri& u, hw::DeviceContext& ctx) -> std::unique_ptr<hw::Base> {
                auto sim = simulatorFor(u.text, ctx);
                return std::make_unique<BaseHandle>(sim, sim->base(), u.text);
              },
              {"seed", "realtime"});
    r.addRange("sim",
               [](const Uri& u, hw::DeviceContext& ctx) -> std::unique_ptr<hw::RangeSensor> {
                 const std::string sensor = u.param("sensor", "laser");
                 if (sensor != "laser" && sensor != "sonar")
                   throw InputError("'" + u.text + "': sensor must be laser or sonar, got '" +
                                    sensor + "'");
                 auto sim = simulatorFor(u.text, ctx);
                 return std::make_unique<RangeHandle>(
                     sim, sensor == "laser" ? sim->laser() : sim->sonar(), u.text);
               },
               {"sensor", "seed", "realtime"});
  });
}

}  // namespace sketchnav::sim
