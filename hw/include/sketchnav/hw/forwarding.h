#pragma once
// Forwarding bases for device decorators: each virtual of the interface forwards to an inner
// device, so a decorator (recording, the camera-lost gate, the UI's stop and live view, a
// test's fault injection, the simulator's handles) overrides only the calls it changes:
//
//   class CountingCamera final : public hw::ForwardingCamera {
//    public:
//     using ForwardingCamera::ForwardingCamera;
//     GrabStatus grab(Frame& f, double timeout_s) override {
//       ++grabs;
//       return ForwardingCamera::grab(f, timeout_s);
//     }
//     int grabs = 0;
//   };
//
// Ownership. The inner device is held by a shared_ptr: pass a unique_ptr to own the device
// alone, or an aliasing shared_ptr to forward to a device that another object owns and keep
// that object alive (sim::registerDrivers' handles onto the shared Simulator's devices).
// The inner device is never null (the constructors throw std::invalid_argument).
//
// Threads. A forwarding base adds no locking and no state: it is exactly as safe for
// concurrent calls as its inner device (see devices.h, "Threads").
#include <memory>
#include <stdexcept>
#include <string>

#include "sketchnav/hw/devices.h"

namespace sketchnav::hw {

namespace detail {
template <class D>
std::shared_ptr<D> notNull(std::shared_ptr<D> p) {
  if (!p) throw std::invalid_argument("forwarding device: no inner device");
  return p;
}
}  // namespace detail

class ForwardingCamera : public Camera {
 public:
  explicit ForwardingCamera(std::shared_ptr<Camera> inner)
      : inner_(detail::notNull(std::move(inner))) {}
  GrabStatus grab(Frame& frame, double timeout_s = 1.0) override {
    return inner_->grab(frame, timeout_s);
  }
  Intrinsics intrinsics() const override { return inner_->intrinsics(); }
  DeviceStats stats() const override { return inner_->stats(); }
  std::string uri() const override { return inner_->uri(); }
  bool setLinkCallback(std::function<void(bool up)> cb) override {
    return inner_->setLinkCallback(std::move(cb));
  }

  Camera& inner() const { return *inner_; }

 private:
  std::shared_ptr<Camera> inner_;
};

class ForwardingBase : public Base {
 public:
  explicit ForwardingBase(std::shared_ptr<Base> inner)
      : inner_(detail::notNull(std::move(inner))) {}
  void command(double v, double w) override { inner_->command(v, w); }
  void stop() noexcept override { inner_->stop(); }
  bool odometry(Odometry& out) override { return inner_->odometry(out); }
  bool ok() const override { return inner_->ok(); }
  DeviceStats stats() const override { return inner_->stats(); }
  std::string uri() const override { return inner_->uri(); }

  Base& inner() const { return *inner_; }

 private:
  std::shared_ptr<Base> inner_;
};

class ForwardingRangeSensor : public RangeSensor {
 public:
  explicit ForwardingRangeSensor(std::shared_ptr<RangeSensor> inner)
      : inner_(detail::notNull(std::move(inner))) {}
  bool read(RangeScan& out) override { return inner_->read(out); }
  DeviceStats stats() const override { return inner_->stats(); }
  std::string uri() const override { return inner_->uri(); }

  RangeSensor& inner() const { return *inner_; }

 private:
  std::shared_ptr<RangeSensor> inner_;
};

}  // namespace sketchnav::hw
