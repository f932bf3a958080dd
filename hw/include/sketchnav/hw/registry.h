#pragma once
// Devices are created from URIs through a registry keyed by scheme, not a type switch:
//   auto cam = hw::Registry::instance().createCamera("folder:///data/frames?fps=10", ctx);
// Drivers register themselves from registerBuiltinDrivers() (hw) and sim::registerDrivers()
// (hw/sim); the command calls both once at start-up.
#include <any>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "sketchnav/core/config.h"
#include "sketchnav/core/uri.h"
#include "sketchnav/hw/clock.h"
#include "sketchnav/hw/devices.h"

namespace sketchnav::hw {

/// What factories get besides the URI: the run's clock, its config, and a place where devices
/// created from the same URI authority share state (e.g. the simulator's world behind
/// sim://lab is shared by its camera, base and range sensors).
struct DeviceContext {
  std::shared_ptr<Clock> clock;  // a factory may install its own (the simulator does)
  Config config;
  std::map<std::string, std::any> shared;
};

class Registry {
 public:
  using CameraFactory = std::function<std::unique_ptr<Camera>(const Uri&, DeviceContext&)>;
  using BaseFactory = std::function<std::unique_ptr<Base>(const Uri&, DeviceContext&)>;
  using RangeFactory = std::function<std::unique_ptr<RangeSensor>(const Uri&, DeviceContext&)>;

  static Registry& instance();

  void addCamera(const std::string& scheme, CameraFactory f);
  void addBase(const std::string& scheme, BaseFactory f);
  void addRange(const std::string& scheme, RangeFactory f);

  /// Throw InputError naming the URI and the known schemes when the scheme is unknown.
  std::unique_ptr<Camera> createCamera(const std::string& uri, DeviceContext& ctx) const;
  std::unique_ptr<Base> createBase(const std::string& uri, DeviceContext& ctx) const;
  std::unique_ptr<RangeSensor> createRange(const std::string& uri, DeviceContext& ctx) const;

  std::vector<std::string> cameraSchemes() const;
  std::vector<std::string> baseSchemes() const;
  std::vector<std::string> rangeSchemes() const;

 private:
  mutable std::mutex mutex_;
  std::map<std::string, CameraFactory> cameras_;
  std::map<std::string, BaseFactory> bases_;
  std::map<std::string, RangeFactory> ranges_;
};

/// Registers folder:// and video:// cameras (and, as they land, the hardware drivers).
/// Idempotent.
void registerBuiltinDrivers();

}  // namespace sketchnav::hw
