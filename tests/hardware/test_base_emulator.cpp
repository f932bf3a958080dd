// The whole base loop over a real socket on loopback: `sketchnav base-emulator` (a separate
// process driving the simulator's vehicle) against the laptop side (dani://) and
// `sketchnav probe`. The emulator is killed, frozen (SIGSTOP: a hung controller or a Wi-Fi
// dropout), fed garbage; every fault must end in a stop.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <sys/socket.h>

#include <nlohmann/json.hpp>

#include <random>
#include <thread>

#include "child_process.h"
#include "sketchnav/drivers/base_protocol.h"
#include "sketchnav/drivers/dani_base.h"

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

bool waitFor(const std::function<bool()>& cond, double timeout_s = 5.0) {
  SteadyClock c;
  while (c.now() < timeout_s) {
    if (cond()) return true;
    sleepS(0.002);
  }
  return cond();
}

/// Starts the emulator on a free port; returns the port (0 on failure).
int startEmulator(std::unique_ptr<test::ChildProcess>& p, const std::string& world = "none",
                  const std::string& watchdog_ms = "200") {
  p = std::make_unique<test::ChildProcess>(
      std::vector<std::string>{SKETCHNAV_EXE, "base-emulator", "--port", "0", "--world", world,
                               "--watchdog-ms", watchdog_ms, "--seconds", "60"});
  std::string line;
  if (!p->readLine(line, 20.0)) return 0;
  const auto colon = line.rfind(':');
  return line.rfind("listening ", 0) == 0 && colon != std::string::npos
             ? std::stoi(line.substr(colon + 1))
             : 0;
}

std::shared_ptr<DaniLink> connect(int port) {
  auto link = std::make_shared<DaniLink>("127.0.0.1", port, DaniParams{}, nullptr);
  return link->connect(3.0) ? link : nullptr;
}

/// A hand-driven laptop on a raw socket (so a test can go silent at a chosen moment).
class RawLaptop {
 public:
  explicit RawLaptop(int port) {
    fd_ = ::socket(AF_INET, SOCK_DGRAM, 0);
    dst_.sin_family = AF_INET;
    dst_.sin_port = htons(static_cast<std::uint16_t>(port));
    ::inet_pton(AF_INET, "127.0.0.1", &dst_.sin_addr);
  }
  ~RawLaptop() { ::close(fd_); }
  void sendRaw(const std::vector<std::uint8_t>& b) {
    ::sendto(fd_, b.data(), b.size(), 0, reinterpret_cast<sockaddr*>(&dst_), sizeof dst_);
  }
  std::uint32_t send(Type t, float v = 0, float w = 0) {
    Message m = proto::makeMessage(t, t == Type::Hello ? 7 : session, ++seq);
    m.cmd = {v, w};
    sendRaw(proto::encode(m));
    return seq;
  }
  /// Next valid message (any type) within timeout.
  bool receive(Message& out, double timeout_s) {
    std::vector<std::uint8_t> buf(2048);
    SteadyClock c;
    while (c.now() < timeout_s) {
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, 10) <= 0) continue;
      const ssize_t n = ::recv(fd_, buf.data(), buf.size(), 0);
      if (n > 0 &&
          proto::decode(buf.data(), static_cast<std::size_t>(n), out) == proto::DecodeError::None)
        return true;
    }
    return false;
  }
  std::uint32_t session = 0, seq = 0;

 private:
  int fd_ = -1;
  sockaddr_in dst_{};
};

}  // namespace

