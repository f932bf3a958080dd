#include "sketchnav/core/log.h"

#include <chrono>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <iostream>
#include <mutex>

#include "sketchnav/core/error.h"
#include "sketchnav/core/input_file.h"

namespace sketchnav::log {
namespace {
struct State {
  std::mutex mutex;
  Level level = Level::Info;
  bool quiet = false;
  std::ofstream file;
};
State& state() {
  static State s;
  return s;
}
const char* name(Level l) {
  switch (l) {
    case Level::Debug:
      return "DEBUG";
    case Level::Info:
      return "INFO ";
    case Level::Warn:
      return "WARN ";
    case Level::Error:
      return "ERROR";
    default:
      return "?????";
  }
}
std::string now() {
  using namespace std::chrono;
  const auto t = system_clock::now();
  const std::time_t secs = system_clock::to_time_t(t);
  const auto ms = duration_cast<milliseconds>(t.time_since_epoch()).count() % 1000;
  std::tm tm{};
  gmtime_r(&secs, &tm);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", tm.tm_year + 1900,
                tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, static_cast<int>(ms));
  return buf;
}
bool needsQuotes(std::string_view v) {
  if (v.empty()) return true;
  for (char c : v)
    if (c == ' ' || c == '"' || c == '=' || c == '\n') return true;
  return false;
}
}  // namespace

void setLevel(Level l) {
  std::lock_guard<std::mutex> lock(state().mutex);
  state().level = l;
}
Level level() {
  return state().level;
}
void setQuiet(bool q) {
  std::lock_guard<std::mutex> lock(state().mutex);
  state().quiet = q;
}
void setFile(const std::string& path) {
  std::lock_guard<std::mutex> lock(state().mutex);
  state().file.close();
  // Appending to a FIFO would block and a device makes no sense: regular/new files only.
  requireOutputFile(path, "--log-file");
  state().file.open(path, std::ios::app);
  if (!state().file) throw InputError("--log-file: cannot open '" + path + "' for writing");
}

void write(Level l, std::string_view component, std::string_view message, Fields fields) {
  State& s = state();
  const bool to_err = !s.quiet && l >= s.level;
  const bool to_file = s.file.is_open();
  if (!to_err && !to_file) return;
  std::string line = now();
  line += ' ';
  line += name(l);
  line += ' ';
  line += component;
  line += ": ";
  for (char c : message) line += (c == '\n' ? ' ' : c);
  for (const auto& [k, v] : fields) {
    line += ' ';
    line += k;
    line += '=';
    if (needsQuotes(v)) {
      line += '"';
      for (char c : v) {
        if (c == '"') line += '\\';
        line += (c == '\n' ? ' ' : c);
      }
      line += '"';
    } else {
      line += v;
    }
  }
  line += '\n';
  std::lock_guard<std::mutex> lock(s.mutex);
  if (to_err) std::cerr << line << std::flush;
  if (to_file) s.file << line << std::flush;
}

}  // namespace sketchnav::log
