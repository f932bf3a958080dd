#pragma once
// The base side of the laptop <-> base protocol (doc/base-protocol.md): a reference
// implementation over any vehicle model that implements hw::Base (the simulator's vehicle,
// the UnicycleBase below, a real motor driver). `sketchnav base-emulator` runs one; firmware
// authors read it next to the protocol document.
//
// Safety behaviour, all observable through stats()/events():
//  - datagrams from any host but `allowed_peer` are refused before they are parsed;
//  - a malformed, truncated, corrupted, unauthenticated, stale or out-of-session datagram is
//    counted and ignored (it never feeds the watchdog);
//  - while moving, no valid CmdVel for `watchdog_s` stops the vehicle and latches Stopped;
//  - a new session (a laptop reconnecting) also latches Stopped: only Resume clears it.
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "sketchnav/drivers/base_protocol.h"
#include "sketchnav/drivers/hw_names.h"

namespace sketchnav::drivers {

struct BaseServerParams {
  std::string bind_host = "127.0.0.1";     // interface to listen on; beyond loopback needs `secret`
  int port = 5600;                         // UDP port; 0 picks a free one (tests)
  std::string allowed_peer = "127.0.0.1";  // the laptop's address; all others are refused
  std::string secret;                      // shared secret (HMAC-SHA256); empty: CRC-32 only
  double watchdog_s = 0.2;                 // [s] stop when moving and no valid CmdVel for this long
  double session_timeout_s = 2.0;  // [s] drop the session when the laptop is silent this long
  double odom_period_s = 0.05;     // [s] Odom stream period
  double status_period_s = 0.2;    // [s] Status stream period (also the base's heartbeat)
  double sonar_period_s = 0.1;     // [s] Sonar stream period (when a sonar is attached)
  double max_v = 0.5;              // [m/s] commands are clamped to +-max_v
  double max_w = 1.5;              // [rad/s] commands are clamped to +-max_w
  double ticks_per_metre = 0.0;    // encoder ticks per metre reported in Odom (0: no ticks)
  double track_width = 0.35;       // [m] wheel separation, for the tick model
  template <class B>
  void bind(B& b) {
    b("bind_host", bind_host);
    b("port", port);
    b("allowed_peer", allowed_peer);
    b("watchdog_s", watchdog_s);
    b("session_timeout_s", session_timeout_s);
    b("odom_period_s", odom_period_s);
    b("status_period_s", status_period_s);
    b("sonar_period_s", sonar_period_s);
    b("max_v", max_v);
    b("max_w", max_w);
    b("ticks_per_metre", ticks_per_metre);
    b("track_width", track_width);
  }
  /// Also enforces "a shared secret beyond loopback" (InputError naming the field).
  void validate() const;
};

/// One thing the server did, for logs and for tests that check ordering and timing.
struct BaseServerEvent {
  enum class Kind {
    Session,     // a Hello opened / replaced the session (vehicle stopped)
    Command,     // a CmdVel was applied
    Stop,        // the vehicle was told to stop (detail says why)
    Resume,      // a Resume cleared the latch
    Rejected,    // a datagram from the allowed peer was malformed / stale / unauthenticated
    Refused,     // a datagram from another host
    SessionEnd,  // Bye or session timeout
  };
  Kind kind;
  double t = 0.0;  // [s] server clock
  std::string detail;
};

struct BaseServerStats {
  std::uint64_t received = 0;               // valid datagrams accepted
  std::uint64_t rejected = 0;               // malformed / stale / out of session, from the peer
  std::uint64_t refused = 0;                // from a host other than allowed_peer
  std::uint64_t ignored_while_stopped = 0;  // CmdVel received while latched Stopped
  std::uint64_t watchdog_trips = 0;
  proto::BaseState state = proto::BaseState::Idle;
  proto::StopReason reason = proto::StopReason::None;
  double last_command_t = -1.0;  // [s] when the last valid CmdVel was applied
  double last_stop_t = -1.0;     // [s] when the vehicle was last told to stop
  std::string last_rejection;    // why the last datagram was rejected / refused
};

class BaseServer {
 public:
  /// `vehicle` and `clock` must outlive the server; `sonar` may be null. Binds at once;
  /// throws InputError on bad params, RuntimeError when the port cannot be bound.
  BaseServer(Base& vehicle, RangeSensor* sonar, Clock& clock, BaseServerParams params);
  ~BaseServer();
  BaseServer(const BaseServer&) = delete;
  BaseServer& operator=(const BaseServer&) = delete;

  /// The bound UDP port (useful with params.port = 0).
  int port() const;

  /// One step of the loop: waits up to `max_wait_s` for datagrams, handles them, checks the
  /// watchdog and sends due streams. Call it from one thread, often (every few ms).
  void spinOnce(double max_wait_s = 0.005);

  /// Runs spinOnce() on an internal thread until stopThread() (or destruction).
  void startThread();
  void stopThread();

  /// Closes the socket and stops the vehicle at once, as a crashed or unplugged base would
  /// look from the laptop (tests use this to "kill" the base in-process).
  void shutdown();

  BaseServerStats stats() const;
  std::vector<BaseServerEvent> events() const;
  const BaseServerParams& params() const { return params_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  BaseServerParams params_;
  std::thread thread_;
  std::atomic<bool> running_{false};
};

/// A unicycle vehicle model (no I/O): integrates the commanded (v, w) on `clock`, with
/// first-order-free instant response. What `base-emulator` drives when no simulator is
/// given, and what the protocol tests drive. Thread-safe.
class UnicycleBase final : public Base {
 public:
  explicit UnicycleBase(Clock& clock, std::string uri = "unicycle://");
  void command(double v, double w) override;
  void stop() noexcept override;
  bool odometry(Odometry& out) override;
  bool ok() const override { return true; }
  DeviceStats stats() const override;
  std::string uri() const override { return uri_; }

  /// Current commanded velocity (what the "motors" are doing).
  void velocity(double& v, double& w) const;
  bool moving() const;
  std::uint64_t stopCount() const;

 private:
  void integrateTo(double t);
  Clock& clock_;
  std::string uri_;
  mutable std::mutex mutex_;
  Odometry odo_;
  double t_ = 0.0;
  std::uint64_t commands_ = 0, stops_ = 0;
};

}  // namespace sketchnav::drivers
