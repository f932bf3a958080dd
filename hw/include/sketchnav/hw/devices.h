#pragma once
// The three device interfaces. Small on purpose: each real device (GigE camera, DaNI base,
// laser) and its simulated twin implement exactly these, nothing more. Devices are not
// copyable; their lifetime is the unique_ptr the registry returns.
#include <string>

#include "sketchnav/hw/types.h"

namespace sketchnav::hw {

enum class GrabStatus {
  Ok,           // `frame` holds a new image
  Timeout,      // nothing arrived in time (a live device may still recover)
  EndOfStream,  // a finite source (folder, file, rawlog) is exhausted
  Error,        // the device failed; stats().last_error says why
};

class Camera {
 public:
  Camera() = default;
  Camera(const Camera&) = delete;
  Camera& operator=(const Camera&) = delete;
  virtual ~Camera() = default;

  /// Waits up to `timeout_s` for the next frame. Never throws for a bad frame: a corrupt
  /// image is skipped with a warning and counted in stats().dropped.
  virtual GrabStatus grab(Frame& frame, double timeout_s = 1.0) = 0;
  virtual Intrinsics intrinsics() const = 0;
  virtual DeviceStats stats() const = 0;
  virtual std::string uri() const = 0;
};

class Base {
 public:
  Base() = default;
  Base(const Base&) = delete;
  Base& operator=(const Base&) = delete;
  virtual ~Base() = default;

  /// Velocity command: v forward [m/s], w yaw rate [rad/s] CCW positive. The base applies its
  /// own limits; a base with a watchdog stops when commands stop arriving.
  virtual void command(double v, double w) = 0;
  /// Stop now. Must not throw (it is what every fault path calls).
  virtual void stop() noexcept = 0;
  /// Latest odometry; false when none is available (link down, not started).
  virtual bool odometry(Odometry& out) = 0;
  /// True while the link to the base is healthy.
  virtual bool ok() const = 0;
  virtual DeviceStats stats() const = 0;
  virtual std::string uri() const = 0;
};

class RangeSensor {
 public:
  RangeSensor() = default;
  RangeSensor(const RangeSensor&) = delete;
  RangeSensor& operator=(const RangeSensor&) = delete;
  virtual ~RangeSensor() = default;

  /// Latest scan; false when none is available yet or the device failed.
  virtual bool read(RangeScan& out) = 0;
  virtual DeviceStats stats() const = 0;
  virtual std::string uri() const = 0;
};

}  // namespace sketchnav::hw
