// CanEncoderSource: wheel encoder counts that motor controllers publish on CAN, as an
// EncoderSource. Runs on any CanBus: SocketCanBus on a target (with kernel receive filters for
// the two wheel ids), SimCanPort in tests and in the simulated rig.
//
// Frames: the ODrive "CAN Simple" Get_Encoder_Count reply (id node_id << 5 | 0x00A, 11-bit,
// DLC 8: int32 shadow count at byte 0, int32 count-in-CPR at byte 4, little endian; the
// shadow count is used: it is cumulative and wraps as an int32, the count-in-CPR wraps every
// motor revolution and would alias above half a revolution per tick), or a generic layout
// (id, 11/29-bit, byte offset, width 16..64 bits in whole bytes, signed or unsigned, little or
// big endian). Both wheels may share one id at different offsets.
//
// read(now):
// - takes at most max_frames_per_read frames from the bus without blocking; frames beyond stay
//   queued (in the kernel socket buffer) for the next read; a backlog delays, never loses,
//   motion (the counts are cumulative);
// - counts are the controller's own counter (after `reverse`, sign-extended from the field's
//   width: the loop's wrap rule applies), so they are continuous across restarts of odometryd
//   while the controller keeps counting (issue 17); before the first frame a wheel reads 0 and
//   is stale (the loop takes a wheel's first fresh count as its reference, so that 0 is never
//   a jump to the first count);
// - every frame is judged on its own receive stamp (the kernel's, SocketCanBus): a step between
//   two frames of a wheel beyond max_counts_per_s * (stamp difference + kLatencySlack) + 1 count
//   is flagged kEncoderImplausibleJump, counted and not integrated (re-based); the sample's
//   left_rejected/right_rejected carry what was left out, so the state record keeps the
//   controller's own counter (issue 39);
// - both wheels are reported at one instant (issue 39): the sample time is the older of the two
//   wheels' newest frame stamps, and the other wheel's count is interpolated linearly between
//   its two frames around that instant (kept: the last kHistory frames of each wheel). Why
//   interpolation rather than "the newest pair whose stamps agree": per-wheel controllers (ODrive
//   axes) send out of phase, so their stamps never agree closer than their phase offset, and a
//   late frame of one wheel would hold both back by whole periods; interpolating keeps the error
//   at the count curve's bend between two frames (a * P^2 / 8 counts at acceleration a, frame
//   period P), independent of the phase. A wheel that falls silent holds the instant back until
//   it is stale (`timeout`); while a wheel is stale the sample time is `now` and each wheel
//   reports its newest count, as before;
// - a wheel whose newest frame is older than `timeout` is flagged kEncoderStaleLeft/Right and
//   keeps its last count; stale_events counts each fresh -> stale transition (the start-up
//   state before the first frame is not an event). On recovery the count difference since the
//   last frame is real motion (the counts are cumulative) unless it is implausible;
// - optionally sends a remote request (RTR) for each wheel's id at request_period, for
//   controllers that answer only on request; a dropped request is counted, never waited for.
//
// Several wheels per side (issue 38, wheels.wheels_per_side = N in 2..4, e.g. one ODrive axis per
// wheel of a 4WD base): every wheel is read as above on its own layout (its own frames, stamps,
// jump check and wrap); a wheel is stale on its own and is then dropped from its side (faulted),
// the side is stale only when all its wheels are; the instant is the oldest newest frame of the
// fresh wheels, except that a wheel silent for longer than the others' kept frames (kHistory)
// is dropped at once rather than holding the instant back until it is stale (mark_lagging); the
// side's count is SideCombiner's (hal/side_wheels.hpp: wrap-aware per wheel,
// 64-bit, never wraps), so counter_bits() is 64. N = 1 is exactly the two-wheel source above.
#pragma once

#include <array>
#include <cstdint>
#include <optional>

#include "odo/hal/can_bus.hpp"
#include "odo/hal/encoder.hpp"
#include "odo/hal/result.hpp"
#include "odo/hal/side_wheels.hpp"
#include "odo/hal/time.hpp"

