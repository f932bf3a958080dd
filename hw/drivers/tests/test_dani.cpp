// The laptop side (dani://) against the reference base side (BaseServer) over real UDP
// sockets on loopback: faults end in a stop, within bounds measured on the clocks of the
// side that acted, and a reconnection never moves the robot without an explicit resume.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <random>
#include <thread>

#include "sketchnav/core/error.h"
#include "sketchnav/drivers/base_server.h"
#include "sketchnav/drivers/dani_base.h"
#include "sketchnav/drivers/register.h"
#include "sketchnav/hw/registry.h"
#include "test_data.h"

using namespace sketchnav;
using namespace sketchnav::hw;
using namespace sketchnav::drivers;
using proto::BaseState;
using proto::Message;
using proto::StopReason;
using proto::Type;

namespace {

constexpr double kStopBound = 0.2;  // [s] the "stops within 200 ms"

void sleepS(double s) {
  std::this_thread::sleep_for(std::chrono::duration<double>(s));
}

/// Polls `cond` every 2 ms for up to `timeout_s` (a bound on the test, not an assertion).
bool waitFor(const std::function<bool()>& cond, double timeout_s = 3.0) {
  SteadyClock c;
  while (c.now() < timeout_s) {
    if (cond()) return true;
    sleepS(0.002);
  }
  return cond();
}

/// A hand-driven laptop: raw UDP from a chosen loopback address, so tests can go silent,
/// send garbage, or pretend to be another host.
class RawPeer {
 public:
  explicit RawPeer(const char* local_ip = "127.0.0.1") {
    fd_ = ::socket(AF_INET, SOCK_DGRAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    ::inet_pton(AF_INET, local_ip, &a.sin_addr);
    EXPECT_EQ(::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
  }
  ~RawPeer() { ::close(fd_); }
  void to(int port) {
    dst_.sin_family = AF_INET;
    dst_.sin_port = htons(static_cast<std::uint16_t>(port));
    ::inet_pton(AF_INET, "127.0.0.1", &dst_.sin_addr);
  }
  void sendRaw(const std::vector<std::uint8_t>& b) {
    ::sendto(fd_, b.data(), b.size(), 0, reinterpret_cast<sockaddr*>(&dst_), sizeof dst_);
  }
  void send(Type t, float v = 0, float w = 0) {
    Message m = proto::makeMessage(t, t == Type::Hello ? 99 : session, ++seq);
    m.cmd = {v, w};
    sendRaw(proto::encode(m, secret));
  }
  /// Next decodable message of type `t` within timeout; false otherwise.
  bool expect(Type t, Message& out, double timeout_s = 1.0) {
    SteadyClock c;
    std::vector<std::uint8_t> buf(2048);
    while (c.now() < timeout_s) {
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, 10) <= 0) continue;
      const ssize_t n = ::recv(fd_, buf.data(), buf.size(), 0);
      if (n <= 0) continue;
      if (proto::decode(buf.data(), static_cast<std::size_t>(n), out, secret) ==
              proto::DecodeError::None &&
          out.header.type == t)
        return true;
    }
    return false;
  }
  /// Hello -> Welcome -> Resume -> Running.
  bool openAndResume() {
    send(Type::Hello);
    Message m;
    if (!expect(Type::Welcome, m)) return false;
    session = m.header.session;
    send(Type::Resume);
    while (expect(Type::Status, m))
      if (m.status.state == BaseState::Running) return true;
    return false;
  }
  std::uint32_t session = 0, seq = 0;
  std::string secret;

 private:
  int fd_ = -1;
  sockaddr_in dst_{};
};

/// A fixed sonar for the base side.
class FixedSonar final : public RangeSensor {
 public:
  bool read(RangeScan& s) override {
    s = RangeScan{};
    s.kind = RangeScan::Kind::Sonar;
    s.angles = {0.0f};
    s.ranges = {1.25f};
    s.max_range = 3.0f;
    s.beam_width = 0.5f;
    s.mount = {0.2, 0.0, 0.0};
    ++n_;
    return true;
  }
  DeviceStats stats() const override { return {n_, 0, 0, {}}; }
  std::string uri() const override { return "fixed://"; }

