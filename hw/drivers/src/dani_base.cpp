#include "sketchnav/drivers/dani_base.h"

#include <atomic>
#include <cmath>
#include <deque>
#include <mutex>
#include <random>
#include <thread>

#include "sketchnav/core/config.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/log.h"
#include "udp_socket.h"

namespace sketchnav::drivers {

using proto::BaseState;
using proto::Message;
using proto::Type;

void DaniParams::validate() const {
  require(link_timeout_s > 0 && link_timeout_s <= 5, "base.dani.link_timeout_s",
          "must be in (0, 5] s");
  require(heartbeat_period_s > 0 && heartbeat_period_s < link_timeout_s * 10,
          "base.dani.heartbeat_period_s", "must be positive");
  require(hello_period_s > 0, "base.dani.hello_period_s", "must be positive");
  require(connect_timeout_s > 0 && connect_timeout_s <= kMaxConnectTimeoutS,
          "base.dani.connect_timeout_s", "must be in (0, 60] s");
  static_assert(kMaxConnectTimeoutS == 60.0, "the message above states the bound");
}

struct DaniLink::Impl {
  Impl(const std::string& host, int port, DaniParams p, std::shared_ptr<Clock> c, std::string s,
       std::string u)
      : params(p),
        clock(std::move(c)),
        secret(std::move(s)),
        uri(std::move(u)),
        rng(std::random_device{}()) {
    base = net::Endpoint::resolve(host, port, uri);
    socket.bind(net::Endpoint::resolve(base.isLoopback() ? "127.0.0.1" : "0.0.0.0", 0, uri));
  }

  DaniParams params;
  std::shared_ptr<Clock> clock;
  std::string secret, uri;
  std::mt19937 rng;
  net::Endpoint base;
  net::UdpSocket socket;
  std::thread thread;
  std::atomic<bool> running{true};

  mutable std::mutex mutex;  // guards everything below
  DaniLinkStatus st;
  proto::WelcomeMsg welcome;
  std::uint32_t session = 0;
  std::uint32_t hello_nonce = 0;
  std::uint32_t seq = 0;
  std::uint32_t base_seq = 0;
  bool ever_connected = false;
  bool want_resume = false;  // resume requested: keep sending Resume until Running
  double next_hello_t = 0, next_heartbeat_t = 0, next_resume_t = 0;
  std::deque<std::pair<std::uint32_t, double>> sent;  // seq -> send time, for the RTT
  bool have_odom = false;
  Odometry odom;
  bool have_ticks = false;
  std::int32_t last_ticks_l = 0, last_ticks_r = 0;
  bool have_scan = false;
  RangeScan scan;
  DeviceStats base_stats, sonar_stats;
  std::vector<std::uint8_t> buf;

  void sendLocked(Message m, double t) {
    if (m.header.type != Type::Hello) m.header.session = session;
    m.header.seq = ++seq;
    socket.sendTo(proto::encode(m, secret), base);
    // Round trips are timed on Heartbeats only: the base answers them at once, whereas
    // other messages are acknowledged by the next periodic stream message.
    if (m.header.type == Type::Heartbeat) {
      sent.emplace_back(m.header.seq, t);
      if (sent.size() > 16) sent.pop_front();
    }
  }

  void fault(double t, const std::string& why) {
    // Every fault path ends in Stop: tell the base (best effort: the link may be dead) and
    // latch locally so no further command goes out until an explicit resume.
    const bool first = st.connected || !st.latched;
    st.connected = false;
    st.latched = true;
    want_resume = false;
    st.last_error = why;
    base_stats.last_error = why;
    if (session != 0) sendLocked(proto::makeMessage(Type::Stop, session, 0), t);
    if (first) {
      st.fault_t = t;
      ++st.faults;
      log::warn("dani", "link fault, base told to stop", {{"uri", uri}, {"why", why}});
    }
    next_hello_t = t;  // start reconnecting at once
  }

