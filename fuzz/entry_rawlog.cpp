#include "entry_points.h"

#include <unistd.h>

#include <fstream>

#include "sketchnav/core/error.h"
#include "sketchnav/drivers/rawlog.h"

namespace sketchnav::fuzz {

// A rawlog as `sketchnav run --replay` / rawlog:// devices read one (RawlogReader: MRPT's
// deserialisation of each record, then the conversion to the project's types), images
// included (their external files are missing here, which the reader must tolerate).
void rawlog(const std::uint8_t* d, std::size_t n) {
  static const std::string path = [] {
    const std::string dir = access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp";
    return dir + "/sketchnav-fuzz-rawlog-" + std::to_string(::getpid()) + ".rawlog";
  }();
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(d), static_cast<std::streamsize>(n));
  }
  refusedIsFine([&] {
    drivers::RawlogReader r(path);
    drivers::RawlogEntry e;
    for (int i = 0; i < 100000 && r.next(e, true); ++i) {
      if (e.kind == drivers::RawlogEntry::Kind::Range && e.range.angles.size() != e.range.ranges.size())
        __builtin_trap();
    }
  });
}

}  // namespace sketchnav::fuzz
