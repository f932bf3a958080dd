#pragma once
// Structured logging: one line per event, "<time> <LEVEL> <component>: <message> k=v ...".
// Thread-safe. Lines go to stderr (from the configured level up) and, when a log file is set,
// to that file (everything from Debug up), flushed per line so a crash leaves a readable log.
#include <initializer_list>
#include <string>
#include <string_view>
#include <utility>

namespace sketchnav::log {

enum class Level { Debug = 0, Info = 1, Warn = 2, Error = 3, Off = 4 };

void setLevel(Level level);
Level level();
/// Also write every line to `path` (appended). Throws InputError when it cannot be opened.
void setFile(const std::string& path);
/// Silence stderr output entirely (used by --json so stdout/stderr stay machine friendly).
void setQuiet(bool quiet);

using Fields = std::initializer_list<std::pair<std::string_view, std::string>>;
void write(Level level, std::string_view component, std::string_view message, Fields fields = {});

inline void debug(std::string_view c, std::string_view m, Fields f = {}) {
  write(Level::Debug, c, m, f);
}
inline void info(std::string_view c, std::string_view m, Fields f = {}) {
  write(Level::Info, c, m, f);
}
inline void warn(std::string_view c, std::string_view m, Fields f = {}) {
  write(Level::Warn, c, m, f);
}
inline void error(std::string_view c, std::string_view m, Fields f = {}) {
  write(Level::Error, c, m, f);
}

}  // namespace sketchnav::log
