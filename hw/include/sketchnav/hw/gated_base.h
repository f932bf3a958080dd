#pragma once
// A Base that refuses to move while a gate is closed: what keeps the robot stopped while the
// camera is gone (the Aravis camera closes the gate when it loses the device and opens it
// when frames flow again: drivers::stopBaseWhileCameraIsLost). Closing the gate stops the
// base at once; while closed, every command() becomes stop(). Thread-safe as far as the gate
// goes (the camera's callback runs on the grabbing thread); the other calls forward to the
// inner base as they come.
#include <atomic>
#include <memory>

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

  void setOpen(bool open) {
    open_ = open;
    if (!open) inner().stop();
  }
  bool isOpen() const { return open_; }

 private:
  std::atomic<bool> open_{true};
};

}  // namespace sketchnav::hw
