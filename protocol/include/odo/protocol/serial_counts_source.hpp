// SerialCountsSource: wheel encoder counts from a microcontroller on a serial line (UART,
// USB CDC-ACM), as an EncoderSource (issue 37), over any ByteLink (drivers/serial_port.hpp on a
// tty; an in-memory link in tests). Two protocols:
// - diffodom: the project's firmware streams SerialCounts records (protocol/serial_counts.hpp)
//   at its own rate; each carries the controller's clock, mapped onto the host's by ClockMap
//   (lower envelope of arrival offsets, with drift);
// - arduino-bridge: ros_arduino_bridge's polled ASCII: the host writes "e\r" every poll period,
//   the board answers "<left> <right>\r\n"; the sample's time is the midpoint of the request and
//   the read that saw the answer.
//
// read(now) runs on the loop thread: non-blocking link reads into a fixed buffer (no
// allocation), each chunk with its arrival time when the link stamps them (SerialPort's reader
// thread does: the sample times are then the bytes' arrival, not the tick that reads them); a
// vanished link (a USB board unplugged, a pty closed) is re-opened every reopen_period (by path: a
// /dev/serial/by-id link finds the board under its new name). Counts are the controller's own
// counters (after `reverse`, each wheel unwrapped from its width into a 64-bit count starting at
// the first reading), so they continue across restarts of odometryd. Faults are counted in
// EncoderCounters and flagged per sample: link errors (CRC, framing, garbage lines), sequence gaps,
// controller resets (booted flag, clock going back, or arduino-bridge counts both returning to
// exactly 0: the counts are re-based, the motion since the boot kept: a jump, not a spin),
// reconnects, stale (no valid sample within the timeout, a board that never answers), and
// kEncoderNoValidData while bytes arrive but none is valid (the typical sign of a wrong baud rate).
//
// Several wheels per side (issue 38, wheels.wheels_per_side = N > 1, diffodom only): records of
// version 2 with N counts per side; each wheel is unwrapped from its side's width on its own, a
// wheel the board flags faulted (wheel_faults) or whose step is implausible is faulted for that
// read (dropped from its side by SideCombiner, which forms the sides' counts); a record with
// another N is a link error. N = 1 is exactly the two-wheel source above.
#pragma once

#include <array>
#include <cstdint>
#include <optional>

#include "odo/hal/byte_link.hpp"
#include "odo/hal/encoder.hpp"
#include "odo/hal/side_wheels.hpp"
#include "odo/hal/time.hpp"
#include "odo/odometry/clock_map.hpp"
#include "odo/protocol/serial_counts.hpp"

namespace odo::protocol {

enum class SerialProtocol : std::uint8_t { kDiffodom, kArduinoBridge };

// The arduino-bridge commands (ros_arduino_bridge's command letters, each ended by CR).
inline constexpr char kBridgeReadEncoders = 'e';   // answer "<left> <right>\r\n"
inline constexpr char kBridgeResetEncoders = 'r';  // answer "OK\r\n"
inline constexpr int kBridgeDefaultBaud = 57600;   // its firmware's BAUDRATE

struct SerialSourceConfig {
  SerialProtocol protocol = SerialProtocol::kDiffodom;
  int bits_left = 32;  // width of the controller's counter of the wheel, 8..32 [bits]
  int bits_right = 32;
  bool reverse_left = false;  // negate the count (mirrored mounting)
  bool reverse_right = false;
  TimeNs timeout = 100'000'000;         // [ns] no valid sample for this long: stale
  TimeNs reopen_period = 500'000'000;   // [ns] between attempts to open a vanished device
  TimeNs poll_period = 10'000'000;      // [ns] arduino-bridge: between "e" requests
  double max_counts_per_s = 1e6;        // physical maximum count rate of a wheel [counts/s]
  TimeNs clock_window = 1'000'000'000;  // [ns] diffodom: ClockMap window
  // Wheels per side and their combination (wheels_per_side > 1: diffodom version 2 records;
  // counter_bits is set to 64 by the source: each wheel is unwrapped on its own first).
  SideWheelsConfig wheels;
};

// Per-source diagnostics beyond EncoderCounters.
struct SerialSourceStats {
  std::uint64_t bytes = 0;          // bytes received
  std::uint64_t samples = 0;        // valid records / answers
  std::uint64_t crc_errors = 0;     // diffodom records with a CRC mismatch
  std::uint64_t bad_frames = 0;     // other corrupt frames / lines (COBS, length, version, text)
  std::uint64_t lost_records = 0;   // records missing in sequence gaps
  std::uint64_t polls = 0;          // arduino-bridge requests written
  std::uint64_t unanswered = 0;     // requests without an answer within the timeout
  std::uint64_t open_failures = 0;  // failed attempts to reopen a vanished link
};

class SerialCountsSource final : public EncoderSource {
 public:
  // `link` (open) must outlive the source; cfg is checked by the config reader (bits 8..32).
  SerialCountsSource(ByteLink& link, const SerialSourceConfig& cfg) noexcept;

