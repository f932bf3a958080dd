#pragma once
// The laptop side of the base protocol (doc/base-protocol.md):
//   dani://HOST:PORT[?secret_file=/path&link_timeout_s=0.15&connect_timeout_s=2]
// gives a hw::Base (velocity commands, odometry) and a hw::RangeSensor (the base's sonar)
// sharing one link. A background thread receives the base's streams, sends heartbeats and
// watches the link: when no valid message arrives for `link_timeout_s` the link latches a
// fault, sends Stop, and keeps trying to reconnect; after reconnecting it stays stopped until
// resume() is called explicitly.
#include <cstdint>
#include <memory>
#include <string>

#include "sketchnav/drivers/base_protocol.h"
#include "sketchnav/drivers/hw_names.h"

namespace sketchnav::drivers {

/// Longest wait for the base's first Welcome [s] (base.dani.connect_timeout_s, URI parameter
/// connect_timeout_s): checked before the link is opened, so 1e308 is refused instead of
/// hanging the run past its --seconds.
constexpr double kMaxConnectTimeoutS = 60.0;
/// Largest secret file read [bytes] (?secret_file=, base.dani.secret_file); only regular files.
constexpr std::uint64_t kMaxSecretFileBytes = 4096;

struct DaniParams {
  double link_timeout_s = 0.15;     // [s] no valid message for this long = link fault
  double heartbeat_period_s = 0.1;  // [s] Heartbeat period (the base answers each at once)
  double hello_period_s = 0.25;     // [s] Hello retry period while (re)connecting
  double connect_timeout_s = 2.0;   // [s] how long the factory waits for the first Welcome;
                                    // in (0, kMaxConnectTimeoutS]
  bool resume_on_connect = true;    // the first session is resumed by opening the device;
                                    // sessions after a fault never are
  template <class B>
  void bind(B& b) {
    b("link_timeout_s", link_timeout_s);
    b("heartbeat_period_s", heartbeat_period_s);
    b("hello_period_s", hello_period_s);
    b("connect_timeout_s", connect_timeout_s);
    b("resume_on_connect", resume_on_connect);
  }
  void validate() const;
};

/// What the link knows, for tests, probe and the UI's health panel. Times on the link clock.
struct DaniLinkStatus {
  bool connected = false;  // a session is open and messages flow
  bool latched = true;     // stopped until resume() (fault, or not yet resumed)
  proto::BaseState base_state = proto::BaseState::Idle;
  proto::StopReason base_reason = proto::StopReason::None;
  double last_rx_t = -1.0;          // [s] last valid message from the base
  double fault_t = -1.0;            // [s] when the link last declared a fault (and sent Stop)
  std::uint64_t faults = 0;         // link faults declared
  std::uint64_t sessions = 0;       // Welcomes received
  std::uint32_t base_rejected = 0;  // datagrams the base reports it refused or rejected
  double rtt_ms = -1.0;             // last Heartbeat -> Status round trip [ms], -1 unknown
  std::string last_error;
};

/// The shared link (one per dani:// authority). Thread-safe: every call takes one internal
/// mutex shared with the receive thread, so command(), stop() and odometry() may come from
/// any thread, concurrently (DaniBase and DaniSonar forward to it).
class DaniLink {
 public:
  /// `secret` empty: CRC-32 datagrams; else HMAC-SHA256 (must match the base's).
  DaniLink(std::string host, int port, DaniParams params, std::shared_ptr<Clock> clock,
           std::string secret = {}, std::string uri = {});
  ~DaniLink();
  DaniLink(const DaniLink&) = delete;
  DaniLink& operator=(const DaniLink&) = delete;

  /// Waits up to `timeout_s` for the first session (and, with resume_on_connect, for the
  /// base to report Running). False when the base did not answer.
  bool connect(double timeout_s);
  /// Sends Resume until the base reports Running or `timeout_s` passes; clears the latch.
  bool resume(double timeout_s = 1.0);

  void command(double v, double w);
  void stop() noexcept;
  bool odometry(Odometry& out);
  /// Latest sonar scan newer than `after_stamp`; false when none.
  bool sonar(RangeScan& out, double after_stamp);
  /// Connected, not latched, and the base reports Running.
  bool ok() const;
  DaniLinkStatus status() const;
  DeviceStats baseStats() const;
  DeviceStats sonarStats() const;
  const std::string& uri() const { return uri_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::string uri_;
};

class DaniBase final : public Base {
 public:
  explicit DaniBase(std::shared_ptr<DaniLink> link) : link_(std::move(link)) {}
  ~DaniBase() override { link_->stop(); }
  void command(double v, double w) override { link_->command(v, w); }
  void stop() noexcept override { link_->stop(); }
  bool odometry(Odometry& out) override { return link_->odometry(out); }
  bool ok() const override { return link_->ok(); }
  DeviceStats stats() const override { return link_->baseStats(); }
  std::string uri() const override { return link_->uri(); }
  /// The explicit resume after a fault (the UI's Resume button, the run command's restart).
  bool resume(double timeout_s = 1.0) { return link_->resume(timeout_s); }
  DaniLinkStatus status() const { return link_->status(); }
  DaniLink& link() { return *link_; }

 private:
  std::shared_ptr<DaniLink> link_;
};

/// The base's ultrasonic sensor(s) as a range sensor: read() returns each new scan once.
class DaniSonar final : public RangeSensor {
 public:
  explicit DaniSonar(std::shared_ptr<DaniLink> link) : link_(std::move(link)) {}
  bool read(RangeScan& out) override;
  DeviceStats stats() const override { return link_->sonarStats(); }
  std::string uri() const override { return link_->uri(); }

 private:
  std::shared_ptr<DaniLink> link_;
  double last_stamp_ = -1.0;
};

}  // namespace sketchnav::drivers
