#include "sketchnav/drivers/laser_sensors.h"

#include <mrpt/config/CConfigFileMemory.h>
#include <mrpt/core/Clock.h>
#include <mrpt/hwdrivers/CGenericSensor.h>
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/obs/CActionCollection.h>
#include <mrpt/obs/CObservation2DRangeScan.h>
#include <mrpt/obs/CObservationRange.h>
#include <mrpt/obs/CRawlog.h>
#include <mrpt/obs/CSensoryFrame.h>
#include <mrpt/serialization/CArchive.h>

#include <atomic>
#include <cmath>
#include <deque>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>
#include <thread>

#include "laser_convert.h"
#include "rawlog_record.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/log.h"
#include "sketchnav/drivers/rawlog.h"

namespace sketchnav::drivers {

using mrpt::obs::CObservation2DRangeScan;

void toRangeScan(const CObservation2DRangeScan& o, RangeScan& s) {
  const std::size_t n = o.getScanSize();
  s = RangeScan{};
  s.kind = RangeScan::Kind::Laser;
  s.max_range = o.maxRange;
  s.min_range = 0.0f;
  s.beam_width = o.beamAperture;
  s.mount = {o.sensorPose.x(), o.sensorPose.y(), o.sensorPose.yaw()};
  s.angles.resize(n);
  s.ranges.resize(n);
  // MRPT: beam i is at -aperture/2 + i * aperture / (n - 1) from the sensor's x axis when
  // scanning right to left (CCW), mirrored otherwise. Bearings here are in the robot frame.
  const double step = n > 1 ? o.aperture / static_cast<double>(n - 1) : 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double rel = -0.5 * o.aperture + step * static_cast<double>(i);
    const double a = s.mount.theta + (o.rightToLeft ? rel : -rel);
    s.angles[i] = static_cast<float>(std::atan2(std::sin(a), std::cos(a)));
    const float r = o.getScanRange(i);
    s.ranges[i] = (o.getScanRangeValidity(i) && r > 0.0f) ? r : o.maxRange;
  }
}

// ---------------------------------------------------------------------------------------

struct RawlogRangeSensor::Impl {
  std::string path, label;
  bool realtime = true, loop = false;
  std::shared_ptr<Clock> clock;
  std::mutex mutex;
  std::unique_ptr<mrpt::io::CFileGZInputStream> file;
  std::deque<std::pair<double, RangeScan>> queue;  // decoded scans, recorded time [s]
  bool eof = false, exhausted = false;
  std::size_t entry = 0;
  double t0_rec = NAN, t0_clock = 0, last_rec = NAN, first_any = NAN;
  std::uint64_t scans_in_file = 0;
  DeviceStats stats;
  // A log whose first record is one run --record writes is read record by record with every
  // length checked before anything is allocated (rawlog_record.h), as RawlogReader does: a
  // corrupt recording cannot make MRPT allocate what a length field claims. Other logs (MRPT's
  // own datasets: CSensoryFrame and action records) are read by MRPT, which knows them.
  bool bounded = false;
  std::vector<std::uint8_t> bytes;  // the record being read (bounded)

  void reopen() {
    file = std::make_unique<mrpt::io::CFileGZInputStream>();
    if (!file->open(path)) throw InputError("rawlog '" + path + "': cannot open");
    eof = false;
    entry = 0;
  }

  // Whether the log is one of ours, from its first record (the file is reopened after).
  void chooseReader() {
    const RawlogRecordRead first = readRawlogRecord(*file, bytes);
    bounded = first.status != RawlogRecordRead::Status::Foreign;
    reopen();
  }

  void stop(const char* message, const std::string& field) {
    // Like an undecodable entry: the log ends here, everything before it is intact.
    log::warn("rawlog", message,
              {{"file", path}, {"record", std::to_string(entry)}, {"field", field}});
    ++stats.incomplete;
    eof = true;
  }