  // read: drains the line, polls (arduino-bridge), reports both wheels; see the header comment.
  EncoderSample read(TimeNs now) noexcept override;
  // counter_bits: 64: each wheel is unwrapped from its own width in the driver.
  int counter_bits() const noexcept override { return 64; }

  const SerialSourceStats& stats() const noexcept { return stats_; }

 private:
  void link_gone(TimeNs now, std::uint32_t& flags) noexcept;
  void try_reopen(TimeNs now, std::uint32_t& flags) noexcept;
  void drain(TimeNs now, std::uint32_t& flags) noexcept;
  // now: the loop's read time; arrival: when the bytes arrived (the link's stamp, else now).
  void on_byte_diffodom(std::uint8_t b, TimeNs now, TimeNs arrival, std::uint32_t& flags) noexcept;
  void on_byte_bridge(std::uint8_t b, TimeNs now, TimeNs arrival, std::uint32_t& flags) noexcept;
  void on_line(TimeNs now, TimeNs arrival, std::uint32_t& flags) noexcept;
  void on_record(const SerialCounts& c, TimeNs now, TimeNs arrival, std::uint32_t& flags) noexcept;
  void accept(std::int64_t left, std::int64_t right, TimeNs stamp, std::uint32_t& flags) noexcept;
  // accept_wheels: a version 2 record's N counts per side (wheels_per_side > 1).
  void accept_wheels(const SerialCounts& c, TimeNs stamp, std::uint32_t& flags) noexcept;
  // combine: wheels_per_side > 1: the wheels' counts and this read's faults into SideCombiner.
  void combine(EncoderSample& s) noexcept;
  void link_error(bool crc, std::uint32_t& flags) noexcept;
  void poll(TimeNs now) noexcept;

  struct Wheel {
    std::int64_t count = 0;     // unwrapped, reported
    std::int64_t last_raw = 0;  // last reading (after reverse), `bits` wide
    int bits = 32;
    bool faulted = false;  // several wheels: the board flagged it in the last record
  };

  ByteLink* link_;
  SerialSourceConfig cfg_;
  bool open_ = true;
  TimeNs next_open_ = 0;
  std::array<std::uint8_t, 512> rx_{};
  protocol::SerialCountsDecoder decoder_;
  bool synced_ = false;  // a delimiter / newline seen since the open
  std::array<char, 48> line_{};
  std::size_t line_len_ = 0;
  bool line_overrun_ = false;
  bool awaiting_ = false;  // arduino-bridge: a request is out
  TimeNs request_time_ = 0;
  TimeNs next_poll_ = 0;
  // Wheel i: side i % 2 (0 left), wheel i / 2 of that side (two wheels: 0 left, 1 right).
  std::array<Wheel, 2 * kMaxWheelsPerSide> wheel_{};
  std::optional<SideCombiner> combiner_;  // wheels_per_side > 1
  std::uint8_t read_faults_ = 0;          // wheels faulted since the last read (wheel_faults bits)
  bool primed_ = false;                   // a valid sample arrived (ever)
  bool have_record_ = false;              // diffodom: seq/time of the previous record are valid
  std::uint16_t last_seq_ = 0;
  std::uint32_t last_time_us_ = 0;
  std::uint8_t last_flags_ = 0;
  std::int64_t controller_ns_ = 0;  // unwrapped controller clock
  ClockMap clock_;
  TimeNs stamp_ = 0;       // host time of the newest sample
  TimeNs last_valid_ = 0;  // when the newest valid sample was read
  std::uint64_t bytes_since_open_ = 0;
  std::uint64_t valid_since_open_ = 0;
  bool stale_ = true;
  EncoderCounters counters_;
  SerialSourceStats stats_;
};

}  // namespace odo::protocol
