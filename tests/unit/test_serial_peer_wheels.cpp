// The serial counts stream with several wheels per side end to end (issue 38): the simulated
// board (fw::SerialPeerModel, what `link = "sim"` and tests/tools/serial_peer run) sending version
// 2 records, read by the real SerialCountsSource; a wheel the board flags is dropped while its
// neighbour carries the side.
#include <gtest/gtest.h>

#include <array>
#include <deque>

#include "odo/firmware/serial_peer.hpp"
#include "odo/protocol/serial_counts_source.hpp"

namespace odo::fw {
namespace {

constexpr TimeNs kMs = 1'000'000;

// Bytes: the peer's output, read by the source as they were sent.
struct Bytes final : ByteLink {
  std::deque<std::uint8_t> in;
  int read(std::span<std::uint8_t> out, TimeNs& /*arrival*/) noexcept override {
    std::size_t n = 0;
    for (; n < out.size() && !in.empty(); ++n, in.pop_front()) out[n] = in.front();
    return static_cast<int>(n);
  }
  bool write(std::span<const std::uint8_t> /*data*/) noexcept override { return true; }
  bool reopen() noexcept override { return true; }
};

TEST(SerialPeerWheels, TwoPerSideThroughThePeerAFlaggedWheelIsDropped) {
  SerialPeerModel peer(SerialProtocol::kDiffodom, 2);
  Bytes link;
  protocol::SerialSourceConfig cfg;
  cfg.max_counts_per_s = 1e5;
  cfg.wheels.wheels_per_side = 2;
  protocol::SerialCountsSource src(link, cfg);
  // Every 10 ms: the left side +30 counts, the right -20 (all of a side's wheels alike, as the
  // peer sends them). Left wheel 2 is flagged from record 10 to 19.
  EncoderSample s;
  for (int i = 0; i <= 30; ++i) {
    const TimeNs t = i * 10 * kMs;
    peer.set_wheel_faults(i >= 10 && i < 20 ? 0x02 : 0x00);
    std::array<std::uint8_t, SerialPeerModel::kMaxOut> buf{};
    const std::size_t n = peer.sample(t, 1000 + 30 * i, 500 - 20 * i, buf);
    link.in.insert(link.in.end(), buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(n));
    s = src.read(t + 1 * kMs);
    // The sides start at 0 on the first record; wheel 1 carries the left side alone while
    // wheel 2 is flagged (its garbage never enters), so the side is exact throughout.
    EXPECT_EQ(s.left, 30 * i) << i;
    EXPECT_EQ(s.right, -20 * i) << i;
    EXPECT_EQ(s.flags, i >= 10 && i < 20 ? kEncoderWheelDropped : 0u) << i;
  }
  EXPECT_EQ(s.counters.wheel_drops, 1u);
  EXPECT_EQ(s.counters.link_errors, 0u);
  EXPECT_EQ(s.counters.implausible_jumps, 0u);
}

}  // namespace
}  // namespace odo::fw