 private:
  std::uint64_t n_ = 0;
};

struct Rig {
  explicit Rig(BaseServerParams p = {}) : vehicle(clock) {
    p.port = 0;
    p.watchdog_s = 0.1;
    server = std::make_unique<BaseServer>(vehicle, &sonar, clock, p);
    server->startThread();
  }
  std::shared_ptr<DaniLink> link(DaniParams dp = {}, const std::string& secret = {}) {
    return std::make_shared<DaniLink>("127.0.0.1", server->port(), dp, nullptr, secret);
  }
  SteadyClock clock;
  UnicycleBase vehicle;
  FixedSonar sonar;
  std::unique_ptr<BaseServer> server;
};

double lastEventTime(const BaseServer& s, BaseServerEvent::Kind k) {
  double t = -1;
  for (const auto& e : s.events())
    if (e.kind == k) t = e.t;
  return t;
}

}  // namespace

TEST(Dani, ConnectsResumesDrivesAndRelaysOdometryAndSonar) {
  Rig rig;
  auto link = rig.link();
  ASSERT_TRUE(link->connect(2.0)) << link->status().last_error;
  DaniBase base(link);
  DaniSonar sonar(link);
  EXPECT_TRUE(base.ok());
  for (int i = 0; i < 20; ++i) {
    base.command(0.4, 0.0);
    sleepS(0.02);
  }
  double v = 0, w = 0;
  rig.vehicle.velocity(v, w);
  EXPECT_DOUBLE_EQ(v, 0.4f);
  Odometry o;
  ASSERT_TRUE(waitFor([&] { return base.odometry(o) && o.pose.x > 0.05; }));
  EXPECT_NEAR(o.pose.y, 0.0, 1e-6);
  // Commands beyond the base's limit are clamped by the base, not trusted.
  base.command(5.0, 0.0);
  ASSERT_TRUE(waitFor([&] {
    return rig.server->stats().last_command_t > 0 && (rig.vehicle.velocity(v, w), v == 0.5);
  }));
  RangeScan s;
  ASSERT_TRUE(waitFor([&] { return sonar.read(s); }));
  EXPECT_EQ(s.kind, RangeScan::Kind::Sonar);
  ASSERT_EQ(s.ranges.size(), 1u);
  EXPECT_FLOAT_EQ(s.ranges[0], 1.25f);
  EXPECT_FLOAT_EQ(s.beam_width, 0.5f);
  EXPECT_DOUBLE_EQ(s.mount.x, 0.2f);
  EXPECT_FALSE(sonar.read(s)) << "a scan is returned once";
  EXPECT_GT(link->status().rtt_ms, 0.0);
  base.stop();
  ASSERT_TRUE(waitFor([&] { return !rig.vehicle.moving(); }));
  EXPECT_GT(base.stats().received, 5u);
  EXPECT_EQ(base.stats().dropped, 0u);
}

TEST(Dani, KilledBaseIsReportedAndStoppedWithin200ms) {
  Rig rig;
  auto link = rig.link();
  ASSERT_TRUE(link->connect(2.0));
  for (int i = 0; i < 10; ++i) link->command(0.3, 0.1), sleepS(0.02);
  rig.server->shutdown();  // the base vanishes (socket closed, as if killed)
  ASSERT_TRUE(waitFor([&] { return link->status().faults == 1; }));
  const auto st = link->status();
  EXPECT_FALSE(link->ok());
  EXPECT_TRUE(st.latched);
  EXPECT_NE(st.last_error.find("link lost"), std::string::npos) << st.last_error;
  EXPECT_GT(st.fault_t, st.last_rx_t);
  EXPECT_LE(st.fault_t - st.last_rx_t, kStopBound) << "fault declared (and Stop sent) late";
  EXPECT_NE(DaniBase(link).stats().last_error, "");
}

TEST(Dani, SilentLaptopTripsTheWatchdogWhichStopsTheVehicle) {
  Rig rig;
  RawPeer laptop;
  laptop.to(rig.server->port());
  ASSERT_TRUE(laptop.openAndResume());
  for (int i = 0; i < 5; ++i) laptop.send(Type::CmdVel, 0.3f, 0.0f), sleepS(0.02);
  ASSERT_TRUE(waitFor([&] { return rig.vehicle.moving(); }));
  // The laptop dies here: no more datagrams.
  ASSERT_TRUE(waitFor([&] { return rig.server->stats().watchdog_trips == 1; }));
  const auto st = rig.server->stats();
  EXPECT_FALSE(rig.vehicle.moving());
  EXPECT_EQ(st.state, BaseState::Stopped);
  EXPECT_EQ(st.reason, StopReason::Watchdog);
  const double silent = st.last_stop_t - st.last_command_t;
  EXPECT_GE(silent, rig.server->params().watchdog_s) << "stopped before the watchdog period";
  EXPECT_LE(silent, kStopBound);
  // Latched: a late command does not move it; Resume does, explicitly.
  laptop.send(Type::CmdVel, 0.3f, 0.0f);
  ASSERT_TRUE(waitFor([&] { return rig.server->stats().ignored_while_stopped >= 1; }));
  EXPECT_FALSE(rig.vehicle.moving());
}

