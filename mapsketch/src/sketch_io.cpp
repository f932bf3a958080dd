#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "geometry.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/image_file.h"
#include "sketchnav/core/input_file.h"
#include "sketchnav/core/json_io.h"
#include "sketchnav/mapsketch/io.h"

namespace fs = std::filesystem;

namespace sketchnav::mapsketch {
namespace {

const char* typeName(const Json& v) {
  if (v.is_number()) return "a number";
  if (v.is_string()) return "a string";
  if (v.is_boolean()) return "a boolean";
  if (v.is_null()) return "null";
  if (v.is_array()) return "an array";
  return "an object";
}

// A goal place as the file writes it (the sketch's "goal_place", and the route's).
Json goalPlaceJson(const GoalPlace& g) {
  return {{"kind", g.kind == GoalPlace::Kind::Doorway ? "doorway" : "point"},
          {"standoff_m", g.standoff_m}};
}

// Every reader names the field with its JSON path so a user can find it in the file.
class Reader {
 public:
  explicit Reader(std::string origin) : origin_(std::move(origin)) {}

  [[noreturn]] void fail(const std::string& field, const std::string& why) const {
    throw InputError(origin_ + ": " + field + ": " + why);
  }

  const Json& member(const Json& obj, const std::string& field, const std::string& key) const {
    auto it = obj.find(key);
    if (it == obj.end()) fail(field.empty() ? key : field + "." + key, "missing");
    return *it;
  }

  double number(const Json& v, const std::string& field) const {
    if (!v.is_number()) fail(field, std::string("expected a number, got ") + typeName(v));
    const double d = v.get<double>();
    if (!std::isfinite(d)) fail(field, "not a finite number");
    return d;
  }

  std::string string(const Json& v, const std::string& field) const {
    if (!v.is_string()) fail(field, std::string("expected a string, got ") + typeName(v));
    return v.get<std::string>();
  }

  void object(const Json& v, const std::string& field) const {
    if (!v.is_object()) fail(field, std::string("expected an object, got ") + typeName(v));
  }

  void array(const Json& v, const std::string& field) const {
    if (!v.is_array()) fail(field, std::string("expected an array, got ") + typeName(v));
  }

  Eigen::Vector2d point(const Json& v, const std::string& field) const {
    // [x, y] is the compact form used for the (long) path; {"x":..,"y":..} is accepted too.
    if (v.is_array()) {
      if (v.size() != 2)
        fail(field, "expected [x, y], got " + std::to_string(v.size()) + " values");
      return {number(v[0], field + "[0]"), number(v[1], field + "[1]")};
    }
    if (v.is_object())
      return {number(member(v, field, "x"), field + ".x"),
              number(member(v, field, "y"), field + ".y")};
    fail(field, std::string("expected a point [x, y], got ") + typeName(v));
  }

  void onlyKeys(const Json& obj, const std::string& field,
                std::initializer_list<const char*> keys) const {
    for (auto it = obj.begin(); it != obj.end(); ++it) {
      bool known = false;
      for (const char* k : keys) known = known || it.key() == k;
      if (!known) {
        std::string list;
        for (const char* k : keys) list += std::string(list.empty() ? "" : ", ") + k;
        fail(field.empty() ? it.key() : field + "." + it.key(),
             "unknown field (expected one of: " + list + ")");
      }
    }
  }

