#include "sketchnav/drivers/base_server.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "sketchnav/core/config.h"
#include "sketchnav/core/error.h"
#include "sketchnav/core/log.h"
#include "udp_socket.h"

namespace sketchnav::drivers {

using proto::BaseState;
using proto::Message;
using proto::StopReason;
using proto::Type;

void BaseServerParams::validate() const {
  const std::string p = "base_server";
  require(port >= 0 && port <= 65535, p + ".port", "must be 0..65535");
  require(!bind_host.empty(), p + ".bind_host", "must name an interface address");
  require(!allowed_peer.empty(), p + ".allowed_peer", "must name the laptop's address");
  require(watchdog_s > 0 && watchdog_s <= 5, p + ".watchdog_s", "must be in (0, 5] s");
  require(session_timeout_s > watchdog_s, p + ".session_timeout_s", "must exceed watchdog_s");
  require(odom_period_s > 0 && odom_period_s <= 1, p + ".odom_period_s", "must be in (0, 1] s");
  require(status_period_s > 0 && status_period_s <= 1, p + ".status_period_s",
          "must be in (0, 1] s");
  require(sonar_period_s > 0 && sonar_period_s <= 5, p + ".sonar_period_s", "must be in (0, 5] s");
  require(max_v > 0, p + ".max_v", "must be positive");
  require(max_w > 0, p + ".max_w", "must be positive");
  require(ticks_per_metre >= 0, p + ".ticks_per_metre", "must be >= 0");
  require(track_width > 0, p + ".track_width", "must be positive");
  const auto local = net::Endpoint::resolve(bind_host, port, "base_server.bind_host");
  // Beyond loopback anyone on the Wi-Fi could send CmdVel with a forged source address;
  // only a MAC over a shared secret tells the laptop's datagrams from theirs.
  require(local.isLoopback() || !secret.empty(), p + ".bind_host",
          "listening beyond loopback (" + bind_host + ") requires a shared secret");
}

struct BaseServer::Impl {
  Impl(Base& v, RangeSensor* s, Clock& c, const BaseServerParams& p)
      : vehicle(v), sonar(s), clock(c), params(p), rng(std::random_device{}()) {
    allowed = net::Endpoint::resolve(p.allowed_peer, 0, "base_server.allowed_peer");
    socket.bind(net::Endpoint::resolve(p.bind_host, p.port, "base_server.bind_host"));
    bound_port = socket.local().port();
  }

  Base& vehicle;
  RangeSensor* sonar;
  Clock& clock;
  BaseServerParams params;
  std::mt19937 rng;
  net::UdpSocket socket;
  net::Endpoint allowed;
  int bound_port = 0;
  bool closed = false;

  mutable std::mutex mutex;  // guards everything below
  BaseServerStats stats;
  std::vector<BaseServerEvent> events;
  net::Endpoint peer;
  std::uint32_t session = 0;
  std::uint32_t peer_seq = 0;  // last accepted laptop seq
  std::uint32_t my_seq = 0;
  bool moving = false;
  double last_rx_t = 0, next_odom_t = 0, next_status_t = 0, next_sonar_t = 0;
  double last_odom_t = -1;
  double dist_left = 0, dist_right = 0;  // [m] integrated wheel travel, for ticks
  std::vector<std::uint8_t> buf;

  void event(BaseServerEvent::Kind k, double t, std::string detail) {
    events.push_back({k, t, std::move(detail)});
    if (events.size() > 10000) events.erase(events.begin(), events.begin() + 5000);
  }

  void stopVehicle(double t, StopReason why, BaseState next) {
    vehicle.stop();
    moving = false;
    stats.last_stop_t = t;
    const bool changed = stats.state != next || stats.reason != why;
    stats.state = next;
    stats.reason = why;
    if (why == StopReason::Watchdog) ++stats.watchdog_trips;
    event(BaseServerEvent::Kind::Stop, t, proto::toString(why));
    if (changed)
      log::info("base-server", "stopped",
                {{"reason", proto::toString(why)}, {"state", proto::toString(next)}});
    sendStatus(t);
  }