TEST(Dani, GarbageTruncatedAndCorruptDatagramsAreCountedAndNeverFeedTheWatchdog) {
  Rig rig;
  RawPeer laptop;
  laptop.to(rig.server->port());
  ASSERT_TRUE(laptop.openAndResume());
  laptop.send(Type::CmdVel, 0.2f, 0.0f);
  ASSERT_TRUE(waitFor([&] { return rig.vehicle.moving(); }));
  const auto before = rig.server->stats();
  // 0.4 s (four watchdog periods) of junk that *looks* like commands.
  std::mt19937 rng(7);
  Message m = proto::makeMessage(Type::CmdVel, laptop.session, 0);
  m.cmd = {0.2f, 0.0f};
  int sent = 0;
  SteadyClock c;
  while (c.now() < 0.4) {
    m.header.seq = ++laptop.seq;
    auto good = proto::encode(m);
    auto junk = good;
    switch (sent % 4) {
      case 0:
        junk.resize(rng() % good.size());
        break;  // truncated
      case 1:
        junk[rng() % junk.size()] ^= 0x10;
        break;  // corrupted
      case 2:
        junk.push_back(0);
        break;  // padded
      default:  // garbage
        for (auto& x : junk) x = static_cast<std::uint8_t>(rng());
    }
    laptop.sendRaw(junk);
    ++sent;
    sleepS(0.002);
  }
  ASSERT_TRUE(waitFor([&] { return rig.server->stats().rejected >= before.rejected + sent; }));
  const auto st = rig.server->stats();
  EXPECT_EQ(st.rejected - before.rejected, static_cast<std::uint64_t>(sent));
  EXPECT_EQ(st.received, before.received) << "junk was accepted as valid";
  EXPECT_EQ(st.watchdog_trips, 1u);
  EXPECT_FALSE(rig.vehicle.moving());
  EXPECT_LE(st.last_stop_t - st.last_command_t, kStopBound);
}

TEST(Dani, DelayedBaseIsAFaultAndReconnectionNeedsAnExplicitResume) {
  SteadyClock clock;
  UnicycleBase vehicle(clock);
  BaseServerParams p;
  p.port = 0;
  p.watchdog_s = 0.1;
  BaseServer server(vehicle, nullptr, clock, p);
  std::atomic<bool> paused{false}, quit{false};
  std::thread loop([&] {
    while (!quit) paused ? sleepS(0.001) : server.spinOnce(0.002);
  });
  auto link = std::make_shared<DaniLink>("127.0.0.1", server.port(), DaniParams{}, nullptr);
  ASSERT_TRUE(link->connect(2.0));
  for (int i = 0; i < 5; ++i) link->command(0.3, 0.0), sleepS(0.02);
  ASSERT_TRUE(waitFor([&] { return vehicle.moving(); }));
  paused = true;  // the base hangs for 0.5 s (a stalled controller, a Wi-Fi dropout)
  ASSERT_TRUE(waitFor([&] { return link->status().faults == 1; }));
  const auto st = link->status();
  EXPECT_LE(st.fault_t - st.last_rx_t, kStopBound);
  link->command(0.3, 0.0);  // the executive keeps commanding: must not be sent as motion
  sleepS(0.5);
  paused = false;
  // The base catches up: the laptop's Stop (and its own watchdog) stop the vehicle; the
  // laptop reconnects with a new session, which the base starts latched.
  ASSERT_TRUE(waitFor([&] { return link->status().sessions == 2 && link->status().connected; }));
  ASSERT_TRUE(waitFor([&] { return !vehicle.moving(); }));
  EXPECT_FALSE(link->ok());
  for (int i = 0; i < 10; ++i) link->command(0.3, 0.0), sleepS(0.02);
  EXPECT_FALSE(vehicle.moving()) << "moved after reconnecting without resume";
  EXPECT_EQ(server.stats().state, BaseState::Stopped);
  // Explicit resume: now commands move it again.
  ASSERT_TRUE(link->resume(2.0));
  EXPECT_TRUE(link->ok());
  link->command(0.3, 0.0);
  EXPECT_TRUE(waitFor([&] { return vehicle.moving(); }));
  // Ordering on the base's clock: the resume came after the reconnection.
  EXPECT_GT(lastEventTime(server, BaseServerEvent::Kind::Resume),
            lastEventTime(server, BaseServerEvent::Kind::Session));
  link.reset();
  quit = true;
  loop.join();
}

