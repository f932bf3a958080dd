#include "entry_points.h"

#include "sketchnav/core/error.h"
#include "sketchnav/core/json_io.h"
#include "sketchnav/sim/world.h"

namespace sketchnav::fuzz {
namespace {
[[maybe_unused]] std::string text(const std::uint8_t* d, std::size_t n) {
  return std::string(reinterpret_cast<const char*>(d), n);
}
template <class F>
void refusedIsFine(F&& f) {
  try {
    f();
  } catch (const InputError&) {
    // the promised outcome for bad input
  }
}
}  // namespace

void world(const std::uint8_t* d, std::size_t n) {
  refusedIsFine([&] {
    const Json j = parseJsonText(text(d, n), "fuzz.world.json");
    const sim::World w = sim::worldFromJson(j, "fuzz.world.json", "");
    (void)sim::worldToJson(w);
  });
}

}  // namespace sketchnav::fuzz