  // One record of a bounded log; false when the log ends (or stops at a bad record).
  bool nextBounded() {
    const RawlogRecordRead got = readRawlogRecord(*file, bytes);
    if (got.status == RawlogRecordRead::Status::End) return false;
    ++entry;
    if (got.status == RawlogRecordRead::Status::Incomplete) {
      stop("log ends with an incomplete record", got.field);
      return false;
    }
    if (got.status != RawlogRecordRead::Status::Ok) {
      stop("log ends at a corrupt record", got.field);
      return false;
    }
    std::string bad;
    const mrpt::obs::CObservation::Ptr obs = decodeRawlogRecord(bytes, bad);
    if (!obs) {
      stop("log ends at a corrupt record", bad);
      return false;
    }
    take(obs);
    return true;
  }

  void take(const mrpt::obs::CObservation::Ptr& o) {
    // The log's first record of any kind is the replay's time origin (shared with the
    // replayed camera and base, so they stay in step).
    if (std::isnan(first_any) && o->timestamp != INVALID_TIMESTAMP)
      first_any = mrpt::Clock::toDouble(o->timestamp);
    if (!label.empty() && o->sensorLabel != label) return;
    RangeScan s;
    if (auto scan = std::dynamic_pointer_cast<CObservation2DRangeScan>(o)) {
      if (const std::string bad = corruptScanField(*scan); !bad.empty()) {
        // Like an undecodable entry (fill()): the log ends here.
        log::warn("rawlog", "stopped at a corrupt laser scan", {{"file", path}, {"field", bad}});
        ++stats.incomplete;
        eof = true;
        return;
      }
      toRangeScan(*scan, s);
    } else if (auto r = std::dynamic_pointer_cast<mrpt::obs::CObservationRange>(o);
               r && !label.empty()) {
      // Sonars only when asked for by label: a log's default range stream is its laser.
      s.kind = RangeScan::Kind::Sonar;
      s.min_range = r->minSensorDistance;
      s.max_range = r->maxSensorDistance;
      s.beam_width = r->sensorConeApperture;
      for (const auto& m : r->sensedData) {
        s.mount = {m.sensorPose.x, m.sensorPose.y, 0.0};
        s.angles.push_back(static_cast<float>(m.sensorPose.yaw));
        s.ranges.push_back(m.sensedDistance);
      }
    } else {
      return;
    }
    double t = mrpt::Clock::toDouble(o->timestamp);
    // Logs without timestamps are paced at 10 Hz (MRPT's default laser rate).
    if (o->timestamp == INVALID_TIMESTAMP || !std::isfinite(t))
      t = std::isnan(last_rec) ? 0.0 : last_rec + 0.1;
    last_rec = t;
    queue.emplace_back(t, std::move(s));
  }

  // Decodes entries until `want` scans are queued or the file ends.
  void fill(std::size_t want = 1) {
    while (queue.size() < want && !eof) {
      if (bounded) {
        if (!nextBounded()) eof = true;
        continue;
      }
      mrpt::obs::CActionCollection::Ptr action;
      mrpt::obs::CSensoryFrame::Ptr sf;
      mrpt::obs::CObservation::Ptr obs;
      auto arch = mrpt::serialization::archiveFrom(*file);
      bool ok = false;
      try {
        ok =
            mrpt::obs::CRawlog::getActionObservationPairOrObservation(arch, action, sf, obs, entry);
      } catch (const std::exception& e) {
        // A truncated tail (a recording that was killed) ends the log; it is not an error.
        log::warn("rawlog", "stopped at an unreadable entry", {{"file", path}, {"why", e.what()}});
        ++stats.incomplete;
        ok = false;
      }
      if (!ok) {
        eof = true;
        break;
      }
      if (obs) take(obs);
      if (sf)
        for (const auto& o : *sf) take(o);
    }
  }
};

RawlogRangeSensor::RawlogRangeSensor(const std::string& path, bool realtime, bool loop,
                                     std::string label, std::shared_ptr<Clock> clock,
                                     std::string uri)
    : impl_(std::make_unique<Impl>()), uri_(uri.empty() ? "rawlog://" + path : uri) {
  if (!std::filesystem::is_regular_file(path))
    throw InputError("range URI '" + uri_ + "': no such rawlog file '" + path + "'");
  Impl& s = *impl_;
  s.path = path;
  s.label = std::move(label);
  s.realtime = realtime;
  s.loop = loop;
  s.clock = clock ? std::move(clock) : std::make_shared<SteadyClock>();
  s.reopen();
  s.chooseReader();
  s.fill();
  if (s.queue.empty())
    throw InputError("range URI '" + uri_ + "': '" + path + "' holds no 2-D laser scan" +
                     std::string(s.label.empty() ? "" : " or sonar") +
                     (s.label.empty() ? std::string() : " labelled '" + s.label + "'"));
  const ReplayOrigin o =
      replayOrigin(std::isnan(s.first_any) ? s.queue.front().first
                                           : std::min(s.first_any, s.queue.front().first),
                   *s.clock, rawlogHasRunInfo(path));
  s.t0_rec = o.t0_rec;
  s.t0_clock = o.t0_clock;
}