TEST(Dani, RestartedBaseReconnectsButStaysStoppedUntilResume) {
  SteadyClock clock;
  UnicycleBase vehicle(clock);
  BaseServerParams p;
  p.port = 0;
  auto server = std::make_unique<BaseServer>(vehicle, nullptr, clock, p);
  server->startThread();
  p.port = server->port();
  auto link = std::make_shared<DaniLink>("127.0.0.1", p.port, DaniParams{}, nullptr);
  ASSERT_TRUE(link->connect(2.0));
  server.reset();  // killed
  ASSERT_TRUE(waitFor([&] { return link->status().faults == 1; }));
  server = std::make_unique<BaseServer>(vehicle, nullptr, clock, p);  // restarted, same port
  server->startThread();
  ASSERT_TRUE(waitFor([&] { return link->status().connected; }));
  EXPECT_FALSE(link->ok());
  link->command(0.2, 0.0);
  sleepS(0.1);
  EXPECT_FALSE(vehicle.moving());
  ASSERT_TRUE(link->resume(2.0));
  link->command(0.2, 0.0);
  EXPECT_TRUE(waitFor([&] { return vehicle.moving(); }));
}

TEST(Dani, DatagramsFromAnyOtherHostAreRefused) {
  Rig rig;
  auto link = rig.link();
  ASSERT_TRUE(link->connect(2.0));
  const auto before = rig.server->stats();
  RawPeer intruder("127.0.0.2");  // another host, as far as the base can tell
  intruder.to(rig.server->port());
  intruder.send(Type::Hello);
  Message m;
  EXPECT_FALSE(intruder.expect(Type::Welcome, m, 0.3)) << "answered a stranger";
  intruder.session = 12345;
  for (int i = 0; i < 20; ++i) intruder.send(Type::CmdVel, 0.5f, 0.0f);
  ASSERT_TRUE(waitFor([&] { return rig.server->stats().refused >= 21; }));
  EXPECT_FALSE(rig.vehicle.moving());
  EXPECT_EQ(rig.server->stats().state, BaseState::Running) << "the laptop's session survives";
  int sessions = 0;
  for (const auto& e : rig.server->events()) sessions += e.kind == BaseServerEvent::Kind::Session;
  EXPECT_EQ(sessions, 1) << "the stranger's Hello opened a session";
  EXPECT_NE(rig.server->stats().last_rejection.find("127.0.0.2"), std::string::npos);
  EXPECT_TRUE(link->ok());
}

TEST(Dani, BeyondLoopbackASharedSecretIsRequiredAndChecked) {
  BaseServerParams wide;
  wide.bind_host = "0.0.0.0";
  try {
    wide.validate();
    FAIL() << "listening on all interfaces without a secret was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("secret"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("bind_host"), std::string::npos) << e.what();
  }
  wide.secret = "a-long-shared-secret";
  EXPECT_NO_THROW(wide.validate());

  BaseServerParams p;
  p.secret = "a-long-shared-secret";
  Rig rig(p);
  DaniParams dp;
  dp.connect_timeout_s = 0.3;
  EXPECT_FALSE(rig.link(dp, "")->connect(0.3)) << "unauthenticated laptop accepted";
  EXPECT_FALSE(rig.link(dp, "the-wrong-secret")->connect(0.3)) << "wrong secret accepted";
  EXPECT_GT(rig.server->stats().rejected, 0u);
  EXPECT_EQ(rig.server->stats().state, BaseState::Idle);
  auto good = rig.link(dp, "a-long-shared-secret");
  ASSERT_TRUE(good->connect(2.0));
  good->command(0.1, 0.0);
  EXPECT_TRUE(waitFor([&] { return rig.vehicle.moving(); }));
}

