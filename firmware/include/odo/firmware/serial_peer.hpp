// SerialPeerModel: a microcontroller that counts two wheels and talks to the host over a serial
// line in one of the two protocols of [serial] (issue 37): diffodom (a SerialCounts record per
// sample) or arduino-bridge (answers "e\r" with "<left> <right>\r\n", "r\r" with "OK\r\n" and
// zeroes its counters). Bytes in, bytes out, times as arguments: the simulated rig runs it
// in-process behind a ByteLink, `odomctl serial-peer` runs it behind a pseudo-terminal. Faults to
// inject: a controller reset (counters and clock from zero, the booted flag), garbage bytes.
#pragma once

#include <array>
#include <cstdint>
#include <span>

#include "odo/firmware/config.hpp"
#include "odo/hal/time.hpp"
#include "odo/protocol/serial_counts.hpp"

namespace odo::fw {

class SerialPeerModel {
 public:
  static constexpr std::size_t kMaxOut = 64;  // bytes one call may produce
  // wheels_per_side > 1 (diffodom): version 2 records with that many counts per side, every
  // wheel of a side at the side's count (wheels alike) unless faulted (set_wheel_faults).
  explicit SerialPeerModel(SerialProtocol p, int wheels_per_side = 1) noexcept
      : protocol_(p), wheels_(wheels_per_side) {}
  // set_wheel_faults: the wheels the board flags faulted from now on (version 2 wheel_faults
  // bits: k left wheel k, 4 + k right wheel k); a faulted wheel's count is sent as garbage.
  void set_wheel_faults(std::uint8_t bits) noexcept { wheel_faults_ = bits; }

  // on_host_bytes: bytes the host wrote (arduino-bridge commands; diffodom ignores them).
  void on_host_bytes(std::span<const std::uint8_t> in) noexcept;
  // sample: the controller at `t` [ns, its clock since power-on] with raw wheel counts `left`,
  // `right`; writes into `out` what it sends now (diffodom: one record; arduino-bridge: the
  // answers to the commands received so far) and returns how many bytes.
  std::size_t sample(TimeNs t, std::int64_t left, std::int64_t right,
                     std::span<std::uint8_t, kMaxOut> out) noexcept;
  // reset: the controller reboots at `t`: counters and clock start from zero (from the counts
  // `left`, `right` of that moment), sequence from 0, the booted flag on the next records.
  void reset(TimeNs t, std::int64_t left, std::int64_t right) noexcept;
  // reported: the counters as the controller reports them for raw counts left/right.
  std::int64_t reported_left(std::int64_t left) const noexcept { return left - base_left_; }
  std::int64_t reported_right(std::int64_t right) const noexcept { return right - base_right_; }

 private:
  // sample_wheels: record `c` (wheel 1 of each side filled) as version 2 with wheels_ per side.
  std::size_t sample_wheels(protocol::SerialCounts& c,
                            std::span<std::uint8_t, kMaxOut> out) noexcept;

  SerialProtocol protocol_;
  int wheels_ = 1;
  std::uint8_t wheel_faults_ = 0;
  std::int64_t base_left_ = 0;  // counts at the last reset / "r"
  std::int64_t base_right_ = 0;
  TimeNs boot_ = 0;  // clock of the last reset
  std::uint16_t seq_ = 0;
  // Records still to carry the booted flag (100 after reset(): 1 s at 100 Hz); 0 at first: the
  // model starts as a controller that has been running for a while.
  int booted_records_ = 0;
  int pending_reads_ = 0;   // "e" commands received, not answered
  int pending_resets_ = 0;  // "r" commands received, not done
  std::array<char, 16> cmd_{};
  std::size_t cmd_len_ = 0;
};

}  // namespace odo::fw
