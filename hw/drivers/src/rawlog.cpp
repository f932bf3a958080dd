#include "sketchnav/drivers/rawlog.h"

#include <fcntl.h>
#include <unistd.h>

#include <mrpt/core/Clock.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/io/CMemoryStream.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationImage.h>
#include <mrpt/obs/CObservationOdometry.h>
#include <mrpt/obs/CObservationRange.h>
#include <mrpt/serialization/CArchive.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <deque>
#include <filesystem>
#include <mutex>
#include <vector>

#include "laser_convert.h"
#include "rawlog_record.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/image_file.h"
#include "sketchnav/core/log.h"

namespace sketchnav::drivers {
namespace fs = std::filesystem;

namespace {
// MRPT's convention: the images of "dir/run.rawlog" live in "dir/run_Images/".
std::string imageDirFor(const std::string& path) {
  const fs::path p(path);
  return (p.parent_path() / (p.stem().string() + "_Images")).string();
}
mrpt::Clock::time_point toMrpt(double stamp) {
  return mrpt::Clock::fromDouble(stamp);
}
}  // namespace

struct RawlogRecorder::Impl {
  int fd = -1;
  std::mutex mutex;
  std::uint64_t records = 0, images = 0;
  std::string path;

  void write(const mrpt::serialization::CSerializable& obj) {
    mrpt::io::CMemoryStream mem;
    auto arch = mrpt::serialization::archiveFrom(mem);
    arch << obj;
    const auto* p = static_cast<const char*>(mem.getRawBufferData());
    std::size_t left = mem.getTotalBytesCount();
    // One record, one write() (retried only if the kernel takes part of it): what reached the
    // kernel survives the process being killed.
    while (left > 0) {
      const ssize_t n = ::write(fd, p, left);
      if (n < 0) {
        if (errno == EINTR) continue;
        throw RuntimeError("rawlog '" + path + "': write failed: " + std::strerror(errno));
      }
      p += n;
      left -= static_cast<std::size_t>(n);
    }
    ++records;
  }
};

RawlogRecorder::RawlogRecorder(const std::string& path)
    : impl_(std::make_unique<Impl>()), path_(path), image_dir_(imageDirFor(path)) {
  std::error_code ec;
  const fs::path parent = fs::path(path).parent_path();
  if (!parent.empty()) fs::create_directories(parent, ec);
  fs::create_directories(image_dir_, ec);
  if (ec)
    throw RuntimeError("rawlog '" + path + "': cannot create " + image_dir_ + ": " + ec.message());
  impl_->path = path;
  impl_->fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (impl_->fd < 0)
    throw RuntimeError("rawlog '" + path + "': cannot create: " + std::strerror(errno));
  log::info("rawlog", "recording", {{"file", path}, {"images", image_dir_}});
}

RawlogRecorder::~RawlogRecorder() {
  if (impl_->fd >= 0) ::close(impl_->fd);
}

void RawlogRecorder::addFrame(const Frame& frame, const Intrinsics& k, const std::string& label) {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  char name[64];
  std::snprintf(name, sizeof name, "img_%08llu.png",
                static_cast<unsigned long long>(impl_->images++));
  // The image file first: a record never names an image that is not on disk yet.
  if (!cv::imwrite(image_dir_ + "/" + name, frame.image))
    throw RuntimeError("rawlog '" + path_ + "': cannot write image " + image_dir_ + "/" + name);
  mrpt::obs::CObservationImage obs;
  obs.sensorLabel = label;
  obs.timestamp = toMrpt(frame.stamp);
  obs.cameraParams.ncols = static_cast<uint32_t>(k.width);
  obs.cameraParams.nrows = static_cast<uint32_t>(k.height);
  obs.cameraParams.setIntrinsicParamsFromValues(k.fx, k.fy, k.cx, k.cy);
  obs.image.setExternalStorage(name);
  impl_->write(obs);
}

void RawlogRecorder::addOdometry(const Odometry& o, const std::string& label) {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  mrpt::obs::CObservationOdometry obs;
  obs.sensorLabel = label;
  obs.timestamp = toMrpt(o.stamp);
  obs.odometry = mrpt::poses::CPose2D(o.pose.x, o.pose.y, o.pose.theta);
  obs.hasVelocities = true;
  obs.velocityLocal = mrpt::math::TTwist2D(o.v, 0.0, o.w);
  impl_->write(obs);
}

void RawlogRecorder::addCommand(double v, double w, double stamp, const std::string& label) {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  mrpt::obs::CObservationOdometry obs;
  obs.sensorLabel = label;
  obs.timestamp = toMrpt(stamp);
  obs.hasVelocities = true;
  obs.velocityLocal = mrpt::math::TTwist2D(v, 0.0, w);
  impl_->write(obs);
}

void RawlogRecorder::addRange(const RangeScan& s, const std::string& label_in) {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  const bool laser = s.kind == RangeScan::Kind::Laser;
  const std::string label = label_in.empty() ? (laser ? "LASER" : "SONAR") : label_in;
  if (laser && s.angles.size() >= 2) {
    mrpt::obs::CObservation2DRangeScan obs;
    obs.sensorLabel = label;
    obs.timestamp = toMrpt(s.stamp);
    obs.sensorPose = mrpt::poses::CPose3D(s.mount.x, s.mount.y, 0.0, s.mount.theta, 0.0, 0.0);
    const double first = s.angles.front() - s.mount.theta, last = s.angles.back() - s.mount.theta;
    // MRPT scans are evenly spaced and symmetric about the sensor axis: store the span.
    obs.aperture = static_cast<float>(std::abs(last - first));
    obs.rightToLeft = last > first;
    obs.maxRange = s.max_range;
    obs.beamAperture = s.beam_width;
    obs.resizeScan(s.ranges.size());
    for (std::size_t i = 0; i < s.ranges.size(); ++i) {
      obs.setScanRange(i, s.ranges[i]);
      obs.setScanRangeValidity(i, s.ranges[i] < s.max_range);
    }
    impl_->write(obs);
    return;
  }
  mrpt::obs::CObservationRange obs;
  obs.sensorLabel = label;
  obs.timestamp = toMrpt(s.stamp);
  obs.minSensorDistance = s.min_range;
  obs.maxSensorDistance = s.max_range;
  obs.sensorConeApperture = s.beam_width;
  for (std::size_t i = 0; i < s.ranges.size() && i < s.angles.size(); ++i) {
    mrpt::obs::CObservationRange::TMeasurement m;
    m.sensorID = static_cast<uint16_t>(i);
    m.sensorPose = mrpt::math::TPose3D(s.mount.x, s.mount.y, 0.0, s.angles[i], 0.0, 0.0);
    m.sensedDistance = s.ranges[i];
    obs.sensedData.push_back(m);
  }
  impl_->write(obs);
}

std::uint64_t RawlogRecorder::records() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->records;
}

