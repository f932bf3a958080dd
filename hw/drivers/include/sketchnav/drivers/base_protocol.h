#pragma once
// The laptop <-> robot base protocol (doc/base-protocol.md is the normative text; this header
// is its C++ encoding). One message per UDP datagram, big-endian ("network order", what
// LabVIEW's Flatten To String produces), a fixed 16-byte header, a payload, and a trailer:
// CRC-32 (4 bytes) or, when a shared secret is configured, HMAC-SHA256 (32 bytes).
//
// Encoding and decoding are pure functions so both sides (and tests feeding garbage) share
// them; nothing here does I/O.
#include <cstdint>
#include <string>
#include <vector>

namespace sketchnav::drivers::proto {

constexpr std::uint8_t kMagic0 = 'S';
constexpr std::uint8_t kMagic1 = 'N';
constexpr std::uint8_t kVersion = 1;
constexpr std::size_t kHeaderSize = 16;
constexpr std::size_t kCrcSize = 4;
constexpr std::size_t kHmacSize = 32;
constexpr std::size_t kMaxDatagram = 1400;  // fits one Ethernet frame, no IP fragmentation
constexpr std::uint16_t kFlagAuthenticated = 0x0001;  // trailer is HMAC-SHA256, not CRC-32

enum class Type : std::uint8_t {
  // laptop -> base
  Hello = 0x01,      // open (or replace) a session; the base stops and answers Welcome
  CmdVel = 0x02,     // velocity command; the only message that feeds the motion watchdog
  Stop = 0x03,       // stop now and latch (obeyed whatever its sequence number)
  Resume = 0x04,     // clear a latched stop (the only way out of Stopped)
  Heartbeat = 0x05,  // keeps the session alive while idle; does not feed the watchdog
  Bye = 0x06,        // close the session; the base stops
  // base -> laptop
  Welcome = 0x81,
  Odom = 0x82,
  Sonar = 0x83,
  Status = 0x84,
};

/// Base state machine (doc/base-protocol.md, "States").
enum class BaseState : std::uint8_t {
  Idle = 0,     // no session: motors off, streams nothing
  Stopped = 1,  // session open, motors stopped and latched until Resume
  Running = 2,  // obeying CmdVel
};

/// Why the base is (or last went) Stopped.
enum class StopReason : std::uint8_t {
  None = 0,
  NewSession = 1,  // a Hello opened or replaced the session
  Watchdog = 2,    // no valid CmdVel within the watchdog period while moving
  StopCommand = 3,
  VehicleFault = 4,
  Bye = 5,
  SessionTimeout = 6,
};

const char* toString(Type t);
const char* toString(BaseState s);
const char* toString(StopReason r);

struct Header {
  std::uint8_t version = kVersion;
  Type type = Type::Heartbeat;
  std::uint32_t session = 0;  // Hello: the laptop's nonce; afterwards the id from Welcome
  std::uint32_t seq = 0;      // per sender, strictly increasing within a session
  std::uint16_t flags = 0;
};

struct HelloMsg {
  std::uint16_t command_period_ms = 50;  // how often the laptop intends to send CmdVel
};

struct CmdVelMsg {
  float v = 0.0f;  // [m/s] forward
  float w = 0.0f;  // [rad/s] CCW positive
};

/// The base's answer to Hello. Its header carries the session id the base chose (random);
/// every later message of the session carries it, so replayed datagrams of an older session
/// are refused.
struct WelcomeMsg {
  std::uint32_t hello_nonce = 0;  // the `session` field of the Hello being answered
  std::uint16_t watchdog_ms = 200;
  std::uint16_t odom_period_ms = 50;
  float max_v = 0.5f;            // [m/s] the base clamps commands to this
  float max_w = 1.5f;            // [rad/s]
  float ticks_per_metre = 0.0f;  // encoder ticks per metre of wheel travel (0: no ticks)
  float track_width = 0.0f;      // [m] distance between the wheels
};

struct OdomMsg {
  std::uint32_t base_time_ms = 0;  // base's own monotonic clock
  std::uint32_t ack_seq = 0;       // last laptop seq the base accepted (latency measurement)
  std::int32_t ticks_left = 0;     // cumulative encoder ticks (wrap allowed)
  std::int32_t ticks_right = 0;
  float x = 0.0f, y = 0.0f, theta = 0.0f;  // [m, m, rad] dead-reckoned pose
  float v = 0.0f, w = 0.0f;                // [m/s, rad/s] measured
  bool has_pose = true;                    // false: the laptop integrates the ticks
  bool has_ticks = false;
};

struct SonarMsg {
  std::uint32_t base_time_ms = 0;
  float min_range = 0.0f, max_range = 0.0f, beam_width = 0.0f;  // [m, m, rad]
  float mount_x = 0.0f, mount_y = 0.0f, mount_theta = 0.0f;     // sensor pose in robot frame
  std::vector<float> angles;  // [rad] bearing per beam in the robot frame (CCW)
  std::vector<float> ranges;  // [m]; >= max_range: nothing seen
};

struct StatusMsg {
  std::uint32_t base_time_ms = 0;
  BaseState state = BaseState::Idle;
  StopReason reason = StopReason::None;
  std::uint16_t watchdog_ms = 0;
  std::uint32_t ack_seq = 0;
  std::uint32_t rejected = 0;  // datagrams the base refused (bad CRC, stale seq, wrong peer...)
};

/// A decoded message: the header plus whichever payload its type carries.
struct Message {
  Header header;
  HelloMsg hello;
  CmdVelMsg cmd;
  WelcomeMsg welcome;
  OdomMsg odom;
  SonarMsg sonar;
  StatusMsg status;
};

/// Why decode() refused a datagram (each is counted by the receiver, never thrown).
enum class DecodeError {
  None,
  TooShort,  // shorter than header + trailer
  BadMagic,
  BadVersion,
  BadLength,    // payload length disagrees with the datagram size (truncated / padded)
  BadChecksum,  // CRC-32 mismatch (corrupted)
  BadAuth,      // HMAC missing, wrong, or present when no secret is configured
  BadPayload,   // unknown type or payload size wrong for the type
};
const char* toString(DecodeError e);

/// Serialises one message. `secret` empty: CRC-32 trailer; else HMAC-SHA256 with it.
std::vector<std::uint8_t> encode(const Message& m, const std::string& secret = {});

/// Parses one datagram. With a non-empty `secret` only authenticated messages are accepted;
/// with an empty one only CRC-protected ones are (so a misconfigured peer is refused loudly).
DecodeError decode(const std::uint8_t* data, std::size_t size, Message& out,
                   const std::string& secret = {});

/// Convenience constructors.
Message makeMessage(Type type, std::uint32_t session, std::uint32_t seq);

}  // namespace sketchnav::drivers::proto