RawlogRangeSensor::~RawlogRangeSensor() = default;

bool RawlogRangeSensor::read(RangeScan& out) {
  Impl& s = *impl_;
  std::lock_guard<std::mutex> lock(s.mutex);
  s.fill();
  if (s.queue.empty() && s.loop) {
    s.reopen();
    s.fill();
    if (!s.queue.empty()) {
      s.t0_rec = s.queue.front().first;
      s.t0_clock = s.clock->now();
    }
  }
  if (s.queue.empty()) {
    s.exhausted = true;
    return false;
  }
  const double now = s.clock->now();
  if (s.realtime) {
    // Deliver the newest scan that is due; scans a slow reader missed count as dropped,
    // as they would with a live device.
    const double due = s.t0_clock + (s.queue.front().first - s.t0_rec);
    if (due > now + kReplaySlack) return false;
    while (true) {
      s.fill(2);
      if (s.queue.size() < 2) break;
      const double next_due = s.t0_clock + (s.queue[1].first - s.t0_rec);
      if (next_due > now + kReplaySlack) break;
      s.queue.pop_front();
      ++s.stats.dropped;
    }
  }
  // Stamped when it was due on the replay clock (when the run scanned), not when it is read.
  const double due = s.t0_clock + (s.queue.front().first - s.t0_rec);
  out = std::move(s.queue.front().second);
  s.queue.pop_front();
  out.stamp = s.realtime ? std::min(due, now) : now;
  ++s.stats.received;
  return true;
}

DeviceStats RawlogRangeSensor::stats() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->stats;
}

bool RawlogRangeSensor::exhausted() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->exhausted;
}

// ---------------------------------------------------------------------------------------

namespace {
const char* const kLaserDrivers[] = {"CHokuyoURG", "CSickLaserSerial",       "CSickLaserUSB",
                                     "CLMS100Eth", "CSICKTim561Eth_2050101", "CRoboPeakLidar"};
}  // namespace

std::string supportedLaserDrivers() {
  std::string s;
  for (const char* d : kLaserDrivers) s += (s.empty() ? "" : ", ") + std::string(d);
  return s;
}

struct MrptLaser::Impl {
  std::shared_ptr<Clock> clock;
  std::string uri;
  mrpt::hwdrivers::CGenericSensor::Ptr sensor;
  std::thread thread;
  std::atomic<bool> quit{false};
  std::mutex mutex;
  bool fresh = false;
  RangeScan latest;
  DeviceStats stats;

  void loop() {
    // The driver reads one scan per doProcess(): poll faster than any supported scanner
    // (40 Hz for a UTM-30LX) unless the configuration says otherwise.
    const double rate = sensor->getProcessRate();
    const double period = 1.0 / (rate > 0 ? rate : 50.0);
    SteadyClock wall;
    double next = wall.now();
    while (!quit) {
      mrpt::hwdrivers::CGenericSensor::TListObservations obs;
      try {
        sensor->doProcess();
        sensor->getObservations(obs);
      } catch (const std::exception& e) {
        std::lock_guard<std::mutex> lock(mutex);
        ++stats.dropped;
        stats.last_error = e.what();
        log::warn("laser", "driver error", {{"uri", uri}, {"why", e.what()}});
      }
      for (const auto& [ts, o] : obs) {
        auto scan = std::dynamic_pointer_cast<CObservation2DRangeScan>(o);
        if (!scan) continue;
        RangeScan s;
        toRangeScan(*scan, s);
        s.stamp = clock->now();
        std::lock_guard<std::mutex> lock(mutex);
        if (fresh) ++stats.dropped;  // the previous scan was never read
        latest = std::move(s);
        fresh = true;
        ++stats.received;
        stats.last_error.clear();
      }
      if (sensor->getState() == mrpt::hwdrivers::CGenericSensor::ssError) {
        std::lock_guard<std::mutex> lock(mutex);
        stats.last_error = "driver reports an error state";
      }
      next += period;
      if (next < wall.now()) next = wall.now();
      while (!quit && wall.now() < next) wall.sleepUntil(std::min(next, wall.now() + 0.02));
    }
  }
};

