#include "sketchnav/core/paths.h"

#include <chrono>
#include <cstdlib>
#include <ctime>
#include <filesystem>

#include "sketchnav/core/error.h"

namespace fs = std::filesystem;

namespace sketchnav {

std::string resourceDir() {
  if (const char* env = std::getenv("SKETCHNAV_SHARE"); env && *env) {
    if (!fs::is_directory(env))
      throw RuntimeError(std::string("SKETCHNAV_SHARE='") + env + "' is not a directory");
    return env;
  }
  // Development builds read the source tree's share/ directly, so edits need no install.
  if (fs::is_directory(SKETCHNAV_SOURCE_SHARE_DIR)) return SKETCHNAV_SOURCE_SHARE_DIR;
  if (fs::is_directory(SKETCHNAV_INSTALL_SHARE_DIR)) return SKETCHNAV_INSTALL_SHARE_DIR;
  throw RuntimeError("sketchnav resources not found (looked in " +
                     std::string(SKETCHNAV_SOURCE_SHARE_DIR) + " and " +
                     SKETCHNAV_INSTALL_SHARE_DIR + "); set SKETCHNAV_SHARE");
}

std::string resourcePath(const std::string& relative) {
  const fs::path p = fs::path(resourceDir()) / relative;
  if (!fs::exists(p)) throw RuntimeError("missing resource '" + p.string() + "'");
  return p.string();
}

std::string utcTimestamp() {
  const std::time_t t = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

std::string makeOutputDir(const std::string& requested) {
  fs::path dir = requested;
  if (dir.empty()) {
    std::string stamp = utcTimestamp();
    for (char& c : stamp)
      if (c == ':') c = '-';
    dir = fs::path("runs") / stamp;
    // Two runs in the same second get distinct folders rather than mixing outputs.
    for (int i = 1; fs::exists(dir); ++i)
      dir = fs::path("runs") / (stamp + "-" + std::to_string(i));
  }
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec)
    throw InputError("--out '" + dir.string() + "': cannot create directory: " + ec.message());
  return dir.string();
}

}  // namespace sketchnav
