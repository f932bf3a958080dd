// World files: JSON read with a small strict reader that names the field on every error and
// rejects unknown keys (typos would otherwise silently fall back to defaults).
#include "sketchnav/sim/world.h"

#include <climits>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <set>

#include "geometry.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/input_file.h"
#include "sketchnav/core/json_io.h"
#include "sketchnav/core/paths.h"
#include "sketchnav/sim/world_check.h"

namespace fs = std::filesystem;

namespace sketchnav::sim {
namespace {

constexpr double kDeg = M_PI / 180.0;

/// One JSON object being read: typed getters mark keys as used; finish() rejects the rest.
class Reader {
 public:
  Reader(const Json& j, std::string path, const std::string& origin)
      : j_(j), path_(std::move(path)), origin_(origin) {
    if (!j.is_object()) fail("", "must be an object");
  }
  std::string field(const std::string& key) const {
    return path_.empty() ? key : (key.empty() ? path_ : path_ + "." + key);
  }
  [[noreturn]] void fail(const std::string& key, const std::string& why) const {
    const std::string f = field(key);
    throw InputError(origin_ + ": " + (f.empty() ? "" : f + ": ") + why);
  }
  bool has(const std::string& key) const { return j_.contains(key); }
  const Json* child(const std::string& key) {
    used_.insert(key);
    auto it = j_.find(key);
    return it == j_.end() ? nullptr : &*it;
  }
  double num(const std::string& key, double def, bool required = false) {
    const Json* v = child(key);
    if (!v) {
      if (required) fail(key, "is required");
      return def;
    }
    if (!v->is_number()) fail(key, "must be a number (got " + clipForMessage(v->dump()) + ")");
    const double x = v->get<double>();
    if (!std::isfinite(x)) fail(key, "must be finite");
    return x;
  }
  int integer(const std::string& key, int def) {
    const Json* v = child(key);
    if (!v) return def;
    if (!v->is_number_integer())
      fail(key, "must be an integer (got " + clipForMessage(v->dump()) + ")");
    // Range-checked as 64 bits first: get<int>() would wrap 4294967297 to 1.
    const bool fits = v->is_number_unsigned()
                          ? v->get<std::uint64_t>() <= static_cast<std::uint64_t>(INT_MAX)
                          : v->get<std::int64_t>() >= INT_MIN && v->get<std::int64_t>() <= INT_MAX;
    if (!fits)
      fail(key, "must be an integer within ±2147483647 (got " + clipForMessage(v->dump()) + ")");
    return v->get<int>();
  }
  bool boolean(const std::string& key, bool def) {
    const Json* v = child(key);
    if (!v) return def;
    if (!v->is_boolean())
      fail(key, "must be true or false (got " + clipForMessage(v->dump()) + ")");
    return v->get<bool>();
  }
  std::string str(const std::string& key, const std::string& def, bool required = false) {
    const Json* v = child(key);
    if (!v) {
      if (required) fail(key, "is required");
      return def;
    }
    if (!v->is_string()) fail(key, "must be a string (got " + clipForMessage(v->dump()) + ")");
    return v->get<std::string>();
  }
  Vec2 vec2(const std::string& key, const Vec2& def, bool required = false) {
    const Json* v = child(key);
    if (!v) {
      if (required) fail(key, "is required");
      return def;
    }
    return toVec2(*v, field(key));
  }
  Vec2 toVec2(const Json& v, const std::string& f) const {
    if (!v.is_array() || v.size() != 2 || !v[0].is_number() || !v[1].is_number())
      throw InputError(origin_ + ": " + f + ": must be [x, y] in metres (got " +
                       clipForMessage(v.dump()) + ")");
    return {v[0].get<double>(), v[1].get<double>()};
  }
  std::vector<Vec2> points(const std::string& key, size_t min_count) {
    const Json* v = child(key);
    if (!v) fail(key, "is required");
    if (!v->is_array()) fail(key, "must be a list of [x, y] points");
    std::vector<Vec2> out;
    for (size_t i = 0; i < v->size(); ++i)
      out.push_back(toVec2((*v)[i], field(key) + "[" + std::to_string(i) + "]"));
    if (out.size() < min_count)
      fail(key, "needs at least " + std::to_string(min_count) + " points");
    return out;
  }
  cv::Scalar color(const std::string& key, const cv::Scalar& def_bgr) {
    const Json* v = child(key);
    if (!v) return def_bgr;
    if (!v->is_array() || v->size() != 3) fail(key, "must be [r, g, b] with values 0..255");
    int rgb[3];
    for (int i = 0; i < 3; ++i) {
      if (!(*v)[i].is_number()) fail(key, "must be [r, g, b] with values 0..255");
      // Checked as a double before the conversion: get<int>() of 1.8e105 is undefined (UBSan,
      // fuzz_world). Fractions truncate as before.
      const double x = (*v)[i].get<double>();
      if (!(x >= 0 && x < 256)) fail(key, "must be [r, g, b] with values 0..255");
      rgb[i] = static_cast<int>(x);
    }
    return cv::Scalar(rgb[2], rgb[1], rgb[0]);
  }
  void finish() const {
    for (auto it = j_.begin(); it != j_.end(); ++it)
      if (!used_.count(it.key())) fail(it.key(), "unknown key");
  }
  void check(bool ok, const std::string& key, const std::string& why) const {
    if (!ok) fail(key, why);
  }
  const std::string& origin() const { return origin_; }

