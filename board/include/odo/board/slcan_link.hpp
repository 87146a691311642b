// The firmware's CAN side in QEMU: SlcanBus is a CanBus over a UART in SLCAN framing
// (protocol/slcan.hpp), and PoseBroadcaster the loop's observer that sends the protocol's pose
// group and status frames (with SideWheels when it has several wheels per side) at their rates and
// posts received set-pose commands into the loop. On a real board the same broadcaster sends
// through bxCAN instead.
#pragma once

#include <cstdint>

#include "odo/board/board_config.hpp"
#include "odo/board/uart.hpp"
#include "odo/hal/can_bus.hpp"
#include "odo/loop/command.hpp"
#include "odo/loop/loop.hpp"
#include "odo/protocol/can_protocol.hpp"
#include "odo/protocol/slcan.hpp"

namespace odo::board {

class SlcanBus final : public CanBus {
 public:
  explicit SlcanBus(Uart& uart) noexcept : uart_(&uart) {}
  // send: the frame as one SLCAN line into the UART's ring; kQueueFull when it does not fit.
  CanTx send(const CanFrame& f) noexcept override;
  // receive: parses received bytes until a frame line ends; false when none is complete.
  bool receive(CanFrame& out) noexcept override;
  std::uint32_t bad_lines() const noexcept { return bad_lines_; }

 private:
  Uart* uart_;
  protocol::SlcanDecoder dec_;
  std::uint32_t bad_lines_ = 0;
};

struct BroadcastOptions {
  std::uint32_t base_id = protocol::kDefaultBaseId;
  int node_id = protocol::kDefaultNodeId;
  std::uint32_t pose_div = 2;     // loop ticks per pose group (protocol::divisor_for)
  std::uint32_t status_div = 10;  // loop ticks per status frame
  int wheels_per_side = 1;        // above 1, SideWheels goes with each Status (as odometryd's)
};

class PoseBroadcaster final : public loop::TickObserver {
 public:
  PoseBroadcaster(const BroadcastOptions& o, CanBus& bus, loop::CommandQueue& commands) noexcept
      : o_(o), bus_(&bus), commands_(&commands) {}
  // on_tick: set-pose commands received (posted, acknowledged in the next status), the frames
  // due on this tick; kicks the watchdog (the loop is alive).
  void on_tick(const loop::LoopSnapshot& s) noexcept override;
  // send_final: the last pose group and a status with the stopping flag (after the run).
  void send_final(const loop::LoopSnapshot& s) noexcept;
  std::uint32_t sent() const noexcept { return sent_; }
  std::uint32_t dropped() const noexcept { return dropped_; }
  std::uint32_t set_pose_applied() const noexcept { return set_pose_applied_; }

 private:
  void take_commands() noexcept;
  void send(const CanFrame& f) noexcept;
  void send_pose_group(const loop::LoopSnapshot& s) noexcept;
  void send_status(const loop::LoopSnapshot& s, bool stopping) noexcept;
  // send_side_wheels: the slip and dropped-wheel flags and counters (before each Status).
  void send_side_wheels(const loop::LoopSnapshot& s) noexcept;
  // several_wheels: constant false in an image built for one wheel per side, so that its flash
  // carries no SideWheels code.
  bool several_wheels() const noexcept { return kBoardWheelsPerSide > 1 && o_.wheels_per_side > 1; }
  std::uint32_t id(protocol::Msg m) const noexcept {
    return protocol::frame_id(o_.base_id, o_.node_id, m);
  }
  BroadcastOptions o_;
  CanBus* bus_;
  loop::CommandQueue* commands_;
  std::uint8_t seq_ = 0;  // pose group counter, as odometryd's (first group: 0)
  bool sent_any_pose_ = false;
  std::uint8_t ack_ = 0;
  std::uint32_t pending_ack_ = 0;
  std::uint32_t sent_ = 0, dropped_ = 0, set_pose_applied_ = 0;
};

}  // namespace odo::board
