#include "entry_points.h"

#include <unistd.h>
#include <fstream>
#include "sketchnav/core/error.h"
#include "sketchnav/landmarks/model.h"

namespace sketchnav::fuzz {

void model(const std::uint8_t* d, std::size_t n) {
  // The loader reads files; a per-process file in /dev/shm (or /tmp) keeps this cheap.
  static const std::string path = [] {
    const std::string dir = access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp";
    return dir + "/sketchnav-fuzz-model-" + std::to_string(::getpid()) + ".slm";
  }();
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(d), static_cast<std::streamsize>(n));
  }
  refusedIsFine([&] { (void)landmarks::LandmarkModel::load(path); });
}

}  // namespace sketchnav::fuzz
