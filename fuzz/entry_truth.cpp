#include "entry_points.h"

#include "perception_bench.h"
#include "sketchnav/core/error.h"

namespace sketchnav::fuzz {

// The perception benchmark's truth files as `replay --truth` reads them: the truth CSV
// (readTruthCsv) and the sequence.json sidecar (readSequenceJson), both from the same bytes.
void truth(const std::uint8_t* d, std::size_t n) {
  static const std::string path = scratchPath("truth", ".csv");
  writeInput(path, d, n);
  refusedIsFine([&] {
    for (const auto& [frame, expected] : app::bench::readTruthCsv(path))
      if (frame.empty() || !(expected.empty() || expected == "Left" || expected == "Straight" ||
                             expected == "Right" || expected == "None"))
        __builtin_trap();
  });
  refusedIsFine([&] { (void)app::bench::readSequenceJson(path); });
}

}  // namespace sketchnav::fuzz