  void ack(std::uint32_t ack_seq, double t) {
    while (!sent.empty() && static_cast<std::int32_t>(sent.front().first - ack_seq) < 0)
      sent.pop_front();
    if (!sent.empty() && sent.front().first == ack_seq) {
      st.rtt_ms = 1000.0 * (t - sent.front().second);
      sent.pop_front();
    }
  }

  void handle(const net::Endpoint& from, double t) {
    if (!(from == base)) {
      ++base_stats.dropped;
      return;
    }
    Message m;
    const auto err = proto::decode(buf.data(), buf.size(), m, secret);
    if (err != proto::DecodeError::None) {
      ++base_stats.dropped;
      if (err == proto::DecodeError::BadLength) ++base_stats.incomplete;
      log::debug("dani", "dropped datagram", {{"why", proto::toString(err)}});
      return;
    }
    const auto& h = m.header;
    if (h.type == Type::Welcome) {
      if (m.welcome.hello_nonce != hello_nonce || hello_nonce == 0) {
        ++base_stats.dropped;
        return;
      }
      session = h.session;
      hello_nonce = 0;
      base_seq = h.seq;
      // The base's limits and geometry are robot-facing inputs: a value that is not finite (or
      // out of range) is a fault, the session is told to stop and is never used.
      if (const std::string bad = badWelcome(m.welcome); !bad.empty()) {
        ++base_stats.dropped;
        fault(t, "base Welcome: " + bad);
        session = 0;  // nothing more from this session is accepted
        return;
      }
      welcome = m.welcome;
      st.connected = true;
      st.last_rx_t = t;
      ++st.sessions;
      have_ticks = false;
      log::info("dani", "session opened",
                {{"uri", uri}, {"watchdog_ms", std::to_string(welcome.watchdog_ms)}});
      if (!ever_connected && params.resume_on_connect) {
        want_resume = true;
        next_resume_t = t;
      }
      ever_connected = true;
      return;
    }
    if (session == 0 || h.session != session || static_cast<std::int32_t>(h.seq - base_seq) <= 0) {
      ++base_stats.dropped;
      return;
    }
    base_seq = h.seq;
    st.last_rx_t = t;
    if (!st.connected) st.connected = true;
    switch (h.type) {
      case Type::Odom:
        return onOdom(m.odom, t);
      case Type::Status:
        ack(m.status.ack_seq, t);
        st.base_state = m.status.state;
        st.base_reason = m.status.reason;
        st.base_rejected = m.status.rejected;
        if (m.status.state == BaseState::Running && want_resume) {
          want_resume = false;
          st.latched = false;
          st.last_error.clear();
          base_stats.last_error.clear();
          log::info("dani", "base running", {{"uri", uri}});
        }
        if (m.status.state != BaseState::Running && !st.latched) {
          // The base stopped on its own (watchdog, fault): mirror its latch.
          st.latched = true;
          st.last_error = std::string("base stopped: ") + proto::toString(m.status.reason);
          log::warn("dani", "base stopped itself", {{"reason", proto::toString(m.status.reason)}});
        }
        return;
      case Type::Sonar: {
        const auto& s = m.sonar;
        scan = RangeScan{};
        scan.kind = RangeScan::Kind::Sonar;
        scan.angles = s.angles;
        scan.ranges = s.ranges;
        scan.min_range = s.min_range;
        scan.max_range = s.max_range;
        scan.beam_width = s.beam_width;
        scan.mount = {s.mount_x, s.mount_y, s.mount_theta};
        scan.stamp = t;
        have_scan = true;
        ++sonar_stats.received;
        return;
      }
      default:
        ++base_stats.dropped;
        return;
    }
  }