 private:
  std::string origin_;
};

std::string fmt(double v) {
  std::ostringstream o;
  o << v;
  return o.str();
}

}  // namespace

Sketch sketchFromJson(const Json& j, const std::string& origin) {
  Reader r(origin);
  r.object(j, "(top level)");
  Sketch s;
  const Json& fmt_v = r.member(j, "", "format");
  if (!fmt_v.is_number_integer())
    r.fail("format", std::string("expected an integer, got ") + typeName(fmt_v));
  s.format = fmt_v.get<int>();
  if (s.format < 1) r.fail("format", "must be >= 1, got " + std::to_string(s.format));
  if (s.format > kSketchFormat)
    r.fail("format", "version " + std::to_string(s.format) +
                         " was written by a newer sketchnav (this one reads up to " +
                         std::to_string(kSketchFormat) + ")");
  r.onlyKeys(j, "",
             {"format", "name", "notes", "canvas", "landmarks", "path", "start", "goal",
              "goal_place", "floor_plan"});
  if (j.contains("name")) s.name = r.string(j["name"], "name");
  if (j.contains("notes")) s.notes = r.string(j["notes"], "notes");

  const Json& canvas = r.member(j, "", "canvas");
  r.object(canvas, "canvas");
  r.onlyKeys(canvas, "canvas", {"width", "height"});
  s.canvas_width = r.number(r.member(canvas, "canvas", "width"), "canvas.width");
  s.canvas_height = r.number(r.member(canvas, "canvas", "height"), "canvas.height");

  const Json& lms = r.member(j, "", "landmarks");
  r.array(lms, "landmarks");
  if (lms.size() > kMaxLandmarks)
    r.fail("landmarks",
           "too many (" + std::to_string(lms.size()) + " > " + std::to_string(kMaxLandmarks) + ")");
  for (size_t i = 0; i < lms.size(); ++i) {
    const std::string f = "landmarks[" + std::to_string(i) + "]";
    const Json& l = lms[i];
    r.object(l, f);
    r.onlyKeys(l, f, {"id", "class", "rect", "distance_m"});
    SketchLandmark lm;
    lm.id = r.string(r.member(l, f, "id"), f + ".id");
    lm.class_name = r.string(r.member(l, f, "class"), f + ".class");
    const Json& rect = r.member(l, f, "rect");
    r.object(rect, f + ".rect");
    r.onlyKeys(rect, f + ".rect", {"x", "y", "w", "h"});
    lm.rect.x = r.number(r.member(rect, f + ".rect", "x"), f + ".rect.x");
    lm.rect.y = r.number(r.member(rect, f + ".rect", "y"), f + ".rect.y");
    lm.rect.w = r.number(r.member(rect, f + ".rect", "w"), f + ".rect.w");
    lm.rect.h = r.number(r.member(rect, f + ".rect", "h"), f + ".rect.h");
    lm.distance_m = r.number(r.member(l, f, "distance_m"), f + ".distance_m");
    s.landmarks.push_back(std::move(lm));
  }

  const Json& path = r.member(j, "", "path");
  r.array(path, "path");
  if (path.size() > kMaxPathPoints)
    r.fail("path", "too many points (" + std::to_string(path.size()) + " > " +
                       std::to_string(kMaxPathPoints) + ")");
  s.path.reserve(path.size());
  for (size_t i = 0; i < path.size(); ++i)
    s.path.push_back(r.point(path[i], "path[" + std::to_string(i) + "]"));
  s.start = r.point(r.member(j, "", "start"), "start");
  s.goal = r.point(r.member(j, "", "goal"), "goal");
  if (j.contains("goal_place")) {
    const Json& g = j["goal_place"];
    r.object(g, "goal_place");
    r.onlyKeys(g, "goal_place", {"kind", "standoff_m"});
    const std::string kind = r.string(r.member(g, "goal_place", "kind"), "goal_place.kind");
    if (kind == "doorway")
      s.goal_place.kind = GoalPlace::Kind::Doorway;
    else if (kind == "point")
      s.goal_place.kind = GoalPlace::Kind::Point;
    else
      r.fail("goal_place.kind", "'" + kind + "' is not one of: point, doorway");
    if (g.contains("standoff_m"))
      s.goal_place.standoff_m = r.number(g["standoff_m"], "goal_place.standoff_m");
  }
  if (j.contains("floor_plan")) {
    const Json& fp = j["floor_plan"];
    r.object(fp, "floor_plan");
    r.onlyKeys(fp, "floor_plan", {"image", "rect", "m_per_px", "scale_points"});
    FloorPlan plan;
    const Json& image = r.member(fp, "floor_plan", "image");
    if (image.is_string() && image.get_ref<const std::string&>().size() > kMaxFloorPlanBytes)
      r.fail("floor_plan.image", "too large (" +
                                     std::to_string(image.get_ref<const std::string&>().size()) +
                                     " bytes > " + std::to_string(kMaxFloorPlanBytes) + ")");
    plan.image = r.string(image, "floor_plan.image");
    const Json& rect = r.member(fp, "floor_plan", "rect");
    r.object(rect, "floor_plan.rect");
    r.onlyKeys(rect, "floor_plan.rect", {"x", "y", "w", "h"});
    plan.rect.x = r.number(r.member(rect, "floor_plan.rect", "x"), "floor_plan.rect.x");
    plan.rect.y = r.number(r.member(rect, "floor_plan.rect", "y"), "floor_plan.rect.y");
    plan.rect.w = r.number(r.member(rect, "floor_plan.rect", "w"), "floor_plan.rect.w");
    plan.rect.h = r.number(r.member(rect, "floor_plan.rect", "h"), "floor_plan.rect.h");
    if (fp.contains("m_per_px")) {
      plan.m_per_px = r.number(fp["m_per_px"], "floor_plan.m_per_px");
      if (plan.m_per_px <= 0)
        r.fail("floor_plan.m_per_px",
               "= " + fmt(plan.m_per_px) + ": must be positive (leave it out for no scale)");
    }
    if (fp.contains("scale_points")) {
      const Json& sp = fp["scale_points"];
      r.array(sp, "floor_plan.scale_points");
      if (sp.size() != 2)
        r.fail("floor_plan.scale_points", "expected 2 points, got " + std::to_string(sp.size()));
      for (size_t i = 0; i < sp.size(); ++i)
        plan.scale_points.push_back(
            r.point(sp[i], "floor_plan.scale_points[" + std::to_string(i) + "]"));
    }
    s.floor_plan = std::move(plan);
  }
  validateSketch(s, origin);
  return s;
}

void validateSketch(const Sketch& s, const std::string& origin) {
  auto fail = [&](const std::string& field, const std::string& why) {
    throw InputError(origin + ": " + field + ": " + why);
  };
  auto finite = [](const Eigen::Vector2d& p) {
    return std::isfinite(p.x()) && std::isfinite(p.y());
  };
  if (s.format < 1 || s.format > kSketchFormat)
    fail("format", "unsupported version " + std::to_string(s.format));
  for (auto [v, name] :
       {std::pair{s.canvas_width, "canvas.width"}, std::pair{s.canvas_height, "canvas.height"}}) {
    if (!std::isfinite(v) || v < 10 || v > kMaxCanvasPx)
      fail(name, "= " + fmt(v) + ": must be between 10 and " + fmt(kMaxCanvasPx) + " px");
  }
  // Points may stray a little outside the canvas (a mouse drag past the edge), not far.
  const double mx = 0.1 * s.canvas_width, my = 0.1 * s.canvas_height;
  auto inside = [&](const Eigen::Vector2d& p) {
    return p.x() >= -mx && p.x() <= s.canvas_width + mx && p.y() >= -my &&
           p.y() <= s.canvas_height + my;
  };
  auto ptxt = [](const Eigen::Vector2d& p) { return "(" + fmt(p.x()) + ", " + fmt(p.y()) + ")"; };

  std::set<std::string> ids;
  for (size_t i = 0; i < s.landmarks.size(); ++i) {
    const auto& l = s.landmarks[i];
    const std::string f = "landmarks[" + std::to_string(i) + "]";
    if (l.id.empty()) fail(f + ".id", "must not be empty");
    if (l.id.size() > 64) fail(f + ".id", "longer than 64 characters");
    if (!ids.insert(l.id).second) fail(f + ".id", "duplicate id '" + l.id + "'");
    if (l.class_name.empty()) fail(f + ".class", "must not be empty");
    const CanvasRect& r = l.rect;
    for (double v : {r.x, r.y, r.w, r.h})
      if (!std::isfinite(v)) fail(f + ".rect", "not a finite number");
    if (r.w <= 0 || r.h <= 0)
      fail(f + ".rect", "width and height must be positive, got " + fmt(r.w) + " x " + fmt(r.h));
    if (!inside(r.centre()))
      fail(f + ".rect", "centre " + ptxt(r.centre()) + " is outside the canvas");
    if (!std::isfinite(l.distance_m)) fail(f + ".distance_m", "not a finite number");
    if (l.distance_m <= 0) fail(f + ".distance_m", "= " + fmt(l.distance_m) + ": must be positive");
    if (l.distance_m > kMaxDistanceM)
      fail(f + ".distance_m",
           "= " + fmt(l.distance_m) + ": absurd (more than " + fmt(kMaxDistanceM) + " m)");
  }
  if (s.landmarks.empty())
    fail("landmarks", "at least one landmark is needed (its distance fixes the scale)");
  if (s.path.size() < 2)
    fail("path", "needs at least 2 points, got " + std::to_string(s.path.size()));
  if (s.path.size() > kMaxPathPoints) fail("path", "too many points");
  for (size_t i = 0; i < s.path.size(); ++i) {
    if (!finite(s.path[i])) fail("path[" + std::to_string(i) + "]", "not a finite number");
    if (!inside(s.path[i]))
      fail("path[" + std::to_string(i) + "]", ptxt(s.path[i]) + " is outside the canvas");
  }
  if (detail::polylineLength(s.path) < 1.0) fail("path", "has zero length");
  for (auto [p, name] : {std::pair{s.start, "start"}, std::pair{s.goal, "goal"}}) {
    if (!finite(p)) fail(name, "not a finite number");
    if (!inside(p)) fail(name, ptxt(p) + " is outside the canvas");
  }
  const double standoff = s.goal_place.standoff_m;
  if (!std::isfinite(standoff) || standoff < 0 || standoff > 3)
    fail("goal_place.standoff_m", "= " + fmt(standoff) + ": must be in [0, 3] m");
  if (s.floor_plan) {
    const FloorPlan& fp = *s.floor_plan;
    // An image the page can show and nothing else: a base64 data URL of a picture type.
    static const char* kinds[] = {"png", "jpeg", "gif", "webp", "svg+xml"};
    std::size_t data = std::string::npos;
    for (const char* k : kinds) {
      const std::string head = std::string("data:image/") + k + ";base64,";
      if (fp.image.compare(0, head.size(), head) == 0) data = head.size();
    }
    if (data == std::string::npos)
      fail("floor_plan.image",
           "must be a data URL data:image/(png|jpeg|gif|webp|svg+xml);base64,...");
    if (fp.image.size() > kMaxFloorPlanBytes)
      fail("floor_plan.image", "too large (" + std::to_string(fp.image.size()) + " bytes > " +
                                   std::to_string(kMaxFloorPlanBytes) + ")");
    std::size_t pad = 0;
    for (std::size_t i = data; i < fp.image.size(); ++i) {
      const unsigned char c = static_cast<unsigned char>(fp.image[i]);
      const bool b64 = std::isalnum(c) || c == '+' || c == '/';
      if (c == '=' && ++pad <= 2) continue;
      if (!b64 || pad > 0) fail("floor_plan.image", "not base64 at byte " + std::to_string(i));
    }
    if (fp.image.size() == data || (fp.image.size() - data) % 4 != 0)
      fail("floor_plan.image", "truncated base64 data");
    const CanvasRect& r = fp.rect;
    for (double v : {r.x, r.y, r.w, r.h})
      if (!std::isfinite(v)) fail("floor_plan.rect", "not a finite number");
    if (r.w <= 0 || r.h <= 0)
      fail("floor_plan.rect",
           "width and height must be positive, got " + fmt(r.w) + " x " + fmt(r.h));
    if (r.w > 10 * kMaxCanvasPx || r.h > 10 * kMaxCanvasPx || std::abs(r.x) > 10 * kMaxCanvasPx ||
        std::abs(r.y) > 10 * kMaxCanvasPx)
      fail("floor_plan.rect", "absurd size or place");
    if (!std::isfinite(fp.m_per_px) || fp.m_per_px < 0 || fp.m_per_px > 100)
      fail("floor_plan.m_per_px", "= " + fmt(fp.m_per_px) + ": must be in (0, 100] m per px");
    if (!fp.scale_points.empty()) {
      if (fp.scale_points.size() != 2) fail("floor_plan.scale_points", "expected 2 points");
      for (size_t i = 0; i < 2; ++i) {
        const std::string f = "floor_plan.scale_points[" + std::to_string(i) + "]";
        if (!finite(fp.scale_points[i])) fail(f, "not a finite number");
        if (!inside(fp.scale_points[i]))
          fail(f, ptxt(fp.scale_points[i]) + " is outside the canvas");
      }
    }
  }
  // A path that passes no landmark gives the robot nothing to look for: almost certainly the
  // path or the landmarks were drawn on the wrong part of the canvas.
  const double near = detail::nearDistancePx(s);
  double best = std::numeric_limits<double>::infinity();
  for (const auto& l : s.landmarks)
    best = std::min(best, detail::rectToPolylineDistance(l.rect, s.path));
  if (best > near)
    fail("path", "never comes near a landmark (closest is " + fmt(std::round(best)) +
                     " px away, limit " + fmt(std::round(near)) + " px)");
}

void validateClasses(const Sketch& s, const std::vector<std::string>& classes,
                     const std::string& origin) {
  for (size_t i = 0; i < s.landmarks.size(); ++i) {
    const auto& c = s.landmarks[i].class_name;
    if (std::find(classes.begin(), classes.end(), c) == classes.end()) {
      std::string known;
      for (size_t k = 0; k < classes.size() && k < 12; ++k) known += (k ? ", " : "") + classes[k];
      if (classes.size() > 12) known += ", ...";
      throw InputError(origin + ": landmarks[" + std::to_string(i) + "].class: unknown class '" +
                       c + "' (the landmark set has: " + known + ")");
    }
  }
}

Sketch sketchFromText(const std::string& text, const std::string& origin) {
  if (text.size() > kMaxSketchBytes)
    throw InputError(origin + ": too large (" + std::to_string(text.size()) + " bytes > " +
                     std::to_string(kMaxSketchBytes) + ")");
  const Json j = parseJsonText(text, origin);
  return sketchFromJson(j, origin);
}

Sketch loadSketch(const std::string& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) throw InputError(path + ": no such sketch file");
  const auto size = fs::file_size(path, ec);
  if (ec) throw InputError(path + ": cannot read: " + ec.message());
  if (size > kMaxSketchBytes)
    throw InputError(path + ": too large (" + std::to_string(size) + " bytes > " +
                     std::to_string(kMaxSketchBytes) + ")");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open");
  std::ostringstream ss;
  ss << in.rdbuf();
  return sketchFromText(ss.str(), path);
}

