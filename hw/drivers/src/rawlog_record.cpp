#include "rawlog_record.h"

#include <mrpt/io/CMemoryStream.h>
#include <mrpt/serialization/CArchive.h>

#include <algorithm>
#include <climits>
#include <cstring>
#include <string_view>

namespace sketchnav::drivers {
namespace {

using Status = RawlogRecordRead::Status;

struct Refused {
  Status status;
  std::string field;
};

// The walk mirrors serializeFrom() of MRPT 2.5 (libs/obs, libs/img, libs/poses) for the
// versions accepted here; RawlogReader checks that MRPT consumed exactly the bytes walked, so
// a mismatch is refused rather than misread.
class Walker {
 public:
  Walker(mrpt::io::CStream& in, std::vector<std::uint8_t>& bytes, std::size_t max)
      : in_(in), bytes_(bytes), max_(max) {}

  // Appends the next `n` bytes of the file; returns where they start. The length is checked
  // against the record's bound before anything is read or allocated, and the file is read in
  // chunks so a length that overshoots a short file costs only the bytes that are there.
  std::size_t take(std::uint64_t n, const std::string& field) {
    const std::size_t at = bytes_.size();
    if (n > max_ - at)
      throw Refused{Status::Corrupt,
                    field + " needs " + std::to_string(n) + " bytes, more than a record may hold"};
    std::uint64_t left = n;
    while (left > 0) {
      const std::size_t chunk = static_cast<std::size_t>(std::min<std::uint64_t>(left, 1 << 16));
      const std::size_t old = bytes_.size();
      bytes_.resize(old + chunk);
      const std::size_t got = read(bytes_.data() + old, chunk);
      bytes_.resize(old + got);
      if (got == 0) throw Refused{Status::Incomplete, field};
      left -= got;
    }
    return at;
  }
  void skip(std::uint64_t n, const std::string& field) { take(n, field); }

  // CFileGZInputStream::Read passes on gzread()'s -1 (corrupt compressed data) as a size_t.
  std::size_t read(void* to, std::size_t n) {
    const std::size_t got = in_.Read(to, n);
    if (got > n) throw Refused{Status::Corrupt, "compressed data (gzip error)"};
    return got;
  }

  template <typename T>
  T pod(const std::string& field) {
    const std::size_t at = take(sizeof(T), field);
    T v;
    std::memcpy(&v, bytes_.data() + at, sizeof(T));  // MRPT streams are little-endian, as we are
    return v;
  }
  std::uint8_t u8(const std::string& f) { return pod<std::uint8_t>(f); }
  std::uint32_t u32(const std::string& f) { return pod<std::uint32_t>(f); }
  std::int32_t i32(const std::string& f) { return pod<std::int32_t>(f); }
  void f32(const std::string& f, int count = 1) { skip(4u * count, f); }
  void f64(const std::string& f, int count = 1) { skip(8u * count, f); }

  // MRPT copies a bool's byte unchecked; one that decides the layout must be 0 or 1.
  bool flag(const std::string& field) {
    const unsigned b = u8(field);
    if (b > 1) throw Refused{Status::Corrupt, field + " byte " + std::to_string(b)};
    return b == 1;
  }
  void string(const std::string& field) {
    const std::uint32_t n = u32(field + " length");
    skip(n, field + " (length " + std::to_string(n) + ")");
  }

  // An object header in MRPT's current format: 0x80 | name length, the name, the version.
  // `h` is its first byte, already taken.
  std::string header(std::uint8_t h, std::uint8_t& version) {
    if (!(h & 0x80)) throw Refused{Status::Corrupt, "object header (old MRPT format)"};
    const std::size_t len = h & 0x7f;
    if (len > 120) throw Refused{Status::Corrupt, "class name length " + std::to_string(len)};
    const std::size_t at = take(len, "class name");
    std::string name(reinterpret_cast<const char*>(bytes_.data() + at), len);
    if (name == "nullptr") throw Refused{Status::Corrupt, "class nullptr"};
    version = u8(clip(name) + " version");
    return name;
  }
  // A member object, whose class is fixed by the member's type.
  void member(std::uint8_t& version, std::string_view expected) {
    const std::string name = header(u8("object header"), version);
    if (name != expected)
      throw Refused{Status::Corrupt,
                    "class " + clip(name) + " where " + std::string(expected) + " belongs"};
  }
  void end(const std::string& cls) {
    const unsigned b = u8(cls + " end flag");
    if (b != 0x88) throw Refused{Status::Corrupt, cls + " end flag " + std::to_string(b)};
  }
  [[noreturn]] static void badVersion(const std::string& cls, unsigned v) {
    throw Refused{Status::Corrupt, cls + " version " + std::to_string(v) + " (not read here)"};
  }

