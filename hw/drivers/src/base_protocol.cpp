#include "sketchnav/drivers/base_protocol.h"

#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/hmac.h>
#include <zlib.h>

#include <cstring>

namespace sketchnav::drivers::proto {
namespace {

// Big-endian writer/reader: explicit byte shuffling keeps the wire format independent of
// the host and identical to LabVIEW's default flattening.
class Writer {
 public:
  explicit Writer(std::vector<std::uint8_t>& b) : b_(b) {}
  void u8(std::uint8_t v) { b_.push_back(v); }
  void u16(std::uint16_t v) {
    u8(static_cast<std::uint8_t>(v >> 8));
    u8(static_cast<std::uint8_t>(v));
  }
  void u32(std::uint32_t v) {
    u16(static_cast<std::uint16_t>(v >> 16));
    u16(static_cast<std::uint16_t>(v));
  }
  void i32(std::int32_t v) { u32(static_cast<std::uint32_t>(v)); }
  void f32(float v) {
    std::uint32_t bits;
    std::memcpy(&bits, &v, 4);
    u32(bits);
  }

 private:
  std::vector<std::uint8_t>& b_;
};

class Reader {
 public:
  Reader(const std::uint8_t* p, std::size_t n) : p_(p), n_(n) {}
  bool ok() const { return ok_; }
  std::size_t left() const { return n_ - i_; }
  std::uint8_t u8() {
    if (i_ + 1 > n_) return fail();
    return p_[i_++];
  }
  std::uint16_t u16() {
    const std::uint16_t hi = u8();
    return static_cast<std::uint16_t>((hi << 8) | u8());
  }
  std::uint32_t u32() {
    const std::uint32_t hi = u16();
    return (hi << 16) | u16();
  }
  std::int32_t i32() { return static_cast<std::int32_t>(u32()); }
  float f32() {
    const std::uint32_t bits = u32();
    float v;
    std::memcpy(&v, &bits, 4);
    return v;
  }

