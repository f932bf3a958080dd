// The sketch editor's JSON API (doc/ui.md). File names from requests never become paths
// directly: classes are looked up in the list read at start, sketch names must pass
// safeSketchFileName() and still resolve inside the sketch directory.
// Eigen (through mapsketch) first: a macro pulled in by httplib.h breaks Eigen's headers.
#include "sketchnav/mapsketch/io.h"
#include "sketchnav/mapsketch/route.h"
// clang-format off
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "server.h"
#include <opencv2/imgcodecs.hpp>

#include "sketchnav/core/error.h"
#include "sketchnav/core/image_file.h"
#include "sketchnav/core/log.h"
// clang-format on

namespace fs = std::filesystem;

namespace sketchnav::ui {
namespace {

const std::string kSuffix = ".sketch.json";

bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::string readFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) throw RuntimeError("cannot read " + p.string());
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::vector<std::string> listSketches(const std::string& dir) {
  std::vector<std::string> out;
  std::error_code ec;
  if (dir.empty() || !fs::is_directory(dir, ec)) return out;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string n = e.path().filename().string();
    if (e.is_regular_file() && endsWith(n, kSuffix)) out.push_back(n);
  }
  std::sort(out.begin(), out.end());
  return out;
}

// Class folder names may hold spaces or other characters a URL cannot carry as they are.
std::string percentEncode(const std::string& s) {
  static const char* hex = "0123456789ABCDEF";
  std::string out;
  for (unsigned char c : s) {
    if (std::isalnum(c) || c == '-' || c == '_' || c == '.' || c == '~') {
      out += static_cast<char>(c);
    } else {
      out += '%';
      out += hex[c >> 4];
      out += hex[c & 15];
    }
  }
  return out;
}

// The picture shown for a class: its catalogue ("Iconic") photo when there is one, else the
// first image by name.
fs::path thumbnailOf(const fs::path& class_dir) {
  std::vector<fs::path> images;
  for (const auto& f : fs::directory_iterator(class_dir))
    if (f.is_regular_file() && isImageFileName(f.path().string())) images.push_back(f.path());
  std::sort(images.begin(), images.end());
  for (const auto& p : images)
    if (p.filename().string().find("Iconic") != std::string::npos) return p;
  return images.empty() ? fs::path() : images.front();
}

// Resolves a requested name inside `dir`, refusing anything that could leave it.
fs::path inside(const std::string& dir, const std::string& requested) {
  const std::string name = safeSketchFileName(requested);
  const fs::path base = fs::weakly_canonical(dir);
  const fs::path p = fs::weakly_canonical(base / name);
  if (p.parent_path() != base)
    throw InputError("sketch name '" + requested + "': not inside the sketch directory");
  return p;
}

}  // namespace

mapsketch::Sketch sketchFromBody(const std::string& body, const std::string& origin,
                                 const std::vector<std::string>& classes) {
  if (body.empty())
    throw InputError(origin + ": empty request body (expected a sketch as JSON)");
  const std::size_t bad = invalidUtf8At(body);
  if (bad != std::string::npos) {
    const std::string field = jsonFieldAt(body, bad);
    throw InputError(origin + ": " + (field.empty() ? "the sketch" : "'" + field + "'") +
                     " is not valid UTF-8 (byte " + std::to_string(bad) + ")");
  }
  mapsketch::Sketch s = mapsketch::sketchFromText(body, origin);
  mapsketch::validateClasses(s, classes, origin);
  return s;
}

std::string safeSketchFileName(const std::string& name) {
  static const std::regex ok(R"([A-Za-z0-9_][A-Za-z0-9_.\-]{0,99})");
  if (!std::regex_match(name, ok) || name.find("..") != std::string::npos)
    throw InputError(
        "sketch name '" + name.substr(0, 120) +
        "': use letters, digits, '_', '-' and '.', no folders (at most 100 characters)");
  return endsWith(name, kSuffix) ? name : name + kSuffix;
}