TEST(Dani, RegistryOpensBaseAndSonarOverOneLinkAndFailsFastWithoutABase) {
  registerDrivers();
  Rig rig;
  DeviceContext ctx;
  const std::string uri = "dani://127.0.0.1:" + std::to_string(rig.server->port());
  auto base = Registry::instance().createBase(uri, ctx);
  auto sonar = Registry::instance().createRange(uri, ctx);
  EXPECT_EQ(rig.server->stats().received > 0, true);
  EXPECT_EQ(lastEventTime(*rig.server, BaseServerEvent::Kind::Session) > 0, true);
  int sessions = 0;
  for (const auto& e : rig.server->events()) sessions += e.kind == BaseServerEvent::Kind::Session;
  EXPECT_EQ(sessions, 1) << "base and sonar must share one session";
  RangeScan s;
  EXPECT_TRUE(waitFor([&] { return sonar->read(s); }));
  EXPECT_TRUE(base->ok());

  // A free port with nothing behind it: RuntimeError naming the URI, after the timeout.
  int free_port = 0;
  {
    SteadyClock c;
    UnicycleBase v(c);
    BaseServerParams q;
    q.port = 0;
    BaseServer tmp(v, nullptr, c, q);
    free_port = tmp.port();
  }
  DeviceContext ctx2;
  const std::string dead =
      "dani://127.0.0.1:" + std::to_string(free_port) + "?connect_timeout_s=0.3";
  try {
    Registry::instance().createBase(dead, ctx2);
    FAIL() << "opened a base that does not exist";
  } catch (const RuntimeError& e) {
    EXPECT_NE(std::string(e.what()).find(dead), std::string::npos) << e.what();
  }
  EXPECT_THROW(Registry::instance().createBase("dani://127.0.0.1", ctx2), InputError);
  const std::string secret = test::tempDir("dani") + "/short";
  std::ofstream(secret) << "abc";
  EXPECT_THROW(Registry::instance().createBase(uri + "?secret_file=" + secret, ctx2), InputError);
}

// Issue 28: ?secret_file=/dev/zero grew past 2 GB in 5 s, connect_timeout_s=1e308 hung the run.
// Both are refused before the link is opened, with the parameter or file named.
TEST(Dani, SecretFileAndConnectTimeoutAreBoundedBeforeUse) {
  registerDrivers();
  DeviceContext ctx;
  const std::string base = "dani://127.0.0.1:9";  // nothing is contacted: refused before
  auto error = [&](const std::string& uri) -> std::string {
    try {
      Registry::instance().createBase(uri, ctx);
    } catch (const InputError& e) {
      return e.what();
    } catch (const std::exception& e) {
      return std::string("other: ") + e.what();
    }
    return "";
  };
  std::string e = error(base + "?secret_file=/dev/zero");
  EXPECT_NE(e.find("secret file '/dev/zero': is a character device"), std::string::npos) << e;
  const std::string dir = test::tempDir("dani-bounds");
  {
    std::ofstream big(dir + "/big");
    big << std::string(kMaxSecretFileBytes + 1, 'k');
  }
  e = error(base + "?secret_file=" + dir + "/big");
  EXPECT_NE(e.find("too large (4097 bytes > 4096)"), std::string::npos) << e;
  e = error(base + "?secret_file=" + dir);
  EXPECT_NE(e.find("is a directory"), std::string::npos) << e;
  for (const char* t : {"1e308", "61", "nan", "0", "-1"}) {
    e = error(base + "?connect_timeout_s=" + t);
    EXPECT_NE(e.find("'base.dani.connect_timeout_s': must be in (0, 60] s"), std::string::npos)
        << t << ": " << e;
  }
  ctx.config.set("base.dani.connect_timeout_s=1e308");
  e = error(base);
  EXPECT_NE(e.find("'base.dani.connect_timeout_s': must be in (0, 60] s"), std::string::npos) << e;
}

