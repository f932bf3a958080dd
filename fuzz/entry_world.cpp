#include "entry_points.h"

#include "sketchnav/core/error.h"
#include "sketchnav/core/json_io.h"
#include "sketchnav/sim/world.h"

namespace sketchnav::fuzz {

void world(const std::uint8_t* d, std::size_t n) {
  refusedIsFine([&] {
    const Json j = parseJsonText(text(d, n), "fuzz.world.json");
    const sim::World w = sim::worldFromJson(j, "fuzz.world.json", "");
    (void)sim::worldToJson(w);
  });
}

}  // namespace sketchnav::fuzz