TEST(BaseEmulator, ProbeReportsTheHealthOfTheEmulatedBase) {
  std::unique_ptr<test::ChildProcess> emu;
  const int port = startEmulator(emu, "lab");
  ASSERT_GT(port, 0) << "base-emulator did not start";
  const std::string uri = "dani://127.0.0.1:" + std::to_string(port);
  test::ChildProcess probe({SKETCHNAV_EXE, "probe", uri, "--frames", "20", "--json"});
  const std::string out = probe.readAll(15.0);
  EXPECT_EQ(probe.wait(5.0), 0) << out;
  const auto j = nlohmann::json::parse(out);
  EXPECT_EQ(j["uri"], uri);
  EXPECT_EQ(j["kind"], "base");
  EXPECT_GE(j["received"].get<int>(), 20);
  EXPECT_GT(j["rate_hz"].get<double>(), 5.0);  // the base streams odometry at 20 Hz
  EXPECT_LT(j["rate_hz"].get<double>(), 100.0);
  EXPECT_EQ(j["dropped"], 0);
  EXPECT_EQ(j["incomplete"], 0);
  EXPECT_TRUE(j["latency_ms"].is_number()) << out;
  EXPECT_TRUE(j["error"].is_null()) << out;

  test::ChildProcess sonar(
      {SKETCHNAV_EXE, "probe", uri, "--kind", "range", "--frames", "5", "--json"});
  const auto js = nlohmann::json::parse(sonar.readAll(15.0));
  EXPECT_EQ(sonar.wait(5.0), 0);
  EXPECT_EQ(js["kind"], "range");
  EXPECT_GE(js["received"].get<int>(), 5);
  EXPECT_GT(js["beams"].get<int>(), 0) << "the simulated sonar has beams";

  // Nothing listening: the probe says so and exits 1.
  emu->kill();
  test::ChildProcess dead({SKETCHNAV_EXE, "probe", uri + "?connect_timeout_s=0.3", "--json"});
  const auto jd = nlohmann::json::parse(dead.readAll(15.0));
  EXPECT_EQ(dead.wait(5.0), 1);
  EXPECT_EQ(jd["received"], 0);
  EXPECT_NE(jd["error"].get<std::string>().find("no answer"), std::string::npos) << jd.dump();
}

TEST(BaseEmulator, KilledEmulatorIsAFaultReportedWithin200msAndTheLaptopStops) {
  std::unique_ptr<test::ChildProcess> emu;
  const int port = startEmulator(emu);
  ASSERT_GT(port, 0);
  auto link = connect(port);
  ASSERT_TRUE(link);
  for (int i = 0; i < 10; ++i) link->command(0.3, 0.0), sleepS(0.02);
  Odometry o;
  ASSERT_TRUE(waitFor([&] { return link->odometry(o) && o.pose.x > 0.01; }));
  emu->kill();
  ASSERT_TRUE(waitFor([&] { return link->status().faults == 1; }));
  const auto st = link->status();
  EXPECT_LE(st.fault_t - st.last_rx_t, kStopBound);
  EXPECT_FALSE(link->ok());
  EXPECT_NE(st.last_error.find("link lost"), std::string::npos);
}

TEST(BaseEmulator, FrozenEmulatorIsAFaultAndAfterReconnectingOnlyAnExplicitResumeMoves) {
  std::unique_ptr<test::ChildProcess> emu;
  const int port = startEmulator(emu);
  ASSERT_GT(port, 0);
  auto link = connect(port);
  ASSERT_TRUE(link);
  for (int i = 0; i < 5; ++i) link->command(0.3, 0.0), sleepS(0.02);
  emu->signal(SIGSTOP);  // the controller hangs for 0.6 s
  ASSERT_TRUE(waitFor([&] { return link->status().faults == 1; }));
  EXPECT_LE(link->status().fault_t - link->status().last_rx_t, kStopBound);
  sleepS(0.6);
  emu->signal(SIGCONT);
  ASSERT_TRUE(waitFor([&] { return link->status().connected && link->status().sessions == 2; }));
  // Reconnected: the base reports itself stopped, the laptop is latched, odometry stands still.
  ASSERT_TRUE(waitFor([&] { return link->status().base_state == BaseState::Stopped; }));
  EXPECT_FALSE(link->ok());
  Odometry before, after;
  ASSERT_TRUE(waitFor([&] { return link->odometry(before); }));
  for (int i = 0; i < 15; ++i) link->command(0.3, 0.0), sleepS(0.02);
  ASSERT_TRUE(link->odometry(after));
  EXPECT_NEAR(after.pose.x, before.pose.x, 1e-4) << "moved without an explicit resume";
  ASSERT_TRUE(link->resume(2.0));
  for (int i = 0; i < 15; ++i) link->command(0.3, 0.0), sleepS(0.02);
  ASSERT_TRUE(
      waitFor([&] { return link->odometry(after) && after.pose.x > before.pose.x + 0.02; }));
}

