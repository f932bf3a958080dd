// readImageFile(): image inputs under the input-file rules (issue 28, doc/reliability.md).
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <random>

#include "sketchnav/core/error.h"
#include "sketchnav/core/image_file.h"
#include "test_data.h"

using namespace sketchnav;
namespace fs = std::filesystem;

namespace {
cv::Mat pattern(int w, int h) {
  cv::Mat m(h, w, CV_8UC3);
  std::mt19937 rng(7);
  cv::randu(m, 0, 255);
  cv::GaussianBlur(m, m, {5, 5}, 2);
  return m;
}

std::string encode(const std::string& ext, const cv::Mat& m) {
  std::vector<uchar> buf;
  EXPECT_TRUE(cv::imencode(ext, m, buf)) << ext;
  return std::string(buf.begin(), buf.end());
}

std::string write(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<long>(bytes.size()));
  return path;
}

// The message of the InputError readImageFile throws, or "" when it returns an image.
std::string errorOf(const std::string& path) {
  try {
    readImageFile(path, "image");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

void putBe16(std::string& b, std::size_t at, unsigned v) {
  b[at] = static_cast<char>(v >> 8);
  b[at + 1] = static_cast<char>(v & 0xFF);
}
void putBe32(std::string& b, std::size_t at, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) b[at + i] = static_cast<char>(v >> (24 - 8 * i));
}

// Offset of the first SOF0 segment's height field in a baseline JPEG.
std::size_t jpegSofHeight(const std::string& b) {
  const std::size_t sof = b.find("\xFF\xC0");
  EXPECT_NE(sof, std::string::npos);
  return sof + 5;
}
}  // namespace

TEST(ImageFile, EveryFormatRoundTripsWithTheDimensionsItsHeaderDeclares) {
  const std::string dir = test::tempDir("image-formats");
  const cv::Mat m = pattern(37, 23);
  for (const std::string ext : {".png", ".jpg", ".bmp", ".ppm", ".pgm", ".tif", ".webp"}) {
    cv::Mat grey;
    cv::cvtColor(m, grey, cv::COLOR_BGR2GRAY);
    const std::string bytes = encode(ext, ext == ".pgm" ? grey : m);
    const ImageHeader h = probeImageHeader(bytes, ext);
    EXPECT_EQ(h.width, 37u) << ext;
    EXPECT_EQ(h.height, 23u) << ext;
    const std::string path = write(dir + "/a" + ext, bytes);
    const cv::Mat got = readImageFile(path, "image");
    const cv::Mat want = cv::imread(path, cv::IMREAD_COLOR);
    ASSERT_EQ(got.size(), want.size()) << ext;
    EXPECT_EQ(got.type(), CV_8UC3) << ext;
    EXPECT_EQ(cv::norm(got, want, cv::NORM_INF), 0) << ext;
  }
  // Unchanged keeps what the file stores (one channel for PGM, 16 bits for a 16-bit PNG).
  cv::Mat grey16(23, 37, CV_16U, cv::Scalar(40000));
  write(dir + "/g16.png", encode(".png", grey16));
  const cv::Mat u = readImageFile(dir + "/g16.png", "image", ImageMode::Unchanged);
  EXPECT_EQ(u.type(), CV_16UC1);
}

TEST(ImageFile, SpecialFilesAreRefusedWithoutBlocking) {
  const std::string dir = test::tempDir("image-special");
  const std::string fifo = dir + "/frame.jpg";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const auto t0 = std::chrono::steady_clock::now();
  EXPECT_EQ(errorOf(fifo), "image '" + fifo + "': is a FIFO, expected a regular file");
  EXPECT_LT(std::chrono::steady_clock::now() - t0, std::chrono::seconds(2));
  EXPECT_EQ(errorOf(dir), "image '" + dir + "': is a directory, expected a regular file");
  EXPECT_EQ(errorOf("/dev/zero"),
            "image '/dev/zero': is a character device, expected a regular file");
  EXPECT_NE(errorOf(dir + "/missing.png").find("cannot be opened"), std::string::npos);
}

TEST(ImageFile, AJpegHeaderDeclaringHugeDimensionsIsRefusedBeforeDecoding) {
  const std::string dir = test::tempDir("image-bomb");
  std::string b = encode(".jpg", pattern(64, 48));
  const std::size_t at = jpegSofHeight(b);
  putBe16(b, at, 30000);
  putBe16(b, at + 2, 30000);
  const std::string path = write(dir + "/bomb.jpg", b);
  EXPECT_EQ(errorOf(path), "image '" + path +
                               "': JPEG header declares 30000 x 30000 pixels (900000000 > " +
                               std::to_string(kMaxImagePixels) + ")");
  // The bound is the caller's: the real 64 x 48 is refused under a 3000-pixel bound.
  const std::string small = write(dir + "/small.jpg", encode(".jpg", pattern(64, 48)));
  EXPECT_THROW(readImageFile(small, "image", ImageMode::Colour, 3000), InputError);
  EXPECT_EQ(readImageFile(small, "image", ImageMode::Colour, 3072).cols, 64);
}

TEST(ImageFile, APngHeaderDeclaringHugeDimensionsIsRefused) {
  const std::string dir = test::tempDir("image-png-bomb");
  std::string b = encode(".png", pattern(64, 48));
  putBe32(b, 16, 20000);
  putBe32(b, 20, 20000);
  const std::string path = write(dir + "/bomb.png", b);
  EXPECT_NE(errorOf(path).find("PNG header declares 20000 x 20000 pixels"), std::string::npos)
      << errorOf(path);
  putBe32(b, 16, 0);
  write(path, b);
  EXPECT_NE(errorOf(path).find("PNG header declares 0 x 20000 pixels"), std::string::npos);
}

