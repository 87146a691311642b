// GpioQuadratureEncoder: A/B quadrature lines of both wheels on GPIO, decoded in software from
// libgpiod 1.6 both-edge events. A dedicated thread waits for events, reads them in batches
// (gpiod_line_event_read_multiple), merges A and B of each wheel by kernel timestamp and feeds
// a QuadTracker; counts and fault counters reach the loop through atomics (no locks). An
// optional index line per wheel latches the count at its rising edge. libgpiod types stay in
// the .cpp.
//
// Several wheels per side (issue 38, wheels.wheels_per_side = N > 1): one A/B pair (and optional
// index) per wheel, each decoded on its own; a wheel whose lines gave an invalid transition since
// the last read is faulted for that read (dropped from its side), and SideCombiner forms the
// sides' counts. N = 1 is exactly the two-wheel encoder above.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "odo/hal/encoder.hpp"
#include "odo/hal/result.hpp"
#include "odo/hal/side_wheels.hpp"
#include "odo/hal/time.hpp"

namespace odo::drivers {

struct GpioWheelLines {
  unsigned a = 0;        // line offset of channel A
  unsigned b = 0;        // channel B
  int index = -1;        // index (Z) line offset, -1 = none
  bool reverse = false;  // negate the count (mirrored motor mounting)
};

// The range of `batch`, checked by open() and by the config reader ([gpio]).
inline constexpr RangeRow kGpioBatch{"batch", 1, 1024, "events"};

struct GpioQuadratureConfig {
  std::string chip;  // /dev/gpiochipN, gpiochipN, a chip label or a number
  GpioWheelLines left;
  GpioWheelLines right;
  bool active_low = false;  // the encoder outputs are inverted
  int batch = 64;           // events read per line and system call, 1..1024
  // An A/B edge is applied once the other line of its wheel has delivered a younger edge
  // (exact order while the wheel turns, whatever the kernel's latency), or once it is older
  // than reorder_window (the other line may not have moved) [ns]. An edge that still arrives
  // out of order is counted as an invalid transition, never as motion.
  TimeNs reorder_window = 20'000'000;
  // With no events for this long the thread compares the tracked levels with the lines and
  // counts a difference as lost edges [ns].
  TimeNs idle_check = 50'000'000;
  std::string consumer = "odometryd";
  // N wheels per side: `left`/`right` are wheel 0 of each side, more_left[k - 1] /
  // more_right[k - 1] wheel k; counter_bits is set to 64 by open().
  SideWheelsConfig wheels;
  std::array<GpioWheelLines, kMaxWheelsPerSide - 1> more_left{};
  std::array<GpioWheelLines, kMaxWheelsPerSide - 1> more_right{};
};

// gpio_wheel_lines: the lines of wheel `i` (0..2 N - 1): side i % 2 (0 left), wheel i / 2.
const GpioWheelLines& gpio_wheel_lines(const GpioQuadratureConfig& cfg, int i) noexcept;

// Diagnostics of one wheel, read from the atomics.
struct GpioWheelStats {
  std::int64_t count = 0;
  std::uint64_t received = 0;  // A/B events read from the kernel (before merging)
  std::uint64_t edges = 0;     // A/B edges decoded
  std::uint64_t invalid = 0;
  std::uint64_t index_pulses = 0;
  std::int64_t index_count = 0;  // count at the last index rising edge
  std::uint64_t dropped = 0;     // events read but lost: the pending buffer was full
};

// BatchSplit: of `got` events read from the kernel, how many fit the `room` free slots of the
// pending buffer; the rest are dropped, and counted (GpioWheelStats::dropped).
struct BatchSplit {
  std::size_t taken = 0;
  std::size_t dropped = 0;
};
constexpr BatchSplit split_batch(std::size_t got, std::size_t room) noexcept {
  return got <= room ? BatchSplit{got, 0} : BatchSplit{room, got - room};
}

class GpioQuadratureEncoder final : public EncoderSource {
 public:
  // open: requests the lines and starts the event thread. Errors name chip, line and role.
  static Result<std::unique_ptr<GpioQuadratureEncoder>> open(const GpioQuadratureConfig& cfg);
  ~GpioQuadratureEncoder() override;  // stops and joins the thread

  // read: the current cumulative counts (64-bit, never wrap in practice); flags
  // kEncoderInvalidTransition when invalid transitions were counted since the last read,
  // kEncoderReadError when the event thread failed.
  EncoderSample read(TimeNs now) noexcept override;
  int counter_bits() const noexcept override { return 64; }

  // wheel: diagnostics of wheel i (gpio_wheel_lines' numbering: 0 left, 1 right, 2 the left
  // side's second, ...).
  GpioWheelStats wheel(int i) const noexcept;
  // hold: diagnostics/tests: while held the thread reads no events (the kernel queue fills and
  // overflows as it would under an overloaded CPU).
  void hold(bool on) noexcept;

 private:
  struct Impl;
  explicit GpioQuadratureEncoder(std::unique_ptr<Impl> impl);
  // combine: several wheels per side: each wheel's count and fault into SideCombiner.
  void combine(bool failed, EncoderSample& s) noexcept;
  std::unique_ptr<Impl> impl_;
  std::uint64_t last_invalid_ = 0;
  // Several wheels per side: each wheel's invalid count at the last read; the combiner.
  std::array<std::uint64_t, 2 * kMaxWheelsPerSide> wheel_invalid_{};
  std::optional<SideCombiner> combiner_;
};

}  // namespace odo::drivers
