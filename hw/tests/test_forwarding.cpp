// The forwarding bases (hw/forwarding.h) and the gate built on them (hw/gated_base.h): every
// call a decorator does not override reaches the inner device unchanged, in both directions.
#include <gtest/gtest.h>

#include <stdexcept>

#include "sketchnav/hw/forwarding.h"
#include "sketchnav/hw/gated_base.h"

using namespace sketchnav::hw;

namespace {

// Inner devices that log each call and answer with recognisable values.
struct LogCamera final : Camera {
  GrabStatus grab(Frame& f, double timeout_s) override {
    last_timeout = timeout_s;
    f.seq = 41;
    return GrabStatus::Timeout;
  }
  Intrinsics intrinsics() const override {
    Intrinsics k;
    k.fx = 123;
    return k;
  }
  DeviceStats stats() const override {
    DeviceStats s;
    s.dropped = 7;
    return s;
  }
  std::string uri() const override { return "log://camera"; }
  double last_timeout = -1;
};

struct LogBase final : Base {
  void command(double v, double w) override {
    last_v = v;
    last_w = w;
    ++commands;
  }
  void stop() noexcept override { ++stops; }
  bool odometry(Odometry& out) override {
    out.pose.x = 2.5;
    return true;
  }
  bool ok() const override { return healthy; }
  DeviceStats stats() const override {
    DeviceStats s;
    s.dropped = 3;
    return s;
  }
  std::string uri() const override { return "log://base"; }
  double last_v = 0, last_w = 0;
  int commands = 0, stops = 0;
  bool healthy = true;
};

struct LogRange final : RangeSensor {
  bool read(RangeScan& out) override {
    out.ranges = {1.5f, 2.5f};
    return true;
  }
  DeviceStats stats() const override {
    DeviceStats s;
    s.dropped = 5;
    return s;
  }
  std::string uri() const override { return "log://range"; }
};

// A decorator that overrides nothing: behaves exactly as its inner device.
struct PlainCamera final : ForwardingCamera {
  using ForwardingCamera::ForwardingCamera;
};
struct PlainBase final : ForwardingBase {
  using ForwardingBase::ForwardingBase;
};
struct PlainRange final : ForwardingRangeSensor {
  using ForwardingRangeSensor::ForwardingRangeSensor;
};

}  // namespace

TEST(Forwarding, CameraForwardsEveryCall) {
  auto inner = std::make_unique<LogCamera>();
  LogCamera* log = inner.get();
  PlainCamera cam(std::move(inner));
  Frame f;
  EXPECT_EQ(cam.grab(f, 0.25), GrabStatus::Timeout);
  EXPECT_EQ(f.seq, 41u);
  EXPECT_EQ(log->last_timeout, 0.25);
  EXPECT_EQ(cam.intrinsics().fx, 123);
  EXPECT_EQ(cam.stats().dropped, 7u);
  EXPECT_EQ(cam.uri(), "log://camera");
  EXPECT_EQ(&cam.inner(), log);
}

TEST(Forwarding, BaseForwardsEveryCall) {
  auto inner = std::make_unique<LogBase>();
  LogBase* log = inner.get();
  PlainBase base(std::move(inner));
  base.command(0.3, -0.2);
  EXPECT_EQ(log->last_v, 0.3);
  EXPECT_EQ(log->last_w, -0.2);
  base.stop();
  EXPECT_EQ(log->stops, 1);
  Odometry o;
  EXPECT_TRUE(base.odometry(o));
  EXPECT_EQ(o.pose.x, 2.5);
  EXPECT_TRUE(base.ok());
  log->healthy = false;
  EXPECT_FALSE(base.ok());
  EXPECT_EQ(base.stats().dropped, 3u);
  EXPECT_EQ(base.uri(), "log://base");
}

TEST(Forwarding, RangeSensorForwardsEveryCall) {
  PlainRange r(std::make_unique<LogRange>());
  RangeScan s;
  EXPECT_TRUE(r.read(s));
  EXPECT_EQ(s.ranges.size(), 2u);
  EXPECT_EQ(r.stats().dropped, 5u);
  EXPECT_EQ(r.uri(), "log://range");
}

