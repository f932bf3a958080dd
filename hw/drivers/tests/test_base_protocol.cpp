#include <gtest/gtest.h>

#include <random>

#include "sketchnav/drivers/base_protocol.h"

using namespace sketchnav::drivers::proto;

namespace {
Message sample(Type t) {
  Message m = makeMessage(t, 0xA1B2C3D4u, 77);
  m.hello.command_period_ms = 40;
  m.cmd = {0.25f, -0.5f};
  m.welcome = {123u, 150, 50, 0.4f, 1.2f, 2000.0f, 0.33f};
  m.odom.base_time_ms = 9;
  m.odom.ack_seq = 76;
  m.odom.ticks_left = -5;
  m.odom.ticks_right = 2147483647;
  m.odom.x = 1.5f;
  m.odom.theta = -3.0f;
  m.odom.has_ticks = true;
  m.sonar.max_range = 3.0f;
  m.sonar.angles = {0.0f, 0.5f};
  m.sonar.ranges = {1.0f, 3.0f};
  m.status.state = BaseState::Running;
  m.status.reason = StopReason::Watchdog;
  m.status.rejected = 4;
  return m;
}
const Type kAll[] = {Type::Hello, Type::CmdVel,  Type::Stop, Type::Resume, Type::Heartbeat,
                     Type::Bye,   Type::Welcome, Type::Odom, Type::Sonar,  Type::Status};
}  // namespace

TEST(BaseProtocol, EveryTypeRoundTripsWithCrcAndWithHmac) {
  for (const std::string secret : {std::string(), std::string("correct horse battery")}) {
    for (Type t : kAll) {
      const Message in = sample(t);
      const auto bytes = encode(in, secret);
      Message out;
      ASSERT_EQ(decode(bytes.data(), bytes.size(), out, secret), DecodeError::None) << toString(t);
      EXPECT_EQ(out.header.type, t);
      EXPECT_EQ(out.header.session, 0xA1B2C3D4u);
      EXPECT_EQ(out.header.seq, 77u);
      EXPECT_LE(bytes.size(), kMaxDatagram);
    }
  }
  const auto b = encode(sample(Type::Odom));
  Message o;
  ASSERT_EQ(decode(b.data(), b.size(), o), DecodeError::None);
  EXPECT_EQ(o.odom.ticks_left, -5);
  EXPECT_EQ(o.odom.ticks_right, 2147483647);
  EXPECT_FLOAT_EQ(o.odom.x, 1.5f);
  EXPECT_FLOAT_EQ(o.odom.theta, -3.0f);
  EXPECT_TRUE(o.odom.has_pose);
  EXPECT_TRUE(o.odom.has_ticks);
  const auto s = encode(sample(Type::Sonar));
  ASSERT_EQ(decode(s.data(), s.size(), o), DecodeError::None);
  ASSERT_EQ(o.sonar.ranges.size(), 2u);
  EXPECT_FLOAT_EQ(o.sonar.angles[1], 0.5f);
  EXPECT_FLOAT_EQ(o.sonar.ranges[1], 3.0f);
  const auto w = encode(sample(Type::Welcome));
  ASSERT_EQ(decode(w.data(), w.size(), o), DecodeError::None);
  EXPECT_EQ(o.welcome.hello_nonce, 123u);
  EXPECT_EQ(o.welcome.watchdog_ms, 150);
  EXPECT_FLOAT_EQ(o.welcome.track_width, 0.33f);
}

TEST(BaseProtocol, WireFormatIsBigEndianAsDocumented) {
  // doc/base-protocol.md gives this exact CmdVel datagram; a firmware author checks against it.
  Message m = makeMessage(Type::CmdVel, 0x01020304u, 5);
  m.cmd = {1.0f, -2.0f};
  const auto b = encode(m);
  const std::vector<std::uint8_t> head = {'S', 'N', 1, 0x02, 1,    2,    3, 4, 0,    0, 0, 5,
                                          0,   8,   0, 0,    0x3F, 0x80, 0, 0, 0xC0, 0, 0, 0};
  ASSERT_EQ(b.size(), head.size() + 4);
  EXPECT_TRUE(std::equal(head.begin(), head.end(), b.begin()));
  // CRC-32 (IEEE 802.3, zlib's) of the 24 bytes above, big-endian.
  // (Python: zlib.crc32(bytes.fromhex("534e0102...c0000000")) == 0x343a7b38.)
  EXPECT_EQ(b[24], 0x34);
  EXPECT_EQ(b[25], 0x3A);
  EXPECT_EQ(b[26], 0x7B);
  EXPECT_EQ(b[27], 0x38);
}

TEST(BaseProtocol, EveryTruncationIsRejected) {
  for (Type t : kAll) {
    const auto b = encode(sample(t));
    for (std::size_t n = 0; n < b.size(); ++n) {
      Message out;
      const auto e = decode(b.data(), n, out);
      EXPECT_NE(e, DecodeError::None) << toString(t) << " truncated to " << n;
    }
  }
}

TEST(BaseProtocol, CorruptionAndGarbageAreRejected) {
  const auto b = encode(sample(Type::CmdVel));
  for (std::size_t i = 0; i < b.size(); ++i) {
    for (int bit = 0; bit < 8; ++bit) {
      auto c = b;
      c[i] ^= static_cast<std::uint8_t>(1u << bit);
      Message out;
      EXPECT_NE(decode(c.data(), c.size(), out), DecodeError::None)
          << "byte " << i << " bit " << bit;
    }
  }
  std::mt19937 rng(42);
  int accepted = 0;
  for (int k = 0; k < 20000; ++k) {
    std::vector<std::uint8_t> g(rng() % 80);
    for (auto& x : g) x = static_cast<std::uint8_t>(rng());
    if (g.size() >= 2 && k % 2) g[0] = 'S', g[1] = 'N';  // get past the magic half the time
    Message out;
    if (decode(g.data(), g.size(), out) == DecodeError::None) ++accepted;
  }
  EXPECT_EQ(accepted, 0);
}

TEST(BaseProtocol, AuthenticationMustMatchTheConfiguredSecret) {
  const auto plain = encode(sample(Type::CmdVel));
  const auto signed_ok = encode(sample(Type::CmdVel), "secret-one");
  Message out;
  EXPECT_EQ(decode(plain.data(), plain.size(), out, "secret-one"), DecodeError::BadAuth);
  EXPECT_EQ(decode(signed_ok.data(), signed_ok.size(), out, "secret-two"), DecodeError::BadAuth);
  EXPECT_EQ(decode(signed_ok.data(), signed_ok.size(), out, ""), DecodeError::BadAuth);
  EXPECT_EQ(decode(signed_ok.data(), signed_ok.size(), out, "secret-one"), DecodeError::None);
  // Flipping the auth flag to pass a CRC datagram off as signed fails too.
  auto forged = plain;
  forged[15] |= 1;
  EXPECT_NE(decode(forged.data(), forged.size(), out, "secret-one"), DecodeError::None);
}