 private:
  const Json& j_;
  std::string path_;
  const std::string& origin_;
  std::set<std::string> used_;
};

template <class F>
void eachItem(Reader& r, const std::string& key, F&& f) {
  const Json* v = r.child(key);
  if (!v) return;
  if (!v->is_array()) r.fail(key, "must be a list");
  for (size_t i = 0; i < v->size(); ++i) {
    Reader item((*v)[i], r.field(key) + "[" + std::to_string(i) + "]", r.origin());
    f(item);
    item.finish();
  }
}

std::string resolveTexture(const std::string& rel, const std::string& base_dir) {
  if (rel.empty()) return {};
  // error_code overloads: a name the OS refuses (too long: fuzz_world) is "not found" (an
  // InputError naming the field at the caller), not a filesystem_error escaping the parser.
  std::error_code ec;
  const auto found = [&ec](const fs::path& f) -> std::string {
    if (!fs::exists(f, ec) || ec) return {};
    const fs::path c = fs::canonical(f, ec);
    return ec ? std::string() : c.string();
  };
  const fs::path p(rel);
  if (p.is_absolute()) return fs::exists(p, ec) && !ec ? p.string() : std::string();
  if (!base_dir.empty())
    if (std::string r = found(fs::path(base_dir) / p); !r.empty()) return r;
  try {
    return found(fs::path(resourceDir()) / p);
  } catch (const RuntimeError&) {
  }
  return {};
}

Json v2(const Vec2& v) {
  return Json::array({v.x(), v.y()});
}
Json rgb(const cv::Scalar& bgr) {
  return Json::array(
      {static_cast<int>(bgr[2]), static_cast<int>(bgr[1]), static_cast<int>(bgr[0])});
}
double deg(double rad) {
  return rad / kDeg;
}

// Walls overlap when they are collinear and share more than 1 cm, or cross in both interiors.
bool wallsOverlap(const Wall& p, const Wall& q) {
  const Vec2 d1 = p.b - p.a, d2 = q.b - q.a;
  const double l1 = d1.norm(), l2 = d2.norm();
  const double den = geom::cross(d1, d2);
  const double tol = 0.01;
  if (std::abs(den) < 1e-9 * l1 * l2) {
    // Parallel: collinear when q's end points lie on p's line.
    if (std::abs(geom::cross(d1, q.a - p.a)) / l1 > tol) return false;
    const Vec2 u = d1 / l1;
    double s0 = (q.a - p.a).dot(u), s1 = (q.b - p.a).dot(u);
    if (s0 > s1) std::swap(s0, s1);
    return std::min(s1, l1) - std::max(s0, 0.0) > tol;
  }
  const double t = geom::cross(q.a - p.a, d2) / den;
  const double u = geom::cross(q.a - p.a, d1) / den;
  return t * l1 > tol && (1 - t) * l1 > tol && u * l2 > tol && (1 - u) * l2 > tol;
}

}  // namespace

hw::Intrinsics CameraSpec::intrinsics() const {
  return hw::Intrinsics::fromFov(width, height, hfov_deg * kDeg);
}

Eigen::Isometry3d CameraSpec::rMc() const {
  Eigen::Matrix3d r0;  // optical axes (columns) in the robot frame
  r0 << 0, 0, 1,       //
      -1, 0, 0,        //
      0, -1, 0;
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  m.translation() = Eigen::Vector3d(x, y, z);
  m.linear() = (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(-pitch, Eigen::Vector3d::UnitY()))
                   .toRotationMatrix() *
               r0;
  return m;
}

const Landmark* World::findLandmark(const std::string& id) const {
  for (const auto& l : landmarks)
    if (l.id == id) return &l;
  return nullptr;
}

World worldFromJson(const Json& j, const std::string& origin, const std::string& base_dir) {
  World w;
  w.source = origin;
  Reader r(j, "", origin);
  w.name = r.str("name", fs::path(origin).stem().stem().string());
  r.str("description", "");  // free text, ignored
  w.floor = r.points("floor", 3);
  double area = 0;
  for (size_t i = 0; i < w.floor.size(); ++i)
    area += geom::cross(w.floor[i], w.floor[(i + 1) % w.floor.size()]);
  r.check(std::abs(area) > 1e-6, "floor", "polygon has no area");
  auto onFloor = [&](const Vec2& p) { return geom::pointInPolygon(p, w.floor); };

  eachItem(r, "walls", [&](Reader& it) {
    Wall wall;
    wall.name = it.str("name", it.field(""));
    wall.a = it.vec2("from", {}, true);
    wall.b = it.vec2("to", {}, true);
    wall.thickness = it.num("thickness", wall.thickness);
    wall.height = it.num("height", wall.height);
    it.check((wall.b - wall.a).norm() > 1e-3, "to", "wall has zero length");
    it.check(wall.thickness > 0, "thickness", "must be > 0");
    it.check(wall.height > 0, "height", "must be > 0");
    for (size_t k = 0; k < w.walls.size(); ++k)
      if (wallsOverlap(w.walls[k], wall))
        it.fail("", "overlaps walls[" + std::to_string(k) + "] (" + w.walls[k].name + ")");
    w.walls.push_back(wall);
  });
  eachItem(r, "doors", [&](Reader& it) {
    Door d;
    d.name = it.str("name", it.field(""));
    d.a = it.vec2("from", {}, true);
    d.b = it.vec2("to", {}, true);
    d.open = it.boolean("open", true);
    it.check((d.b - d.a).norm() > 0.1, "to", "door narrower than 0.1 m");
    w.doors.push_back(d);
  });
  eachItem(r, "obstacles", [&](Reader& it) {
    Obstacle o;
    o.name = it.str("name", it.field(""));
    const std::string shape = it.str("shape", "box");
    if (shape == "box") {
      o.shape = Obstacle::Shape::Box;
      const Vec2 size = it.vec2("size", {}, true);
      o.size_x = size.x();
      o.size_y = size.y();
      it.check(o.size_x > 0 && o.size_y > 0, "size", "must be positive");
    } else if (shape == "cylinder") {
      o.shape = Obstacle::Shape::Cylinder;
      o.radius = it.num("radius", 0, true);
      it.check(o.radius > 0, "radius", "must be > 0");
    } else {
      it.fail("shape", "must be \"box\" or \"cylinder\" (got \"" + shape + "\")");
    }
    o.centre = it.vec2("centre", {}, true);
    o.yaw = it.num("yaw_deg", 0) * kDeg;
    o.height = it.num("height", o.height);
    o.color = it.color("color", o.color);
    it.check(o.height > 0, "height", "must be > 0");
    it.check(onFloor(o.centre), "centre", "is outside the floor polygon");
    w.obstacles.push_back(o);
  });
  std::set<std::string> ids;
  eachItem(r, "landmarks", [&](Reader& it) {
    Landmark l;
    l.id = it.str("id", "", true);
    it.check(!l.id.empty(), "id", "must not be empty");
    it.check(ids.insert(l.id).second, "id", "duplicate landmark id '" + l.id + "'");
    l.class_name = it.str("class", "", true);
    it.check(!l.class_name.empty(), "class", "must not be empty");
    const std::string tex = it.str("texture", "", true);
    l.texture = resolveTexture(tex, base_dir);
    it.check(!l.texture.empty(), "texture", "file '" + clipForMessage(tex) + "' not found");
    it.check(l.texture.empty() || fs::is_regular_file(l.texture), "texture",
             "'" + clipForMessage(tex) + "' is not a regular file");
    const std::string back = it.str("back_texture", "");
    l.back_texture = resolveTexture(back, base_dir);
    it.check(back.empty() || !l.back_texture.empty(), "back_texture",
             "file '" + clipForMessage(back) + "' not found");
    it.check(l.back_texture.empty() || fs::is_regular_file(l.back_texture), "back_texture",
             "'" + clipForMessage(back) + "' is not a regular file");
    l.position = it.vec2("position", {}, true);
    l.yaw = it.num("yaw_deg", 0, true) * kDeg;
    l.width = it.num("width", l.width);
    l.height = it.num("height", l.height);
    l.elevation = it.num("elevation", l.elevation);
    it.check(l.width > 0 && l.width < 10, "width", "must be in (0, 10) m");
    it.check(l.height > 0 && l.height < 10, "height", "must be in (0, 10) m");
    it.check(l.elevation - 0.5 * l.height >= -1e-6, "elevation",
             "puts the bottom of the photo below the floor");
    it.check(onFloor(l.position), "position", "is outside the floor polygon");
    w.landmarks.push_back(l);
  });
  eachItem(r, "pedestrians", [&](Reader& it) {
    Pedestrian p;
    p.name = it.str("name", it.field(""));
    p.path = it.points("path", 2);
    p.speed = it.num("speed", p.speed);
    p.loop = it.boolean("loop", p.loop);
    p.phase = it.num("phase", p.phase);
    p.radius = it.num("radius", p.radius);
    p.height = it.num("height", p.height);
    p.color = it.color("color", p.color);
    it.check(p.speed >= 0 && p.speed < 5, "speed", "must be in [0, 5) m/s");
    it.check(p.radius > 0, "radius", "must be > 0");
    it.check(p.height > 0, "height", "must be > 0");
    double len = 0;
    for (size_t k = 1; k < p.path.size(); ++k) len += (p.path[k] - p.path[k - 1]).norm();
    it.check(len > 1e-3, "path", "has zero length");
    w.pedestrians.push_back(p);
  });
  eachItem(r, "regions", [&](Reader& it) {
    Region g;
    g.name = it.str("name", "", true);
    g.polygon = it.points("polygon", 3);
    w.regions.push_back(g);
  });
  {
    const Json* s = r.child("start");
    if (!s) r.fail("start", "is required");
    Reader it(*s, "start", origin);
    w.start.x = it.num("x", 0, true);
    w.start.y = it.num("y", 0, true);
    w.start.theta = it.num("yaw_deg", 0) * kDeg;
    it.finish();
    it.check(onFloor({w.start.x, w.start.y}), "", "is outside the floor polygon");
  }
  {
    const Json* s = r.child("goal");
    if (!s) r.fail("goal", "is required");
    Reader it(*s, "goal", origin);
    w.goal.centre = {it.num("x", 0, true), it.num("y", 0, true)};
    w.goal.radius = it.num("radius", w.goal.radius);
    it.finish();
    it.check(w.goal.radius > 0, "radius", "must be > 0");
    it.check(onFloor(w.goal.centre), "", "is outside the floor polygon");
  }
  if (const Json* s = r.child("lighting")) {
    Reader it(*s, "lighting", origin);
    auto& l = w.lighting;
    l.brightness = it.num("brightness", l.brightness);
    l.variation = it.num("variation", l.variation);
    l.period = it.num("period", l.period);
    it.finish();
    it.check(l.brightness > 0 && l.brightness < 5, "brightness", "must be in (0, 5)");
    it.check(l.variation >= 0 && l.variation < 1, "variation", "must be in [0, 1)");
    it.check(l.period > 0, "period", "must be > 0");
  }
  if (const Json* s = r.child("camera")) {
    Reader it(*s, "camera", origin);
    auto& c = w.camera;
    c.width = it.integer("width", c.width);
    c.height = it.integer("height", c.height);
    c.hfov_deg = it.num("hfov_deg", c.hfov_deg);
    c.x = it.num("x", c.x);
    c.y = it.num("y", c.y);
    c.z = it.num("z", c.z);
    c.yaw = it.num("yaw_deg", 0) * kDeg;
    c.pitch = it.num("pitch_deg", c.pitch / kDeg) * kDeg;
    c.near = it.num("near", c.near);
    c.far = it.num("far", c.far);
    it.finish();
    it.check(c.width >= 16 && c.width <= 4096, "width", "must be in [16, 4096]");
    it.check(c.height >= 16 && c.height <= 4096, "height", "must be in [16, 4096]");
    it.check(c.hfov_deg > 1 && c.hfov_deg < 170, "hfov_deg", "must be in (1, 170)");
    it.check(c.z > 0, "z", "camera must be above the floor");
    it.check(std::abs(c.pitch) < 80 * kDeg, "pitch_deg", "must be in (-80, 80)");
    it.check(c.near > 0, "near", "must be > 0");
    it.check(c.far > c.near, "far", "must be > near");
  }
  if (const Json* s = r.child("laser")) {
    Reader it(*s, "laser", origin);
    auto& l = w.laser;
    l.enabled = it.boolean("enabled", l.enabled);
    l.x = it.num("x", l.x);
    l.y = it.num("y", l.y);
    l.z = it.num("z", l.z);
    l.yaw = it.num("yaw_deg", 0) * kDeg;
    l.fov_deg = it.num("fov_deg", l.fov_deg);
    l.resolution_deg = it.num("resolution_deg", l.resolution_deg);
    l.min_range = it.num("min_range", l.min_range);
    l.max_range = it.num("max_range", l.max_range);
    l.noise_std = it.num("noise_std", l.noise_std);
    l.rate_hz = it.num("rate_hz", l.rate_hz);
    it.finish();
    it.check(l.fov_deg > 0 && l.fov_deg <= 360, "fov_deg", "must be in (0, 360]");
    it.check(l.resolution_deg >= 0.05 && l.resolution_deg <= l.fov_deg, "resolution_deg",
             "must be in [0.05, fov_deg]");
    it.check(l.min_range >= 0, "min_range", "must be >= 0");
    it.check(l.max_range > l.min_range, "max_range", "must be > min_range");
    it.check(l.noise_std >= 0, "noise_std", "must be >= 0");
    it.check(l.rate_hz > 0 && l.rate_hz <= kMaxRangeRateHz, "rate_hz", "must be in (0, 100] Hz");
    static_assert(kMaxRangeRateHz == 100.0, "the message states the bound");
  }
  bool sonar_beams_given = false;
  if (const Json* s = r.child("sonar")) {
    Reader it(*s, "sonar", origin);
    auto& so = w.sonar;
    so.enabled = it.boolean("enabled", so.enabled);
    if (it.has("beams")) {
      sonar_beams_given = true;
      eachItem(it, "beams", [&](Reader& b) {
        SonarBeam beam;
        beam.x = b.num("x", 0);
        beam.y = b.num("y", 0);
        beam.yaw = b.num("yaw_deg", 0, true) * kDeg;
        so.beams.push_back(beam);
      });
    }
    so.z = it.num("z", so.z);
    so.beam_width_deg = it.num("beam_width_deg", so.beam_width_deg);
    so.min_range = it.num("min_range", so.min_range);
    so.max_range = it.num("max_range", so.max_range);
    so.noise_std = it.num("noise_std", so.noise_std);
    so.rate_hz = it.num("rate_hz", so.rate_hz);
    it.finish();
    it.check(so.beam_width_deg > 0 && so.beam_width_deg < 180, "beam_width_deg",
             "must be in (0, 180)");
    it.check(so.min_range >= 0, "min_range", "must be >= 0");
    it.check(so.max_range > so.min_range, "max_range", "must be > min_range");
    it.check(so.noise_std >= 0, "noise_std", "must be >= 0");
    it.check(so.rate_hz > 0 && so.rate_hz <= kMaxRangeRateHz, "rate_hz", "must be in (0, 100] Hz");
    static_assert(kMaxRangeRateHz == 100.0, "the message states the bound");
  }
  if (const Json* s = r.child("robot")) {
    Reader it(*s, "robot", origin);
    w.robot.radius = it.num("radius", w.robot.radius);
    it.finish();
    it.check(w.robot.radius > 0.02 && w.robot.radius < 2, "radius", "must be in (0.02, 2) m");
  }
  r.finish();
  if (!sonar_beams_given && w.sonar.beams.empty()) {
    // Default ring: 8 transducers on the front half of the body, every 25 degrees.
    const double rr = w.robot.radius;
    for (int k = -3; k <= 4; ++k) {
      const double a = (k - 0.5) * 25.0 * kDeg;
      w.sonar.beams.push_back({rr * std::cos(a), rr * std::sin(a), a});
    }
  }
  // The robot must start free: overlapping a solid at t = 0 is a broken world, not a crash.
  const geom::Solids solids = geom::buildSolids(w);
  const Vec2 s(w.start.x, w.start.y);
  for (const auto& p : solids.polys)
    if (geom::signedDistance(s, p) < w.robot.radius)
      r.fail("start",
             "robot (radius " + std::to_string(w.robot.radius) + " m) overlaps '" + p.name + "'");
  for (const auto& c : solids.circles)
    if ((s - c.c).norm() - c.r < w.robot.radius) r.fail("start", "robot overlaps '" + c.name + "'");
  // Plausibility (world_check.h): a photo hidden in a wall, furniture standing in one.
  // Warnings are left to the caller (checkWorldGeometry again) to report.
  for (const auto& issue : checkWorldGeometry(w))
    if (issue.isError()) throw InputError(issue.text(origin));
  return w;
}

World loadWorld(const std::string& path) {
  const Json j = parseJsonFile(path, "world file");
  return worldFromJson(j, path, fs::path(path).parent_path().string());
}

World labWorld() {
  return loadWorld(resourcePath("worlds/lab.world.json"));
}

World loadWorldByName(const std::string& name) {
  if (name == "lab") return labWorld();
  if (name.find('/') == std::string::npos && name.find('.') == std::string::npos) {
    std::string p;
    try {
      p = resourcePath("worlds/" + name + ".world.json");
    } catch (const RuntimeError&) {
      throw InputError("world '" + name + "': no such built-in world (share/worlds/" + name +
                       ".world.json) and not a file path");
    }
    return loadWorld(p);
  }
  return loadWorld(name);
}

Json worldToJson(const World& w) {
  Json j;
  j["name"] = w.name;
  j["floor"] = Json::array();
  for (const auto& p : w.floor) j["floor"].push_back(v2(p));
  j["walls"] = Json::array();
  for (const auto& x : w.walls)
    j["walls"].push_back({{"name", x.name},
                          {"from", v2(x.a)},
                          {"to", v2(x.b)},
                          {"thickness", x.thickness},
                          {"height", x.height}});
  j["doors"] = Json::array();
  for (const auto& x : w.doors)
    j["doors"].push_back({{"name", x.name}, {"from", v2(x.a)}, {"to", v2(x.b)}, {"open", x.open}});
  j["obstacles"] = Json::array();
  for (const auto& o : w.obstacles) {
    Json oj = {
        {"name", o.name}, {"centre", v2(o.centre)}, {"height", o.height}, {"color", rgb(o.color)}};
    if (o.shape == Obstacle::Shape::Box) {
      oj["shape"] = "box";
      oj["size"] = Json::array({o.size_x, o.size_y});
      oj["yaw_deg"] = deg(o.yaw);
    } else {
      oj["shape"] = "cylinder";
      oj["radius"] = o.radius;
    }
    j["obstacles"].push_back(oj);
  }
  j["landmarks"] = Json::array();
  for (const auto& l : w.landmarks) {
    Json lj = {{"id", l.id},
               {"class", l.class_name},
               {"texture", l.texture},
               {"position", v2(l.position)},
               {"yaw_deg", deg(l.yaw)},
               {"width", l.width},
               {"height", l.height},
               {"elevation", l.elevation}};
    if (!l.back_texture.empty()) lj["back_texture"] = l.back_texture;
    j["landmarks"].push_back(lj);
  }
  j["pedestrians"] = Json::array();
  for (const auto& p : w.pedestrians) {
    Json path = Json::array();
    for (const auto& q : p.path) path.push_back(v2(q));
    j["pedestrians"].push_back({{"name", p.name},
                                {"path", path},
                                {"speed", p.speed},
                                {"loop", p.loop},
                                {"phase", p.phase},
                                {"radius", p.radius},
                                {"height", p.height},
                                {"color", rgb(p.color)}});
  }
  j["regions"] = Json::array();
  for (const auto& g : w.regions) {
    Json poly = Json::array();
    for (const auto& q : g.polygon) poly.push_back(v2(q));
    j["regions"].push_back({{"name", g.name}, {"polygon", poly}});
  }
  j["start"] = {{"x", w.start.x}, {"y", w.start.y}, {"yaw_deg", deg(w.start.theta)}};
  j["goal"] = {{"x", w.goal.centre.x()}, {"y", w.goal.centre.y()}, {"radius", w.goal.radius}};
  j["lighting"] = {{"brightness", w.lighting.brightness},
                   {"variation", w.lighting.variation},
                   {"period", w.lighting.period}};
  const auto& c = w.camera;
  j["camera"] = {{"width", c.width},
                 {"height", c.height},
                 {"hfov_deg", c.hfov_deg},
                 {"x", c.x},
                 {"y", c.y},
                 {"z", c.z},
                 {"yaw_deg", deg(c.yaw)},
                 {"pitch_deg", deg(c.pitch)},
                 {"near", c.near},
                 {"far", c.far}};
  const auto& l = w.laser;
  j["laser"] = {{"enabled", l.enabled},
                {"x", l.x},
                {"y", l.y},
                {"z", l.z},
                {"yaw_deg", deg(l.yaw)},
                {"fov_deg", l.fov_deg},
                {"resolution_deg", l.resolution_deg},
                {"min_range", l.min_range},
                {"max_range", l.max_range},
                {"noise_std", l.noise_std},
                {"rate_hz", l.rate_hz}};
  Json beams = Json::array();
  for (const auto& b : w.sonar.beams)
    beams.push_back({{"x", b.x}, {"y", b.y}, {"yaw_deg", deg(b.yaw)}});
  const auto& s = w.sonar;
  j["sonar"] = {{"enabled", s.enabled},
                {"beams", beams},
                {"z", s.z},
                {"beam_width_deg", s.beam_width_deg},
                {"min_range", s.min_range},
                {"max_range", s.max_range},
                {"noise_std", s.noise_std},
                {"rate_hz", s.rate_hz}};
  j["robot"] = {{"radius", w.robot.radius}};
  return j;
}

}  // namespace sketchnav::sim