  Message out(Type type) { return proto::makeMessage(type, session, ++my_seq); }
  void send(const Message& m) {
    if (session != 0 || m.header.type == Type::Welcome)
      socket.sendTo(proto::encode(m, params.secret), peer);
  }
  std::uint32_t baseMs(double t) const {
    return static_cast<std::uint32_t>(static_cast<std::uint64_t>(t * 1000.0));
  }
  void sendStatus(double t) {
    if (session == 0) return;
    Message m = out(Type::Status);
    m.status.base_time_ms = baseMs(t);
    m.status.state = stats.state;
    m.status.reason = stats.reason;
    m.status.watchdog_ms = static_cast<std::uint16_t>(std::lround(params.watchdog_s * 1000));
    m.status.ack_seq = peer_seq;
    m.status.rejected = static_cast<std::uint32_t>(stats.rejected + stats.refused);
    send(m);
    next_status_t = t + params.status_period_s;
  }

  void reject(double t, const std::string& why) {
    ++stats.rejected;
    stats.last_rejection = why;
    event(BaseServerEvent::Kind::Rejected, t, why);
    log::debug("base-server", "rejected datagram", {{"why", why}});
  }

  void handle(const net::Endpoint& from, double t) {
    if (!from.sameHost(allowed)) {
      ++stats.refused;
      stats.last_rejection = "refused datagram from " + from.host();
      event(BaseServerEvent::Kind::Refused, t, from.host());
      if (stats.refused == 1 || stats.refused % 100 == 0)
        log::warn("base-server", "refused datagram from a host that is not the laptop",
                  {{"from", from.str()},
                   {"allowed", allowed.host()},
                   {"count", std::to_string(stats.refused)}});
      return;
    }
    Message m;
    const auto err = proto::decode(buf.data(), buf.size(), m, params.secret);
    if (err != proto::DecodeError::None) return reject(t, proto::toString(err));
    const auto& h = m.header;
    if (h.type == Type::Hello) return hello(m, from, t);
    if (static_cast<std::uint8_t>(h.type) >= 0x80) return reject(t, "base-to-laptop type");
    if (session == 0 || h.session != session || !(from == peer))
      return reject(t, "not in the current session");
    // Stop is obeyed even when reordered: stopping late is never worse than not stopping.
    if (h.type != Type::Stop && static_cast<std::int32_t>(h.seq - peer_seq) <= 0)
      return reject(t, "stale sequence number");
    ++stats.received;
    if (static_cast<std::int32_t>(h.seq - peer_seq) > 0) peer_seq = h.seq;
    last_rx_t = t;
    switch (h.type) {
      case Type::CmdVel:
        return cmdVel(m, t);
      case Type::Stop:
        stopVehicle(t, StopReason::StopCommand, stats.state);
        return;
      case Type::Resume:
        if (stats.state == BaseState::Stopped) {
          stats.state = BaseState::Running;
          stats.reason = StopReason::None;
          moving = false;
          stats.last_command_t = t;
          event(BaseServerEvent::Kind::Resume, t, "");
          log::info("base-server", "resumed");
        }
        sendStatus(t);
        return;
      case Type::Heartbeat:
        sendStatus(t);  // answered at once: the laptop measures the round trip on it
        return;
      case Type::Bye:
        stopVehicle(t, StopReason::Bye, BaseState::Idle);
        event(BaseServerEvent::Kind::SessionEnd, t, "bye");
        session = 0;
        return;
      default:
        return;
    }
  }

  void hello(const Message& m, const net::Endpoint& from, double t) {
    // A new session always starts latched: a laptop that restarted or reconnected after a
    // fault must say Resume explicitly before anything moves.
    std::uint32_t id = 0;
    while (id == 0 || id == session) id = rng();
    session = id;
    peer = from;
    peer_seq = m.header.seq;
    ++stats.received;
    last_rx_t = t;
    event(BaseServerEvent::Kind::Session, t, from.str());
    log::info("base-server", "session opened", {{"peer", from.str()}});
    vehicle.stop();  // at once; stopVehicle() below records it after the Welcome is out
    Message w = out(Type::Welcome);
    w.welcome.hello_nonce = m.header.session;
    w.welcome.watchdog_ms = static_cast<std::uint16_t>(std::lround(params.watchdog_s * 1000));
    w.welcome.odom_period_ms = static_cast<std::uint16_t>(std::lround(params.odom_period_s * 1000));
    w.welcome.max_v = static_cast<float>(params.max_v);
    w.welcome.max_w = static_cast<float>(params.max_w);
    w.welcome.ticks_per_metre = static_cast<float>(params.ticks_per_metre);
    w.welcome.track_width = static_cast<float>(params.track_width);
    send(w);  // first, so the laptop knows the session before any other message of it
    stopVehicle(t, StopReason::NewSession, BaseState::Stopped);
    next_odom_t = t;
  }