  static std::string badWelcome(const proto::WelcomeMsg& w) {
    auto num = [](float v) { return std::to_string(v); };
    if (!std::isfinite(w.max_v) || w.max_v <= 0) return "max_v " + num(w.max_v) + " m/s";
    if (!std::isfinite(w.max_w) || w.max_w <= 0) return "max_w " + num(w.max_w) + " rad/s";
    if (!std::isfinite(w.ticks_per_metre) || w.ticks_per_metre < 0)
      return "ticks_per_metre " + num(w.ticks_per_metre);
    if (!std::isfinite(w.track_width) || w.track_width < 0)
      return "track_width " + num(w.track_width) + " m";
    if (w.watchdog_ms == 0) return "watchdog_ms 0";
    return {};
  }

  void onOdom(const proto::OdomMsg& o, double t) {
    if (o.has_pose) {
      const float f[5] = {o.x, o.y, o.theta, o.v, o.w};
      const char* names[5] = {"x", "y", "theta", "v", "w"};
      for (int i = 0; i < 5; ++i)
        if (!std::isfinite(f[i])) {
          // Never integrate or relay it: a pose the laptop cannot trust stops the robot.
          ++base_stats.dropped;
          fault(t, std::string("base odometry ") + names[i] + " is not finite (" +
                       std::to_string(f[i]) + ")");
          return;
        }
    }
    ++base_stats.received;
    if (o.has_pose) {
      odom.pose = {o.x, o.y, o.theta};
      odom.v = o.v;
      odom.w = o.w;
    } else if (o.has_ticks && welcome.ticks_per_metre > 0 && welcome.track_width > 0) {
      // Differential-drive dead reckoning from encoder ticks (wrap-safe differences).
      if (have_ticks) {
        const double dl = static_cast<std::int32_t>(o.ticks_left - last_ticks_l) /
                          static_cast<double>(welcome.ticks_per_metre);
        const double dr = static_cast<std::int32_t>(o.ticks_right - last_ticks_r) /
                          static_cast<double>(welcome.ticks_per_metre);
        const double ds = 0.5 * (dl + dr), dth = (dr - dl) / welcome.track_width;
        const double mid = odom.pose.theta + 0.5 * dth;
        odom.pose.x += ds * std::cos(mid);
        odom.pose.y += ds * std::sin(mid);
        odom.pose.theta =
            std::atan2(std::sin(odom.pose.theta + dth), std::cos(odom.pose.theta + dth));
        const double dt = have_odom ? t - odom.stamp : 0.0;
        odom.v = dt > 0 ? ds / dt : 0.0;
        odom.w = dt > 0 ? dth / dt : 0.0;
      }
      last_ticks_l = o.ticks_left;
      last_ticks_r = o.ticks_right;
      have_ticks = true;
    } else {
      return;
    }
    odom.stamp = t;
    have_odom = true;
  }

  void periodic(double t) {
    if (st.connected && t - st.last_rx_t > params.link_timeout_s) {
      fault(t, "link lost: no valid message from the base for " +
                   std::to_string(std::lround((t - st.last_rx_t) * 1000)) + " ms");
    }
    if (!st.connected && t >= next_hello_t) {
      hello_nonce = 0;
      while (hello_nonce == 0) hello_nonce = rng();
      Message m = proto::makeMessage(Type::Hello, hello_nonce, 0);
      m.hello.command_period_ms = 50;
      sendLocked(m, t);
      next_hello_t = t + params.hello_period_s;
      return;
    }
    if (!st.connected) return;
    if (want_resume && t >= next_resume_t) {
      sendLocked(proto::makeMessage(Type::Resume, session, 0), t);
      next_resume_t = t + 0.05;
    }
    if (t >= next_heartbeat_t) {
      sendLocked(proto::makeMessage(Type::Heartbeat, session, 0), t);
      next_heartbeat_t = t + params.heartbeat_period_s;
    }
  }

