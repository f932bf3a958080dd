#include "sketchnav/hw/registry.h"

#include <algorithm>
#include <cmath>

#include "sketchnav/core/error.h"
#include "sketchnav/core/input_file.h"

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

}  // namespace sketchnav::hw
