#include "entry_points.h"

#include "sketchnav/core/error.h"
#include "sketchnav/landmarks/voc.h"

namespace sketchnav::fuzz {

// A VOC annotation XML file (readVocAnnotation: `propose --eval`, the proposal benchmark).
// What it returns must hold what voc.h promises: boxes non-empty and, when the image size is
// known, inside the image.
void voc(const std::uint8_t* d, std::size_t n) {
  static const std::string path = scratchPath("voc", ".xml");
  writeInput(path, d, n);
  refusedIsFine([&] {
    const landmarks::VocImage img = landmarks::readVocAnnotation(path);
    const cv::Rect frame(0, 0, img.size.width, img.size.height);
    for (const auto& o : img.objects) {
      if (o.box.width <= 0 || o.box.height <= 0) __builtin_trap();
      if (img.size.width > 0 && (o.box & frame) != o.box) __builtin_trap();
    }
  });
}

}  // namespace sketchnav::fuzz
