// BxCanModel: register model of the STM32F4's bxCAN (CAN1, RM0090 32) for the board's driver on
// the host (issue 36): MCR/MSR initialisation handshake (INRQ -> INAK), BTR writable only in
// initialisation, three transmit mailboxes (TXRQ queues a frame, the bus takes it when
// transmit() is called, TMEx empty again), receive FIFO 0 of three frames (FMP0, RFOM0, overrun
// FOVR0), and the 14 filter banks' 32-bit identifier-mask and identifier-list filters (FINIT,
// FM1R, FS1R, FFA1R, FA1R, FxR1/FxR2). Frames the filters send to FIFO 1 are counted, not kept.
#pragma once

#include <array>
#include <cstdint>
#include <deque>
#include <vector>

#include "odo/hal/can_bus.hpp"
#include "odo/hal/register_bus.hpp"

namespace odo::sim {

class BxCanModel final : public RegisterBus {
 public:
  static constexpr std::uint32_t kBase = 0x40006400;
  std::uint32_t read(std::uint32_t addr) noexcept override;
  void write(std::uint32_t addr, std::uint32_t value) noexcept override;

  // transmit: the bus takes every requested mailbox (lowest first); the frames sent so far.
  void transmit() noexcept;
  const std::vector<CanFrame>& sent() const noexcept { return sent_; }
  // deliver: a frame from the bus through the filters; true when FIFO 0 took it.
  bool deliver(const CanFrame& f) noexcept;
  bool overrun() const noexcept { return (rf0r_ & (1u << 4)) != 0; }
  int fifo1_frames() const noexcept { return fifo1_; }
  bool initialising() const noexcept { return (msr_ & 1u) != 0; }

 private:
  // match: the filter bank that accepts identifier register value `ir` (-1: none).
  int match(std::uint32_t ir) const noexcept;
  std::uint32_t mcr_ = 0x00010002u, msr_ = 0x00000C02u, btr_ = 0x01230000u, rf0r_ = 0;
  std::array<std::array<std::uint32_t, 4>, 3> tx_{};  // TIxR, TDTxR, TDLxR, TDHxR
  std::deque<std::array<std::uint32_t, 4>> fifo0_;    // RIxR, RDTxR, RDLxR, RDHxR
  std::uint32_t fmr_ = 0x2A1C0E01u, fm1r_ = 0, fs1r_ = 0, ffa1r_ = 0, fa1r_ = 0;
  std::array<std::array<std::uint32_t, 2>, 14> banks_{};
  std::vector<CanFrame> sent_;
  int fifo1_ = 0;
};

}  // namespace odo::sim