MrptLaser::MrptLaser(const std::string& driver, const std::string& ini, const std::string& section,
                     std::shared_ptr<Clock> clock, std::string uri)
    : impl_(std::make_unique<Impl>()), uri_(uri.empty() ? "laser://" + driver : uri) {
  Impl& s = *impl_;
  s.clock = clock ? std::move(clock) : std::make_shared<SteadyClock>();
  s.uri = uri_;
  bool known = false;
  for (const char* d : kLaserDrivers) known = known || driver == d;
  if (!known)
    throw InputError("range URI '" + uri_ + "': unknown laser driver '" + driver +
                     "' (known: " + supportedLaserDrivers() + ")");
  s.sensor = mrpt::hwdrivers::CGenericSensor::createSensorPtr(driver);
  if (!s.sensor)
    throw InputError("range URI '" + uri_ + "': MRPT hwdrivers has no driver '" + driver + "'");
  try {
    mrpt::config::CConfigFileMemory cfg(ini);
    s.sensor->loadConfig(cfg, section);
  } catch (const std::exception& e) {
    throw InputError("range URI '" + uri_ +
                     "': bad laser configuration: " + std::string(e.what()).substr(0, 300));
  }
  try {
    s.sensor->initialize();
  } catch (const std::exception& e) {
    throw RuntimeError("range URI '" + uri_ +
                       "': laser did not initialise: " + std::string(e.what()).substr(0, 300));
  }
  s.thread = std::thread([this] { impl_->loop(); });
  log::info("laser", "streaming", {{"uri", uri_}, {"driver", driver}});
}

MrptLaser::~MrptLaser() {
  impl_->quit = true;
  if (impl_->thread.joinable()) impl_->thread.join();
}

bool MrptLaser::read(RangeScan& out) {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  if (!impl_->fresh) return false;
  out = impl_->latest;
  impl_->fresh = false;
  return true;
}

DeviceStats MrptLaser::stats() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->stats;
}

// ---------------------------------------------------------------------------------------

std::unique_ptr<RangeSensor> createLaserFromUri(const Uri& uri, std::shared_ptr<Clock> clock) {
  if (uri.scheme == "rawlog") {
    if (uri.path.empty())
      throw InputError("range URI '" + uri.text + "': expected rawlog:///path/file.rawlog");
    return std::make_unique<RawlogRangeSensor>(uri.path, uri.paramInt("realtime", 1) != 0,
                                               uri.paramInt("loop", 0) != 0, uri.param("label", ""),
                                               std::move(clock), uri.text);
  }
  // laser://DRIVER?key=value...: the query becomes the driver's .ini section.
  // laser:///path/file.ini?section=S: an MRPT .ini whose section names the driver.
  const std::string section = uri.param("section", "LASER");
  std::string ini, driver = uri.authority;
  if (!uri.path.empty()) {
    std::ifstream in(uri.path);
    if (!in) throw InputError("range URI '" + uri.text + "': cannot read '" + uri.path + "'");
    std::stringstream ss;
    ss << in.rdbuf();
    ini = ss.str();
    mrpt::config::CConfigFileMemory cfg(ini);
    driver = cfg.read_string(section, "driver", "");
    if (driver.empty())
      throw InputError("range URI '" + uri.text + "': section [" + section + "] of '" + uri.path +
                       "' has no 'driver = CLASS' line");
  } else {
    if (driver.empty())
      throw InputError("range URI '" + uri.text +
                       "': expected laser://DRIVER?... or "
                       "laser:///path/config.ini");
    ini = "[" + section + "]\n";
    for (const auto& [k, v] : uri.query)
      if (k != "section") ini += k + " = " + v + "\n";
    if (!uri.hasParam("process_rate")) ini += "process_rate = 50\n";
  }
  return std::make_unique<MrptLaser>(driver, ini, section, std::move(clock), uri.text);
}

}  // namespace sketchnav::drivers
