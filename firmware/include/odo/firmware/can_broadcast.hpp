// CanBroadcaster (issue 10): a loop::TickObserver that encodes the protocol's frames at their
// configured rates and sends them through a CanBus without ever blocking, on the loop thread (no
// thread of its own). On each tick it lets its CanCommandReceiver take the commands addressed
// to this node, and hands every frame sent to the --can-log ring (CanLogWriter's thread writes
// it). README "CAN protocol" documents the frames; CanLink (can_link.hpp) wires [can].
#pragma once

#include <cstdint>
#include <thread>

#include "odo/firmware/can_command_receiver.hpp"
#include "odo/firmware/can_log_writer.hpp"
#include "odo/hal/can_bus.hpp"
#include "odo/loop/command.hpp"
#include "odo/loop/loop.hpp"
#include "odo/loop/recording_encoder.hpp"
#include "odo/protocol/can_protocol.hpp"

namespace odo::fw {

// Transmit counters; written by the loop thread, read after the run (or for the status frame
// on the loop thread).
struct CanTxCounters {
  std::uint64_t sent = 0;
  std::uint64_t dropped_queue_full = 0;
  std::uint64_t dropped_link_down = 0;
  std::uint64_t dropped_error = 0;
  std::uint64_t dropped() const noexcept {
    return dropped_queue_full + dropped_link_down + dropped_error;
  }
};

// Transmit and command counters of one broadcaster (its receiver's), as --json reports them.
struct CanBroadcastCounters : CanTxCounters, CanCommandCounters {};

// Per-message rates as divisors of the loop rate (send on ticks where tick % div == 0; 0 = off).
struct CanDivisors {
  std::uint32_t pose = 0, velocity = 0, uncertainty = 0, status = 0, timing = 0;
};

// The node's identity and what it receives (CanReceiveOptions), and what it sends.
struct CanBroadcastOptions : CanReceiveOptions {
  CanDivisors div;
  // [encoder] wheels_per_side: above 1, SideWheels goes with each Status (issue 38).
  int wheels_per_side = 1;
  bool lossless_log = false;  // virtual time: wait for the log writer instead of dropping
};

class CanBroadcaster final : public loop::TickObserver {
 public:
  // bus: where frames go; commands: the loop's queue for set-pose commands (may be null:
  // commands ignored); log: optional ring that gets every frame the bus accepted.
  CanBroadcaster(const CanBroadcastOptions& o, CanBus& bus, loop::CommandQueue* commands,
                 CanFrameRing* log) noexcept;

  void on_tick(const loop::LoopSnapshot& snap) noexcept override;
  // send_final: the final pose group, velocity, uncertainty, timing, encoder faults and a
  // status frame with the stopping flag (clean stop); call on the loop thread after run() returned.
  void send_final(const loop::LoopSnapshot& snap) noexcept;

  // counters: what was sent and dropped, and what the receiver took.
  const CanBroadcastCounters& counters() const noexcept { return c_; }
  std::uint8_t seq() const noexcept { return seq_; }
  // set_fix_ring: configure time; FixPose + FixSigma addressed to this node go there (null:
  // fix frames are ignored).
  void set_fix_ring(loop::FixRing* r) noexcept { rx_.set_fix_ring(r); }

 private:
  void send(const CanFrame& f, std::int64_t loop_time) noexcept;
  void send_pose_group(const loop::LoopSnapshot& s) noexcept;
  void send_velocity(const loop::LoopSnapshot& s) noexcept;
  void send_uncertainty(const loop::LoopSnapshot& s) noexcept;
  void send_status(const loop::LoopSnapshot& s, bool stopping) noexcept;
  void send_timing(const loop::LoopSnapshot& s) noexcept;
  // send_encoder_faults: the EncoderFaults frame (the backend's counters, saturating at 255).
  void send_encoder_faults(const loop::LoopSnapshot& s) noexcept;
  // send_side_wheels: the SideWheels frame (slip and dropped-wheel flags and counters).
  void send_side_wheels(const loop::LoopSnapshot& s) noexcept;
  void log_frame(const CanFrame& f) noexcept {
    if (o_.lossless_log)
      log_->push_wait(f, [] { std::this_thread::yield(); });
    else
      log_->push(f);
  }
  std::uint32_t id(protocol::Msg m) const noexcept {
    return protocol::frame_id(o_.base_id, o_.node_id, m);
  }

  CanBroadcastOptions o_;
  CanBus* bus_;
  CanFrameRing* log_;
  CanBroadcastCounters c_;  // the transmit part here, the command part the receiver's
  CanCommandReceiver rx_;   // set-pose and fixes, taken at the start of each tick
  std::uint8_t seq_ = 0;    // pose group counter (first group: 0)
  bool sent_any_pose_ = false;
  std::uint8_t ack_ = 0;  // set-pose commands applied (mod 256), in the status frame
  // Ticks strictly between quiet_after_ and quiet_after_ + quiet_span_ + 1 are a multiple of no
  // divisor: on them the rate checks are skipped (the span is 0 until the first check).
  std::uint64_t quiet_after_ = 0;
  std::uint64_t quiet_span_ = 0;

  // send_due: sends what is due on tick t (t % divisor == 0) and notes the next such tick.
  void send_due(const loop::LoopSnapshot& s) noexcept;
};

}  // namespace odo::fw