TEST(BaseEmulator, WatchdogStopsTheVehicleWhenTheLaptopFallsSilent) {
  std::unique_ptr<test::ChildProcess> emu;
  const int port = startEmulator(emu, "none", "100");
  ASSERT_GT(port, 0);
  RawLaptop laptop(port);
  laptop.send(Type::Hello);
  Message m;
  ASSERT_TRUE(laptop.receive(m, 2.0));
  ASSERT_EQ(m.header.type, Type::Welcome);
  laptop.session = m.header.session;
  EXPECT_EQ(m.welcome.watchdog_ms, 100);
  laptop.send(Type::Resume);
  std::uint32_t last_cmd = 0;
  for (int i = 0; i < 10; ++i) last_cmd = laptop.send(Type::CmdVel, 0.25f, 0.0f), sleepS(0.02);
  // Now silent. On the base's own clock: the last Odom that had not yet seen our last command
  // was sent before that command was applied, so (stop time - its time) bounds the silence
  // the watchdog allowed from above.
  std::uint32_t before_cmd_ms = 0, stop_ms = 0;
  bool stopped = false;
  double v_after = -1;
  SteadyClock c;
  while (c.now() < 3.0 && !(stopped && v_after >= 0)) {
    if (!laptop.receive(m, 0.5)) continue;
    if (m.header.type == Type::Odom) {
      if (m.odom.ack_seq < last_cmd) before_cmd_ms = m.odom.base_time_ms;
      if (stopped) v_after = m.odom.v;
    }
    if (m.header.type == Type::Status && m.status.state == BaseState::Stopped &&
        m.status.reason == StopReason::Watchdog && !stopped) {
      stopped = true;
      stop_ms = m.status.base_time_ms;
    }
  }
  ASSERT_TRUE(stopped) << "the emulator's watchdog never stopped the vehicle";
  ASSERT_GT(before_cmd_ms, 0u);
  EXPECT_GE(stop_ms - before_cmd_ms, 100u);
  EXPECT_LE(stop_ms - before_cmd_ms, static_cast<std::uint32_t>(kStopBound * 1000));
  EXPECT_EQ(v_after, 0.0) << "odometry still shows motion after the watchdog stop";
}

TEST(BaseEmulator, GarbageAndTruncatedDatagramsAreRejectedAndTheSessionSurvives) {
  std::unique_ptr<test::ChildProcess> emu;
  const int port = startEmulator(emu);
  ASSERT_GT(port, 0);
  auto link = connect(port);
  ASSERT_TRUE(link);
  RawLaptop junk(port);
  std::mt19937 rng(3);
  Message cmd = proto::makeMessage(Type::CmdVel, 1, 1);
  const auto good = proto::encode(cmd);
  for (int i = 0; i < 60; ++i) {
    std::vector<std::uint8_t> b = good;
    if (i % 3 == 0)
      b.resize(rng() % good.size());
    else if (i % 3 == 1)
      b[rng() % b.size()] ^= 0x40;
    else
      for (auto& x : b) x = static_cast<std::uint8_t>(rng());
    junk.sendRaw(b);
  }
  ASSERT_TRUE(waitFor([&] { return link->status().base_rejected >= 60; }))
      << "the base reports " << link->status().base_rejected << " rejected";
  EXPECT_TRUE(link->ok()) << link->status().last_error;
  EXPECT_EQ(link->status().faults, 0u);
}
