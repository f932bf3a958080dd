#include "entry_points.h"

#include "sketchnav/core/error.h"
#include "sketchnav/mapsketch/io.h"

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

void sketch(const std::uint8_t* d, std::size_t n) {
  refusedIsFine([&] {
    const auto s = mapsketch::sketchFromText(text(d, n), "fuzz.sketch.json");
    (void)mapsketch::sketchToText(s);
  });
}

}  // namespace sketchnav::fuzz
