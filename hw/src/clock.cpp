#include "sketchnav/hw/clock.h"

#include <chrono>
#include <thread>

namespace sketchnav::hw {
namespace {
double steadySeconds() {
  using namespace std::chrono;
  return duration<double>(steady_clock::now().time_since_epoch()).count();
}
}  // namespace

SteadyClock::SteadyClock() : epoch_(steadySeconds()) {}
double SteadyClock::now() const {
  return steadySeconds() - epoch_;
}
void SteadyClock::sleepUntil(double t) {
  const double dt = t - now();
  if (dt > 0) std::this_thread::sleep_for(std::chrono::duration<double>(dt));
}

double SimClock::now() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return t_;
}
void SimClock::sleepUntil(double t) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (t > t_) t_ = t;
}
void SimClock::advance(double dt) {
  std::lock_guard<std::mutex> lock(mutex_);
  if (dt > 0) t_ += dt;
}

}  // namespace sketchnav::hw