 private:
  std::uint8_t fail() {
    ok_ = false;
    i_ = n_;
    return 0;
  }
  const std::uint8_t* p_;
  std::size_t n_;
  std::size_t i_ = 0;
  bool ok_ = true;
};

std::uint32_t crc32Of(const std::uint8_t* p, std::size_t n) {
  return static_cast<std::uint32_t>(::crc32(::crc32(0L, Z_NULL, 0), p, static_cast<uInt>(n)));
}

void hmacOf(const std::string& secret, const std::uint8_t* p, std::size_t n,
            std::uint8_t out[kHmacSize]) {
  unsigned int len = 0;
  HMAC(EVP_sha256(), secret.data(), static_cast<int>(secret.size()), p, n, out, &len);
}

void writePayload(const Message& m, Writer& w) {
  switch (m.header.type) {
    case Type::Hello:
      w.u16(m.hello.command_period_ms);
      break;
    case Type::CmdVel:
      w.f32(m.cmd.v);
      w.f32(m.cmd.w);
      break;
    case Type::Welcome:
      w.u32(m.welcome.hello_nonce);
      w.u16(m.welcome.watchdog_ms);
      w.u16(m.welcome.odom_period_ms);
      w.f32(m.welcome.max_v);
      w.f32(m.welcome.max_w);
      w.f32(m.welcome.ticks_per_metre);
      w.f32(m.welcome.track_width);
      break;
    case Type::Odom: {
      const OdomMsg& o = m.odom;
      w.u32(o.base_time_ms);
      w.u32(o.ack_seq);
      w.i32(o.ticks_left);
      w.i32(o.ticks_right);
      w.f32(o.x);
      w.f32(o.y);
      w.f32(o.theta);
      w.f32(o.v);
      w.f32(o.w);
      w.u8(o.has_pose ? 1 : 0);
      w.u8(o.has_ticks ? 1 : 0);
      w.u16(0);
      break;
    }
    case Type::Sonar: {
      const SonarMsg& s = m.sonar;
      w.u32(s.base_time_ms);
      w.f32(s.min_range);
      w.f32(s.max_range);
      w.f32(s.beam_width);
      w.f32(s.mount_x);
      w.f32(s.mount_y);
      w.f32(s.mount_theta);
      const std::size_t n = std::min(s.angles.size(), s.ranges.size());
      w.u16(static_cast<std::uint16_t>(n));
      w.u16(0);
      for (std::size_t i = 0; i < n; ++i) {
        w.f32(s.angles[i]);
        w.f32(s.ranges[i]);
      }
      break;
    }
    case Type::Status:
      w.u32(m.status.base_time_ms);
      w.u8(static_cast<std::uint8_t>(m.status.state));
      w.u8(static_cast<std::uint8_t>(m.status.reason));
      w.u16(m.status.watchdog_ms);
      w.u32(m.status.ack_seq);
      w.u32(m.status.rejected);
      break;
    case Type::Stop:
    case Type::Resume:
    case Type::Heartbeat:
    case Type::Bye:
      break;
  }
}

// Returns false when the payload does not have exactly the size its type requires.
bool readPayload(Message& m, Reader& r) {
  switch (m.header.type) {
    case Type::Hello:
      m.hello.command_period_ms = r.u16();
      break;
    case Type::CmdVel:
      m.cmd.v = r.f32();
      m.cmd.w = r.f32();
      break;
    case Type::Welcome:
      m.welcome.hello_nonce = r.u32();
      m.welcome.watchdog_ms = r.u16();
      m.welcome.odom_period_ms = r.u16();
      m.welcome.max_v = r.f32();
      m.welcome.max_w = r.f32();
      m.welcome.ticks_per_metre = r.f32();
      m.welcome.track_width = r.f32();
      break;
    case Type::Odom: {
      OdomMsg& o = m.odom;
      o.base_time_ms = r.u32();
      o.ack_seq = r.u32();
      o.ticks_left = r.i32();
      o.ticks_right = r.i32();
      o.x = r.f32();
      o.y = r.f32();
      o.theta = r.f32();
      o.v = r.f32();
      o.w = r.f32();
      o.has_pose = r.u8() != 0;
      o.has_ticks = r.u8() != 0;
      r.u16();
      break;
    }
    case Type::Sonar: {
      SonarMsg& s = m.sonar;
      s.base_time_ms = r.u32();
      s.min_range = r.f32();
      s.max_range = r.f32();
      s.beam_width = r.f32();
      s.mount_x = r.f32();
      s.mount_y = r.f32();
      s.mount_theta = r.f32();
      const std::uint16_t n = r.u16();
      r.u16();
      if (!r.ok() || r.left() != 8u * n) return false;
      s.angles.resize(n);
      s.ranges.resize(n);
      for (std::uint16_t i = 0; i < n; ++i) {
        s.angles[i] = r.f32();
        s.ranges[i] = r.f32();
      }
      break;
    }
    case Type::Status: {
      m.status.base_time_ms = r.u32();
      const std::uint8_t state = r.u8();
      const std::uint8_t reason = r.u8();
      if (state > 2 || reason > 6) return false;
      m.status.state = static_cast<BaseState>(state);
      m.status.reason = static_cast<StopReason>(reason);
      m.status.watchdog_ms = r.u16();
      m.status.ack_seq = r.u32();
      m.status.rejected = r.u32();
      break;
    }
    case Type::Stop:
    case Type::Resume:
    case Type::Heartbeat:
    case Type::Bye:
      break;
    default:
      return false;
  }
  return r.ok() && r.left() == 0;
}

bool knownType(std::uint8_t t) {
  return (t >= 0x01 && t <= 0x06) || (t >= 0x81 && t <= 0x84);
}

}  // namespace

const char* toString(Type t) {
  switch (t) {
    case Type::Hello:
      return "hello";
    case Type::CmdVel:
      return "cmd_vel";
    case Type::Stop:
      return "stop";
    case Type::Resume:
      return "resume";
    case Type::Heartbeat:
      return "heartbeat";
    case Type::Bye:
      return "bye";
    case Type::Welcome:
      return "welcome";
    case Type::Odom:
      return "odom";
    case Type::Sonar:
      return "sonar";
    case Type::Status:
      return "status";
  }
  return "unknown";
}

const char* toString(BaseState s) {
  switch (s) {
    case BaseState::Idle:
      return "idle";
    case BaseState::Stopped:
      return "stopped";
    case BaseState::Running:
      return "running";
  }
  return "unknown";
}

const char* toString(StopReason r) {
  switch (r) {
    case StopReason::None:
      return "none";
    case StopReason::NewSession:
      return "new session";
    case StopReason::Watchdog:
      return "watchdog";
    case StopReason::StopCommand:
      return "stop command";
    case StopReason::VehicleFault:
      return "vehicle fault";
    case StopReason::Bye:
      return "bye";
    case StopReason::SessionTimeout:
      return "session timeout";
  }
  return "unknown";
}

const char* toString(DecodeError e) {
  switch (e) {
    case DecodeError::None:
      return "ok";
    case DecodeError::TooShort:
      return "too short";
    case DecodeError::BadMagic:
      return "bad magic";
    case DecodeError::BadVersion:
      return "unsupported version";
    case DecodeError::BadLength:
      return "length mismatch (truncated?)";
    case DecodeError::BadChecksum:
      return "bad CRC-32";
    case DecodeError::BadAuth:
      return "authentication failed";
    case DecodeError::BadPayload:
      return "bad payload for type";
  }
  return "unknown";
}

Message makeMessage(Type type, std::uint32_t session, std::uint32_t seq) {
  Message m;
  m.header.type = type;
  m.header.session = session;
  m.header.seq = seq;
  return m;
}

std::vector<std::uint8_t> encode(const Message& m, const std::string& secret) {
  std::vector<std::uint8_t> out;
  out.reserve(64);
  Writer w(out);
  w.u8(kMagic0);
  w.u8(kMagic1);
  w.u8(m.header.version);
  w.u8(static_cast<std::uint8_t>(m.header.type));
  w.u32(m.header.session);
  w.u32(m.header.seq);
  w.u16(0);  // payload length, patched below
  const std::uint16_t flags = static_cast<std::uint16_t>((m.header.flags & ~kFlagAuthenticated) |
                                                         (secret.empty() ? 0 : kFlagAuthenticated));
  w.u16(flags);
  writePayload(m, w);
  const std::size_t payload = out.size() - kHeaderSize;
  out[12] = static_cast<std::uint8_t>(payload >> 8);
  out[13] = static_cast<std::uint8_t>(payload);
  if (secret.empty()) {
    w.u32(crc32Of(out.data(), out.size()));
  } else {
    std::uint8_t mac[kHmacSize];
    hmacOf(secret, out.data(), out.size(), mac);
    out.insert(out.end(), mac, mac + kHmacSize);
  }
  return out;
}

DecodeError decode(const std::uint8_t* data, std::size_t size, Message& out,
                   const std::string& secret) {
  if (size < kHeaderSize + kCrcSize) return DecodeError::TooShort;
  if (data[0] != kMagic0 || data[1] != kMagic1) return DecodeError::BadMagic;
  if (data[2] != kVersion) return DecodeError::BadVersion;
  Reader h(data, kHeaderSize);
  h.u8();
  h.u8();
  Message m;
  m.header.version = h.u8();
  const std::uint8_t type = h.u8();
  m.header.session = h.u32();
  m.header.seq = h.u32();
  const std::uint16_t payload = h.u16();
  m.header.flags = h.u16();
  const bool authed = (m.header.flags & kFlagAuthenticated) != 0;
  const std::size_t trailer = authed ? kHmacSize : kCrcSize;
  if (size != kHeaderSize + payload + trailer) return DecodeError::BadLength;
  const std::size_t body = kHeaderSize + payload;
  if (authed != !secret.empty()) return DecodeError::BadAuth;
  if (authed) {
    std::uint8_t mac[kHmacSize];
    hmacOf(secret, data, body, mac);
    if (CRYPTO_memcmp(mac, data + body, kHmacSize) != 0) return DecodeError::BadAuth;
  } else {
    Reader t(data + body, kCrcSize);
    if (t.u32() != crc32Of(data, body)) return DecodeError::BadChecksum;
  }
  if (!knownType(type)) return DecodeError::BadPayload;
  m.header.type = static_cast<Type>(type);
  Reader r(data + kHeaderSize, payload);
  if (!readPayload(m, r)) return DecodeError::BadPayload;
  out = std::move(m);
  return DecodeError::None;
}

}  // namespace sketchnav::drivers::proto