namespace odo::drivers {

// CanCountLayout: where one wheel's count sits in which frame.
struct CanCountLayout {
  std::uint32_t id = 0;     // arbitration id, 11-bit (extended false) or 29-bit
  bool extended = false;    // 29-bit identifier
  int byte_offset = 0;      // first byte of the count in the data field, 0..7
  int width_bits = 32;      // 16, 24, ..., 64 (whole bytes)
  bool is_signed = true;    // two's complement; false: unsigned
  bool big_endian = false;  // byte order of the count
};

// odrive_count_layout: the shadow count of ODrive CAN Simple Get_Encoder_Count (cmd 0x00A) of
// node `node_id` (0..63).
CanCountLayout odrive_count_layout(std::uint32_t node_id) noexcept;

enum class CanDecode : std::uint8_t {
  kOk,
  kOtherId,     // id or id length differs: not this wheel's frame
  kRemote,      // a remote request with this id: carries no count
  kShortFrame,  // DLC too short for offset + width
};

// decode_count: the count of `layout` in frame `f` [counts, as the sender's counter holds it:
// signed values sign-extended, unsigned zero-extended (64-bit unsigned: reinterpreted)]; no
// allocation, no exceptions. `out` is written only for kOk.
CanDecode decode_count(const CanFrame& f, const CanCountLayout& layout, std::int64_t& out) noexcept;

// check_layout: configure-time validation of a layout; the message names the field.
Status check_layout(const CanCountLayout& layout);

// The range of max_frames_per_read of the CAN sources (encoder counts, gyro), checked by their
// create() and by the config reader ([can_encoder], [can_gyro]).
inline constexpr RangeRow kCanMaxFramesPerRead{"max_frames_per_read", 1, 4096, "frames"};

struct CanEncoderConfig {
  CanCountLayout left;
  CanCountLayout right;
  bool reverse_left = false;  // negate the count (mirrored motor mounting)
  bool reverse_right = false;
  TimeNs timeout = 100'000'000;   // [ns] newest frame older than this: stale
  double max_counts_per_s = 1e6;  // physical maximum count rate of a wheel [counts/s]
  int max_frames_per_read = 64;   // frames taken from the bus per read, 1..4096
  TimeNs request_period = 0;      // [ns] between remote requests, 0 = never (cyclic senders)
  // N wheels per side: `left`/`right` are wheel 0 of each side, more_left[k - 1] /
  // more_right[k - 1] wheel k (k < wheels.wheels_per_side); reverse_* applies to a whole side.
  // wheels.counter_bits is set by create() to the layouts' width.
  SideWheelsConfig wheels;
  std::array<CanCountLayout, kMaxWheelsPerSide - 1> more_left{};
  std::array<CanCountLayout, kMaxWheelsPerSide - 1> more_right{};
};

// can_wheel_count: the number of wheels of `cfg`, both sides (2 * wheels_per_side).
int can_wheel_count(const CanEncoderConfig& cfg) noexcept;
// can_wheel_layout: the layout of wheel `i` (0..can_wheel_count - 1): side i % 2 (0 left,
// 1 right), wheel i / 2 of that side; so wheels 0 and 1 are `left` and `right`.
const CanCountLayout& can_wheel_layout(const CanEncoderConfig& cfg, int i) noexcept;

// Per-source diagnostics beyond EncoderCounters.
struct CanEncoderStats {
  std::uint64_t frames = 0;            // frames taken from the bus
  std::uint64_t decoded = 0;           // counts decoded (a frame may carry both wheels)
  std::uint64_t foreign = 0;           // frames of other ids (the kernel filter lets none pass)
  std::uint64_t short_frames = 0;      // our id with a DLC too short: ignored
  std::uint64_t remote = 0;            // remote requests with our id: ignored
  std::uint64_t capped_reads = 0;      // reads that stopped at max_frames_per_read
  std::uint64_t requests_sent = 0;     // remote requests sent
  std::uint64_t requests_dropped = 0;  // remote requests the bus refused
};

class CanEncoderSource final : public EncoderSource {
 public:
  // create: validates the configuration (layouts, equal widths, ranges); `bus` must outlive it.
  static Result<CanEncoderSource> create(CanBus& bus, const CanEncoderConfig& cfg);

