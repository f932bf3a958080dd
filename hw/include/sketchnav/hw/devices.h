#pragma once
// The three device interfaces. Small on purpose: each real device (GigE camera, DaNI base,
// laser) and its simulated twin implement exactly these, nothing more. Devices are not
// copyable; their lifetime is the unique_ptr the registry returns.
//
// Threads. A device is not required to be safe for concurrent calls: its user makes one call
// at a time. Those calls may come from different threads in turn, so an implementation must
// not depend on which thread calls it (no thread-local state, no handle bound to the thread
// that opened it) and must synchronise with any thread of its own (a receive or polling loop).
// Where this matters: the run page's Stop (`sketchnav ui`, StoppableBase in
// apps/ui/run_api.cpp) calls Base::stop() of a real robot's base on the HTTP server's thread
// while the run's thread is driving; StoppableBase serialises it with the run thread's
// command(), odometry(), ok() and stats() under one mutex. (On the simulator it only flags
// the stop, and the run thread's next command() becomes stop().) Implementations that are
// safe for concurrent calls say so: DaniLink/DaniBase, GatedBase, sim::Simulator's devices.
#include <functional>
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
  /// Asks to be told when the device is lost (`up` false) and when frames flow again (true),
  /// on the thread calling grab(). False when this camera cannot tell (the default: the
  /// executive's stale-frame check is then what stops the robot); decorators forward it.
  virtual bool setLinkCallback(std::function<void(bool up)> /*cb*/) { return false; }
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
  /// Stop now. Must not throw (it is what every fault path calls). May be called on another
  /// thread than the previous command() (see "Threads" above: the run page's Stop).
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
