// The board's bxCAN driver (board/bxcan) against sim_hal's register model of the controller:
// initialisation handshake and bit timing, the three transmit mailboxes, the filter that lets
// only the node's set-pose frames into FIFO 0, FIFO overrun.
#include <gtest/gtest.h>

#include "odo/board/bxcan.hpp"
#include "odo/sim/bxcan_model.hpp"

namespace {

using odo::CanFrame;
using odo::CanTx;
using odo::board::BxCan;
using odo::sim::BxCanModel;

CanFrame frame(std::uint32_t id, std::uint8_t first, bool extended = false) {
  CanFrame f;
  f.id = id;
  f.extended = extended;
  f.len = 8;
  for (int i = 0; i < 8; ++i)
    f.data[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(first + i);
  return f;
}

// The set-pose id of node 1: 0x400 + 16 + 8 = 0x418, accepted exactly (mask 0x7FF).
constexpr std::uint32_t kSetPose = 0x418;

TEST(BxCan, InitSetsTimingAndLeavesInitialisation) {
  BxCanModel m;
  BxCan can(m);
  ASSERT_TRUE(can.init(BxCan::kBtr500k, kSetPose, 0x7FF));
  EXPECT_FALSE(m.initialising());
  EXPECT_EQ(m.read(BxCanModel::kBase + 0x1C), BxCan::kBtr500k);  // written while initialising
}

TEST(BxCan, ThreeMailboxesThenQueueFull) {
  BxCanModel m;
  BxCan can(m);
  ASSERT_TRUE(can.init(BxCan::kBtr500k, kSetPose, 0x7FF));
  EXPECT_EQ(can.send(frame(0x410, 1)), CanTx::kSent);
  EXPECT_EQ(can.send(frame(0x411, 2)), CanTx::kSent);
  EXPECT_EQ(can.send(frame(0x1ABCDEF0, 3, true)), CanTx::kSent);
  EXPECT_EQ(can.send(frame(0x414, 4)), CanTx::kQueueFull);  // the bus has not taken any yet
  m.transmit();
  ASSERT_EQ(m.sent().size(), 3u);
  EXPECT_EQ(m.sent()[0].id, 0x410u);
  EXPECT_EQ(m.sent()[0].data[7], 8);
  EXPECT_TRUE(m.sent()[2].extended);
  EXPECT_EQ(m.sent()[2].id, 0x1ABCDEF0u);
  EXPECT_EQ(m.sent()[2].data[0], 3);
  EXPECT_EQ(can.send(frame(0x414, 4)), CanTx::kSent);  // mailboxes free again
}

TEST(BxCan, FilterPassesOnlyTheSetPoseIdIntoFifo0) {
  BxCanModel m;
  BxCan can(m);
  ASSERT_TRUE(can.init(BxCan::kBtr500k, kSetPose, 0x7FF));
  EXPECT_FALSE(m.deliver(frame(0x419, 0)));           // the node's FixPose: not for this driver
  EXPECT_FALSE(m.deliver(frame(0x408, 0)));           // node 0's set-pose
  EXPECT_FALSE(m.deliver(frame(kSetPose, 0, true)));  // an extended id 0x418
  EXPECT_TRUE(m.deliver(frame(kSetPose, 0x10)));
  CanFrame f;
  ASSERT_TRUE(can.receive(f));
  EXPECT_EQ(f.id, kSetPose);
  EXPECT_FALSE(f.extended);
  EXPECT_EQ(f.len, 8);
  EXPECT_EQ(f.data[0], 0x10);
  EXPECT_EQ(f.data[7], 0x17);
  EXPECT_FALSE(can.receive(f));  // released: the FIFO is empty
}

TEST(BxCan, FifoOverrunKeepsTheNewestFrame) {
  BxCanModel m;
  BxCan can(m);
  ASSERT_TRUE(can.init(BxCan::kBtr500k, kSetPose, 0x7FF));
  for (std::uint8_t i = 0; i < 4; ++i)
    m.deliver(frame(kSetPose, static_cast<std::uint8_t>(16 * i)));
  EXPECT_TRUE(m.overrun());
  CanFrame f;
  std::uint8_t firsts[3] = {};
  for (auto& b : firsts) {
    ASSERT_TRUE(can.receive(f));
    b = f.data[0];
  }
  EXPECT_FALSE(can.receive(f));
  // RFLM clear (the driver leaves it): the fourth frame replaced the third.
  EXPECT_EQ(firsts[0], 0);
  EXPECT_EQ(firsts[1], 16);
  EXPECT_EQ(firsts[2], 48);
}

}  // namespace
