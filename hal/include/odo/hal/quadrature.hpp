// Quadrature 4x decoding: the pure state table shared by the GPIO decoder (drivers/) and the
// simulated HCTL-1100 (sim_hal/). No I/O, no state: a transition in, a step out.
#pragma once

#include <cstdint>

namespace odo {

// QuadState: the two channel levels packed as (A << 1) | B, 0..3.
using QuadState = std::uint8_t;

// quad_state: packs the levels of channel A and B.
constexpr QuadState quad_state(bool a, bool b) noexcept {
  return static_cast<QuadState>((a ? 2u : 0u) | (b ? 1u : 0u));
}

// QuadStep: what one transition between two sampled states means.
enum class QuadStep : std::int8_t {
  kNone = 0,      // same state: no edge
  kForward = 1,   // one count forward (A leads B)
  kBackward = 2,  // one count backward (B leads A)
  kInvalid = 3,   // both channels changed: direction unknown, never turned into motion
};

// Forward (A leads B) runs through the Gray sequence 00 -> 10 -> 11 -> 01 -> 00, i.e. the packed
// states 0 -> 2 -> 3 -> 1 -> 0. Indexed by (from << 2) | to.
inline constexpr QuadStep kQuadTable[16] = {
    // from 00: to 00, 01, 10, 11
    QuadStep::kNone, QuadStep::kBackward, QuadStep::kForward, QuadStep::kInvalid,
    // from 01
    QuadStep::kForward, QuadStep::kNone, QuadStep::kInvalid, QuadStep::kBackward,
    // from 10
    QuadStep::kBackward, QuadStep::kInvalid, QuadStep::kNone, QuadStep::kForward,
    // from 11
    QuadStep::kInvalid, QuadStep::kForward, QuadStep::kBackward, QuadStep::kNone};

// quad_decode: the meaning of the transition from -> to (states 0..3).
constexpr QuadStep quad_decode(QuadState from, QuadState to) noexcept {
  return kQuadTable[((from & 3u) << 2) | (to & 3u)];
}

// quad_delta: the count change of a step (+1, -1, or 0 for none and invalid).
constexpr int quad_delta(QuadStep s) noexcept {
  return s == QuadStep::kForward ? 1 : (s == QuadStep::kBackward ? -1 : 0);
}

// quad_state_at: the channel state of an ideal encoder at position `count` (4x counts), with
// count 0 in state 00 and forward motion following the Gray sequence above.
constexpr QuadState quad_state_at(std::int64_t count) noexcept {
  constexpr QuadState kSeq[4] = {0, 2, 3, 1};
  return kSeq[static_cast<std::uint64_t>(count) & 3u];
}

}  // namespace odo