Json sketchToJson(const Sketch& s) {
  Json j = Json::object();
  j["format"] = s.format;
  j["name"] = s.name;
  if (!s.notes.empty()) j["notes"] = s.notes;
  j["canvas"] = {{"width", s.canvas_width}, {"height", s.canvas_height}};
  Json lms = Json::array();
  for (const auto& l : s.landmarks)
    lms.push_back({{"id", l.id},
                   {"class", l.class_name},
                   {"rect", {{"x", l.rect.x}, {"y", l.rect.y}, {"w", l.rect.w}, {"h", l.rect.h}}},
                   {"distance_m", l.distance_m}});
  j["landmarks"] = lms;
  Json path = Json::array();
  for (const auto& p : s.path) path.push_back({p.x(), p.y()});
  j["path"] = path;
  j["start"] = {s.start.x(), s.start.y()};
  j["goal"] = {s.goal.x(), s.goal.y()};
  if (s.goal_place.kind == GoalPlace::Kind::Doorway) j["goal_place"] = goalPlaceJson(s.goal_place);
  if (s.floor_plan) {
    const FloorPlan& fp = *s.floor_plan;
    Json plan = {
        {"image", fp.image},
        {"rect", {{"x", fp.rect.x}, {"y", fp.rect.y}, {"w", fp.rect.w}, {"h", fp.rect.h}}}};
    if (fp.m_per_px > 0) plan["m_per_px"] = fp.m_per_px;
    if (!fp.scale_points.empty()) {
      Json pts = Json::array();
      for (const auto& p : fp.scale_points) pts.push_back({p.x(), p.y()});
      plan["scale_points"] = pts;
    }
    j["floor_plan"] = plan;
  }
  return j;
}

