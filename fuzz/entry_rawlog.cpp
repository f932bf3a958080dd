#include "entry_points.h"

#include "sketchnav/core/error.h"
#include "sketchnav/drivers/rawlog.h"

namespace sketchnav::fuzz {

// A rawlog as `sketchnav run --replay` / rawlog:// devices read one (RawlogReader: MRPT's
// deserialisation of each record, then the conversion to the project's types), images
// included (their external files are missing here, which the reader must tolerate).
void rawlog(const std::uint8_t* d, std::size_t n) {
  static const std::string path = scratchPath("rawlog", ".rawlog");
  writeInput(path, d, n);
  refusedIsFine([&] {
    drivers::RawlogReader r(path);
    drivers::RawlogEntry e;
    for (int i = 0; i < 100000 && r.next(e, true); ++i) {
      if (e.kind == drivers::RawlogEntry::Kind::Range &&
          e.range.angles.size() != e.range.ranges.size())
        __builtin_trap();
    }
  });
}

}  // namespace sketchnav::fuzz
