#include "entry_points.h"

#include <unistd.h>

#include <fstream>

#include "perception_bench.h"
#include "sketchnav/core/error.h"

namespace sketchnav::fuzz {

// The perception benchmark's truth files as `replay --truth` reads them: the truth CSV
// (readTruthCsv) and the sequence.json sidecar (readSequenceJson), both from the same bytes.
void truth(const std::uint8_t* d, std::size_t n) {
  static const std::string path = [] {
    const std::string dir = access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp";
    return dir + "/sketchnav-fuzz-truth-" + std::to_string(::getpid()) + ".csv";
  }();
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(d), static_cast<std::streamsize>(n));
  }
  refusedIsFine([&] {
    for (const auto& [frame, expected] : app::bench::readTruthCsv(path))
      if (frame.empty() || !(expected.empty() || expected == "Left" || expected == "Straight" ||
                             expected == "Right" || expected == "None"))
        __builtin_trap();
  });
  refusedIsFine([&] { (void)app::bench::readSequenceJson(path); });
}

}  // namespace sketchnav::fuzz