std::string sketchToText(const Sketch& s) {
  // Field order and line breaks for people reading or diffing the file: one landmark per
  // line, eight path points per line (nlohmann would sort the keys and put every number on
  // a line of its own).
  const Json j = sketchToJson(s);
  std::ostringstream o;
  o << "{\n  \"format\": " << j["format"].dump() << ",\n  \"name\": " << j["name"].dump();
  if (j.contains("notes")) o << ",\n  \"notes\": " << j["notes"].dump();
  o << ",\n  \"canvas\": " << j["canvas"].dump() << ",\n  \"landmarks\": [";
  for (size_t i = 0; i < j["landmarks"].size(); ++i) {
    const Json& l = j["landmarks"][i];
    o << (i ? ",\n    " : "\n    ") << "{\"id\": " << l["id"].dump()
      << ", \"class\": " << l["class"].dump() << ", \"rect\": " << l["rect"].dump()
      << ", \"distance_m\": " << l["distance_m"].dump() << "}";
  }
  o << (j["landmarks"].empty() ? "]" : "\n  ]") << ",\n  \"path\": [";
  for (size_t i = 0; i < j["path"].size(); ++i)
    o << (i == 0 ? "\n    " : i % 8 == 0 ? ",\n    " : ", ") << j["path"][i].dump();
  o << (j["path"].empty() ? "]" : "\n  ]") << ",\n  \"start\": " << j["start"].dump()
    << ",\n  \"goal\": " << j["goal"].dump();
  if (j.contains("goal_place")) o << ",\n  \"goal_place\": " << j["goal_place"].dump();
  if (j.contains("floor_plan")) {
    // The image last, on a line of its own (long): the rest of the plan stays readable.
    Json rest = j["floor_plan"];
    rest.erase("image");
    o << ",\n  \"floor_plan\": {";
    bool first = true;
    for (const char* k : {"rect", "m_per_px", "scale_points"})
      if (rest.contains(k)) {
        o << (first ? "" : ", ") << '"' << k << "\": " << rest[k].dump();
        first = false;
      }
    o << (first ? "" : ",") << "\n    \"image\": " << j["floor_plan"]["image"].dump() << "}";
  }
  o << "\n}\n";
  return o.str();
}