  void cmdVel(const Message& m, double t) {
    if (stats.state != BaseState::Running) {
      ++stats.ignored_while_stopped;
      return;
    }
    if (!std::isfinite(m.cmd.v) || !std::isfinite(m.cmd.w))
      return stopVehicle(t, StopReason::StopCommand, stats.state);
    const double v = std::clamp<double>(m.cmd.v, -params.max_v, params.max_v);
    const double w = std::clamp<double>(m.cmd.w, -params.max_w, params.max_w);
    vehicle.command(v, w);
    moving = v != 0.0 || w != 0.0;
    stats.last_command_t = t;
    event(BaseServerEvent::Kind::Command, t, std::to_string(v) + " " + std::to_string(w));
  }

  void periodic(double t) {
    if (session == 0) return;
    if (stats.state == BaseState::Running && moving &&
        t - stats.last_command_t > params.watchdog_s) {
      log::warn("base-server", "watchdog: no valid command, stopping",
                {{"silent_ms", std::to_string(std::lround((t - stats.last_command_t) * 1000))}});
      stopVehicle(t, StopReason::Watchdog, BaseState::Stopped);
    }
    if (stats.state == BaseState::Running && !vehicle.ok())
      stopVehicle(t, StopReason::VehicleFault, BaseState::Stopped);
    if (t - last_rx_t > params.session_timeout_s) {
      stopVehicle(t, StopReason::SessionTimeout, BaseState::Idle);
      event(BaseServerEvent::Kind::SessionEnd, t, "timeout");
      log::warn("base-server", "session timed out", {{"peer", peer.str()}});
      session = 0;
      return;
    }
    if (t >= next_odom_t) {
      Odometry o;
      Message m = out(Type::Odom);
      m.odom.base_time_ms = baseMs(t);
      m.odom.ack_seq = peer_seq;
      m.odom.has_pose = vehicle.odometry(o);
      if (m.odom.has_pose) {
        m.odom.x = static_cast<float>(o.pose.x);
        m.odom.y = static_cast<float>(o.pose.y);
        m.odom.theta = static_cast<float>(o.pose.theta);
        m.odom.v = static_cast<float>(o.v);
        m.odom.w = static_cast<float>(o.w);
        if (last_odom_t >= 0) {
          const double dt = t - last_odom_t;
          dist_left += (o.v - 0.5 * o.w * params.track_width) * dt;
          dist_right += (o.v + 0.5 * o.w * params.track_width) * dt;
        }
        last_odom_t = t;
      }
      if (params.ticks_per_metre > 0) {
        m.odom.has_ticks = true;
        m.odom.ticks_left =
            static_cast<std::int32_t>(std::lround(dist_left * params.ticks_per_metre));
        m.odom.ticks_right =
            static_cast<std::int32_t>(std::lround(dist_right * params.ticks_per_metre));
      }
      send(m);
      next_odom_t = std::max(next_odom_t + params.odom_period_s, t);
    }
    if (t >= next_status_t) sendStatus(t);
    if (sonar && t >= next_sonar_t) {
      RangeScan s;
      if (sonar->read(s)) {
        Message m = out(Type::Sonar);
        m.sonar.base_time_ms = baseMs(t);
        m.sonar.min_range = s.min_range;
        m.sonar.max_range = s.max_range;
        m.sonar.beam_width = s.beam_width;
        m.sonar.mount_x = static_cast<float>(s.mount.x);
        m.sonar.mount_y = static_cast<float>(s.mount.y);
        m.sonar.mount_theta = static_cast<float>(s.mount.theta);
        const std::size_t n = std::min<std::size_t>(
            {s.angles.size(), s.ranges.size(), (proto::kMaxDatagram - 100) / 8});
        m.sonar.angles.assign(s.angles.begin(), s.angles.begin() + n);
        m.sonar.ranges.assign(s.ranges.begin(), s.ranges.begin() + n);
        send(m);
      }
      next_sonar_t = t + params.sonar_period_s;
    }
  }
};

BaseServer::BaseServer(Base& vehicle, RangeSensor* sonar, Clock& clock, BaseServerParams params)
    : params_(std::move(params)) {
  params_.validate();
  impl_ = std::make_unique<Impl>(vehicle, sonar, clock, params_);
  vehicle.stop();  // whatever the motors did before, a base starts stopped
  log::info("base-server", "listening",
            {{"bind", params_.bind_host + ":" + std::to_string(impl_->bound_port)},
             {"laptop", params_.allowed_peer},
             {"auth", params_.secret.empty() ? "crc32" : "hmac-sha256"}});
}

BaseServer::~BaseServer() {
  stopThread();
  shutdown();
}

int BaseServer::port() const {
  return impl_->bound_port;
}

void BaseServer::spinOnce(double max_wait_s) {
  Impl& s = *impl_;
  if (s.closed) return;
  net::Endpoint from;
  double wait = max_wait_s;
  // Drain everything queued (so a burst of stale commands is decided by the newest), but
  // keep the watchdog and streams running even under a flood of garbage.
  for (int i = 0; i < 256; ++i) {
    const long n = s.socket.recvFrom(s.buf, from, wait);
    if (n <= 0) break;
    std::lock_guard<std::mutex> lock(s.mutex);
    s.handle(from, s.clock.now());
    wait = 0.0;
  }
  std::lock_guard<std::mutex> lock(s.mutex);
  s.periodic(s.clock.now());
}

void BaseServer::startThread() {
  if (running_.exchange(true)) return;
  thread_ = std::thread([this] {
    while (running_) spinOnce(0.005);
  });
}

void BaseServer::stopThread() {
  running_ = false;
  if (thread_.joinable()) thread_.join();
}

void BaseServer::shutdown() {
  stopThread();
  if (!impl_ || impl_->closed) return;
  std::lock_guard<std::mutex> lock(impl_->mutex);
  impl_->vehicle.stop();
  impl_->socket.close();
  impl_->closed = true;
}

BaseServerStats BaseServer::stats() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->stats;
}

