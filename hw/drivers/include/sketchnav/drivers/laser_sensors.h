#pragma once
// Laser scanners through MRPT 2.5 hwdrivers, and recorded scans replayed as a device.
//
//   laser://CHokuyoURG?COM_port_LIN=/dev/ttyACM0&pose_x=0.2     a driver by MRPT class name,
//   laser://CHokuyoURG?IP_DIR=192.168.0.10&PORT_DIR=10940       query keys = the driver's .ini keys
//   laser:///etc/robot/laser.ini?section=LASER                  an MRPT .ini; `driver = CLASS`
//                                                               in the section picks the class
//   rawlog:///usr/share/mrpt/datasets/FILE.rawlog[?realtime=1&loop=0&label=NAME]
//
// Supported drivers are whatever MRPT's hwdrivers registry builds as 2-D range finders:
// CHokuyoURG (URG/UTM, serial or Ethernet), CSickLaserSerial, CSickLaserUSB, CLMS100Eth,
// CSICKTim561Eth_2050101, CRoboPeakLidar. Both kinds deliver hw::RangeScan in the robot frame
// (bearing CCW, invalid ranges reported as max_range, the sensor pose as `mount`), stamped
// with the device's Clock when the scan is handed out.
#include <memory>
#include <string>

#include "sketchnav/core/uri.h"
#include "sketchnav/drivers/hw_names.h"

namespace sketchnav::drivers {

/// 2-D scans (CObservation2DRangeScan) from an MRPT rawlog, in either rawlog format
/// (observations, or actions + sensory frames). With `realtime` the scans come out at their
/// recorded pace (read() returns false until the next one is due), like a live device;
/// without, each read() returns the next scan. At the end of the file read() returns false
/// (or restarts, with `loop`) and exhausted() becomes true.
class RawlogRangeSensor final : public RangeSensor {
 public:
  /// Throws InputError naming the file when it cannot be opened or holds no 2-D scan.
  RawlogRangeSensor(const std::string& path, bool realtime, bool loop, std::string label,
                    std::shared_ptr<Clock> clock, std::string uri = {});
  ~RawlogRangeSensor() override;
  bool read(RangeScan& out) override;
  DeviceStats stats() const override;
  std::string uri() const override { return uri_; }
  bool exhausted() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::string uri_;
};

/// A live laser through an MRPT hwdrivers class, polled on a background thread at the
/// driver's process rate. read() returns each new scan once.
class MrptLaser final : public RangeSensor {
 public:
  /// `ini` is an MRPT configuration text; `section` the section holding the driver's keys.
  /// Throws InputError for an unknown driver / bad config, RuntimeError when the device does
  /// not initialise.
  MrptLaser(const std::string& driver, const std::string& ini, const std::string& section,
            std::shared_ptr<Clock> clock, std::string uri = {});
  ~MrptLaser() override;
  bool read(RangeScan& out) override;
  DeviceStats stats() const override;
  std::string uri() const override { return uri_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::string uri_;
};

/// The laser drivers MRPT hwdrivers can create (class names), for help texts and errors.
std::string supportedLaserDrivers();

/// Builds a range sensor from a laser:// or rawlog:// URI (used by the registry).
std::unique_ptr<RangeSensor> createLaserFromUri(const Uri& uri, std::shared_ptr<Clock> clock);

}  // namespace sketchnav::drivers
