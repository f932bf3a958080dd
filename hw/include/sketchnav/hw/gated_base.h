#pragma once
// A Base that refuses to move while a gate is closed: what keeps the robot stopped while the
// camera is gone (the Aravis camera closes the gate when it loses the device and opens it
// when frames flow again). Closing the gate stops the base at once; while closed, every
// command() becomes stop(). Thread-safe (the camera's callback runs on the grabbing thread).
#include <atomic>
#include <memory>
#include <string>

#include "sketchnav/hw/devices.h"

namespace sketchnav::hw {

class GatedBase final : public Base {
 public:
  explicit GatedBase(std::unique_ptr<Base> inner) : inner_(std::move(inner)) {}
  void command(double v, double w) override {
    if (open_)
      inner_->command(v, w);
    else
      inner_->stop();
  }
  void stop() noexcept override { inner_->stop(); }
  bool odometry(Odometry& out) override { return inner_->odometry(out); }
  /// False while the gate is closed, so the executive sees the fault too.
  bool ok() const override { return open_ && inner_->ok(); }
  DeviceStats stats() const override { return inner_->stats(); }
  std::string uri() const override { return inner_->uri(); }

  void setOpen(bool open) {
    open_ = open;
    if (!open) inner_->stop();
  }
  bool isOpen() const { return open_; }
  Base& inner() { return *inner_; }

 private:
  std::unique_ptr<Base> inner_;
  std::atomic<bool> open_{true};
};

/// When `camera` can report losing its device (an AravisCamera), wraps `base` so that it is
/// stopped at once when the camera is lost and stays stopped until frames flow again; other
/// cameras leave `base` as it is. The camera keeps a pointer to the returned base: destroy the
/// camera before it.
std::unique_ptr<Base> stopBaseWhileCameraIsLost(std::unique_ptr<Base> base, Camera& camera);

}  // namespace sketchnav::hw
