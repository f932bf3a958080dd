#include "sketchnav/core/json_io.h"

#include "sketchnav/core/input_file.h"

namespace sketchnav {
namespace {
// nlohmann's what() starts with "[json.exception.parse_error.101] "; the user needs the rest.
std::string stripPrefix(const std::string& what) {
  if (what.rfind("[json.exception.", 0) == 0)
    if (auto p = what.find("] "); p != std::string::npos) return what.substr(p + 2);
  return what;
}

struct TooDeep {
  int depth;
};
}  // namespace

Json parseJsonText(const std::string& text, const std::string& origin, int max_depth) {
  // The callback sees `depth` = number of enclosing containers when a container starts.
  const Json::parser_callback_t limit = [max_depth](int depth, Json::parse_event_t ev, Json&) {
    if ((ev == Json::parse_event_t::object_start || ev == Json::parse_event_t::array_start) &&
        depth + 1 > max_depth)
      throw TooDeep{depth + 1};
    return true;
  };
  try {
    return Json::parse(text, limit);
  } catch (const TooDeep& d) {
    throw InputError(origin + ": JSON nested deeper than " + std::to_string(max_depth) +
                     " levels (reached depth " + std::to_string(d.depth) + ")");
  } catch (const Json::exception& e) {
    throw InputError(origin + ": not valid JSON: " + clipForMessage(stripPrefix(e.what()), 160));
  }
}

Json parseJsonFile(const std::string& path, const std::string& what, std::uint64_t max_bytes,
                   int max_depth) {
  const std::string text = readInputFile(path, what, max_bytes);
  return parseJsonText(text, what + " '" + clipForMessage(path, 200) + "'", max_depth);
}

}  // namespace sketchnav