// ---------------------------------------------------------------------------------------

struct RawlogReader::Impl {
  std::string path, image_dir;
  mrpt::io::CFileGZInputStream file;
  std::size_t entry = 0;
  bool eof = false;
  std::uint64_t truncated = 0;
  std::deque<mrpt::obs::CObservation::Ptr> pending;
  std::vector<std::uint8_t> bytes;  // the record being read

  bool fetch() {
    while (pending.empty() && !eof) {
      // The record's bytes first, every length in them checked (rawlog_record.h); MRPT then
      // deserialises from those bytes only, so no length field can make it allocate more.
      const RawlogRecordRead got = readRawlogRecord(file, bytes);
      if (got.status == RawlogRecordRead::Status::End) {
        eof = true;
        break;
      }
      ++entry;
      if (got.status == RawlogRecordRead::Status::Incomplete) {
        // The tail of a killed recording: everything before it is intact.
        end("log ends with an incomplete record", got.field);
        break;
      }
      if (got.status == RawlogRecordRead::Status::Corrupt ||
          got.status == RawlogRecordRead::Status::Foreign) {
        end("log ends at a corrupt record", got.field);
        break;
      }
      std::string bad;
      const mrpt::obs::CObservation::Ptr obs = decodeRawlogRecord(bytes, bad);
      if (obs) bad = corruptField(*obs);
      if (!bad.empty()) {
        // Like an undecodable record: the log ends here, everything before is intact.
        end("log ends at a corrupt record", bad);
        break;
      }
      pending.push_back(obs);
    }
    return !pending.empty();
  }

  void end(const char* message, const std::string& field) {
    ++truncated;
    eof = true;
    log::warn("rawlog", message,
              {{"file", path}, {"record", std::to_string(entry)}, {"field", field}});
  }

  // The bool fields next() reads, checked as bytes (see boolByte()).
  static std::string corruptField(const mrpt::obs::CObservation& o) {
    if (const auto* scan = dynamic_cast<const mrpt::obs::CObservation2DRangeScan*>(&o))
      return corruptScanField(*scan);
    if (const auto* odo = dynamic_cast<const mrpt::obs::CObservationOdometry*>(&o))
      if (const unsigned b = boolByte(odo->hasVelocities); b > 1)
        return "hasVelocities byte " + std::to_string(b);
    return {};
  }
};