  void pose3d(const std::string& field) {
    std::uint8_t v = 0;
    member(v, "mrpt::poses::CPose3D");
    if (v == 2)
      f64(field, 7);  // x y z + quaternion
    else if (v == 3)
      f64(field, 12);  // x y z + rotation matrix
    else
      badVersion(field + " CPose3D", v);
    end(field + " CPose3D");
  }
  void pose2d(const std::string& field) {
    std::uint8_t v = 0;
    member(v, "mrpt::poses::CPose2D");
    if (v == 0)
      f32(field, 3);
    else if (v == 1)
      f64(field, 3);
    else
      badVersion(field + " CPose2D", v);
    end(field + " CPose2D");
  }

  void scan(unsigned v) {
    if (v < 6 || v > 7) badVersion("CObservation2DRangeScan", v);  // older ones hold a CMatrixF
    f32("aperture");
    flag("rightToLeft");
    f32("maxRange");
    pose3d("sensorPose");
    const std::uint32_t n = u32("scan count");
    // Ranges (float) and validity bytes; MRPT sizes both, and the intensities, from n first.
    skip(5ull * n, "scan (count " + std::to_string(n) + ")");
    f32("stdError");
    skip(8, "timestamp");
    f32("beamAperture");
    string("sensorLabel");
    f64("deltaPitch");
    if (v >= 7 && flag("hasIntensity"))
      skip(4ull * n, "intensity (count " + std::to_string(n) + ")");
  }

  void range(unsigned v) {
    if (v > 3) badVersion("CObservationRange", v);
    f32("minSensorDistance");
    f32("maxSensorDistance");
    f32("sensorConeApperture");
    const std::uint32_t n = u32("sensedData count");
    // MRPT resizes the measurement deque to n before reading one: the smallest measurement
    // (sensor id, a 7-double CPose3D, the distance) must fit n times in what a record may hold.
    const std::uint64_t smallest = (v >= 3 ? 2 : 0) + 1 + 20 + 1 + 7 * 8 + 1 + 4;
    if (n * smallest > max_ - bytes_.size())
      throw Refused{Status::Corrupt,
                    "sensedData count " + std::to_string(n) + ", more than a record may hold"};
    for (std::uint32_t i = 0; i < n; ++i) {
      if (v >= 3) skip(2, "sensorID");
      pose3d("sensorPose");
      f32("sensedDistance");
    }
    if (v >= 1) string("sensorLabel");
    if (v >= 2) skip(8, "timestamp");
  }

  void odometry(unsigned v) {
    if (v > 2) badVersion("CObservationOdometry", v);
    pose2d("odometry");
    string("sensorLabel");
    skip(8, "timestamp");
    if (v >= 1) {
      const bool encoders = flag("hasEncodersInfo");
      if (encoders || v < 2) skip(8, "encoder ticks");
      const bool velocities = flag("hasVelocities");
      if (v < 2)
        f32("velocities", 2);
      else if (velocities)
        f64("velocityLocal", 3);
    }
  }

  void camera() {
    std::uint8_t v = 0;
    member(v, "mrpt::img::TCamera");
    if (v < 4 || v > 6) badVersion("cameraParams TCamera", v);  // older ones hold a matrix
    f64("focalLengthMeters");
    f64("dist", 8);
    f64("intrinsics", 4);
    skip(8, "nrows, ncols");
    if (v >= 5) string("cameraName");
    if (v >= 6) skip(1, "distortion");
    end("cameraParams TCamera");
  }

