#include "entry_points.h"

#include "sketchnav/core/config.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/json_io.h"

namespace sketchnav::fuzz {

void config(const std::uint8_t* d, std::size_t n) {
  refusedIsFine([&] {
    const std::string t = text(d, n);
    // The first line is also tried as a --set assignment.
    Config c;
    c.set(t.substr(0, t.find('\n')));
    const Config f = Config::fromJson(parseJsonText(t, "fuzz.json"), "fuzz.json");
    (void)f.keys("");
  });
}

}  // namespace sketchnav::fuzz
