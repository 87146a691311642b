// EncoderSource: where the loop gets the cumulative counts of both wheels.
#pragma once

#include <cstdint>

#include "odo/hal/choice.hpp"
#include "odo/hal/time.hpp"

namespace odo {

// Health flags of one sample; several may be set at once.
enum EncoderFlag : std::uint32_t {
  kEncoderOk = 0,
  kEncoderStaleLeft = 1u << 0,          // no fresh reading of the left wheel within the timeout
  kEncoderStaleRight = 1u << 1,         // same for the right wheel
  kEncoderInvalidTransition = 1u << 2,  // quadrature decoder saw an illegal A/B transition
  kEncoderImplausibleJump = 1u << 3,    // a count step beyond the wheel's physical maximum
  kEncoderReadError = 1u << 4,          // the backend could not read the hardware this tick
  kEncoderLinkError = 1u << 5,          // serial: a corrupt frame/line or a sequence gap this tick
  kEncoderControllerReset = 1u << 6,    // serial: the controller restarted (counts re-based)
  kEncoderNoValidData = 1u << 7,        // serial: bytes arrive, none valid (wrong baud/protocol?)
  // Several encoders per side (side_wheels.hpp):
  kEncoderSlipLeft = 1u << 8,       // the left side's wheels disagree beyond the slip threshold
  kEncoderSlipRight = 1u << 9,      // same for the right side
  kEncoderWheelDropped = 1u << 10,  // a wheel's counter faulted: left out of its side this read
};

// The flags' names in odometryd's status line (README), in the order they are printed.
inline constexpr Choice<EncoderFlag> kEncoderFlagNames[] = {
    {kEncoderStaleLeft, "stale-left"},
    {kEncoderStaleRight, "stale-right"},
    {kEncoderInvalidTransition, "invalid-transition"},
    {kEncoderImplausibleJump, "implausible-jump"},
    {kEncoderReadError, "read-error"},
    {kEncoderLinkError, "link-error"},
    {kEncoderControllerReset, "controller-reset"},
    {kEncoderNoValidData, "no-valid-data(wrong-baud?)"},
    {kEncoderSlipLeft, "slip-left"},
    {kEncoderSlipRight, "slip-right"},
    {kEncoderWheelDropped, "wheel-dropped"}};

// Cumulative event counters of a backend since start; they only grow.
struct EncoderCounters {
  std::uint64_t invalid_transitions = 0;
  std::uint64_t implausible_jumps = 0;
  std::uint64_t stale_events = 0;
  std::uint64_t read_errors = 0;
  // Serial links (drivers/serial_encoder.hpp); 0 for the other backends.
  std::uint64_t link_errors = 0;        // corrupt frames / lines (CRC, framing, garbage)
  std::uint64_t sequence_gaps = 0;      // records missing from the controller's sequence
  std::uint64_t controller_resets = 0;  // controller restarts seen (counters from zero)
  std::uint64_t reconnects = 0;         // the device vanished and was opened again
  // Several encoders per side (side_wheels.hpp); 0 with one encoder per side.
  std::uint64_t slip_events = 0;  // rising edges of kEncoderSlipLeft plus of kEncoderSlipRight
  std::uint64_t wheel_drops = 0;  // wheels whose counter went from clean to faulted
};

// One reading of both wheels. left/right are raw counter readings exactly as the counter holds
// them (two's complement, counter_bits wide, sign-extended to 64 bits); the loop takes wrap-aware
// differences, so a counter may wrap freely.
struct EncoderSample {
  std::int64_t left = 0;
  std::int64_t right = 0;
  TimeNs stamp = 0;         // when the counts were latched [ns, clock of the loop]
  std::uint32_t flags = 0;  // EncoderFlag bits for this sample
  EncoderCounters counters;
  // Counts of implausible jumps this backend rejected since it started (wrap rule): the counter
  // itself holds left + left_rejected. The loop integrates left/right; the state record keeps
  // the counter's own value, so a restart sees only the motion made while nobody listened.
  std::int64_t left_rejected = 0;
  std::int64_t right_rejected = 0;
  // Several encoders per side: the within-side spread this sample adds to a slip interval
  // [counts] (SideStep::spread_left/right); 0 when the side is not flagged kEncoderSlip*.
  std::int64_t spread_left = 0;
  std::int64_t spread_right = 0;
};

// wrap_delta: signed difference cur - prev of two readings of a `bits`-wide counter, taking the
// shortest way round the wrap (|delta| < 2^(bits-1)). Readings may be given signed or unsigned;
// only their low `bits` bits are used. bits must be in [16, 64] (checked by the caller once).
constexpr std::int64_t wrap_delta(std::int64_t prev, std::int64_t cur, int bits) noexcept {
  // Unsigned arithmetic wraps modulo 2^64 without UB; shifting the difference up to the top of
  // the word and back down (arithmetic shift) sign-extends it from `bits` bits.
  const std::uint64_t diff = static_cast<std::uint64_t>(cur) - static_cast<std::uint64_t>(prev);
  const int shift = 64 - bits;
  return static_cast<std::int64_t>(diff << shift) >> shift;
}

class EncoderSource {
 public:
  virtual ~EncoderSource() = default;
  // read: latch and return both counters; never blocks longer than one bus transaction.
  virtual EncoderSample read(TimeNs now) noexcept = 0;
  // counter_bits: width of the hardware counter in bits (16..64); readings wrap at 2^bits.
  virtual int counter_bits() const noexcept = 0;
};

}  // namespace odo
