#include "odo/firmware/serial_peer.hpp"

#include <cstdio>

#include "odo/protocol/serial_counts.hpp"
#include "odo/protocol/serial_counts_source.hpp"

namespace odo::fw {

void SerialPeerModel::on_host_bytes(std::span<const std::uint8_t> in) noexcept {
  if (protocol_ != SerialProtocol::kArduinoBridge) return;
  for (const std::uint8_t b : in) {
    if (b != '\r') {
      if (cmd_len_ < cmd_.size()) cmd_[cmd_len_++] = static_cast<char>(b);
      continue;
    }
    // A command is its first letter (arguments, which "e" and "r" do not take, are ignored).
    if (cmd_len_ > 0 && cmd_[0] == protocol::kBridgeReadEncoders) ++pending_reads_;
    if (cmd_len_ > 0 && cmd_[0] == protocol::kBridgeResetEncoders) ++pending_resets_;
    cmd_len_ = 0;
  }
}

void SerialPeerModel::reset(TimeNs t, std::int64_t left, std::int64_t right) noexcept {
  base_left_ = left;
  base_right_ = right;
  boot_ = t;
  seq_ = 0;
  booted_records_ = 100;
  pending_reads_ = pending_resets_ = 0;
  cmd_len_ = 0;
}

std::size_t SerialPeerModel::sample_wheels(protocol::SerialCounts& c,
                                           std::span<std::uint8_t, kMaxOut> out) noexcept {
  c.wheels_per_side = static_cast<std::uint8_t>(wheels_);
  c.wheel_faults = wheel_faults_;
  c.more_left.fill(c.left);
  c.more_right.fill(c.right);
  // A faulted wheel's counter reads garbage (a fixed pattern far from any count).
  constexpr std::int32_t kGarbage = 0x55AA55AA;
  for (int k = 0; k < wheels_; ++k) {
    auto& l = k == 0 ? c.left : c.more_left[static_cast<std::size_t>(k - 1)];
    auto& r = k == 0 ? c.right : c.more_right[static_cast<std::size_t>(k - 1)];
    if ((wheel_faults_ >> k) & 1u) l = kGarbage;
    if ((wheel_faults_ >> (4 + k)) & 1u) r = kGarbage;
  }
  return protocol::encode_serial_counts_v2(c, out.first<protocol::kSerialCountsFrameMaxV2>());
}

std::size_t SerialPeerModel::sample(TimeNs t, std::int64_t left, std::int64_t right,
                                    std::span<std::uint8_t, kMaxOut> out) noexcept {
  if (protocol_ == SerialProtocol::kDiffodom) {
    protocol::SerialCounts c;
    c.seq = seq_++;
    c.time_us = static_cast<std::uint32_t>((t - boot_) / 1000);
    c.left = static_cast<std::int32_t>(left - base_left_);
    c.right = static_cast<std::int32_t>(right - base_right_);
    c.flags = booted_records_ > 0 ? protocol::kSerialFlagBooted : 0;
    if (booted_records_ > 0) --booted_records_;
    if (wheels_ > 1) return sample_wheels(c, out);
    return protocol::encode_serial_counts(c, out.first<protocol::kSerialCountsFrameMax>());
  }
  std::size_t n = 0;
  for (; pending_resets_ > 0; --pending_resets_) {
    base_left_ = left;
    base_right_ = right;
    n += static_cast<std::size_t>(
        std::snprintf(reinterpret_cast<char*>(out.data() + n), out.size() - n, "OK\r\n"));
  }
  // Several requests answered at once would be one stale answer each: one answer per call.
  if (pending_reads_ > 0 && n + 26 < out.size()) {
    pending_reads_ = 0;
    n += static_cast<std::size_t>(
        std::snprintf(reinterpret_cast<char*>(out.data() + n), out.size() - n, "%ld %ld\r\n",
                      static_cast<long>(static_cast<std::int32_t>(left - base_left_)),
                      static_cast<long>(static_cast<std::int32_t>(right - base_right_))));
  }
  return n;
}

}  // namespace odo::fw