namespace {
/// A hand-driven base: answers the link's Hello with a chosen Welcome and sends chosen
/// stream messages, recording what the laptop sends.
class RawBase {
 public:
  RawBase() {
    fd_ = ::socket(AF_INET, SOCK_DGRAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    ::inet_pton(AF_INET, "127.0.0.1", &a.sin_addr);
    EXPECT_EQ(::bind(fd_, reinterpret_cast<sockaddr*>(&a), sizeof a), 0);
    socklen_t len = sizeof a;
    ::getsockname(fd_, reinterpret_cast<sockaddr*>(&a), &len);
    port = ntohs(a.sin_port);
  }
  ~RawBase() { ::close(fd_); }
  /// Next message of type `t` from the laptop within timeout.
  bool expect(Type t, Message& out, double timeout_s = 1.0) {
    SteadyClock c;
    std::vector<std::uint8_t> buf(2048);
    while (c.now() < timeout_s) {
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, 10) <= 0) continue;
      socklen_t len = sizeof peer_;
      const ssize_t n =
          ::recvfrom(fd_, buf.data(), buf.size(), 0, reinterpret_cast<sockaddr*>(&peer_), &len);
      if (n <= 0) continue;
      if (proto::decode(buf.data(), static_cast<std::size_t>(n), out) == proto::DecodeError::None &&
          out.header.type == t)
        return true;
    }
    return false;
  }
  void send(Message m) {
    m.header.session = session;
    m.header.seq = ++seq;
    const auto b = proto::encode(m);
    ::sendto(fd_, b.data(), b.size(), 0, reinterpret_cast<sockaddr*>(&peer_), sizeof peer_);
  }
  /// Waits for Hello and answers `w` (its nonce filled in).
  bool welcome(proto::WelcomeMsg w) {
    Message hello;
    if (!expect(Type::Hello, hello)) return false;
    Message m = proto::makeMessage(Type::Welcome, session, 0);
    w.hello_nonce = hello.header.session;
    m.welcome = w;
    send(m);
    return true;
  }
  void running() {
    Message m = proto::makeMessage(Type::Status, session, 0);
    m.status.state = BaseState::Running;
    send(m);
  }
  void odom(float x) {
    Message m = proto::makeMessage(Type::Odom, session, 0);
    m.odom.x = x;
    m.odom.has_pose = true;
    send(m);
  }
  int port = 0;
  std::uint32_t session = 4242, seq = 0;

 private:
  int fd_ = -1;
  sockaddr_in peer_{};
};
}  // namespace

// Bad-input campaign (issue 28): NaN/inf odometry and NaN limits in the Welcome were reported
// ok and used. A robot-facing value that is not finite is a fault that ends in Stop.
TEST(Dani, NonFiniteOdometryIsAFaultThatStopsTheBase) {
  for (const float bad :
       {std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
    RawBase fake;
    DaniParams dp;
    dp.link_timeout_s = 5;  // the fake base sends no periodic stream
    auto link = std::make_shared<DaniLink>("127.0.0.1", fake.port, dp, nullptr, "");
    ASSERT_TRUE(fake.welcome({}));
    Message resume;
    ASSERT_TRUE(fake.expect(Type::Resume, resume));
    fake.running();
    ASSERT_TRUE(link->connect(1.0)) << link->status().last_error;
    fake.odom(0.5f);
    Odometry o;
    ASSERT_TRUE(waitFor([&] { return link->odometry(o) && link->ok(); }));
    EXPECT_FLOAT_EQ(static_cast<float>(o.pose.x), 0.5f);
    fake.odom(bad);
    Message stop;
    EXPECT_TRUE(fake.expect(Type::Stop, stop)) << "no Stop after non-finite odometry";
    EXPECT_FALSE(link->ok());
    EXPECT_NE(link->status().last_error.find("not finite"), std::string::npos)
        << link->status().last_error;
    link->command(0.3, 0.0);  // faulted and latched: never a CmdVel
    Message cmd;
    EXPECT_FALSE(fake.expect(Type::CmdVel, cmd, 0.2));
    if (link->odometry(o)) EXPECT_TRUE(std::isfinite(o.pose.x));
  }
}

TEST(Dani, NonFiniteLimitsInTheWelcomeAreAFaultThatStopsTheBase) {
  RawBase fake;
  DaniParams dp;
  dp.resume_on_connect = false;  // connect() then needs only the session
  dp.link_timeout_s = 5;
  auto link = std::make_shared<DaniLink>("127.0.0.1", fake.port, dp, nullptr, "");
  proto::WelcomeMsg w;
  w.max_v = std::numeric_limits<float>::quiet_NaN();
  ASSERT_TRUE(fake.welcome(w));
  Message stop;
  EXPECT_TRUE(fake.expect(Type::Stop, stop)) << "no Stop after a NaN max_v";
  EXPECT_FALSE(link->connect(0.3));
  EXPECT_FALSE(link->ok());
  EXPECT_NE(link->status().last_error.find("max_v"), std::string::npos)
      << link->status().last_error;
  fake.running();
  fake.odom(1.0f);  // the refused session's stream is not used
  sleepS(0.05);
  Odometry o;
  EXPECT_FALSE(link->odometry(o));
}