  void loop() {
    net::Endpoint from;
    while (running) {
      const long n = socket.recvFrom(buf, from, 0.005);
      std::lock_guard<std::mutex> lock(mutex);
      const double t = clock->now();
      if (n > 0) handle(from, t);
      periodic(t);
    }
  }
};

DaniLink::DaniLink(std::string host, int port, DaniParams params, std::shared_ptr<Clock> clock,
                   std::string secret, std::string uri)
    : uri_(uri.empty() ? "dani://" + host + ":" + std::to_string(port) : uri) {
  params.validate();
  if (!clock) clock = std::make_shared<SteadyClock>();
  impl_ = std::make_unique<Impl>(host, port, params, std::move(clock), std::move(secret), uri_);
  impl_->thread = std::thread([this] { impl_->loop(); });
}

DaniLink::~DaniLink() {
  stop();
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    if (impl_->session != 0)
      impl_->sendLocked(proto::makeMessage(Type::Bye, impl_->session, 0), impl_->clock->now());
  }
  impl_->running = false;
  if (impl_->thread.joinable()) impl_->thread.join();
}

bool DaniLink::connect(double timeout_s) {
  SteadyClock wall;
  while (wall.now() < timeout_s) {
    {
      std::lock_guard<std::mutex> lock(impl_->mutex);
      const bool resumed = !impl_->params.resume_on_connect || !impl_->st.latched;
      if (impl_->st.connected && resumed) return true;
    }
    wall.sleepUntil(wall.now() + 0.005);
  }
  std::lock_guard<std::mutex> lock(impl_->mutex);
  if (impl_->st.last_error.empty())
    impl_->st.last_error = impl_->base_stats.last_error =
        "no answer from the base at " + impl_->base.str();
  return false;
}

bool DaniLink::resume(double timeout_s) {
  {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    if (!impl_->st.connected) return false;
    impl_->want_resume = true;
    impl_->next_resume_t = impl_->clock->now();
  }
  SteadyClock wall;
  while (wall.now() < timeout_s) {
    {
      std::lock_guard<std::mutex> lock(impl_->mutex);
      if (!impl_->st.latched && impl_->st.connected) return true;
    }
    wall.sleepUntil(wall.now() + 0.005);
  }
  return false;
}

void DaniLink::command(double v, double w) {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  auto& s = *impl_;
  const double t = s.clock->now();
  if (!s.st.connected) return;  // nothing to talk to; the fault already sent Stop
  if (s.st.latched || !std::isfinite(v) || !std::isfinite(w)) {
    s.sendLocked(proto::makeMessage(Type::Stop, s.session, 0), t);
    return;
  }
  Message m = proto::makeMessage(Type::CmdVel, s.session, 0);
  m.cmd.v = static_cast<float>(v);
  m.cmd.w = static_cast<float>(w);
  s.sendLocked(m, t);
}

void DaniLink::stop() noexcept {
  try {
    std::lock_guard<std::mutex> lock(impl_->mutex);
    if (impl_->session != 0)
      impl_->sendLocked(proto::makeMessage(Type::Stop, impl_->session, 0), impl_->clock->now());
  } catch (...) {
    // stop() must not throw; a failed send is covered by the base's watchdog.
  }
}

bool DaniLink::odometry(Odometry& out) {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  if (!impl_->have_odom || !impl_->st.connected) return false;
  out = impl_->odom;
  return true;
}

bool DaniLink::sonar(RangeScan& out, double after_stamp) {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  if (!impl_->have_scan || impl_->scan.stamp <= after_stamp || !impl_->st.connected) return false;
  out = impl_->scan;
  return true;
}

bool DaniLink::ok() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->st.connected && !impl_->st.latched && impl_->st.base_state == BaseState::Running;
}

DaniLinkStatus DaniLink::status() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->st;
}

DeviceStats DaniLink::baseStats() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->base_stats;
}

DeviceStats DaniLink::sonarStats() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  DeviceStats s = impl_->sonar_stats;
  s.last_error = impl_->base_stats.last_error;
  return s;
}

bool DaniSonar::read(RangeScan& out) {
  if (!link_->sonar(out, last_stamp_)) return false;
  last_stamp_ = out.stamp;
  return true;
}

}  // namespace sketchnav::drivers
