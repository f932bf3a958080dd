#pragma once
// A Base that refuses to move while a gate is closed: what keeps the robot stopped while the
// camera is gone (a camera that can report losing its device closes the gate when it does and
// opens it when frames flow again: stopBaseWhileCameraIsLost, wired by `sketchnav run`).
// Closing the gate stops the base at once; while closed, every command() becomes stop().
// Thread-safe as far as the gate goes (the camera's callback runs on the grabbing thread); the
// other calls forward to the inner base as they come.
#include <atomic>
#include <memory>
#include <mutex>
#include <string>

#include "sketchnav/hw/forwarding.h"

namespace sketchnav::hw {

class GatedBase final : public ForwardingBase {
 public:
  using ForwardingBase::ForwardingBase;
  void command(double v, double w) override {
    if (open_)
      inner().command(v, w);
    else
      inner().stop();
  }
  /// False while the gate is closed, so the executive sees the fault too.
  bool ok() const override { return open_ && inner().ok(); }
  /// While closed, last_error says why motion is blocked (the reason given to setOpen()).
  DeviceStats stats() const override {
    DeviceStats s = inner().stats();
    if (!open_) {
      std::lock_guard<std::mutex> lock(why_mutex_);
      s.last_error = why_.empty() ? "motion blocked" : why_;
    }
    return s;
  }

  /// Opens or closes the gate; `why` is what stats().last_error says while it is closed.
  void setOpen(bool open, const std::string& why = {}) {
    if (!open) {
      std::lock_guard<std::mutex> lock(why_mutex_);
      why_ = why;
    }
    open_ = open;
    if (!open) inner().stop();
  }
  bool isOpen() const { return open_; }

 private:
  std::atomic<bool> open_{true};
  mutable std::mutex why_mutex_;
  std::string why_;
};

/// Wraps `base` in a GatedBase that `camera` closes when it reports losing its device
/// (Camera::setLinkCallback: aravis:// after its lost_timeout_s without a frame) and opens when
/// frames flow again: the base is sent stop() in that same call, and every command becomes
/// stop() until then; each change is logged (warning "camera lost: ..."). A camera that cannot
/// report loss never closes it. The camera keeps a pointer to the returned base: destroy the
/// camera before it.
std::unique_ptr<Base> stopBaseWhileCameraIsLost(std::unique_ptr<Base> base, Camera& camera);

}  // namespace sketchnav::hw
