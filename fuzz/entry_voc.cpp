#include "entry_points.h"

#include <unistd.h>

#include <fstream>

#include "sketchnav/core/error.h"
#include "sketchnav/landmarks/voc.h"

namespace sketchnav::fuzz {

// A VOC annotation XML file (readVocAnnotation: `propose --eval`, the proposal benchmark).
// What it returns must hold what voc.h promises: boxes non-empty and, when the image size is
// known, inside the image.
void voc(const std::uint8_t* d, std::size_t n) {
  static const std::string path = [] {
    const std::string dir = access("/dev/shm", W_OK) == 0 ? "/dev/shm" : "/tmp";
    return dir + "/sketchnav-fuzz-voc-" + std::to_string(::getpid()) + ".xml";
  }();
  {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(d), static_cast<std::streamsize>(n));
  }
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
