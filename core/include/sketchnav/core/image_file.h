#pragma once
// Reading an image file under the input-file rules (doc/reliability.md): a FIFO, device or
// directory is refused before it is opened, the file's size is bounded, the width and height
// its header declares are checked against a pixel bound *before* anything is decoded (a
// 30000 x 30000 JPEG header would otherwise allocate ~2.7 GB), and a truncated or non-image
// file is an InputError naming the file, never an OpenCV exception. Every image the project
// reads from a file goes through readImageFile() (cameras, landmark sets, training, VOC
// evaluation, replay); decodeImage() is the same rule for bytes already in memory.
#include <opencv2/core.hpp>

#include <cstdint>
#include <string>

namespace sketchnav {

/// Largest image accepted, in pixels as the header declares them (width x height): 64 Mi px,
/// e.g. 9216 x 7168 (a 48 MP phone photo is 8000 x 6000). 8-bit BGR at this size is 192 MiB.
constexpr std::uint64_t kMaxImagePixels = std::uint64_t{64} << 20;
/// Largest image file read, in bytes (a file is read whole before it is decoded): 256 MiB.
constexpr std::uint64_t kMaxImageFileBytes = std::uint64_t{256} << 20;

/// What an image file's header declares.
struct ImageHeader {
  std::string format;  ///< "JPEG", "PNG", "BMP", "PNM", "TIFF", "WebP"
  std::uint64_t width = 0, height = 0;
};

/// The format and dimensions declared by the header of an encoded image held in `bytes`,
/// without decoding it. Throws InputError "<name>: ..." when the bytes are not one of the
/// formats above or the header is cut short; for JPEG also when the data has no end-of-image
/// marker after its scan (a truncated file).
ImageHeader probeImageHeader(const std::string& bytes, const std::string& name);

enum class ImageMode {
  Colour,     ///< 8-bit BGR, EXIF orientation applied (cv::IMREAD_COLOR)
  Unchanged,  ///< as stored: depth, channels, alpha (cv::IMREAD_UNCHANGED)
};

/// Decodes an encoded image held in `bytes` under the same rules as readImageFile() (header
/// probed and its dimensions bounded before anything is decoded). `name` starts each message,
/// e.g. "image 'a.jpg'". Never returns an empty Mat.
cv::Mat decodeImage(const std::string& bytes, const std::string& name,
                    ImageMode mode = ImageMode::Colour, std::uint64_t max_pixels = kMaxImagePixels);

/// Reads and decodes an image file. Every problem is an InputError "<what> '<path>': ...":
/// not a regular file, larger than `max_bytes`, not a supported image format, a header that
/// declares more than `max_pixels` pixels or a zero dimension, data that cannot be decoded.
/// Never returns an empty Mat.
cv::Mat readImageFile(const std::string& path, const std::string& what,
                      ImageMode mode = ImageMode::Colour,
                      std::uint64_t max_pixels = kMaxImagePixels,
                      std::uint64_t max_bytes = kMaxImageFileBytes);

/// True when the file name ends in an extension of a format readImageFile() decodes (case
/// does not matter): .jpg .jpeg .png .bmp .pgm .ppm .pnm .tif .tiff .webp. The one list of
/// image files for folder cameras, landmark sets, sketches' landmark folders and replay.
bool isImageFileName(const std::string& path);

}  // namespace sketchnav
