#include "entry_points.h"

#include "sketchnav/core/error.h"
#include "sketchnav/core/image_file.h"

namespace sketchnav::fuzz {

// Image loading as every reader of the project does it: readImageFile() on a file (the
// regular-file and size rule, the header probe and pixel bound, then OpenCV's decoder), in
// both modes. Whatever it returns must hold what the header promises to its callers.
void image(const std::uint8_t* d, std::size_t n) {
  static const std::string path = scratchPath("image", ".img");
  writeInput(path, d, n);
  for (const ImageMode mode : {ImageMode::Colour, ImageMode::Unchanged}) {
    refusedIsFine([&] {
      const cv::Mat img = readImageFile(path, "image", mode);
      const bool bounded = !img.empty() && static_cast<std::uint64_t>(img.cols) *
                                                   static_cast<std::uint64_t>(img.rows) <=
                                               kMaxImagePixels;
      if (!bounded || (mode == ImageMode::Colour && img.type() != CV_8UC3)) __builtin_trap();
    });
  }
}

}  // namespace sketchnav::fuzz
