// The CAN pose protocol written down once: every signal of every message (name, start bit,
// width, scale, signedness, raw range, unit). The encoders and decoders (can_protocol.cpp),
// `odomctl decode` and the candump decoding read their layout from this table, and a unit test
// checks protocol/odometry.dbc against it, so the four cannot drift apart.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <string>

#include "odo/hal/bytes.hpp"
#include "odo/hal/can_bus.hpp"
#include "odo/hal/encoder.hpp"
#include "odo/protocol/can_protocol.hpp"

namespace odo::protocol {

// Signal: bits [start_bit, start_bit + width) of the 8-byte payload, Intel byte order;
// physical value = raw * scale with raw in [raw_min, raw_max].
struct Signal {
  const char* name;  // as in the DBC file
  int start_bit;
  int width;  // [bits]
  double scale;
  bool is_signed;
  std::int64_t raw_min;
  std::int64_t raw_max;
  const char* unit;
};

namespace sig {
constexpr std::int64_t kI32Min = std::numeric_limits<std::int32_t>::min();
constexpr std::int64_t kI32Max = std::numeric_limits<std::int32_t>::max();
constexpr std::int64_t kI24Min = -(std::int64_t{1} << 23);
constexpr std::int64_t kI24Max = (std::int64_t{1} << 23) - 1;

inline constexpr Signal x{"x", 0, 32, kPosScale, true, kI32Min, kI32Max, "m"};
inline constexpr Signal y{"y", 0, 32, kPosScale, true, kI32Min, kI32Max, "m"};
inline constexpr Signal theta{"theta",      32,   16, kThetaScale, true, -(kThetaRawMax - 1),
                              kThetaRawMax, "rad"};
inline constexpr Signal seq{"seq", 56, 8, 1.0, false, 0, 255, ""};
inline constexpr Signal v{"v", 0, 16, kVelScale, true, -32768, 32767, "m/s"};
inline constexpr Signal omega{"omega", 16, 16, kOmegaScale, true, -32768, 32767, "rad/s"};
inline constexpr Signal sigma_x{"sigma_x", 0, 16, kSigmaPosScale, false, 0, 65535, "m"};
inline constexpr Signal sigma_y{"sigma_y", 16, 16, kSigmaPosScale, false, 0, 65535, "m"};
inline constexpr Signal sigma_theta{"sigma_theta", 32, 16,    kSigmaThetaScale,
                                    false,         0,  65535, "rad"};
inline constexpr Signal rho_xy{"rho_xy", 48, 8, kRhoScale, true, -100, 100, ""};
inline constexpr Signal encoder_flags{"encoder_flags", 0, 8, 1.0, false, 0, 255, ""};
inline constexpr Signal calibration_state{"calibration_state", 8, 2, 1.0, false, 0, 2, ""};
inline constexpr Signal stopping{"stopping", 10, 1, 1.0, false, 0, 1, ""};
inline constexpr Signal gyro_state{"gyro_state", 11, 2, 1.0, false, 0, 3, ""};
inline constexpr Signal gyro_events{"gyro_events", 13, 3, 1.0, false, 0, 7, ""};
inline constexpr Signal set_pose_ack{"set_pose_ack", 16, 8, 1.0, false, 0, 255, ""};
inline constexpr Signal missed_deadlines{"missed_deadlines", 24, 16, 1.0, false, 0, 65535, ""};
inline constexpr Signal uptime{"uptime", 40, 24, 1.0, false, 0, 0xFFFFFF, "s"};
inline constexpr Signal wakeup_p99{"wakeup_p99", 0, 16, kLatencyScale, false, 0, 65535, "s"};
inline constexpr Signal wakeup_max{"wakeup_max", 16, 16, kLatencyScale, false, 0, 65535, "s"};
inline constexpr Signal compute_max{"compute_max", 32, 16, kLatencyScale, false, 0, 65535, "s"};
inline constexpr Signal tx_dropped{"tx_dropped", 48, 16, 1.0, false, 0, 65535, ""};
// EncoderFaults: hal's EncoderCounters, one byte each, saturating at 255.
inline constexpr Signal invalid_transitions{"invalid_transitions", 0, 8, 1.0, false, 0, 255, ""};
inline constexpr Signal implausible_jumps{"implausible_jumps", 8, 8, 1.0, false, 0, 255, ""};
inline constexpr Signal stale_events{"stale_events", 16, 8, 1.0, false, 0, 255, ""};
inline constexpr Signal read_errors{"read_errors", 24, 8, 1.0, false, 0, 255, ""};
inline constexpr Signal link_errors{"link_errors", 32, 8, 1.0, false, 0, 255, ""};
inline constexpr Signal sequence_gaps{"sequence_gaps", 40, 8, 1.0, false, 0, 255, ""};
inline constexpr Signal controller_resets{"controller_resets", 48, 8, 1.0, false, 0, 255, ""};
inline constexpr Signal reconnects{"reconnects", 56, 8, 1.0, false, 0, 255, ""};
// SideWheels (issue 38): the side flags as single bits, then the side's counters.
inline constexpr Signal slip_left{"slip_left", 0, 1, 1.0, false, 0, 1, ""};
inline constexpr Signal slip_right{"slip_right", 1, 1, 1.0, false, 0, 1, ""};
inline constexpr Signal wheel_dropped{"wheel_dropped", 2, 1, 1.0, false, 0, 1, ""};
inline constexpr Signal wheels_per_side{"wheels_per_side", 4, 3, 1.0, false, 1, 7, ""};
inline constexpr Signal slip_events{"slip_events", 8, 16, 1.0, false, 0, 65535, ""};
inline constexpr Signal wheel_drops{"wheel_drops", 24, 16, 1.0, false, 0, 65535, ""};
inline constexpr Signal set_x{"set_x", 0, 24, kSetPosScale, true, kI24Min, kI24Max, "m"};
inline constexpr Signal set_y{"set_y", 24, 24, kSetPosScale, true, kI24Min, kI24Max, "m"};
inline constexpr Signal set_theta{"set_theta",   48,           16,   kThetaScale, true,
                                  -kThetaRawMax, kThetaRawMax, "rad"};
inline constexpr Signal fix_x{"fix_x", 0, 24, kSetPosScale, true, kI24Min, kI24Max, "m"};
inline constexpr Signal fix_y{"fix_y", 24, 24, kSetPosScale, true, kI24Min, kI24Max, "m"};
inline constexpr Signal fix_theta{"fix_theta",  0,    16, kThetaScale, true, -kThetaRawMax,
                                  kThetaRawMax, "rad"};
inline constexpr Signal fix_sigma_xy{"fix_sigma_xy", 16, 16,    kFixSigmaXyScale,
                                     false,          1,  65535, "m"};
inline constexpr Signal fix_sigma_theta{
    "fix_sigma_theta", 32, 12, kFixSigmaThetaScale, false, 0, 4095, "rad"};
inline constexpr Signal fix_age{"fix_age", 44, 12, kFixAgeScale, false, 0, 4095, "s"};
inline constexpr Signal fix_seq{"fix_seq", 56, 8, 1.0, false, 0, 255, ""};

inline constexpr const Signal* kPoseX[] = {&x, &seq};
inline constexpr const Signal* kPoseYTheta[] = {&y, &theta, &seq};
inline constexpr const Signal* kVelocity[] = {&v, &omega, &seq};
inline constexpr const Signal* kUncertainty[] = {&sigma_x, &sigma_y, &sigma_theta, &rho_xy, &seq};
inline constexpr const Signal* kStatus[] = {
    &encoder_flags, &calibration_state, &stopping,         &gyro_state,
    &gyro_events,   &set_pose_ack,      &missed_deadlines, &uptime};
inline constexpr const Signal* kTiming[] = {&wakeup_p99, &wakeup_max, &compute_max, &tx_dropped};
// kEncoderFaultFields: each EncoderFaults signal and the EncoderCounters field it carries; the
// message's signal list, its encoder and its decoder all come from here.
struct CounterSignal {
  const Signal* signal;
  std::uint64_t EncoderCounters::*field;
};
inline constexpr CounterSignal kEncoderFaultFields[] = {
    {&invalid_transitions, &EncoderCounters::invalid_transitions},
    {&implausible_jumps, &EncoderCounters::implausible_jumps},
    {&stale_events, &EncoderCounters::stale_events},
    {&read_errors, &EncoderCounters::read_errors},
    {&link_errors, &EncoderCounters::link_errors},
    {&sequence_gaps, &EncoderCounters::sequence_gaps},
    {&controller_resets, &EncoderCounters::controller_resets},
    {&reconnects, &EncoderCounters::reconnects}};
inline constexpr auto kEncoderFaults = [] {
  std::array<const Signal*, std::size(kEncoderFaultFields)> a{};
  for (std::size_t i = 0; i < a.size(); ++i) a[i] = kEncoderFaultFields[i].signal;
  return a;
}();
// kSideWheelFlags: each SideWheels flag signal and the EncoderFlag bit it carries.
struct FlagSignal {
  const Signal* signal;
  EncoderFlag flag;
};
inline constexpr FlagSignal kSideWheelFlags[] = {{&slip_left, kEncoderSlipLeft},
                                                 {&slip_right, kEncoderSlipRight},
                                                 {&wheel_dropped, kEncoderWheelDropped}};
// kSideWheelCounters: the SideWheels counters and the EncoderCounters field each carries.
inline constexpr CounterSignal kSideWheelCounters[] = {
    {&slip_events, &EncoderCounters::slip_events}, {&wheel_drops, &EncoderCounters::wheel_drops}};
inline constexpr auto kSideWheels = [] {
  std::array<const Signal*, std::size(kSideWheelFlags) + 1 + std::size(kSideWheelCounters)> a{};
  std::size_t i = 0;
  for (const FlagSignal& f : kSideWheelFlags) a[i++] = f.signal;
  a[i++] = &wheels_per_side;
  for (const CounterSignal& c : kSideWheelCounters) a[i++] = c.signal;
  return a;
}();
inline constexpr const Signal* kSetPose[] = {&set_x, &set_y, &set_theta};
inline constexpr const Signal* kFixPose[] = {&fix_x, &fix_y, &fix_seq};
inline constexpr const Signal* kFixSigma[] = {&fix_theta, &fix_sigma_xy, &fix_sigma_theta, &fix_age,
                                              &fix_seq};
}  // namespace sig

// MessageSpec: one message: its offset in the node's id block, DBC name and signals in order.
struct MessageSpec {
  Msg msg;
  const char* name;
  bool to_node;  // a command to odometryd (SetPose) rather than sent by it
  std::span<const Signal* const> signals;
};

inline constexpr MessageSpec kMessages[] = {
    {Msg::kPoseX, "PoseX", false, sig::kPoseX},
    {Msg::kPoseYTheta, "PoseYTheta", false, sig::kPoseYTheta},
    {Msg::kVelocity, "Velocity", false, sig::kVelocity},
    {Msg::kUncertainty, "Uncertainty", false, sig::kUncertainty},
    {Msg::kStatus, "Status", false, sig::kStatus},
    {Msg::kTiming, "Timing", false, sig::kTiming},
    {Msg::kEncoderFaults, "EncoderFaults", false, sig::kEncoderFaults},
    {Msg::kSideWheels, "SideWheels", false, sig::kSideWheels},
    {Msg::kSetPose, "SetPose", true, sig::kSetPose},
    {Msg::kFixPose, "FixPose", true, sig::kFixPose},
    {Msg::kFixSigma, "FixSigma", true, sig::kFixSigma},
};

// kMaxMessageSignals: the most signals any message has: the size of a decoded frame's fields,
// derived from the table so that a message that gains a signal cannot overflow it.
inline constexpr std::size_t kMaxMessageSignals = [] {
  std::size_t n = 0;
  for (const MessageSpec& m : kMessages) n = m.signals.size() > n ? m.signals.size() : n;
  return n;
}();

// message_spec: the table entry of message m (every Msg has one).
const MessageSpec& message_spec(Msg m) noexcept;

// dbc_decimal: `v` as a plain decimal with at most 9 decimals and no trailing zeros.
std::string dbc_decimal(double v);
// dbc_message_line: the BO_ line of message m for node kDefaultNodeId at kDefaultBaseId.
std::string dbc_message_line(const MessageSpec& m);
// dbc_signal_line: the SG_ line of signal s of message m.
std::string dbc_signal_line(const MessageSpec& m, const Signal& s);

// put_raw: writes `raw` (already within the signal's range) into the signal's bits.
constexpr void put_raw(CanFrame& f, const Signal& s, std::int64_t raw) noexcept {
  const auto u = static_cast<std::uint64_t>(raw);
  if (s.start_bit % 8 == 0 && s.width % 8 == 0) {
    put_le(f.data.data() + s.start_bit / 8, static_cast<std::size_t>(s.width / 8), u);
    return;
  }
  if (s.start_bit / 8 != (s.start_bit + s.width - 1) / 8) {
    // A bit field across bytes (the fix's 12-bit sigma_theta and age): the payload as one
    // little-endian 64-bit word.
    const std::uint64_t m = ((std::uint64_t{1} << s.width) - 1u) << s.start_bit;
    const std::uint64_t w = get_le(f.data.data(), 8);
    put_le(f.data.data(), 8, (w & ~m) | ((u << s.start_bit) & m));
    return;
  }
  // A bit field inside one byte (the Status flags): keep the byte's other bits.
  const auto mask = static_cast<std::uint8_t>(((1u << s.width) - 1u) << (s.start_bit % 8));
  std::uint8_t& b = f.data[static_cast<std::size_t>(s.start_bit / 8)];
  b = static_cast<std::uint8_t>((b & ~mask) | ((u << (s.start_bit % 8)) & mask));
}

// get_raw: the signal's raw value, sign-extended when the signal is signed.
constexpr std::int64_t get_raw(const CanFrame& f, const Signal& s) noexcept {
  std::uint64_t u = 0;
  if (s.start_bit % 8 == 0 && s.width % 8 == 0) {
    u = get_le(f.data.data() + s.start_bit / 8, static_cast<std::size_t>(s.width / 8));
  } else if (s.start_bit / 8 != (s.start_bit + s.width - 1) / 8) {
    u = (get_le(f.data.data(), 8) >> s.start_bit) & ((std::uint64_t{1} << s.width) - 1u);
  } else {
    u = (f.data[static_cast<std::size_t>(s.start_bit / 8)] >> (s.start_bit % 8)) &
        ((1u << s.width) - 1u);
  }
  return s.is_signed ? sign_extend(u, s.width) : static_cast<std::int64_t>(u);
}

// get_value: the signal's physical value (raw * scale).
constexpr double get_value(const CanFrame& f, const Signal& s) noexcept {
  return static_cast<double>(get_raw(f, s)) * s.scale;
}

}  // namespace odo::protocol
