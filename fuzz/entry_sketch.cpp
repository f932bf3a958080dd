#include "entry_points.h"

#include "sketchnav/core/error.h"
#include "sketchnav/mapsketch/io.h"

namespace sketchnav::fuzz {

void sketch(const std::uint8_t* d, std::size_t n) {
  refusedIsFine([&] {
    const auto s = mapsketch::sketchFromText(text(d, n), "fuzz.sketch.json");
    (void)mapsketch::sketchToText(s);
  });
}

}  // namespace sketchnav::fuzz
