// Hctl1100Encoder: both wheels' HCTL-1100 position counters, read through a ParallelBus (the
// libgpiod bus on a target, the register model in simulation), as an EncoderSource.
//
// Read protocol (tear-proof without relying on the chip's byte latch, which we could not
// confirm): one reading is R14H, R13H, R12H (LSB first, so a latch on the LSB read would hold
// the upper bytes); readings are repeated until two consecutive ones agree within
// `agree_window` counts (the distance the wheel can move during one reading). A torn reading is
// off by at least 256 - agree_window counts, so it never agrees with a good one.
// Plausibility: a step between ticks beyond max_counts_per_s * dt + agree_window is flagged
// kEncoderImplausibleJump, counted, and not integrated (the driver re-bases on the new value).
#pragma once

#include <array>
#include <cstdint>

#include "odo/hal/encoder.hpp"
#include "odo/hal/parallel_bus.hpp"
#include "odo/hal/result.hpp"

namespace odo::drivers {

// The ranges of the read-back settings, checked by create() and by the config reader ([hctl1100]).
inline constexpr RangeRow kHctlAgreeWindow{"agree_window", 0, 64, "counts"};
inline constexpr RangeRow kHctlMaxAttempts{"max_attempts", 2, 16, ""};

struct Hctl1100Config {
  int unit_left = 0;          // chip-select index of the left wheel's chip
  int unit_right = 1;         // and of the right wheel's
  bool reverse_left = false;  // negate the count (mirrored motor mounting)
  bool reverse_right = false;
  double max_counts_per_s = 1e6;  // physical maximum count rate of a wheel [counts/s]
  int agree_window = 16;          // [counts] 0..64, see above
  int max_attempts = 4;           // readings per wheel and tick before a read error, 2..16
};

class Hctl1100Encoder final : public EncoderSource {
 public:
  static constexpr int kBits = 24;

  // create: validates the configuration against the bus (units exist, ranges).
  static Result<Hctl1100Encoder> create(ParallelBus& bus, const Hctl1100Config& cfg);

  // read: reads both chips; see the header comment for the protocol and the flags.
  EncoderSample read(TimeNs now) noexcept override;
  int counter_bits() const noexcept override { return kBits; }

  // read_position: one tear-proof reading of one chip (sign-extended 24-bit value); false on a
  // bus fault or when no two consecutive readings agreed.
  bool read_position(int unit, std::int32_t& out) noexcept;

 private:
  Hctl1100Encoder(ParallelBus& bus, const Hctl1100Config& cfg) : bus_(&bus), cfg_(cfg) {}
  bool read_once(int unit, std::int32_t& out) noexcept;

  struct Wheel {
    std::int64_t offset = 0;    // subtracted from the chip's value (re-basing after a jump)
    std::int64_t last_raw = 0;  // last accepted chip value
    std::int64_t last_out = 0;  // last reported value
    bool primed = false;
  };

  ParallelBus* bus_;
  Hctl1100Config cfg_;
  std::array<Wheel, 2> wheel_{};
  TimeNs last_stamp_ = 0;
  bool have_stamp_ = false;
  EncoderCounters counters_;
};

}  // namespace odo::drivers
