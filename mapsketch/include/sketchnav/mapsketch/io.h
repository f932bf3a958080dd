#pragma once
// `.sketch.json` reading, writing and validation (doc/sketch-format.md), and the JSON form of
// a Route (what `sketchnav route --json` and the editor's live preview print).
#include <string>
#include <vector>

#include "sketchnav/core/config.h"
#include "sketchnav/mapsketch/route.h"
#include "sketchnav/mapsketch/sketch.h"

namespace sketchnav::mapsketch {

/// The newest format this code writes; files with a larger "format" are refused.
constexpr int kSketchFormat = 1;
/// Files (and request bodies) larger than this are refused before parsing.
constexpr std::size_t kMaxSketchBytes = 4u << 20;
/// Limits that keep a malformed file from exhausting memory or producing nonsense.
constexpr std::size_t kMaxPathPoints = 20000;  // a mouse path of ~60 canvas widths
constexpr std::size_t kMaxLandmarks = 200;
constexpr double kMaxDistanceM = 1000;  // a "distance" above this is a typo (mm? feet?)
constexpr double kMaxCanvasPx = 20000;
// The floor plan's data URL (Sketch::floor_plan): 3 MiB, so that the sketch fits its limit.
constexpr std::size_t kMaxFloorPlanBytes = 3u << 20;

/// Parses and structurally validates a sketch from JSON: types, NaN/inf, ranges, duplicate
/// ids, path length, the path coming near a landmark. `origin` (a file name) prefixes every
/// message: "lab.sketch.json: landmarks[2].distance_m = -1: must be positive".
/// Throws InputError.
Sketch sketchFromJson(const Json& j, const std::string& origin = "<sketch>");
/// Parses text (size-checked, JSON syntax errors reported with their position).
Sketch sketchFromText(const std::string& text, const std::string& origin = "<sketch>");
/// Reads and parses a file; InputError naming the file when missing, too big or invalid.
Sketch loadSketch(const std::string& path);

Json sketchToJson(const Sketch& s);
/// The file text: readable field order, one landmark per line, eight path points per line.
std::string sketchToText(const Sketch& s);
/// Writes the file (atomically: temp file + rename). RuntimeError on I/O failure.
void saveSketch(const Sketch& s, const std::string& path);

/// Structural checks (what sketchFromJson runs after parsing; call it on sketches built in
/// code). Throws InputError "<origin>: <field>: <why>".
void validateSketch(const Sketch& s, const std::string& origin = "<sketch>");
/// Every landmark's class must be one of `classes` (the landmark set's folder names).
void validateClasses(const Sketch& s, const std::vector<std::string>& classes,
                     const std::string& origin = "<sketch>");

/// The classes of a landmark set: names of the sub-folders of `dir` that contain at least one
/// image, sorted. InputError when `dir` is not a directory or holds no class.
std::vector<std::string> landmarkClasses(const std::string& dir);

Json routeToJson(const Route& r);

}  // namespace sketchnav::mapsketch
