#pragma once
// Time is an input: every device and the executive read a Clock, so the simulator can run
// faster than real time and the same code drives the real robot.
#include <mutex>

namespace sketchnav::hw {

class Clock {
 public:
  virtual ~Clock() = default;
  /// Seconds since an arbitrary epoch fixed for the clock's lifetime.
  virtual double now() const = 0;
  /// Blocks (or, for a simulated clock, advances) until now() >= t.
  virtual void sleepUntil(double t) = 0;
};

/// Wall time from std::chrono::steady_clock, epoch at construction.
class SteadyClock final : public Clock {
 public:
  SteadyClock();
  double now() const override;
  void sleepUntil(double t) override;

 private:
  double epoch_;
};

/// Simulated time: starts at 0 and only moves when advanced. sleepUntil() jumps forward, so
/// a simulation runs as fast as the CPU allows. Thread-safe.
class SimClock final : public Clock {
 public:
  double now() const override;
  void sleepUntil(double t) override;
  void advance(double dt);

 private:
  mutable std::mutex mutex_;
  double t_ = 0.0;
};

}  // namespace sketchnav::hw