void saveSketch(const Sketch& s, const std::string& path) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw RuntimeError(path + ": cannot write");
    out << sketchToText(s);
    if (!out.flush()) throw RuntimeError(path + ": write failed");
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) throw RuntimeError(path + ": cannot write: " + ec.message());
}

std::vector<std::string> landmarkClasses(const std::string& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw InputError(dir + ": not a directory (expected a landmark set: one folder per class)");
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    if (!e.is_directory()) continue;
    bool has_image = false;
    for (const auto& f : fs::directory_iterator(e.path(), ec)) {
      if (f.is_regular_file() && isImageFileName(f.path().string())) {
        has_image = true;
        break;
      }
    }
    if (has_image) out.push_back(e.path().filename().string());
  }
  if (ec) throw InputError(dir + ": cannot list: " + ec.message());
  if (out.empty())
    throw InputError(dir + ": no class folders with images (expected <dir>/<class>/*.jpg)");
  std::sort(out.begin(), out.end());
  return out;
}

Json routeToJson(const Route& r) {
  auto pt = [](const Eigen::Vector2d& p) { return Json::array({p.x(), p.y()}); };
  Json j = Json::object();
  j["scale_m_per_px"] = r.scale_m_per_px;
  j["scale_residual"] = r.scale_residual;
  j["total_length_m"] = r.total_length_m;
  j["start_m"] = pt(r.start_m);
  j["goal_m"] = pt(r.goal_m);
  if (r.goal_place.kind == GoalPlace::Kind::Doorway) j["goal_place"] = goalPlaceJson(r.goal_place);
  j["start_heading_rad"] = r.start_heading_rad;
  Json gp = Json::array();
  for (const auto& p : r.guide_points_m) gp.push_back(pt(p));
  j["guide_points_m"] = gp;
  j["guide_point_path_index"] = r.guide_point_path_index;
  Json secs = Json::array();
  for (const auto& s : r.sections) {
    Json lms = Json::array();
    for (const auto& l : s.landmarks)
      lms.push_back({{"id", l.id},
                     {"class", l.class_name},
                     {"order", l.order},
                     {"side", sideName(l.side)},
                     {"range_m", l.range_m},
                     {"along_m", l.along_m},
                     {"position_m", pt(l.position_m)}});
    secs.push_back({{"index", s.index},
                    {"start_m", pt(s.start_m)},
                    {"end_m", pt(s.end_m)},
                    {"length_m", s.length_m},
                    {"heading_rad", s.heading_rad},
                    {"heading_change_rad", s.heading_change_rad},
                    {"landmarks", lms}});
  }
  j["sections"] = secs;
  j["distance_outliers"] = r.distance_outliers;
  j["warnings"] = r.warnings;
  return j;
}

}  // namespace sketchnav::mapsketch