TEST(Forwarding, AnAliasingInnerKeepsItsOwnerAlive) {
  struct Owner {
    LogCamera camera;
  };
  auto owner = std::make_shared<Owner>();
  std::weak_ptr<Owner> watch = owner;
  PlainCamera cam(std::shared_ptr<Camera>(owner, &owner->camera));
  owner.reset();
  EXPECT_FALSE(watch.expired());  // the handle holds the owner
  EXPECT_EQ(cam.uri(), "log://camera");
}

TEST(Forwarding, ANullInnerDeviceIsRefused) {
  EXPECT_THROW(PlainCamera(std::unique_ptr<Camera>()), std::invalid_argument);
  EXPECT_THROW(PlainBase(std::unique_ptr<Base>()), std::invalid_argument);
  EXPECT_THROW(PlainRange(std::unique_ptr<RangeSensor>()), std::invalid_argument);
}

TEST(GatedBase, ClosingStopsAtOnceAndCommandsBecomeStopsUntilReopened) {
  auto inner = std::make_unique<LogBase>();
  LogBase* log = inner.get();
  GatedBase gate(std::move(inner));
  gate.command(0.2, 0.1);
  EXPECT_EQ(log->commands, 1);
  EXPECT_TRUE(gate.ok());
  gate.setOpen(false);
  EXPECT_EQ(log->stops, 1);  // stopped when the gate closed, before any command
  EXPECT_FALSE(gate.ok());
  EXPECT_FALSE(gate.isOpen());
  gate.command(0.2, 0.1);
  EXPECT_EQ(log->commands, 1);
  EXPECT_EQ(log->stops, 2);
  Odometry o;
  EXPECT_TRUE(gate.odometry(o));  // odometry still flows
  gate.setOpen(true);
  gate.command(0.4, 0.0);
  EXPECT_EQ(log->commands, 2);
  EXPECT_EQ(log->last_v, 0.4);
  EXPECT_TRUE(gate.ok());
  log->healthy = false;
  EXPECT_FALSE(gate.ok());
}

namespace {
// A camera that reports its link: the decorators pass the callback through to it.
struct LinkCamera final : ForwardingCamera {
  using ForwardingCamera::ForwardingCamera;
};
struct ReportingCamera final : Camera {
  GrabStatus grab(Frame&, double) override { return GrabStatus::Timeout; }
  Intrinsics intrinsics() const override { return {}; }
  DeviceStats stats() const override { return {}; }
  std::string uri() const override { return "log://reporting"; }
  bool setLinkCallback(std::function<void(bool)> cb) override {
    link = std::move(cb);
    return true;
  }
  std::function<void(bool)> link;
};
}  // namespace

TEST(GatedBase, ACameraReportingItsDeviceLostThroughDecoratorsClosesTheGate) {
  auto inner_cam = std::make_unique<ReportingCamera>();
  ReportingCamera* device = inner_cam.get();
  LinkCamera cam(std::move(inner_cam));  // e.g. the recording around the real camera
  auto inner = std::make_unique<LogBase>();
  LogBase* log = inner.get();
  auto base = stopBaseWhileCameraIsLost(std::move(inner), cam);
  ASSERT_TRUE(device->link) << "the decorator did not pass the callback on";
  base->command(0.2, 0.0);
  EXPECT_EQ(log->commands, 1);
  device->link(false);
  EXPECT_EQ(log->stops, 1) << "not stopped in the call that reported the camera lost";
  EXPECT_FALSE(base->ok());
  // The reason the executive reports with its fault names the camera.
  EXPECT_NE(base->stats().last_error.find("camera lost (log://reporting)"), std::string::npos)
      << base->stats().last_error;
  base->command(0.2, 0.0);
  EXPECT_EQ(log->commands, 1);
  device->link(true);
  EXPECT_TRUE(base->ok());
  EXPECT_TRUE(base->stats().last_error.empty());
  base->command(0.2, 0.0);
  EXPECT_EQ(log->commands, 2);

  // A camera that cannot report its link never closes the gate.
  PlainCamera plain(std::make_unique<LogCamera>());
  EXPECT_FALSE(plain.setLinkCallback([](bool) {}));
  auto open = stopBaseWhileCameraIsLost(std::make_unique<LogBase>(), plain);
  EXPECT_TRUE(open->ok());
}
