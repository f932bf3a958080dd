// One libFuzzer harness; FUZZ_ENTRY names the entry point (fuzz/CMakeLists.txt).
#include <cstddef>
#include <cstdint>

#include "entry_points.h"
#include "sketchnav/core/log.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  sketchnav::log::setQuiet(true);  // warnings about skipped fields would swamp the output
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  sketchnav::fuzz::FUZZ_ENTRY(data, size);
  return 0;
}
