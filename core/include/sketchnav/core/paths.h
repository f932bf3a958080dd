#pragma once
#include <string>

namespace sketchnav {

/// Where the shipped read-only resources (demo landmark set, lab world, example sketches)
/// live: $SKETCHNAV_SHARE if set, else the source tree's share/ (development build), else the
/// installed share/sketchnav. Throws RuntimeError when none exists.
std::string resourceDir();
/// resourceDir() + "/" + relative; throws RuntimeError naming the file when it is missing.
std::string resourcePath(const std::string& relative);

/// A new output directory "runs/<UTC timestamp>" (or `requested` if non-empty), created.
std::string makeOutputDir(const std::string& requested);

/// UTC timestamp "2026-11-22T05:01:02Z".
std::string utcTimestamp();

}  // namespace sketchnav
