// CanCommandReceiver: the commands addressed to this node on the CAN bus, taken on the loop
// thread (no thread of its own): set-pose into the loop's command queue, FixPose + FixSigma
// pairs into the self-calibration's fix ring. README "CAN protocol" documents the frames.
#pragma once

#include <cstddef>
#include <cstdint>

#include "odo/hal/can_bus.hpp"
#include "odo/hal/time.hpp"
#include "odo/loop/command.hpp"
#include "odo/loop/recording_encoder.hpp"
#include "odo/protocol/can_protocol.hpp"

namespace odo::fw {

// CanReceiveOptions: this node's identity on the bus and what it takes from it.
struct CanReceiveOptions {
  std::uint32_t base_id = protocol::kDefaultBaseId;
  int node_id = protocol::kDefaultNodeId;
  bool set_pose = true;             // accept set-pose commands
  std::size_t max_rx_per_tick = 8;  // receive() calls per tick at most (a flood cannot stall us)
};

// Command counters; written by the loop thread, read after the run.
struct CanCommandCounters {
  std::uint64_t set_pose_applied = 0;   // commands posted to the loop
  std::uint64_t set_pose_rejected = 0;  // for this node but malformed (length, theta range)
  std::uint64_t fixes_forwarded = 0;    // FixPose + FixSigma pairs handed to the estimator
  std::uint64_t fixes_refused = 0;      // fix frames malformed, unpaired or not taken (ring full)
};

class CanCommandReceiver {
 public:
  // bus: where commands arrive; commands: the loop's queue for set-pose commands (may be null:
  // commands ignored); counters: where the counts go (the owner's, so that its own counters
  // and these are one struct its readers can hold a reference to).
  CanCommandReceiver(const CanReceiveOptions& o, CanBus& bus, loop::CommandQueue* commands,
                     CanCommandCounters& counters) noexcept
      : o_(o), bus_(&bus), commands_(commands), c_(&counters) {
    update_listening();
  }

  // receive: on the loop thread, once a tick: takes up to max_rx_per_tick frames; `stamp` is
  // the tick's sample time [ns] (a fix's age counts back from it).
  void receive(TimeNs stamp) noexcept {
    // Inline, with the options' test made once at configure time: on nearly every tick the one
    // receive finds nothing, and the tick pays that call alone (issue 33: the split had made
    // this a call of its own, +8 instructions a tick, tools/callgrind_tick.sh).
    if (!listening_) return;
    if (bus_->receive(rx_)) [[unlikely]]
      take_commands(stamp);
  }
  // take_posted: set-pose commands posted since the last call (the loop applies them at the
  // start of its next tick: the broadcaster acknowledges them then).
  std::uint32_t take_posted() noexcept {
    const std::uint32_t n = pending_ack_;
    pending_ack_ = 0;
    return n;
  }
  const CanCommandCounters& counters() const noexcept { return *c_; }
  // set_fix_ring: configure time; FixPose + FixSigma addressed to this node go there (null:
  // fix frames are ignored).
  void set_fix_ring(loop::FixRing* r) noexcept {
    fixes_ = r;
    update_listening();
  }

 private:
  // take_commands: handles the received frame rx_, then receives and handles more, up to
  // max_rx_per_tick frames in all (`stamp` as receive's).
  void take_commands(TimeNs stamp) noexcept;
  // update_listening: whether anything is taken from the bus at all (configure time).
  void update_listening() noexcept {
    listening_ = (o_.set_pose || fixes_ != nullptr) && o_.max_rx_per_tick > 0;
  }
  // take_fix: one FixPose or FixSigma frame; a FixSigma completing the FixPose of the same seq
  // becomes a PoseFix at rx_stamp_ - age.
  void take_fix(const CanFrame& f, protocol::Msg m) noexcept;

  CanReceiveOptions o_;
  CanBus* bus_;
  loop::CommandQueue* commands_;
  CanCommandCounters* c_;
  std::uint32_t pending_ack_ = 0;  // requested this tick, applied at the next one
  loop::FixRing* fixes_ = nullptr;
  protocol::FixMsg fix_half_;  // the last FixPose received
  bool have_fix_half_ = false;
  bool listening_ = false;  // set-pose or fixes taken, and max_rx_per_tick > 0
  // Where frames are received: a member, so that the empty poll of nearly every tick does not
  // initialise a frame (receive() overwrites every field of one it returns).
  CanFrame rx_;
  TimeNs rx_stamp_ = 0;  // sample time of the tick that receives [ns]
};

}  // namespace odo::fw
