#include "sketchnav/hw/registry.h"

#include <algorithm>
#include <cmath>

#include "sketchnav/core/error.h"
#include "sketchnav/core/input_file.h"
#include "sketchnav/hw/file_cameras.h"
#include "sketchnav/hw/hardware_drivers.h"

namespace sketchnav::hw {
namespace {
template <class Map>
std::vector<std::string> schemesOf(const Map& m) {
  std::vector<std::string> out;
  for (const auto& [k, v] : m) out.push_back(k);
  return out;
}
std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return s.empty() ? "none registered" : s;
}
template <class Map>
auto create(const Map& m, const char* kind, const std::string& text, DeviceContext& ctx,
            std::mutex& mutex) {
  const Uri uri = Uri::parse(text);
  typename Map::mapped_type entry;
  {
    std::lock_guard<std::mutex> lock(mutex);
    auto it = m.find(uri.scheme);
    if (it == m.end())
      throw InputError(std::string("unknown ") + kind + " URI scheme '" + uri.scheme + "' in '" +
                       text + "' (known: " + joined(schemesOf(m)) + ")");
    entry = it->second;
  }
  requireKnownParameters(uri, kind, entry.params);
  return entry.factory(uri, ctx);
}
}  // namespace

Intrinsics Intrinsics::fromFov(int width, int height, double hfov_rad) {
  Intrinsics k;
  k.width = width;
  k.height = height;
  k.fx = k.fy = 0.5 * width / std::tan(0.5 * hfov_rad);
  k.cx = 0.5 * (width - 1);
  k.cy = 0.5 * (height - 1);
  return k;
}

namespace {
// The known parameter the unknown one most likely meant: one it abbreviates ("hfov" for
// "hfov_deg"), else the closest by edit distance ("fsp" for "fps").
std::string closestParameter(const std::string& key, const Registry::Parameters& known) {
  for (const auto& k : known)
    if (!key.empty() && k.size() > key.size() && k.compare(0, key.size(), key) == 0) return k;
  return closestKey(key, known);
}
}  // namespace

void requireKnownParameters(const Uri& uri, const std::string& kind,
                            const Registry::Parameters& known) {
  if (std::find(known.begin(), known.end(), Registry::kAnyParameter) != known.end()) return;
  for (const auto& [key, value] : uri.query) {
    if (std::find(known.begin(), known.end(), key) != known.end()) continue;
    std::string msg = kind + " URI '" + clipForMessage(uri.text, 200) + "': unknown parameter '" +
                      clipForMessage(key) + "'";
    if (known.empty())
      msg += " (" + uri.scheme + ":// takes no parameters)";
    else
      msg += " (did you mean '" + closestParameter(key, known) + "'?)";
    throw InputError(msg);
  }
}

Registry& Registry::instance() {
  static Registry r;
  return r;
}

void Registry::addCamera(const std::string& s, CameraFactory f, Parameters params) {
  std::lock_guard<std::mutex> lock(mutex_);
  cameras_[s] = {std::move(f), std::move(params)};
}
void Registry::addBase(const std::string& s, BaseFactory f, Parameters params) {
  std::lock_guard<std::mutex> lock(mutex_);
  bases_[s] = {std::move(f), std::move(params)};
}
void Registry::addRange(const std::string& s, RangeFactory f, Parameters params) {
  std::lock_guard<std::mutex> lock(mutex_);
  ranges_[s] = {std::move(f), std::move(params)};
}

std::unique_ptr<Camera> Registry::createCamera(const std::string& uri, DeviceContext& ctx) const {
  return create(cameras_, "camera", uri, ctx, mutex_);
}
std::unique_ptr<Base> Registry::createBase(const std::string& uri, DeviceContext& ctx) const {
  return create(bases_, "base", uri, ctx, mutex_);
}
std::unique_ptr<RangeSensor> Registry::createRange(const std::string& uri,
                                                   DeviceContext& ctx) const {
  return create(ranges_, "range sensor", uri, ctx, mutex_);
}

std::vector<std::string> Registry::cameraSchemes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return schemesOf(cameras_);
}
std::vector<std::string> Registry::baseSchemes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return schemesOf(bases_);
}
std::vector<std::string> Registry::rangeSchemes() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return schemesOf(ranges_);
}

void registerBuiltinDrivers() {
  Registry& r = Registry::instance();
  r.addCamera(
      "folder",
      [](const Uri& uri, DeviceContext& ctx) -> std::unique_ptr<Camera> {
        if (uri.path.empty())
          throw InputError("camera URI '" + uri.text + "': expected folder:///absolute/path");
        FolderCameraParams p;
        applyConfig(p, ctx.config, "camera.folder");
        p.fps = uri.paramDouble("fps", p.fps);
        p.loop = uri.paramInt("loop", p.loop ? 1 : 0) != 0;
        p.hfov_deg = uri.paramDouble("hfov_deg", p.hfov_deg);
        p.validate();
        return std::make_unique<FolderCamera>(uri.path, p, uri.text);
      },
      {"fps", "loop", "hfov_deg"});
  r.addCamera("video",
              [](const Uri& uri, DeviceContext&) -> std::unique_ptr<Camera> {
                const std::string source = uri.path.empty() ? uri.authority : uri.path;
                if (source.empty())
                  throw InputError("camera URI '" + uri.text +
                                   "': expected video:///file or video://INDEX");
                return std::make_unique<VideoCamera>(source, uri.paramDouble("hfov_deg", 60.0),
                                                     uri.text);
              },
              {"hfov_deg"});
  registerHardwareDrivers();
}

}  // namespace sketchnav::hw
