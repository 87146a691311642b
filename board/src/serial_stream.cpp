#include "odo/board/serial_stream.hpp"

#include <array>

#include "odo/board/board_config.hpp"
#include "odo/hal/encoder.hpp"

namespace odo::board {

void SerialStream::on_tick(const loop::LoopSnapshot& s) noexcept {
  if (div_ == 0 || s.tick % div_ != 0) return;
  protocol::SerialCounts c;
  c.seq = seq_;
  // The controller's microsecond clock: the sample's time, wrapping at 2^32 us as the contract
  // says.
  c.time_us = static_cast<std::uint32_t>(static_cast<std::uint64_t>(s.stamp / 1000));
  constexpr std::uint32_t kFault = kEncoderReadError | kEncoderInvalidTransition;
  if ((s.encoder_flags & (kFault | kEncoderStaleLeft)) != 0)
    c.flags |= protocol::kSerialFlagFaultLeft;
  if ((s.encoder_flags & (kFault | kEncoderStaleRight)) != 0)
    c.flags |= protocol::kSerialFlagFaultRight;
  if (sent_ == 0) c.flags |= protocol::kSerialFlagBooted;  // the first record after a boot
  bool sent = false;
  // An image built for one wheel per side carries no version 2 code (the branch folds away).
  if (kBoardWheelsPerSide > 1 && n_ > 1) {
    sent = send_wheels(c);
  } else {
    // The counters as the hardware holds them, their low 32 bits (the host takes wrap-aware
    // deltas).
    c.left = static_cast<std::int32_t>(static_cast<std::uint32_t>(loop_->last_left()));
    c.right = static_cast<std::int32_t>(static_cast<std::uint32_t>(loop_->last_right()));
    std::array<std::uint8_t, protocol::kSerialCountsFrameMax> frame{};
    const std::size_t n = protocol::encode_serial_counts(c, frame);
    sent = uart_->write(reinterpret_cast<const char*>(frame.data()), n);
  }
  if (sent) {
    ++seq_;
    ++sent_;
  }
}

bool SerialStream::send_wheels(protocol::SerialCounts& c) noexcept {
  const std::array<SideReadings, 2>& w = *wheels_;
  c.wheels_per_side = static_cast<std::uint8_t>(n_);
  // Each wheel's counter, its low 32 bits, as the host's version 2 reader takes them (wheel k of
  // a side: k = 0 in left/right, k >= 1 in more_*[k - 1]).
  const auto low32 = [](std::int64_t v) {
    return static_cast<std::int32_t>(static_cast<std::uint32_t>(v));
  };
  c.left = low32(w[0].counts[0]);
  c.right = low32(w[1].counts[0]);
  for (int k = 1; k < n_; ++k) {
    const auto i = static_cast<std::size_t>(k);
    c.more_left[i - 1] = low32(w[0].counts[i]);
    c.more_right[i - 1] = low32(w[1].counts[i]);
  }
  // wheel_faults: bit k left wheel k, bit 4 + k right wheel k (the host drops such a wheel from
  // its side for that record).
  c.wheel_faults = static_cast<std::uint8_t>((w[0].faulted & 0xFu) | ((w[1].faulted & 0xFu) << 4));
  std::array<std::uint8_t, protocol::kSerialCountsFrameMaxV2> frame{};
  const std::size_t n = protocol::encode_serial_counts_v2(c, frame);
  return uart_->write(reinterpret_cast<const char*>(frame.data()), n);
}

}  // namespace odo::board