TEST(ImageFile, TruncatedAndNonImageFilesAreOneLineErrorsNamingTheFile) {
  const std::string dir = test::tempDir("image-truncated");
  const std::string jpg = encode(".jpg", pattern(64, 48));
  const std::string png = encode(".png", pattern(64, 48));
  // libjpeg decodes a cut JPEG to a partly grey image with only a warning: the missing
  // end-of-image marker is what tells.
  const std::string cut_jpg = write(dir + "/cut.jpg", jpg.substr(0, jpg.size() * 2 / 3));
  EXPECT_EQ(errorOf(cut_jpg), "image '" + cut_jpg + "': truncated JPEG (no end-of-image marker)");
  const std::string head_jpg = write(dir + "/head.jpg", jpg.substr(0, 20));
  EXPECT_EQ(errorOf(head_jpg), "image '" + head_jpg + "': truncated JPEG header");
  const std::string cut_png = write(dir + "/cut.png", png.substr(0, png.size() * 2 / 3));
  EXPECT_NE(errorOf(cut_png).find("image '" + cut_png + "': PNG data cannot be decoded"),
            std::string::npos)
      << errorOf(cut_png);
  const std::string text = write(dir + "/notes.jpg", "not an image at all\n");
  EXPECT_EQ(errorOf(text),
            "image '" + text + "': not an image (expected JPEG, PNG, BMP, PNM, TIFF or WebP)");
  const std::string empty = write(dir + "/empty.png", "");
  EXPECT_EQ(errorOf(empty), "image '" + empty + "': empty file, not an image");
  for (const auto& p : {cut_jpg, head_jpg, cut_png, text, empty})
    EXPECT_EQ(errorOf(p).find('\n'), std::string::npos) << p;
}

TEST(ImageFile, ThinImagesAndAOneByMillionsHeaderNeverCrash) {
  const std::string dir = test::tempDir("image-thin");
  const std::string src = test::sourceDir() + "/tests/cli/fixtures/";
  EXPECT_EQ(readImageFile(src + "thin_1x4000.png", "image").size(), cv::Size(1, 4000));
  EXPECT_EQ(readImageFile(src + "thin_4000x1.png", "image").size(), cv::Size(4000, 1));
  // A JPEG header patched to 1 x 60000 (under the pixel bound, so it is decoded): an image or
  // an InputError, nothing else.
  std::string b = encode(".jpg", pattern(64, 48));
  const std::size_t at = jpegSofHeight(b);
  putBe16(b, at, 60000);
  putBe16(b, at + 2, 1);
  const std::string path = write(dir + "/tall.jpg", b);
  try {
    const cv::Mat m = readImageFile(path, "image");
    EXPECT_FALSE(m.empty());
  } catch (const InputError&) {
  }
}

TEST(ImageFile, RealPhotosDecodeAsImreadDecodesThem) {
  SKETCHNAV_REQUIRE_DATA(voc, "voc07-mini/JPEGImages");
  SKETCHNAV_REQUIRE_DATA(iconic, "grocery-packages/iconic");  // phone photos, larger
  int n = 0;
  for (const auto& e : fs::recursive_directory_iterator(iconic)) {
    if (e.path().extension() != ".jpg") continue;
    const cv::Mat got = readImageFile(e.path().string(), "image");
    const cv::Mat want = cv::imread(e.path().string(), cv::IMREAD_COLOR);
    ASSERT_EQ(got.size(), want.size()) << e.path();
    EXPECT_EQ(cv::norm(got, want, cv::NORM_INF), 0) << e.path();
    ++n;
  }
  for (const auto& e : fs::directory_iterator(voc)) {
    const cv::Mat got = readImageFile(e.path().string(), "image");
    const cv::Mat want = cv::imread(e.path().string(), cv::IMREAD_COLOR);
    ASSERT_EQ(got.size(), want.size()) << e.path();
    EXPECT_EQ(cv::norm(got, want, cv::NORM_INF), 0) << e.path();
    ++n;
  }
  EXPECT_GT(n, 30);
}

TEST(ImageFile, DecodeImageAppliesTheSameRuleToBytesInMemory) {
  const cv::Mat m = pattern(32, 16);
  const cv::Mat got = decodeImage(encode(".png", m), "bytes");
  EXPECT_EQ(cv::norm(got, m, cv::NORM_INF), 0);
  std::string b = encode(".jpg", pattern(64, 48));
  const std::size_t at = jpegSofHeight(b);
  putBe16(b, at, 30000);
  putBe16(b, at + 2, 30000);
  try {
    decodeImage(b, "bytes");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("bytes: JPEG header declares 30000 x 30000 pixels", 0),
              0u)
        << e.what();
  }
  EXPECT_THROW(decodeImage("", "bytes"), InputError);
}

TEST(ImageFile, OneListOfImageFileNames) {
  for (const char* yes : {"a.jpg", "b.JPEG", "c.png", "d.Bmp", "e.pgm", "f.ppm", "g.pnm", "h.tif",
                          "i.TIFF", "j.webp", "/x.y/z.png"})
    EXPECT_TRUE(isImageFileName(yes)) << yes;
  for (const char* no : {"a.txt", "b", "c.jpg.part", ".png/x", "d.gif", "e.json", "png"})
    EXPECT_FALSE(isImageFileName(no)) << no;
}
