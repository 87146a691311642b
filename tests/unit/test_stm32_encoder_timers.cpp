// The board's TIM3/TIM4 encoder driver (board/stm32_encoder_timers) against sim_hal's register
// model of the STM32F4 timers, as the HCTL-1100 backend is tested against its model: the
// configuration the driver writes makes the model count, and the 16-bit counters read through
// the loop's wrap-aware delta give back every count across many wraps.
#include <gtest/gtest.h>

#include <cstdint>

#include "odo/board/stm32_encoder_timers.hpp"
#include "odo/odometry/count_delta.hpp"
#include "odo/sim/stm32_timer_model.hpp"

namespace {

using odo::board::Stm32EncoderTimers;
using odo::sim::Stm32TimerModel;

TEST(Stm32EncoderTimers, InitConfiguresEncoderMode3AndCounts) {
  Stm32TimerModel m;
  Stm32EncoderTimers enc(m);
  m.edges(0, 100);  // before init: the timer is stopped, nothing counts
  EXPECT_FALSE(m.counting(0));
  enc.init();
  EXPECT_TRUE(m.counting(0));
  EXPECT_TRUE(m.counting(1));
  EXPECT_EQ(m.unknown_writes(), 0);
  // SMS = 3 (x4), CC1S = CC2S = 01 with the 8-sample filter (IC1F = IC2F = 3), ARR = 0xFFFF.
  EXPECT_EQ(m.read(Stm32TimerModel::kTim3 + Stm32TimerModel::kSmcr), 3u);
  EXPECT_EQ(m.read(Stm32TimerModel::kTim4 + Stm32TimerModel::kCcmr1), 0x3131u);
  EXPECT_EQ(m.read(Stm32TimerModel::kTim3 + Stm32TimerModel::kArr), 0xFFFFu);
  m.edges(0, 7);   // left: 7 edges forward
  m.edges(1, -3);  // right: 3 backward, wrapping below 0 to 65533
  const odo::EncoderSample s = enc.read(123);
  EXPECT_EQ(s.left, 7);
  EXPECT_EQ(s.right, 65533);
  EXPECT_EQ(s.stamp, 123);
  EXPECT_EQ(enc.counter_bits(), 16);
}

TEST(Stm32EncoderTimers, WrapAwareDeltaRecoversEveryCountOverManyWraps) {
  Stm32TimerModel m;
  Stm32EncoderTimers enc(m);
  enc.init();
  // 2000 readings, the left wheel +30001 edges between two (just under the 32767 a 16-bit delta
  // can tell), the right one alternating -32767 and +1000: 60002000 counts (915 wraps of the
  // 65536-count counter) and -31767000 (485 wraps backward).
  std::int64_t left = 0, right = 0, sum_l = 0, sum_r = 0;
  odo::EncoderSample prev = enc.read(0);
  for (int i = 0; i < 2000; ++i) {
    const std::int64_t dl = 30001, dr = i % 2 == 0 ? -32767 : 1000;
    m.edges(0, dl);
    m.edges(1, dr);
    left += dl;
    right += dr;
    const odo::EncoderSample s = enc.read(i + 1);
    sum_l += odo::wrap_delta(prev.left, s.left, enc.counter_bits());
    sum_r += odo::wrap_delta(prev.right, s.right, enc.counter_bits());
    prev = s;
  }
  EXPECT_EQ(sum_l, left);
  EXPECT_EQ(sum_r, right);
}

// Two wheels per side (Stm32SideTimers): TIM3 and TIM5 left, TIM4 and TIM8 right, each wheel
// wrapped on its own and the side's count the mean of its wheels (SideCombiner's default).
TEST(Stm32SideTimers, FourTimersCountedAndEachSideTheMeanOfItsWheels) {
  Stm32TimerModel m;
  auto made = odo::board::Stm32SideTimers::create(m, odo::SideWheelsConfig{});
  ASSERT_TRUE(made);
  odo::board::Stm32SideTimers enc = std::move(*made);
  enc.init();
  for (int unit = 0; unit < 4; ++unit) EXPECT_TRUE(m.counting(unit)) << unit;
  EXPECT_EQ(m.unknown_writes(), 0);
  EXPECT_EQ(m.read(Stm32TimerModel::kTim8 + Stm32TimerModel::kSmcr), 3u);
  EXPECT_EQ(m.read(Stm32TimerModel::kTim5 + Stm32TimerModel::kArr), 0xFFFFu);
  enc.read(0);  // the reference reading of every wheel
  // 300 reads; between two the left wheels move +20000 and +20004 counts (TIM3, TIM5), the
  // right ones -1000 and -998 (TIM4, TIM8): 6000000 and 6001200 counts left (91 wraps of the
  // 16-bit counters), -300000 and -299400 right. Each side's count is the mean of its wheels'
  // travels: (6000000 + 6001200) / 2 = 6000600 and (-300000 - 299400) / 2 = -299700.
  odo::EncoderSample s;
  for (int i = 0; i < 300; ++i) {
    m.edges(0, 20000);
    m.edges(2, 20004);
    m.edges(1, -1000);
    m.edges(3, -998);
    s = enc.read(i + 1);
  }
  EXPECT_EQ(s.left, 6000600);
  EXPECT_EQ(s.right, -299700);
  EXPECT_EQ(s.flags & (odo::kEncoderSlipLeft | odo::kEncoderSlipRight), 0u);
  // The readings the serial counts records carry: the counters as the registers hold them.
  EXPECT_EQ(enc.readings()[0].counts[0], 6000000 % 65536);
  EXPECT_EQ(enc.readings()[0].counts[1], 6001200 % 65536);
  EXPECT_EQ(enc.readings()[1].counts[0], 65536 - 300000 % 65536);
  EXPECT_EQ(enc.readings()[1].counts[1], 65536 - 299400 % 65536);
  EXPECT_EQ(enc.counter_bits(), 64);
}

TEST(Stm32SideTimers, ACombinationOutOfRangeIsRefused) {
  Stm32TimerModel m;
  odo::SideWheelsConfig c;
  c.slip_counts = 0.0;  // the threshold's absolute part must be > 0 (side_wheels_range)
  EXPECT_FALSE(odo::board::Stm32SideTimers::create(m, c));
  EXPECT_FALSE(odo::check_side_wheels(c));  // the same verdict as the checked create()
}

}  // namespace
