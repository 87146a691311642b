// CAN pose protocol: every frame round-trips (encode, decode), saturates at its limits, rounds
// to the nearest step and wraps theta to (-pi, pi]. Expected raw bytes are derived by hand from
// the layout in README "CAN protocol".
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <fstream>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "odo/protocol/can_protocol.hpp"
#include "odo/protocol/candump_log.hpp"
#include "odo/protocol/signals.hpp"

namespace odo::protocol {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr std::uint32_t kId = 0x410;

TEST(CanIds, NodeBlocksAndSplit) {
  EXPECT_EQ(frame_id(kDefaultBaseId, 1, Msg::kPoseX), 0x410u);
  EXPECT_EQ(frame_id(kDefaultBaseId, 1, Msg::kSetPose), 0x418u);
  EXPECT_EQ(frame_id(kDefaultBaseId, 63, Msg::kTiming), 0x7F5u);
  EXPECT_TRUE(valid_addressing(0x400, 63));
  EXPECT_FALSE(valid_addressing(0x410, 63));  // above 0x7FF
  EXPECT_FALSE(valid_addressing(0x404, 1));   // not a multiple of 16
  EXPECT_FALSE(valid_addressing(0x400, 64));
  CanFrame f;
  int node = -1;
  Msg m{};
  f.id = 0x435;
  ASSERT_TRUE(split_id(0x400, f, node, m));
  EXPECT_EQ(node, 3);
  EXPECT_EQ(m, Msg::kTiming);
  f.id = 0x436;
  ASSERT_TRUE(split_id(0x400, f, node, m));
  EXPECT_EQ(m, Msg::kEncoderFaults);
  f.id = 0x437;
  ASSERT_TRUE(split_id(0x400, f, node, m));
  EXPECT_EQ(m, Msg::kSideWheels);
  for (std::uint32_t off : {11u, 12u, 15u}) {  // offsets the message table does not list
    f.id = 0x430 + off;
    EXPECT_FALSE(split_id(0x400, f, node, m)) << off;
  }
  f.id = 0x3FF;
  EXPECT_FALSE(split_id(0x400, f, node, m));
  f.id = 0x410;
  f.extended = true;
  EXPECT_FALSE(split_id(0x400, f, node, m));
}

// A fix (issue 18), bytes derived by hand. FixPose: x = -2.5 m -> raw -2500 = 0xFFF63C (int24)
// -> 3C F6 FF; y = 0.25 m -> 250 = 0x0000FA -> FA 00 00; byte 6 unused; seq 7 in byte 7.
// FixSigma: theta 0.5 rad -> 5000 = 0x1388 -> 88 13; sigma_xy 5 mm -> 50 -> 32 00;
// sigma_theta 0.5 deg = 8.7266e-3 rad -> 87 = 0x057 (bits 32..43), age 0.12 s -> 120 = 0x078
// (bits 44..55): the 24-bit word 0x078057 -> 57 80 07; seq 7.
TEST(CanFix, EncodesHandDerivedBytesAndDecodesBack) {
  const FixMsg in{-2.5, 0.25, 0.5, 0.005, 0.5 * std::numbers::pi / 180.0, 0.12, 7};
  CanFrame a, b;
  encode_fix(frame_id(kDefaultBaseId, 1, Msg::kFixPose),
             frame_id(kDefaultBaseId, 1, Msg::kFixSigma), in, a, b);
  EXPECT_EQ(a.id, 0x419u);
  EXPECT_EQ(b.id, 0x41Au);
  EXPECT_EQ(a.data, (std::array<std::uint8_t, 8>{0x3C, 0xF6, 0xFF, 0xFA, 0x00, 0x00, 0x00, 0x07}));
  EXPECT_EQ(b.data, (std::array<std::uint8_t, 8>{0x88, 0x13, 0x32, 0x00, 0x57, 0x80, 0x07, 0x07}));
  FixMsg out;
  ASSERT_TRUE(decode_fix_pose(a, out));
  ASSERT_TRUE(decode_fix_sigma(b, out));
  EXPECT_DOUBLE_EQ(out.x, -2.5);
  EXPECT_DOUBLE_EQ(out.y, 0.25);
  EXPECT_DOUBLE_EQ(out.theta, 0.5);
  EXPECT_DOUBLE_EQ(out.sigma_xy, 0.005);
  EXPECT_DOUBLE_EQ(out.sigma_theta, 87e-4);
  EXPECT_DOUBLE_EQ(out.age, 0.12);
  EXPECT_EQ(out.seq, 7);
  int node = -1;
  Msg m{};
  ASSERT_TRUE(split_id(kDefaultBaseId, b, node, m));
  EXPECT_EQ(m, Msg::kFixSigma);
  // Heading unknown: sigma_theta raw 0 and theta 0 on the wire.
  FixMsg no_heading = in;
  no_heading.sigma_theta = 0.0;
  encode_fix(a.id, b.id, no_heading, a, b);
  ASSERT_TRUE(decode_fix_sigma(b, out));
  EXPECT_EQ(out.sigma_theta, 0.0);
  EXPECT_EQ(out.theta, 0.0);
  // sigma_xy raw 0 is not a fix.
  b.data[2] = b.data[3] = 0;
  EXPECT_FALSE(decode_fix_sigma(b, out));
}

TEST(CanPose, RoundTripWithinHalfAStep) {
  for (double x : {0.0, 1.23456789, -1.23456789, 4000.00004, -199999.99995}) {
    for (double th : {0.0, 0.5, -3.0, 3.14, -3.14}) {
      const PoseMsg p{x, -x / 3, th, 77};
      CanFrame a, b;
      encode_pose_x(kId, p, a);
      encode_pose_y_theta(kId + 1, p, b);
      EXPECT_EQ(a.id, kId);
      EXPECT_EQ(a.len, 8);
      double dx = 0, dy = 0, dth = 0;
      std::uint8_t s1 = 0, s2 = 0;
      ASSERT_TRUE(decode_pose_x(a, dx, s1));
      ASSERT_TRUE(decode_pose_y_theta(b, dy, dth, s2));
      EXPECT_NEAR(dx, x, kPosScale / 2 + 1e-9);
      EXPECT_NEAR(dy, -x / 3, kPosScale / 2 + 1e-9);
      EXPECT_NEAR(dth, th, kThetaScale / 2 + 1e-12);
      EXPECT_EQ(s1, 77);
      EXPECT_EQ(s2, 77);
    }
  }
}

TEST(CanPose, ByteLayoutByHand) {
  // x = 1.0001 m -> raw 10001 = 0x00002711, little-endian; y = -0.0001 m -> raw -1 =
  // 0xFFFFFFFF; theta = -1e-4 rad -> raw -1 = 0xFFFF; seq in byte 7.
  CanFrame a, b;
  encode_pose_x(kId, PoseMsg{1.0001, -0.0001, -1e-4, 0xA5}, a);
  encode_pose_y_theta(kId + 1, PoseMsg{1.0001, -0.0001, -1e-4, 0xA5}, b);
  const std::array<std::uint8_t, 8> wa{0x11, 0x27, 0, 0, 0, 0, 0, 0xA5};
  const std::array<std::uint8_t, 8> wb{0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0, 0xA5};
  EXPECT_EQ(a.data, wa);
  EXPECT_EQ(b.data, wb);
}

TEST(CanPose, RoundsToNearestStep) {
  CanFrame f;
  double x = 0;
  std::uint8_t s = 0;
  encode_pose_x(kId, PoseMsg{0.00014, 0, 0, 0}, f);  // 1.4 steps -> 1
  ASSERT_TRUE(decode_pose_x(f, x, s));
  EXPECT_DOUBLE_EQ(x, 1e-4);
  encode_pose_x(kId, PoseMsg{0.00016, 0, 0, 0}, f);  // 1.6 steps -> 2
  ASSERT_TRUE(decode_pose_x(f, x, s));
  EXPECT_DOUBLE_EQ(x, 2e-4);
  encode_pose_x(kId, PoseMsg{-0.00016, 0, 0, 0}, f);  // symmetric
  ASSERT_TRUE(decode_pose_x(f, x, s));
  EXPECT_DOUBLE_EQ(x, -2e-4);
}

TEST(CanPose, SaturatesAtTheLimits) {
  CanFrame f;
  double x = 0;
  std::uint8_t s = 0;
  encode_pose_x(kId, PoseMsg{1e9, 0, 0, 0}, f);
  ASSERT_TRUE(decode_pose_x(f, x, s));
  EXPECT_DOUBLE_EQ(x, 2147483647 * kPosScale);
  encode_pose_x(kId, PoseMsg{-1e9, 0, 0, 0}, f);
  ASSERT_TRUE(decode_pose_x(f, x, s));
  EXPECT_DOUBLE_EQ(x, -2147483648.0 * kPosScale);
  // The documented range holds: +-200 km are carried exactly to the step.
  encode_pose_x(kId, PoseMsg{200000.0, 0, 0, 0}, f);
  ASSERT_TRUE(decode_pose_x(f, x, s));
  EXPECT_NEAR(x, 200000.0, 1e-6);
  encode_pose_x(kId, PoseMsg{std::nan(""), 0, 0, 0}, f);
  ASSERT_TRUE(decode_pose_x(f, x, s));
  EXPECT_EQ(x, 0.0);
}

TEST(CanPose, ThetaWrapsIntoMinusPiPi) {
  auto roundtrip = [](double th) {
    CanFrame f;
    encode_pose_y_theta(kId + 1, PoseMsg{0, 0, th, 0}, f);
    double y = 0, t = 0;
    std::uint8_t s = 0;
    EXPECT_TRUE(decode_pose_y_theta(f, y, t, s));
    return t;
  };
  EXPECT_NEAR(roundtrip(1.5 * kPi), -0.5 * kPi, kThetaScale / 2);
  EXPECT_NEAR(roundtrip(-1.5 * kPi), 0.5 * kPi, kThetaScale / 2);
  EXPECT_NEAR(roundtrip(20 * kPi + 0.1), 0.1, kThetaScale / 2 + 1e-9);
  // +pi and -pi are both sent as +pi (raw 31416): the interval is (-pi, pi].
  EXPECT_DOUBLE_EQ(roundtrip(kPi), 31416 * kThetaScale);
  EXPECT_DOUBLE_EQ(roundtrip(-kPi), 31416 * kThetaScale);
  EXPECT_EQ(theta_raw(-kPi + 0.4e-4), kThetaRawMax);  // rounds to -pi: sent as +pi
  EXPECT_EQ(theta_raw(-kPi + 0.6e-4), -31415);
  EXPECT_EQ(theta_raw(std::numeric_limits<double>::infinity()), 0);
}

TEST(CanVelocity, RoundTripAndSaturation) {
  CanFrame f;
  encode_velocity(kId + 2, VelocityMsg{0.2004, -1.2346, 9}, f);
  VelocityMsg v;
  ASSERT_TRUE(decode_velocity(f, v));
  EXPECT_NEAR(v.v, 0.200, 1e-12);
  EXPECT_NEAR(v.omega, -1.235, 1e-12);
  EXPECT_EQ(v.seq, 9);
  encode_velocity(kId + 2, VelocityMsg{100.0, -100.0, 0}, f);
  ASSERT_TRUE(decode_velocity(f, v));
  EXPECT_DOUBLE_EQ(v.v, 32.767);
  EXPECT_DOUBLE_EQ(v.omega, -32.768);
}

TEST(CanUncertainty, RoundTripUnknownAndSaturation) {
  CanFrame f;
  encode_uncertainty(kId + 3, UncertaintyMsg{0.01234, 0.00056, 0.0012345, -0.456, 3}, f);
  UncertaintyMsg u;
  ASSERT_TRUE(decode_uncertainty(f, u));
  EXPECT_NEAR(u.sigma_x, 0.0123, 1e-12);
  EXPECT_NEAR(u.sigma_y, 0.0006, 1e-12);
  EXPECT_NEAR(u.sigma_theta, 0.00123, 1e-12);
  EXPECT_NEAR(u.rho_xy, -0.46, 1e-12);
  EXPECT_EQ(u.seq, 3);
  encode_uncertainty(kId + 3, UncertaintyMsg{100.0, std::nan(""), -1.0, 5.0, 0}, f);
  ASSERT_TRUE(decode_uncertainty(f, u));
  EXPECT_DOUBLE_EQ(u.sigma_x, 65535 * kSigmaPosScale);  // saturated
  EXPECT_DOUBLE_EQ(u.sigma_y, 65535 * kSigmaPosScale);  // unknown
  EXPECT_DOUBLE_EQ(u.sigma_theta, 0.0);                 // a negative sigma cannot be: 0
  EXPECT_DOUBLE_EQ(u.rho_xy, 1.0);
}

TEST(CanStatus, RoundTripBitsAndSaturation) {
  StatusMsg s;
  s.encoder_flags = 0x11;
  s.calibration_state = 2;
  s.stopping = true;
  s.set_pose_ack = 200;
  s.missed_deadlines = 70000;  // saturates at 65535
  s.uptime = 3600.9;           // whole seconds
  CanFrame f;
  encode_status(kId + 4, s, f);
  const std::array<std::uint8_t, 8> want{0x11, 0x06, 200, 0xFF, 0xFF, 0x10, 0x0E, 0x00};
  EXPECT_EQ(f.data, want);
  StatusMsg d;
  ASSERT_TRUE(decode_status(f, d));
  EXPECT_EQ(d.encoder_flags, 0x11);
  EXPECT_EQ(d.calibration_state, 2);
  EXPECT_TRUE(d.stopping);
  EXPECT_EQ(d.set_pose_ack, 200);
  EXPECT_EQ(d.missed_deadlines, 65535u);
  EXPECT_DOUBLE_EQ(d.uptime, 3600.0);
  // Gyro bits 11-12 (state) and 13-15 (events mod 8) of byte 1: 0x06 | 3 << 3 | 5 << 5 = 0xBE.
  s.gyro_state = 3;
  s.gyro_events = 13;  // modulo 8 on the wire: 5
  encode_status(kId + 4, s, f);
  EXPECT_EQ(f.data[1], 0xBE);
  ASSERT_TRUE(decode_status(f, d));
  EXPECT_EQ(d.gyro_state, 3);
  EXPECT_EQ(d.gyro_events, 5);
  EXPECT_EQ(d.calibration_state, 2);
  EXPECT_TRUE(d.stopping);
  s.uptime = 1e12;
  encode_status(kId + 4, s, f);
  ASSERT_TRUE(decode_status(f, d));
  EXPECT_DOUBLE_EQ(d.uptime, 16777215.0);
}

TEST(CanTiming, RoundTripInMicroseconds) {
  CanFrame f;
  encode_timing(kId + 5, TimingMsg{12.4e-6, 1.5e-3, 0.2, 70000}, f);
  TimingMsg t;
  ASSERT_TRUE(decode_timing(f, t));
  EXPECT_NEAR(t.wakeup_p99, 12e-6, 1e-15);
  EXPECT_NEAR(t.wakeup_max, 1.5e-3, 1e-15);
  EXPECT_NEAR(t.compute_max, 0.065535, 1e-15);  // saturated
  EXPECT_EQ(t.tx_dropped, 65535u);
}

// EncoderFaults, bytes by hand: one byte per counter in EncoderCounters' order (invalid
// transitions, implausible jumps, stale events, read errors, link errors, sequence gaps,
// controller resets, reconnects); 300 saturates at 0xFF, 2^40 too.
TEST(CanEncoderFaults, OneByteEachInOrderSaturating) {
  CanFrame f;
  encode_encoder_faults(kId + 6, EncoderCounters{1, 2, 3, 4, 300, 0, 5, std::uint64_t{1} << 40}, f);
  EXPECT_EQ(f.id, kId + 6);
  ASSERT_EQ(f.len, 8);
  const std::array<std::uint8_t, 8> want{0x01, 0x02, 0x03, 0x04, 0xFF, 0x00, 0x05, 0xFF};
  for (std::size_t i = 0; i < 8; ++i) EXPECT_EQ(f.data[i], want[i]) << i;
  EncoderCounters c;
  ASSERT_TRUE(decode_encoder_faults(f, c));
  EXPECT_EQ(c.read_errors, 4u);
  EXPECT_EQ(c.link_errors, 255u);
  EXPECT_EQ(c.reconnects, 255u);
  f.len = 7;
  EXPECT_FALSE(decode_encoder_faults(f, c));
}

// SideWheels (issue 38), bytes by hand: byte 0 = slip_left (bit 0) | slip_right (bit 1) |
// wheel_dropped (bit 2) | wheels_per_side << 4; bytes 1-2 slip_events, bytes 3-4 wheel_drops,
// little-endian u16, saturating; bytes 5-7 zero. Flags slip-right + wheel-dropped, 2 per side:
// 0b010 | 0b100 | 2 << 4 = 0x26; 300 slip events = 0x012C; 70000 drops saturate at 0xFFFF.
// Status's own flags (stale-left) are not carried.
TEST(CanSideWheels, FlagBitsWheelsAndSaturatingCounters) {
  SideWheelsMsg m;
  m.encoder_flags = kEncoderSlipRight | kEncoderWheelDropped | kEncoderStaleLeft;
  m.wheels_per_side = 2;
  m.counters.slip_events = 300;
  m.counters.wheel_drops = 70000;
  m.counters.link_errors = 9;  // an EncoderFaults counter: not in this frame
  CanFrame f;
  encode_side_wheels(kId + 7, m, f);
  EXPECT_EQ(f.id, kId + 7);
  ASSERT_EQ(f.len, 8);
  const std::array<std::uint8_t, 8> want{0x26, 0x2C, 0x01, 0xFF, 0xFF, 0x00, 0x00, 0x00};
  for (std::size_t i = 0; i < 8; ++i) EXPECT_EQ(f.data[i], want[i]) << i;
  SideWheelsMsg got;
  got.counters.link_errors = 5;  // decoding clears what the frame does not carry
  ASSERT_TRUE(decode_side_wheels(f, got));
  EXPECT_EQ(got.encoder_flags, std::uint32_t{kEncoderSlipRight | kEncoderWheelDropped});
  EXPECT_EQ(got.wheels_per_side, 2);
  EXPECT_EQ(got.counters.slip_events, 300u);
  EXPECT_EQ(got.counters.wheel_drops, 65535u);
  EXPECT_EQ(got.counters.link_errors, 0u);
  f.len = 7;
  EXPECT_FALSE(decode_side_wheels(f, got));
}

TEST(CanSetPose, SetResetAndRejects) {
  CanFrame f;
  encode_set_pose(kId + 8, SetPose{{12.3456, -7.0004, 1.0}}, f);
  EXPECT_EQ(f.len, 8);
  SetPose c;
  ASSERT_TRUE(decode_set_pose(f, c));
  EXPECT_NEAR(c.pose.x, 12.346, 1e-9);
  EXPECT_NEAR(c.pose.y, -7.000, 1e-9);
  EXPECT_NEAR(c.pose.theta, 1.0, 1e-12);
  // Limits of the command: +-8388.607 m, saturating.
  encode_set_pose(kId + 8, SetPose{{1e6, -1e6, 0}}, f);
  ASSERT_TRUE(decode_set_pose(f, c));
  EXPECT_DOUBLE_EQ(c.pose.x, 8388.607);
  EXPECT_DOUBLE_EQ(c.pose.y, -8388.608);
  // Reset: DLC 0, decoded as the pose (0, 0, 0) whatever c held.
  encode_set_pose_reset(kId + 8, f);
  EXPECT_EQ(f.id, kId + 8);
  EXPECT_EQ(f.len, 0);
  c = SetPose{{5, 5, 1}};
  ASSERT_TRUE(decode_set_pose(f, c));
  EXPECT_EQ(c.pose.x, 0.0);
  EXPECT_EQ(c.pose.y, 0.0);
  EXPECT_EQ(c.pose.theta, 0.0);
  // Rejected: other lengths, theta beyond pi.
  for (std::uint8_t len : {1, 4, 7}) {
    f.len = len;
    EXPECT_FALSE(decode_set_pose(f, c)) << int(len);
  }
  f.len = 8;
  f.data[6] = 0x79;  // raw 31417 = 0x7AB9 > 31416
  f.data[7] = 0x7A;
  f.data[6] = 0xB9;
  EXPECT_FALSE(decode_set_pose(f, c));
}

TEST(CanDivisor, WholeDivisorsOnly) {
  EXPECT_EQ(divisor_for(100, 50), 2);
  EXPECT_EQ(divisor_for(100, 100), 1);
  EXPECT_EQ(divisor_for(100, 0), 0);
  EXPECT_EQ(divisor_for(100, 1), 100);
  EXPECT_EQ(divisor_for(100, 30), -1);
  EXPECT_EQ(divisor_for(100, 200), -1);
  EXPECT_EQ(divisor_for(100, -1), -1);
  EXPECT_EQ(divisor_for(1000, 0.5), 2000);
}

TEST(CandumpLog, InterfaceNamesMustBePrintable) {
  // "(ts) <iface> <id>#<data>": a name with a NUL byte (found by fuzz_candump), a control
  // character, a non-ASCII byte or a '/' cannot be a Linux interface name and would not survive
  // being printed back; a name of 15 printable characters is the longest there is.
  using namespace std::string_literals;
  EXPECT_TRUE(parse_candump_line("(1.000000) can-bus_0.1 410#00").ok());
  EXPECT_TRUE(parse_candump_line("(1.000000) abcdefghijklmno 410#00").ok());
  for (const std::string& line : {"(1.000000) \0\0\0.sim0 410#00"s, "(1.000000) ca\tn0 410#00"s,
                                  "(1.000000) can\xc3\xa9"
                                  "0 410#00"s,
                                  "(1.000000) a/b 410#00"s}) {
    auto bad = parse_candump_line(line);
    ASSERT_FALSE(bad.ok()) << line;
    EXPECT_NE(bad.error().message.find("interface name"), std::string::npos) << bad.error().message;
  }
}

TEST(CandumpLog, TimeStampsBeyondTheNanosecondClockAreRefused) {
  // 9223372035 s is the last whole second whose nanoseconds (plus 999999 us) fit an int64:
  // 9223372035 * 1e9 + 999999000 = 9223372035999999000 < 2^63 - 1 = 9223372036854775807.
  auto ok = parse_candump_line("(9223372035.999999) vcan0 410#00");
  ASSERT_TRUE(ok.ok()) << ok.error().message;
  EXPECT_EQ(ok->sec, 9223372035);
  // One second later the nanoseconds would overflow (found by fuzz_candump: 179535382837 s).
  for (const char* line :
       {"(9223372036.000000) vcan0 410#00", "(179535382837.303618) sim0 410#00"}) {
    auto bad = parse_candump_line(line);
    ASSERT_FALSE(bad.ok()) << line;
    EXPECT_NE(bad.error().message.find("beyond the range"), std::string::npos)
        << bad.error().message;
  }
}

// The DBC file is the signal table written out: its BO_ and SG_ lines are exactly those derived
// from protocol/signals.hpp (ids for node 1 at base 0x400), factors and limits as plain decimals.
TEST(CanProtocolDbc, FileMatchesTheSignalTable) {
  std::string path = ODO_SOURCE_DIR;
  path += "/protocol/odometry.dbc";  // two steps: see TESTING.md, "The tests' precompiled header"
  std::ifstream in(path);
  ASSERT_TRUE(in) << "protocol/odometry.dbc not found";
  std::vector<std::string> got;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("BO_ ", 0) == 0 || line.rfind(" SG_ ", 0) == 0) got.push_back(line);
  }
  std::vector<std::string> want;
  for (const MessageSpec& m : kMessages) {
    want.push_back(dbc_message_line(m));
    for (const Signal* s : m.signals) want.push_back(dbc_signal_line(m, *s));
  }
  EXPECT_EQ(got, want);
  for (const std::string& l : got) EXPECT_EQ(l.find("e-"), std::string::npos) << l;
}

TEST(CanProtocolDbc, DecimalsArePlain) {
  EXPECT_EQ(dbc_decimal(1e-5), "0.00001");
  EXPECT_EQ(dbc_decimal(1e-6), "0.000001");
  EXPECT_EQ(dbc_decimal(1.0), "1");
  EXPECT_EQ(dbc_decimal(-2147483648 * 1e-4), "-214748.3648");
  EXPECT_EQ(dbc_decimal(65535 * 1e-5), "0.65535");
}

}  // namespace
}  // namespace odo::protocol