RawlogReader::RawlogReader(const std::string& path) : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  impl_->image_dir = imageDirFor(path);
  if (!fs::is_regular_file(path) || !impl_->file.open(path))
    throw InputError("rawlog '" + path + "': cannot open");
}

RawlogReader::~RawlogReader() = default;

std::uint64_t RawlogReader::truncated() const {
  return impl_->truncated;
}

bool RawlogReader::next(RawlogEntry& out, bool load_images) {
  using namespace mrpt::obs;
  if (!impl_->fetch()) return false;
  const CObservation::Ptr o = impl_->pending.front();
  impl_->pending.pop_front();
  out = RawlogEntry{};
  out.label = o->sensorLabel;
  out.stamp = mrpt::Clock::toDouble(o->timestamp);
  if (auto img = std::dynamic_pointer_cast<CObservationImage>(o)) {
    out.kind = RawlogEntry::Kind::Frame;
    const auto& c = img->cameraParams;
    out.intrinsics.width = static_cast<int>(c.ncols);
    out.intrinsics.height = static_cast<int>(c.nrows);
    out.intrinsics.fx = c.fx();
    out.intrinsics.fy = c.fy();
    out.intrinsics.cx = c.cx();
    out.intrinsics.cy = c.cy();
    out.frame.stamp = out.stamp;
    if (img->image.isExternallyStored()) {
      const std::string file = img->image.getExternalStorageFile();
      out.frame.source = file;
      if (load_images) {
        const fs::path p =
            fs::path(file).is_absolute() ? fs::path(file) : fs::path(impl_->image_dir) / file;
        try {
          out.frame.image = readImageFile(p.string(), "rawlog image");
        } catch (const InputError&) {
          out.frame.image.release();  // missing or corrupt: the frame comes without an image
        }
      }
    } else if (load_images) {
      out.frame.image = img->image.asCvMatRef().clone();
      if (out.frame.image.channels() == 1)
        cv::cvtColor(out.frame.image, out.frame.image, cv::COLOR_GRAY2BGR);
    }
  } else if (auto odo = std::dynamic_pointer_cast<CObservationOdometry>(o)) {
    const bool command = o->sensorLabel == "CMD_VEL";
    out.kind = command ? RawlogEntry::Kind::Command : RawlogEntry::Kind::Odometry;
    out.odometry.pose = {odo->odometry.x(), odo->odometry.y(), odo->odometry.phi()};
    if (odo->hasVelocities) {
      out.odometry.v = odo->velocityLocal.vx;
      out.odometry.w = odo->velocityLocal.omega;
    }
    out.odometry.stamp = out.stamp;
    out.v = out.odometry.v;
    out.w = out.odometry.w;
  } else if (auto scan = std::dynamic_pointer_cast<CObservation2DRangeScan>(o)) {
    out.kind = RawlogEntry::Kind::Range;
    toRangeScan(*scan, out.range);
    out.range.stamp = out.stamp;
  } else if (auto r = std::dynamic_pointer_cast<CObservationRange>(o)) {
    out.kind = RawlogEntry::Kind::Range;
    out.range.kind = RangeScan::Kind::Sonar;
    out.range.min_range = r->minSensorDistance;
    out.range.max_range = r->maxSensorDistance;
    out.range.beam_width = r->sensorConeApperture;
    for (const auto& m : r->sensedData) {
      out.range.mount = {m.sensorPose.x, m.sensorPose.y, 0.0};
      out.range.angles.push_back(static_cast<float>(m.sensorPose.yaw));
      out.range.ranges.push_back(m.sensedDistance);
    }
    out.range.stamp = out.stamp;
  }
  return true;
}

// ---------------------------------------------------------------------------------------

ReplayOrigin replayOrigin(double first_stamp, const Clock& clock, bool run_clock) {
  if (run_clock) return {};
  return {std::isfinite(first_stamp) ? first_stamp : 0.0, clock.now()};
}

bool rawlogHasRunInfo(const std::string& path) {
  std::error_code ec;
  return std::filesystem::is_regular_file(path + ".run.json", ec);
}

double rawlogFirstStamp(const std::string& path) {
  RawlogReader r(path);
  RawlogEntry e;
  return r.next(e, false) ? e.stamp : NAN;
}

