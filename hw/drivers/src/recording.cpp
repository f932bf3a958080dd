#include "sketchnav/drivers/recording.h"

#include <atomic>

#include "sketchnav/core/log.h"
#include "sketchnav/hw/forwarding.h"

namespace sketchnav::drivers {
namespace {

// Shared by the three decorators: the first write error turns recording off (logged once), so a
// full disk costs the log, not the run.
class Sink {
 public:
  explicit Sink(std::shared_ptr<RawlogRecorder> r) : rec_(std::move(r)) {}
  template <class F>
  void write(F&& f) {
    if (failed_) return;
    try {
      f(*rec_);
    } catch (const std::exception& e) {
      if (!failed_.exchange(true))
        log::error("record", "recording stopped", {{"file", rec_->path()}, {"why", e.what()}});
    }
  }

 private:
  std::shared_ptr<RawlogRecorder> rec_;
  std::atomic<bool> failed_{false};
};

class RecordingCamera final : public hw::ForwardingCamera {
 public:
  RecordingCamera(std::unique_ptr<Camera> inner, std::shared_ptr<RawlogRecorder> r)
      : ForwardingCamera(std::move(inner)), sink_(std::move(r)) {}
  GrabStatus grab(Frame& frame, double timeout_s) override {
    const GrabStatus st = inner().grab(frame, timeout_s);
    if (st == GrabStatus::Ok)
      sink_.write([&](RawlogRecorder& r) { r.addFrame(frame, inner().intrinsics()); });
    return st;
  }

 private:
  Sink sink_;
};

class RecordingBase final : public hw::ForwardingBase {
 public:
  RecordingBase(std::unique_ptr<Base> inner, std::shared_ptr<RawlogRecorder> r,
                std::shared_ptr<Clock> clock)
      : ForwardingBase(std::move(inner)), sink_(std::move(r)), clock_(std::move(clock)) {}
  void command(double v, double w) override {
    inner().command(v, w);
    const double t = clock_ ? clock_->now() : 0.0;
    sink_.write([&](RawlogRecorder& r) { r.addCommand(v, w, t); });
  }
  void stop() noexcept override {
    inner().stop();
    const double t = clock_ ? clock_->now() : 0.0;
    sink_.write([&](RawlogRecorder& r) { r.addCommand(0.0, 0.0, t, "CMD_STOP"); });
  }
  bool odometry(Odometry& out) override {
    if (!inner().odometry(out)) return false;
    sink_.write([&](RawlogRecorder& r) { r.addOdometry(out); });
    return true;
  }

 private:
  Sink sink_;
  std::shared_ptr<Clock> clock_;
};

class RecordingRange final : public hw::ForwardingRangeSensor {
 public:
  RecordingRange(std::unique_ptr<RangeSensor> inner, std::shared_ptr<RawlogRecorder> r,
                 std::string label)
      : ForwardingRangeSensor(std::move(inner)), sink_(std::move(r)), label_(std::move(label)) {}
  bool read(RangeScan& out) override {
    if (!inner().read(out)) return false;
    sink_.write([&](RawlogRecorder& r) { r.addRange(out, label_); });
    return true;
  }

 private:
  Sink sink_;
  std::string label_;
};

}  // namespace

std::unique_ptr<Camera> recordCamera(std::unique_ptr<Camera> inner,
                                     std::shared_ptr<RawlogRecorder> recorder) {
  if (!inner) return inner;
  return std::make_unique<RecordingCamera>(std::move(inner), std::move(recorder));
}
std::unique_ptr<Base> recordBase(std::unique_ptr<Base> inner,
                                 std::shared_ptr<RawlogRecorder> recorder,
                                 std::shared_ptr<Clock> clock) {
  if (!inner) return inner;
  return std::make_unique<RecordingBase>(std::move(inner), std::move(recorder), std::move(clock));
}
std::unique_ptr<RangeSensor> recordRange(std::unique_ptr<RangeSensor> inner,
                                         std::shared_ptr<RawlogRecorder> recorder,
                                         std::string label) {
  if (!inner) return inner;
  return std::make_unique<RecordingRange>(std::move(inner), std::move(recorder), std::move(label));
}

}  // namespace sketchnav::drivers
