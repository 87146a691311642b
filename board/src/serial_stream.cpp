#include "odo/board/serial_stream.hpp"

#include <array>

#include "odo/hal/encoder.hpp"
#include "odo/protocol/serial_counts.hpp"

namespace odo::board {

void SerialStream::on_tick(const loop::LoopSnapshot& s) noexcept {
  if (div_ == 0 || s.tick % div_ != 0) return;
  protocol::SerialCounts c;
  c.seq = seq_;
  // The controller's microsecond clock: the sample's time, wrapping at 2^32 us as the contract
  // says.
  c.time_us = static_cast<std::uint32_t>(static_cast<std::uint64_t>(s.stamp / 1000));
  // The counters as the hardware holds them, their low 32 bits (the host takes wrap-aware deltas).
  c.left = static_cast<std::int32_t>(static_cast<std::uint32_t>(loop_->last_left()));
  c.right = static_cast<std::int32_t>(static_cast<std::uint32_t>(loop_->last_right()));
  constexpr std::uint32_t kFault = kEncoderReadError | kEncoderInvalidTransition;
  if ((s.encoder_flags & (kFault | kEncoderStaleLeft)) != 0)
    c.flags |= protocol::kSerialFlagFaultLeft;
  if ((s.encoder_flags & (kFault | kEncoderStaleRight)) != 0)
    c.flags |= protocol::kSerialFlagFaultRight;
  if (sent_ == 0) c.flags |= protocol::kSerialFlagBooted;  // the first record after a boot
  std::array<std::uint8_t, protocol::kSerialCountsFrameMax> frame{};
  const std::size_t n = protocol::encode_serial_counts(c, frame);
  if (uart_->write(reinterpret_cast<const char*>(frame.data()), n)) {
    ++seq_;
    ++sent_;
  }
}

}  // namespace odo::board
