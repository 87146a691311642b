// candump -L log lines ("(1699999999.123456) can0 418#0102030405060708") and a field-by-field
// decoding of the protocol's frames, for `odomctl decode` and the tests.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <string_view>

#include "odo/hal/can_bus.hpp"
#include "odo/hal/result.hpp"
#include "odo/protocol/can_protocol.hpp"
#include "odo/protocol/signals.hpp"

namespace odo::protocol {

struct CandumpLine {
  std::int64_t sec = 0;   // wall-clock seconds of the capture
  std::int32_t usec = 0;  // microseconds 0..999999
  std::string iface;
  CanFrame frame;  // extended when the id has 8 hex digits (as candump prints it)
};

// Largest accepted time stamp [s]: sec * 1e9 + 999999000 still fits a signed 64-bit TimeNs.
inline constexpr std::int64_t kCandumpMaxSeconds = 9'223'372'035;

// format_candump_line: "(sec.usec) iface ID#HEX\n" of candump -L into buf; returns the length.
std::size_t format_candump_line(char* buf, std::size_t size, std::int64_t wall_ns,
                                const char* iface, const CanFrame& f) noexcept;

// parse_candump_line: one log line (no newline); the error says what is wrong (no file/line).
// The time stamp's seconds are at most kCandumpMaxSeconds.
// Accepts classic frames only: 3 hex digits (11-bit id) or 8 (29-bit id), then '#' and 0..8
// bytes as hex pairs; remote (#R) and CAN FD (##) frames are rejected.
Result<CandumpLine> parse_candump_line(std::string_view line);

struct DecodedField {
  const char* name = "";
  double value = 0.0;
};

// DecodedFrame: one of our frames in physical units (names as in the DBC file).
struct DecodedFrame {
  int node = -1;
  Msg msg{};
  const char* message = "";  // PoseX, PoseYTheta, Velocity, Uncertainty, Status, Timing, SetPose
  std::array<DecodedField, kMaxMessageSignals> fields{};
  std::size_t n_fields = 0;
};

// decode_protocol_frame: false when the id is not in our block (base_id) or the length is
// wrong for the message (a set-pose frame may be DLC 0 or 8).
bool decode_protocol_frame(std::uint32_t base_id, const CanFrame& f, DecodedFrame& out) noexcept;

}  // namespace odo::protocol