  // read: drains frames and reports both wheels; see the header comment.
  EncoderSample read(TimeNs now) noexcept override;
  // counter_bits: the width of the configured count field; 64 with N > 1 wheels per side (the
  // combined counts never wrap).
  int counter_bits() const noexcept override {
    return cfg_.wheels.wheels_per_side > 1 ? 64 : cfg_.left.width_bits;
  }

  const CanEncoderStats& stats() const noexcept { return stats_; }
  // last_frame: receive stamp of the newest accepted frame of wheel `wheel` (can_wheel_layout's
  // numbering: 0 left, 1 right, 2 the left side's second, ...) [ns]; 0 before the first.
  TimeNs last_frame(int wheel) const noexcept {
    const Wheel& w = wheel_[static_cast<std::size_t>(wheel_index(wheel))];
    return w.primed ? w.last_stamp : 0;
  }

 private:
  CanEncoderSource(CanBus& bus, const CanEncoderConfig& cfg) : bus_(&bus), cfg_(cfg) {}
  int wheel_index(int wheel) const noexcept {
    return wheel >= 0 && wheel < can_wheel_count(cfg_) ? wheel : (wheel == 0 ? 0 : 1);
  }
  // Frames of one wheel kept for interpolation: a wheel may lag the other by up to
  // kHistory - 1 of its frames before its count at the common instant is clamped to the oldest.
  static constexpr std::size_t kHistory = 8;
  struct Stamped {
    TimeNs stamp = 0;        // receive time [ns]
    std::int64_t count = 0;  // reported count (offset applied)
  };
  struct Wheel {
    std::int64_t offset = 0;    // subtracted from the sender's count (re-basing after jumps)
    std::int64_t last_raw = 0;  // last accepted count (after reverse)
    TimeNs last_stamp = 0;      // receive time of the newest frame [ns]
    bool primed = false;        // a frame has arrived
    bool stale = true;          // flagged stale at the last read
    bool lagging = false;       // N > 1: left out of the last read (mark_lagging)
    std::array<Stamped, kHistory> history{};  // ring; newest at `newest`
    std::size_t newest = 0;
    std::size_t kept = 0;  // valid entries, 0..kHistory
  };

  void accept(int wheel, std::int64_t raw, TimeNs stamp, std::uint32_t& flags) noexcept;
  void send_requests(TimeNs now) noexcept;
  int drain(TimeNs now, std::uint32_t& flags) noexcept;
  // count_at: wheel `w`'s reported count at `t` [ns]: interpolated between the frames around t,
  // the newest count after the newest frame, the oldest kept before the oldest.
  std::int64_t count_at(const Wheel& w, TimeNs t) const noexcept;
  // mark_lagging: N > 1 wheels per side: a fresh wheel whose newest frame is older than another
  // fresh wheel's oldest kept frame would hold the instant where that wheel's count is clamped
  // (its travel half-weighted in its side's mean until the silent wheel is stale): it is left
  // out of this read (faulted: dropped) unless every fresh wheel of its side lags.
  void mark_lagging() noexcept;
  // sample_time: the instant of this read (see the header comment); marks stale wheels.
  TimeNs sample_time(TimeNs now, std::uint32_t& flags) noexcept;
  // combine: N > 1 wheels per side: each wheel's count at `t` into SideCombiner.
  void combine(TimeNs t, EncoderSample& s) noexcept;

  CanBus* bus_;
  CanEncoderConfig cfg_;
  std::optional<SideCombiner> combiner_;  // with wheels_per_side > 1
  std::array<Wheel, 2 * kMaxWheelsPerSide> wheel_{};
  EncoderCounters counters_;
  CanEncoderStats stats_;
  TimeNs next_request_ = 0;
  TimeNs last_sample_ = 0;  // sample time of the last read [ns]: never goes back
};

}  // namespace odo::drivers