  void image() {
    std::uint8_t v = 0;
    member(v, "mrpt::img::CImage");
    if (v == 100) {  // written by an MRPT without OpenCV: a file name or nothing
      if (flag("image external")) string("image file");
    } else if (v >= 6 && v <= 9) {
      if (flag("image external")) {
        string("image file");
      } else if (u8("image hasColor") == 0) {
        const std::int64_t w = i32("image width"), h = i32("image height");
        skip(4, "image origin");
        const std::int64_t size = i32("image size");
        std::int64_t pixel = 1;
        if (v >= 9) {
          // OpenCV depths 8U 8S 16U 16S 32S 32F 64F.
          static const int kBytes[] = {1, 1, 2, 2, 4, 4, 8};
          const std::int32_t depth = i32("image depth");
          if (depth < 0 || depth > 6)
            throw Refused{Status::Corrupt, "image depth " + std::to_string(depth)};
          pixel = kBytes[depth];
        }
        // MRPT allocates width x height before it checks the size field against it.
        if (w < 0 || h < 0 || (w > 0 && h > INT32_MAX / w / pixel) || size != w * h * pixel)
          throw Refused{Status::Corrupt, "image " + std::to_string(w) + "x" + std::to_string(h) +
                                             " of " + std::to_string(size) + " bytes"};
        if (flag("image isZIP")) throw Refused{Status::Corrupt, "image (zip-compressed)"};
        skip(static_cast<std::uint64_t>(size), "image data");
      } else {
        // Colour: JPEG (whose decoded size the record cannot bound), or raw with negated sizes.
        const std::int64_t w = v >= 7 ? i32("image width") : 1;
        const std::int64_t h = v >= 7 ? i32("image height") : 1;
        if (w >= 1 && h >= 1) throw Refused{Status::Corrupt, "image (embedded JPEG)"};
        if (w < 0 && h < 0)
          skip(static_cast<std::uint64_t>(-w) * static_cast<std::uint64_t>(-h) * 3,
               "image data (raw " + std::to_string(-w) + "x" + std::to_string(-h) + ")");
        else if (w < 0 || h < 0)
          throw Refused{Status::Corrupt, "image " + std::to_string(w) + "x" + std::to_string(h)};
      }
    } else {
      badVersion("image CImage", v);
    }
    end("image CImage");
  }

  void picture(unsigned v) {
    if (v != 4) badVersion("CObservationImage", v);  // older ones hold matrices
    pose3d("cameraPose");
    camera();
    image();
    skip(8, "timestamp");
    string("sensorLabel");
  }

  RawlogRecordRead record() {
    std::uint8_t first = 0;
    if (read(&first, 1) == 0) return {Status::End, {}};
    bytes_.push_back(first);
    std::uint8_t v = 0;
    const std::string name = header(first, v);
    if (name == "mrpt::obs::CObservation2DRangeScan")
      scan(v);
    else if (name == "mrpt::obs::CObservationRange")
      range(v);
    else if (name == "mrpt::obs::CObservationOdometry")
      odometry(v);
    else if (name == "mrpt::obs::CObservationImage")
      picture(v);
    else
      throw Refused{Status::Foreign, "class " + clip(name) + " (not one run --record writes)"};
    end(name.substr(name.rfind(':') + 1));
    return {Status::Ok, {}};
  }

 private:
  static std::string clip(const std::string& s) {
    std::string out;
    for (const char c : s.substr(0, 60)) out += (c >= 0x20 && c < 0x7f) ? c : '?';
    return out;
  }

  mrpt::io::CStream& in_;
  std::vector<std::uint8_t>& bytes_;
  std::size_t max_;
};

}  // namespace

RawlogRecordRead readRawlogRecord(mrpt::io::CStream& in, std::vector<std::uint8_t>& bytes,
                                  std::size_t max_bytes) {
  bytes.clear();
  Walker w(in, bytes, max_bytes);
  try {
    return w.record();
  } catch (const Refused& r) {
    return {r.status, r.field};
  } catch (const std::exception& e) {
    return {Status::Corrupt, std::string("file read (") + e.what() + ")"};
  }
}

mrpt::obs::CObservation::Ptr decodeRawlogRecord(const std::vector<std::uint8_t>& bytes,
                                                std::string& bad) {
  mrpt::io::CMemoryStream mem;
  mem.assignMemoryNotOwn(bytes.data(), bytes.size());
  auto arch = mrpt::serialization::archiveFrom(mem);
  mrpt::obs::CObservation::Ptr obs;
  try {
    obs = std::dynamic_pointer_cast<mrpt::obs::CObservation>(arch.ReadObject());
    if (mem.getPosition() != bytes.size()) {
      bad = "record layout (MRPT read a different length)";
      return nullptr;
    }
  } catch (const std::exception& e) {
    const std::string what = e.what();
    bad =
        "record layout (MRPT: " + what.substr(0, std::min(what.find('\n'), std::size_t{120})) + ")";
    return nullptr;
  }
  if (!obs) bad = "record class";
  return obs;
}

}  // namespace sketchnav::drivers