std::vector<BaseServerEvent> BaseServer::events() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->events;
}

// ---------------------------------------------------------------------------------------

UnicycleBase::UnicycleBase(Clock& clock, std::string uri)
    : clock_(clock), uri_(std::move(uri)), t_(clock.now()) {}

void UnicycleBase::integrateTo(double t) {
  const double dt = t - t_;
  if (dt <= 0) return;
  Pose2D& p = odo_.pose;
  // Exact arc integration, so the model's pose does not depend on how often it is read.
  if (std::abs(odo_.w) < 1e-9) {
    p.x += odo_.v * dt * std::cos(p.theta);
    p.y += odo_.v * dt * std::sin(p.theta);
  } else {
    const double th = p.theta + odo_.w * dt;
    p.x += odo_.v / odo_.w * (std::sin(th) - std::sin(p.theta));
    p.y -= odo_.v / odo_.w * (std::cos(th) - std::cos(p.theta));
    p.theta = std::atan2(std::sin(th), std::cos(th));
  }
  t_ = t;
}

void UnicycleBase::command(double v, double w) {
  std::lock_guard<std::mutex> lock(mutex_);
  integrateTo(clock_.now());
  odo_.v = v;
  odo_.w = w;
  ++commands_;
}

void UnicycleBase::stop() noexcept {
  std::lock_guard<std::mutex> lock(mutex_);
  integrateTo(clock_.now());
  odo_.v = odo_.w = 0.0;
  ++stops_;
}

bool UnicycleBase::odometry(Odometry& out) {
  std::lock_guard<std::mutex> lock(mutex_);
  integrateTo(clock_.now());
  odo_.stamp = t_;
  out = odo_;
  return true;
}

DeviceStats UnicycleBase::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  DeviceStats s;
  s.received = commands_;
  return s;
}

void UnicycleBase::velocity(double& v, double& w) const {
  std::lock_guard<std::mutex> lock(mutex_);
  v = odo_.v;
  w = odo_.w;
}

bool UnicycleBase::moving() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return odo_.v != 0.0 || odo_.w != 0.0;
}

std::uint64_t UnicycleBase::stopCount() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stops_;
}

}  // namespace sketchnav::drivers