RawlogCamera::RawlogCamera(const std::string& path, std::string label, std::string uri,
                           std::shared_ptr<Clock> clock)
    : reader_(std::make_unique<RawlogReader>(path)),
      label_(std::move(label)),
      uri_(uri.empty() ? "rawlog://" + path : uri),
      clock_(std::move(clock)) {
  if (clock_) {
    const ReplayOrigin o = replayOrigin(rawlogFirstStamp(path), *clock_, rawlogHasRunInfo(path));
    t0_rec_ = o.t0_rec;
    t0_clock_ = o.t0_clock;
  }
  // Read ahead to the first frame so intrinsics() is right before the first grab().
  RawlogEntry e;
  while (reader_->next(e, true)) {
    if (e.kind == RawlogEntry::Kind::Frame && (label_.empty() || e.label == label_)) {
      intrinsics_ = e.intrinsics;
      first_ = std::move(e);
      have_first_ = true;
      return;
    }
  }
  throw InputError("camera URI '" + uri_ + "': '" + path + "' holds no camera frame" +
                   (label_.empty() ? std::string() : " labelled '" + label_ + "'"));
}

RawlogCamera::~RawlogCamera() = default;

GrabStatus RawlogCamera::grab(Frame& frame, double timeout_s) {
  while (true) {
    RawlogEntry e;
    if (have_first_) {
      e = std::move(first_);
      have_first_ = false;
    } else if (!reader_->next(e, true)) {
      return GrabStatus::EndOfStream;
    }
    if (e.kind != RawlogEntry::Kind::Frame || (!label_.empty() && e.label != label_)) continue;
    if (e.frame.image.empty()) {
      ++stats_.dropped;
      stats_.last_error = "missing image " + e.frame.source;
      log::warn("rawlog", "frame skipped: image missing", {{"image", e.frame.source}});
      continue;
    }
    if (clock_) {
      // Wait (or, on a simulated clock, jump) until the frame is due; a caller that will not
      // wait that long gets Timeout and the frame on the next call.
      const double due = t0_clock_ + (e.stamp - t0_rec_), now = clock_->now();
      if (std::abs(due - now) <= kReplaySlack) {
        e.frame.stamp = now;
      } else if (due - now > timeout_s) {
        clock_->sleepUntil(now + timeout_s);
        first_ = std::move(e);
        have_first_ = true;
        return GrabStatus::Timeout;
      } else {
        clock_->sleepUntil(due);
        e.frame.stamp = due;
      }
    }
    frame = std::move(e.frame);
    frame.seq = stats_.received++;
    return GrabStatus::Ok;
  }
}

// ---------------------------------------------------------------------------------------

RawlogBase::RawlogBase(const std::string& path, std::shared_ptr<Clock> clock, std::string label,
                       std::string uri)
    : reader_(std::make_unique<RawlogReader>(path)),
      clock_(clock ? std::move(clock) : std::make_shared<SteadyClock>()),
      label_(std::move(label)),
      uri_(uri.empty() ? "rawlog://" + path : uri) {
  if (!fetch())
    throw InputError("base URI '" + uri_ + "': '" + path + "' holds no odometry labelled '" +
                     label_ + "'");
  const ReplayOrigin o = replayOrigin(rawlogFirstStamp(path), *clock_, rawlogHasRunInfo(path));
  t0_rec_ = o.t0_rec;
  t0_clock_ = o.t0_clock;
}

RawlogBase::~RawlogBase() = default;

bool RawlogBase::fetch() {
  RawlogEntry e;
  while (reader_->next(e, false)) {
    if (e.kind == RawlogEntry::Kind::Odometry && e.label == label_) {
      next_ = e.odometry;
      have_next_ = true;
      return true;
    }
  }
  have_next_ = false;
  return false;
}

void RawlogBase::command(double, double) {
  ++stats_.received;
}

bool RawlogBase::odometry(Odometry& out) {
  const double now = clock_->now();
  // Move to the newest record that is due on the replay clock.
  // (1 us of slack: MRPT stores times in 100 ns ticks, so a record stamped exactly on a tick
  // of the replay clock must not wait for the next one.)
  while (have_next_ && t0_clock_ + (next_.stamp - t0_rec_) <= now + kReplaySlack) {
    current_ = next_;
    current_.stamp = t0_clock_ + (next_.stamp - t0_rec_);
    have_current_ = true;
    if (!fetch()) ended_ = true;
  }
  if (!have_current_) return false;
  out = current_;
  return true;
}

}  // namespace sketchnav::drivers