void addEditorRoutes(Server& server, const EditorOptions& o) {
  const auto classes = mapsketch::landmarkClasses(o.landmarks_dir);
  std::error_code ec;
  fs::create_directories(o.sketch_dir, ec);
  if (!fs::is_directory(o.sketch_dir))
    throw InputError("--sketch-dir '" + o.sketch_dir + "': not a directory");
  log::info("ui", "editor ready",
            {{"classes", std::to_string(classes.size())},
             {"landmarks", o.landmarks_dir},
             {"sketches", o.sketch_dir}});

  server.get("/api/info", [o, classes](const httplib::Request&, httplib::Response& res) {
    sendJson(res, {{"landmarks_dir", o.landmarks_dir},
                   {"sketch_dir", fs::absolute(o.sketch_dir).string()},
                   {"format", mapsketch::kSketchFormat},
                   {"max_bytes", mapsketch::kMaxSketchBytes}});
  });

  server.get("/api/classes", [classes](const httplib::Request&, httplib::Response& res) {
    Json list = Json::array();
    for (const auto& c : classes)
      list.push_back(
          {{"name", c}, {"thumbnail", "/api/classes/" + percentEncode(c) + "/thumbnail"}});
    sendJson(res, {{"classes", list}});
  });

  server.get(R"(/api/classes/([^/]+)/thumbnail)",
             [o, classes](const httplib::Request& req, httplib::Response& res) {
               const std::string name = req.matches[1];
               if (std::find(classes.begin(), classes.end(), name) == classes.end())
                 return sendError(res, 404, "unknown landmark class '" + name + "'");
               const fs::path img = thumbnailOf(fs::path(o.landmarks_dir) / name);
               if (img.empty()) return sendError(res, 404, "class '" + name + "' has no image");
               std::string ext = img.extension().string();
               std::transform(ext.begin(), ext.end(), ext.begin(),
                              [](unsigned char c) { return std::tolower(c); });
               if (ext == ".png" || ext == ".jpg" || ext == ".jpeg") {
                 res.set_content(readFile(img), ext == ".png" ? "image/png" : "image/jpeg");
               } else {
                 // A format a browser may not show (TIFF, PGM, ...): sent as JPEG.
                 std::vector<uchar> jpg;
                 cv::imencode(".jpg", readImageFile(img.string(), "thumbnail"), jpg);
                 res.set_content(std::string(jpg.begin(), jpg.end()), "image/jpeg");
               }
               res.set_header("Cache-Control", "max-age=3600");
             });

  server.get("/api/sketches", [o](const httplib::Request&, httplib::Response& res) {
    sendJson(res,
             {{"files", listSketches(o.sketch_dir)}, {"examples", listSketches(o.examples_dir)}});
  });

  server.get(R"(/api/sketches/([^/]+))", [o](const httplib::Request& req, httplib::Response& res) {
    const fs::path p = inside(o.sketch_dir, req.matches[1]);
    if (!fs::is_regular_file(p))
      return sendError(res, 404, "no sketch '" + p.filename().string() + "'");
    // Parsed before sending, so the editor only ever receives a sketch it can draw.
    sendJson(res, mapsketch::sketchToJson(mapsketch::loadSketch(p.string())));
  });

  server.get(R"(/api/examples/([^/]+))", [o](const httplib::Request& req, httplib::Response& res) {
    if (o.examples_dir.empty()) return sendError(res, 404, "no examples");
    const fs::path p = inside(o.examples_dir, req.matches[1]);
    if (!fs::is_regular_file(p))
      return sendError(res, 404, "no example '" + p.filename().string() + "'");
    sendJson(res, mapsketch::sketchToJson(mapsketch::loadSketch(p.string())));
  });

  server.post(R"(/api/sketches/([^/]+))",
              [o, classes](const httplib::Request& req, httplib::Response& res) {
                const fs::path p = inside(o.sketch_dir, req.matches[1]);
                const mapsketch::Sketch s = sketchFromBody(req.body, p.filename().string(), classes);
                if (fs::exists(p) && req.get_param_value("overwrite") != "1")
                  return sendError(
                      res, 409, "'" + p.filename().string() + "' exists (save again to overwrite)");
                mapsketch::saveSketch(s, p.string());
                log::info("ui", "sketch saved", {{"file", p.string()}});
                sendJson(res, {{"saved", p.filename().string()}, {"path", p.string()}});
              });

  server.post("/api/route", [classes](const httplib::Request& req, httplib::Response& res) {
    const mapsketch::Sketch s = sketchFromBody(req.body, "sketch", classes);
    sendJson(res, mapsketch::routeToJson(mapsketch::toRoute(s)));
  });
}

}  // namespace sketchnav::ui
