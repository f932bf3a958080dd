#pragma once
// Devices are created from URIs through a registry keyed by scheme, not a type switch:
//   auto cam = hw::Registry::instance().createCamera("folder:///data/frames?fps=10", ctx);
// The registry knows no driver: drivers::registerDrivers() (hw/drivers: folder, video, aravis,
// dani, laser, rawlog) and sim::registerDrivers() (hw/sim: sim) add their schemes; a program
// calls both once at start-up. Linking sketchnav::hw alone links no vendor library.
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

  /// The query parameters a scheme's URIs may carry (e.g. {"fps", "loop", "hfov_deg"} for
  /// folder://); any other is refused before the factory runs, like an unknown setting.
  /// kAnyParameter in the list lets every other key through (laser://, whose query is the
  /// driver's own configuration).
  using Parameters = std::vector<std::string>;
  static constexpr const char* kAnyParameter = "*";

  void addCamera(const std::string& scheme, CameraFactory f, Parameters params = {});
  void addBase(const std::string& scheme, BaseFactory f, Parameters params = {});
  void addRange(const std::string& scheme, RangeFactory f, Parameters params = {});

  /// Throw InputError naming the URI and the known schemes when the scheme is unknown, and
  /// naming the parameter and the closest known one when the query holds a parameter the
  /// scheme does not take: "camera URI 'folder:///x?fsp=10': unknown parameter 'fsp' (did
  /// you mean 'fps'?)".
  std::unique_ptr<Camera> createCamera(const std::string& uri, DeviceContext& ctx) const;
  std::unique_ptr<Base> createBase(const std::string& uri, DeviceContext& ctx) const;
  std::unique_ptr<RangeSensor> createRange(const std::string& uri, DeviceContext& ctx) const;

  std::vector<std::string> cameraSchemes() const;
  std::vector<std::string> baseSchemes() const;
  std::vector<std::string> rangeSchemes() const;

 private:
  mutable std::mutex mutex_;
  template <class F>
  struct Entry {
    F factory;
    Parameters params;
  };
  std::map<std::string, Entry<CameraFactory>> cameras_;
  std::map<std::string, Entry<BaseFactory>> bases_;
  std::map<std::string, Entry<RangeFactory>> ranges_;
};

/// Throws InputError "<kind> URI '<uri>': unknown parameter 'k' (did you mean 'known'?)" for
/// the first query key not in `known` (see Registry::Parameters).
void requireKnownParameters(const Uri& uri, const std::string& kind,
                            const Registry::Parameters& known);

}  // namespace sketchnav::hw
