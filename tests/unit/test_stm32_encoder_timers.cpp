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

}  // namespace
