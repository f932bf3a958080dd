#include "entry_points.h"

#include "sketchnav/core/error.h"
#include "sketchnav/landmarks/model.h"

namespace sketchnav::fuzz {

void model(const std::uint8_t* d, std::size_t n) {
  static const std::string path = scratchPath("model", ".slm");
  writeInput(path, d, n);
  refusedIsFine([&] { (void)landmarks::LandmarkModel::load(path); });
}

}  // namespace sketchnav::fuzz
