#pragma once
// The one way input JSON is parsed (world files, sketches, --config, model parameter blocks):
// nesting deeper than kMaxJsonDepth is refused while parsing (a deeply nested document would
// otherwise exhaust the stack in code that walks it), numbers out of range (1e400) and syntax
// errors become an InputError naming the origin.
#include <cstdint>
#include <string>

#include "sketchnav/core/config.h"

namespace sketchnav {

/// Deepest nesting of arrays/objects accepted in any input JSON document.
constexpr int kMaxJsonDepth = 64;
/// Largest JSON input file read [bytes].
constexpr std::uint64_t kMaxJsonFileBytes = 16ull << 20;

/// Parses `text`; throws InputError "<origin>: ..." (one line) on invalid JSON, a number out
/// of range or nesting deeper than `max_depth`.
Json parseJsonText(const std::string& text, const std::string& origin,
                   int max_depth = kMaxJsonDepth);

/// Reads and parses the file `path` (a regular file of at most `max_bytes`); errors name
/// "<what> '<path>'".
Json parseJsonFile(const std::string& path, const std::string& what,
                   std::uint64_t max_bytes = kMaxJsonFileBytes, int max_depth = kMaxJsonDepth);

}  // namespace sketchnav
