#include "sketchnav/core/image_file.h"

#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <cctype>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include "sketchnav/core/error.h"
#include "sketchnav/core/input_file.h"

namespace sketchnav {
namespace {

// Bounds-checked reads of the header bytes; every short read is a truncated header.
struct Reader {
  const std::string& b;
  const std::string& name;
  const char* format;

  [[noreturn]] void truncated() const {
    throw InputError(name + ": truncated " + format + " header");
  }
  std::uint8_t u8(std::size_t at) const {
    if (at >= b.size()) truncated();
    return static_cast<std::uint8_t>(b[at]);
  }
  std::uint32_t be16(std::size_t at) const { return (u32of(at, 2, false)); }
  std::uint32_t be32(std::size_t at) const { return (u32of(at, 4, false)); }
  std::uint32_t le16(std::size_t at) const { return (u32of(at, 2, true)); }
  std::uint32_t le24(std::size_t at) const { return (u32of(at, 3, true)); }
  std::uint32_t le32(std::size_t at) const { return (u32of(at, 4, true)); }
  std::uint32_t u32of(std::size_t at, int n, bool little) const {
    if (at + n > b.size() || at + n < at) truncated();
    std::uint32_t v = 0;
    for (int i = 0; i < n; ++i) {
      const std::uint32_t byte = static_cast<std::uint8_t>(b[at + (little ? n - 1 - i : i)]);
      v = (v << 8) | byte;
    }
    return v;
  }
};

bool startsWith(const std::string& b, const char* magic, std::size_t n, std::size_t at = 0) {
  return b.size() >= at + n && b.compare(at, n, magic, n) == 0;
}

ImageHeader probeJpeg(const std::string& b, const std::string& name) {
  const Reader r{b, name, "JPEG"};
  ImageHeader h{"JPEG"};
  std::size_t pos = 2;
  bool frame = false;
  while (true) {
    if (r.u8(pos) != 0xFF) throw InputError(name + ": corrupt JPEG (no marker where expected)");
    while (r.u8(pos) == 0xFF) ++pos;  // fill bytes
    const std::uint8_t m = r.u8(pos++);
    if (m == 0x01 || (m >= 0xD0 && m <= 0xD8)) continue;  // markers without a length
    if (m == 0xD9) throw InputError(name + ": corrupt JPEG (ends before its image data)");
    const std::uint32_t len = r.be16(pos);
    if (len < 2)
      throw InputError(name + ": corrupt JPEG (segment length " + std::to_string(len) + ")");
    // SOF0..SOF15 except DHT (C4), JPG (C8) and DAC (CC): the frame header.
    if (m >= 0xC0 && m <= 0xCF && m != 0xC4 && m != 0xC8 && m != 0xCC && !frame) {
      h.height = r.be16(pos + 3);
      h.width = r.be16(pos + 5);
      frame = true;
    }
    if (m == 0xDA) {  // start of scan: the entropy-coded data follows
      if (!frame) throw InputError(name + ": corrupt JPEG (scan before any frame header)");
      // In entropy-coded data a 0xFF byte is followed by 0x00 or a restart marker, so FF D9
      // is the end-of-image marker; without it the file was cut short.
      if (b.find("\xFF\xD9", pos + len) == std::string::npos)
        throw InputError(name + ": truncated JPEG (no end-of-image marker)");
      return h;
    }
    pos += len;
  }
}

ImageHeader probePng(const std::string& b, const std::string& name) {
  const Reader r{b, name, "PNG"};
  if (!startsWith(b, "IHDR", 4, 12)) throw InputError(name + ": corrupt PNG (no IHDR chunk first)");
  return {"PNG", r.be32(16), r.be32(20)};
}

ImageHeader probeBmp(const std::string& b, const std::string& name) {
  const Reader r{b, name, "BMP"};
  const std::uint32_t dib = r.le32(14);
  if (dib == 12) return {"BMP", r.le16(18), r.le16(20)};  // OS/2 BITMAPCOREHEADER
  const auto w = static_cast<std::int32_t>(r.le32(18));
  const auto hgt = static_cast<std::int32_t>(r.le32(22));  // negative: stored top-down
  return {"BMP", static_cast<std::uint64_t>(std::llabs(w)),
          static_cast<std::uint64_t>(std::llabs(static_cast<long long>(hgt)))};
}

// P1..P6 (and PF/Pf, PFM): magic, then width and height as decimal text, with comments.
ImageHeader probePnm(const std::string& b, const std::string& name) {
  std::size_t pos = 2;
  auto number = [&]() -> std::uint64_t {
    while (pos < b.size()) {
      if (b[pos] == '#') {
        while (pos < b.size() && b[pos] != '\n') ++pos;
      } else if (std::isspace(static_cast<unsigned char>(b[pos]))) {
        ++pos;
      } else {
        break;
      }
    }
    if (pos >= b.size()) throw InputError(name + ": truncated PNM header");
    if (!std::isdigit(static_cast<unsigned char>(b[pos])))
      throw InputError(name + ": corrupt PNM header (expected a number)");
    std::uint64_t v = 0;
    while (pos < b.size() && std::isdigit(static_cast<unsigned char>(b[pos]))) {
      v = v * 10 + static_cast<std::uint64_t>(b[pos++] - '0');
      if (v > (std::uint64_t{1} << 40)) throw InputError(name + ": PNM dimension out of range");
    }
    return v;
  };
  const std::uint64_t w = number();
  const std::uint64_t h = number();
  return {"PNM", w, h};
}

// P7 (PAM): "WIDTH n" and "HEIGHT n" lines before ENDHDR.
ImageHeader probePam(const std::string& b, const std::string& name) {
  ImageHeader h{"PNM"};
  const std::size_t end = b.find("ENDHDR");
  if (end == std::string::npos) throw InputError(name + ": truncated PAM header");
  for (const char* key : {"WIDTH", "HEIGHT"}) {
    const std::size_t at = b.find(key);
    if (at == std::string::npos || at > end)
      throw InputError(name + ": corrupt PAM header (no " + key + ")");
    const std::uint64_t v = std::strtoull(b.c_str() + at + std::strlen(key), nullptr, 10);
    (key[0] == 'W' ? h.width : h.height) = v;
  }
  return h;
}

ImageHeader probeTiff(const std::string& b, const std::string& name) {
  const Reader r{b, name, "TIFF"};
  const bool le = b[0] == 'I';
  auto u16 = [&](std::size_t at) { return le ? r.le16(at) : r.be16(at); };
  auto u32 = [&](std::size_t at) { return le ? r.le32(at) : r.be32(at); };
  const std::size_t ifd = u32(4);
  const std::uint32_t n = u16(ifd);
  ImageHeader h{"TIFF"};
  for (std::uint32_t i = 0; i < n; ++i) {
    const std::size_t e = ifd + 2 + 12 * static_cast<std::size_t>(i);
    const std::uint32_t tag = u16(e), type = u16(e + 2);
    if (tag != 256 && tag != 257) continue;
    const std::uint64_t v = type == 3 ? u16(e + 8) : u32(e + 8);  // SHORT or LONG
    (tag == 256 ? h.width : h.height) = v;
  }
  return h;
}

ImageHeader probeWebp(const std::string& b, const std::string& name) {
  const Reader r{b, name, "WebP"};
  if (startsWith(b, "VP8 ", 4, 12)) {
    if (r.u8(23) != 0x9D || r.u8(24) != 0x01 || r.u8(25) != 0x2A)
      throw InputError(name + ": corrupt WebP (no VP8 start code)");
    return {"WebP", r.le16(26) & 0x3FFF, r.le16(28) & 0x3FFF};
  }
  if (startsWith(b, "VP8L", 4, 12)) {
    if (r.u8(20) != 0x2F) throw InputError(name + ": corrupt WebP (no VP8L signature)");
    const std::uint32_t bits = r.le32(21);
    return {"WebP", (bits & 0x3FFF) + 1, ((bits >> 14) & 0x3FFF) + 1};
  }
  if (startsWith(b, "VP8X", 4, 12))
    return {"WebP", std::uint64_t{r.le24(24)} + 1, std::uint64_t{r.le24(27)} + 1};
  throw InputError(name + ": corrupt WebP (unknown first chunk)");
}

}  // namespace

ImageHeader probeImageHeader(const std::string& b, const std::string& name) {
  if (startsWith(b, "\xFF\xD8", 2)) return probeJpeg(b, name);
  if (startsWith(b, "\x89PNG\r\n\x1A\n", 8)) return probePng(b, name);
  if (startsWith(b, "BM", 2)) return probeBmp(b, name);
  if (b.size() >= 2 && b[0] == 'P' && ((b[1] >= '1' && b[1] <= '6') || b[1] == 'F' || b[1] == 'f'))
    return probePnm(b, name);
  if (startsWith(b, "P7", 2)) return probePam(b, name);
  if (startsWith(b, "II*\0", 4) || startsWith(b, "MM\0*", 4)) return probeTiff(b, name);
  if (startsWith(b, "RIFF", 4) && startsWith(b, "WEBP", 4, 8)) return probeWebp(b, name);
  if (b.empty()) throw InputError(name + ": empty file, not an image");
  throw InputError(name + ": not an image (expected JPEG, PNG, BMP, PNM, TIFF or WebP)");
}

cv::Mat decodeImage(const std::string& bytes, const std::string& name, ImageMode mode,
                    std::uint64_t max_pixels) {
  const ImageHeader h = probeImageHeader(bytes, name);
  const std::string dims = std::to_string(h.width) + " x " + std::to_string(h.height);
  if (h.width == 0 || h.height == 0)
    throw InputError(name + ": " + h.format + " header declares " + dims + " pixels");
  // Both factors are below 2^32, so the product does not overflow.
  if (h.width * h.height > max_pixels)
    throw InputError(name + ": " + h.format + " header declares " + dims + " pixels (" +
                     std::to_string(h.width * h.height) + " > " + std::to_string(max_pixels) + ")");
  if (bytes.size() > static_cast<std::size_t>(INT_MAX))
    throw InputError(name + ": too large to decode (" + std::to_string(bytes.size()) + " bytes)");
  cv::Mat img;
  try {
    const cv::Mat buf(1, static_cast<int>(bytes.size()), CV_8U, const_cast<char*>(bytes.data()));
    img = cv::imdecode(buf, mode == ImageMode::Colour ? cv::IMREAD_COLOR : cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    throw InputError(name + ": " + h.format + " data cannot be decoded (" + clipForMessage(e.err) +
                     ")");
  }
  if (img.empty())
    throw InputError(name + ": " + h.format + " data cannot be decoded (corrupt or truncated)");
  if (static_cast<std::uint64_t>(img.cols) * static_cast<std::uint64_t>(img.rows) > max_pixels)
    throw InputError(name + ": decodes to " + std::to_string(img.cols) + " x " +
                     std::to_string(img.rows) + " pixels (> " + std::to_string(max_pixels) + ")");
  return img;
}

cv::Mat readImageFile(const std::string& path, const std::string& what, ImageMode mode,
                      std::uint64_t max_pixels, std::uint64_t max_bytes) {
  const std::string name = what + " '" + clipForMessage(path, 200) + "'";
  const std::string bytes = readInputFile(path, what, max_bytes);  // regular files only
  return decodeImage(bytes, name, mode, max_pixels);
}

bool isImageFileName(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  static const char* known[] = {".jpg", ".jpeg", ".png", ".bmp",  ".pgm",
                                ".ppm", ".pnm",  ".tif", ".tiff", ".webp"};
  return std::any_of(std::begin(known), std::end(known), [&](const char* k) { return ext == k; });
}

}  // namespace sketchnav
