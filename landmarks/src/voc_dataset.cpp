// VOC annotation reading (voc.h). The XML subset VOC uses is flat and regular, so a small
// tag scanner suffices; no XML library is a dependency of this module.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "sketchnav/core/error.h"
#include "sketchnav/landmarks/voc.h"

namespace sketchnav::landmarks {
namespace fs = std::filesystem;
namespace {

// Text between <tag> and </tag> starting the search at `from`; npos-safe. Returns false when
// absent.
bool tagText(const std::string& s, const std::string& tag, std::string& out, size_t from = 0,
             size_t to = std::string::npos, size_t* end_pos = nullptr) {
  const std::string open = "<" + tag + ">", close = "</" + tag + ">";
  const size_t a = s.find(open, from);
  if (a == std::string::npos || (to != std::string::npos && a >= to)) return false;
  const size_t b = s.find(close, a + open.size());
  if (b == std::string::npos || (to != std::string::npos && b > to)) return false;
  out = s.substr(a + open.size(), b - a - open.size());
  if (end_pos) *end_pos = b + close.size();
  return true;
}

std::string trim(const std::string& s) {
  const auto a = s.find_first_not_of(" \t\r\n");
  if (a == std::string::npos) return "";
  const auto b = s.find_last_not_of(" \t\r\n");
  return s.substr(a, b - a + 1);
}

// Bound on corner coordinates and image sides [px]: far beyond any photograph, and small
// enough that the int box arithmetic below (corners, widths, clipping) cannot overflow.
constexpr double kMaxPixels = 1e6;

double number(const std::string& block, const std::string& tag, const std::string& file) {
  std::string t;
  if (!tagText(block, tag, t)) throw InputError(file + ": <bndbox> has no <" + tag + ">");
  double v = 0;
  try {
    size_t used = 0;
    v = std::stod(trim(t), &used);
    if (used != trim(t).size()) throw std::invalid_argument(t);
  } catch (const std::exception&) {
    throw InputError(file + ": <" + tag + "> is not a number ('" + trim(t).substr(0, 40) + "')");
  }
  if (!std::isfinite(v) || std::abs(v) > kMaxPixels)
    throw InputError(file + ": <" + tag + "> " + trim(t).substr(0, 40) +
                     " is not a pixel coordinate (finite, at most 1000000 in magnitude)");
  return v;
}

// <width> / <height> of <size>: absent or empty = unknown (0); otherwise a whole number of
// pixels 0..kMaxPixels (0 = unknown, as VOC writes for images it never measured).
int side(const std::string& size_block, const std::string& tag, const std::string& file) {
  std::string t;
  if (!tagText(size_block, tag, t) || trim(t).empty()) return 0;
  t = trim(t);
  if (t.size() > 7 || t.find_first_not_of("0123456789") != std::string::npos ||
      std::stod(t) > kMaxPixels)
    throw InputError(file + ": <size> <" + tag + "> '" + t.substr(0, 40) +
                     "' is not a pixel count (a whole number 0..1000000)");
  return std::stoi(t);
}

}  // namespace

VocImage readVocAnnotation(const std::string& xml_path) {
  std::ifstream in(xml_path);
  if (!in) throw InputError(xml_path + ": cannot read annotation");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string s = ss.str();
  if (s.find("<annotation") == std::string::npos)
    throw InputError(xml_path + ": not a VOC annotation (no <annotation>)");
  VocImage img;
  img.id = fs::path(xml_path).stem().string();
  std::string size_block, t;
  if (tagText(s, "size", size_block)) {
    const int w = side(size_block, "width", xml_path), h = side(size_block, "height", xml_path);
    if (w > 0 && h > 0) img.size = cv::Size(w, h);
  }
  size_t pos = 0, end = 0;
  std::string obj;
  while (tagText(s, "object", obj, pos, std::string::npos, &end)) {
    pos = end;
    VocObject o;
    if (tagText(obj, "name", t)) o.name = trim(t);
    if (tagText(obj, "difficult", t)) o.difficult = trim(t) == "1";
    std::string bb;
    if (!tagText(obj, "bndbox", bb)) throw InputError(xml_path + ": <object> has no <bndbox>");
    // VOC corners are 1-based and inclusive: pixel columns xmin..xmax.
    const double x0 = number(bb, "xmin", xml_path), y0 = number(bb, "ymin", xml_path);
    const double x1 = number(bb, "xmax", xml_path), y1 = number(bb, "ymax", xml_path);
    cv::Rect r(
        cv::Point(static_cast<int>(std::lround(x0)) - 1, static_cast<int>(std::lround(y0)) - 1),
        cv::Point(static_cast<int>(std::lround(x1)), static_cast<int>(std::lround(y1))));
    // (not size.area(): width * height may exceed int)
    if (img.size.width > 0) r &= cv::Rect(0, 0, img.size.width, img.size.height);
    if (r.width <= 0 || r.height <= 0) {
      img.warnings.push_back("object '" + o.name + "' box outside the image or empty: dropped");
      continue;
    }
    o.box = r;
    img.objects.push_back(o);
  }
  return img;
}

std::vector<VocImage> readVocDataset(const std::string& dir) {
  const fs::path root(dir), ann = root / "Annotations", jpg = root / "JPEGImages";
  if (!fs::is_directory(root)) throw InputError(dir + ": not a directory");
  if (!fs::is_directory(ann)) throw InputError(dir + ": no Annotations/ folder (VOC layout)");
  std::vector<std::string> ids;
  const fs::path sets = root / "ImageSets" / "Main";
  if (fs::is_directory(sets)) {
    fs::path list = sets / "test.txt";
    if (!fs::exists(list)) {
      std::vector<fs::path> txts;
      for (const auto& e : fs::directory_iterator(sets))
        if (e.path().extension() == ".txt") txts.push_back(e.path());
      std::sort(txts.begin(), txts.end());
      list = txts.empty() ? fs::path() : txts.front();
    }
    if (!list.empty()) {
      std::ifstream in(list);
      std::string line;
      while (std::getline(in, line)) {
        std::istringstream ls(line);
        std::string id;
        if (ls >> id) ids.push_back(id);
      }
    }
  }
  if (ids.empty()) {
    for (const auto& e : fs::directory_iterator(ann))
      if (e.path().extension() == ".xml") ids.push_back(e.path().stem().string());
    std::sort(ids.begin(), ids.end());
  }
  if (ids.empty()) throw InputError(dir + ": Annotations/ holds no .xml file");
  std::vector<VocImage> out;
  out.reserve(ids.size());
  for (const auto& id : ids) {
    const fs::path x = ann / (id + ".xml");
    if (!fs::exists(x)) throw InputError(x.string() + ": listed in ImageSets but missing");
    VocImage img = readVocAnnotation(x.string());
    img.id = id;
    for (const char* ext : {".jpg", ".jpeg", ".png", ".JPG", ".JPEG", ".PNG"}) {
      const fs::path p = jpg / (id + ext);
      if (fs::exists(p)) {
        img.image_path = p.string();
        break;
      }
    }
    if (img.image_path.empty()) img.image_path = (jpg / (id + ".jpg")).string();
    out.push_back(std::move(img));
  }
  return out;
}

}  // namespace sketchnav::landmarks
