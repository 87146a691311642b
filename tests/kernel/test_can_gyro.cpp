// Kernel tier (issue 16, CAN gyro backend): CanGyroSource on a SocketCanBus bound to a vcan
// interface in the VM harness, fed by can-utils (cansend, cangen: an independent sender, not our
// code). Checks the decoded rates for the configured scale, sign, byte order and id length, that
// the kernel filter keeps foreign ids and remote requests away from user space, that the stamps
// are monotonic and inside the read window, and the stale detection of a stopped sender.
#include <gtest/gtest.h>
#include <sched.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "can_env.hpp"
#include "kernel_env.hpp"
#include "odo/drivers/can_gyro.hpp"
#include "odo/drivers/monotonic_clock.hpp"
#include "odo/drivers/socketcan_bus.hpp"

namespace odo::test {
namespace {

using drivers::CanCountLayout;
using drivers::CanGyroConfig;
using drivers::CanGyroSource;
using drivers::SocketCanBus;

constexpr TimeNs kMs = 1'000'000;
constexpr TimeNs kS = 1'000'000'000;
// 2^-12 rad/s per LSB: exact in double, so are the rates below (v / 4096).
const double kScale = std::ldexp(1.0, -12);

#define ODO_REQUIRE_ROOT()                                                                   \
  do {                                                                                       \
    if (::geteuid() != 0) GTEST_SKIP() << "needs root to create a vcan interface (ip link)"; \
  } while (0)

// Rig: a SocketCanBus with an exact kernel filter for the gyro's id and the gyro on it.
struct Rig {
  std::unique_ptr<SocketCanBus> bus;
  std::optional<CanGyroSource> gyro;
  drivers::MonotonicClock clock;
  bool open(const std::string& ifname, const CanGyroConfig& c) {
    drivers::SocketCanOptions o;
    o.interface = ifname;
    const CanCountLayout& l = c.field;
    o.filters.push_back({l.id, l.extended ? 0x1FFFFFFFu : 0x7FFu, l.extended});
    auto b = SocketCanBus::open(o);
    if (!b) {
      ADD_FAILURE() << b.error().message;
      return false;
    }
    bus = std::move(b).value();
    auto g = CanGyroSource::create(*bus, c);
    if (!g) {
      ADD_FAILURE() << g.error().message;
      return false;
    }
    gyro.emplace(std::move(g).value());
    return true;
  }
  // next_sample: reads every 1 ms until a read takes a sample (at most 10 s: a process start
  // under TCG is slow); `after` is the clock right after that read.
  GyroSample next_sample(TimeNs& after) {
    GyroSample s;
    for (int i = 0; i < 10'000; ++i) {
      s = gyro->read(clock.now());
      after = clock.now();
      if (s.samples > 0) return s;
      clock.sleep_until(clock.now() + kMs);
    }
    ADD_FAILURE() << "no frame reached the gyro in 10 s";
    return s;
  }
  // settle: reads for `ms` at 1 ms steps; returns the number of samples taken.
  std::uint64_t settle(int ms) {
    std::uint64_t n = 0;
    for (int i = 0; i < ms; ++i) {
      n += gyro->read(clock.now()).samples;
      clock.sleep_until(clock.now() + kMs);
    }
    return n;
  }
};

// Sent: one frame of ours (cansend's data hex) and the rate it must decode to.
struct Sent {
  std::string hex;
  double rate;  // [rad/s]
  bool saturated;
};

// expect_rates: sends each frame of ours with cansend, between foreign frames sent by the same
// command (`foreign_before` / `foreign_after`: cansend commands), and checks each read.
void expect_rates(Rig& r, const std::string& ifname, const std::string& our_id,
                  const std::vector<Sent>& sent, const std::string& foreign_before,
                  const std::string& foreign_after) {
  TimeNs prev_stamp = 0;
  for (const Sent& x : sent) {
    const TimeNs t0 = r.clock.now();
    ASSERT_EQ(run(foreign_before + " && cansend " + ifname + " " + our_id + "#" + x.hex + " && " +
                  foreign_after),
              0);
    TimeNs after = 0;
    const GyroSample s = r.next_sample(after);
    EXPECT_EQ(s.samples, 1u) << x.hex;
    EXPECT_EQ(s.rate_z, x.rate) << x.hex;
    EXPECT_EQ(s.flags, x.saturated ? static_cast<std::uint32_t>(kGyroSaturated) : 0u) << x.hex;
    // Receive stamps: after the clock read before cansend, not after the read, increasing.
    EXPECT_GE(s.stamp, t0) << x.hex;
    EXPECT_LE(s.stamp, after) << x.hex;
    EXPECT_GT(s.stamp, prev_stamp) << x.hex;
    prev_stamp = s.stamp;
  }
}

CanGyroConfig base_config() {
  CanGyroConfig c;
  c.scale = kScale;
  // The decoding tests read single frames; under emulation on a loaded host a read loop can be
  // late by far more than 50 ms. Staleness has its own test; here it must not interfere.
  c.stale_timeout = 10 * kS;
  return c;
}

// 11-bit id 0x1A0, int16 big endian at byte 2, device mounted upside down (sign -1).
TEST(CanGyroKernel, SignedBigEndianRatesFromCansendForeignIdsFilteredByTheKernel) {
  ODO_REQUIRE_VM();
  ODO_REQUIRE_ROOT();
  Vcan v("vcgy0");
  ASSERT_TRUE(v.ok);
  CanGyroConfig c = base_config();
  c.field = CanCountLayout{0x1A0, false, 2, 16, true, true};
  c.sign = -1;
  Rig r;
  ASSERT_TRUE(r.open(v.name, c));
  // Before the first frame (within stale_timeout of the first read): starting, not an event.
  const GyroSample before = r.gyro->read(r.clock.now());
  EXPECT_EQ(before.flags, static_cast<std::uint32_t>(kGyroStarting));
  EXPECT_EQ(before.counters.stale_events, 0u);
  // Bytes 2..3 big endian, v / 4096, negated:
  const std::vector<Sent> sent{
      {"AAAA0C00AAAAAAAA", -0.75, false},     // 0x0C00 = 3072: 0.75 on the device -> -0.75
      {"0000F4000000", 0.75, false},          // 0xF400 = -3072 (DLC 6)
      {"01028000", 8.0, true},                // 0x8000 = -32768: -8 -> +8, the field's low end
      {"0102E000", 2.0, false},               // 0xE000 = -8192: -2 -> +2
      {"00007FFF", -32767.0 / 4096.0, true},  // 0x7FFF = 32767, the high end
  };
  // Around each: a neighbouring 11-bit id, our number as a 29-bit id, a remote request of our
  // id, and 0x7FF; the kernel filter (id, 11-bit, no RTR) passes none of them.
  expect_rates(r, v.name, "1A0", sent,
               "cansend vcgy0 1A1#00000C00 && cansend vcgy0 000001A0#00000C00",
               "cansend vcgy0 1A0#R && cansend vcgy0 7FF#00007FFF");
  EXPECT_EQ(r.settle(50), 0u);  // nothing else arrives
  // Exactly our five frames reached user space.
  EXPECT_EQ(r.bus->counters().received, 5u);
  EXPECT_EQ(r.gyro->stats().frames, 5u);
  EXPECT_EQ(r.gyro->stats().foreign, 0u);
  EXPECT_EQ(r.gyro->stats().remote, 0u);
  const GyroSample s = r.gyro->read(r.clock.now());
  EXPECT_EQ(s.counters.samples, 5u);
  EXPECT_EQ(s.counters.saturated, 2u);
  EXPECT_EQ(s.counters.invalid, 0u);
  EXPECT_EQ(s.counters.stale_events, 0u);
}

// J1939-style: 29-bit id 0x18FF0A10, uint16 little endian at byte 0, offset -32000 LSB
// (-32000 / 4096 = -7.8125 rad/s), sign +1.
TEST(CanGyroKernel, UnsignedLittleEndianExtendedIdWithOffset) {
  ODO_REQUIRE_VM();
  ODO_REQUIRE_ROOT();
  Vcan v("vcgy1");
  ASSERT_TRUE(v.ok);
  CanGyroConfig c = base_config();
  c.field = CanCountLayout{0x18FF0A10, true, 0, 16, false, false};
  c.offset = -32000.0 * kScale;
  Rig r;
  ASSERT_TRUE(r.open(v.name, c));
  // (v - 32000) / 4096, v little endian at bytes 0..1:
  const std::vector<Sent> sent{
      {"007D", 0.0, false},              // 0x7D00 = 32000: at rest
      {"008DFFFFFFFFFFFF", 1.0, false},  // 0x8D00 = 36096: +4096 LSB
      {"0075", -0.5, false},             // 0x7500 = 29952: -2048 LSB
      {"0000", -7.8125, true},           // 0: the low end
      {"FFFF", 33535.0 / 4096.0, true},  // 65535: the high end
  };
  // Neighbouring 29-bit ids, an 11-bit id, and a remote request of our id.
  expect_rates(r, v.name, "18FF0A10", sent, "cansend vcgy1 18FF0A11#008D && cansend vcgy1 210#008D",
               "cansend vcgy1 18FF0A00#0000 && cansend vcgy1 18FF0A10#R");
  EXPECT_EQ(r.settle(50), 0u);
  EXPECT_EQ(r.bus->counters().received, 5u);
  EXPECT_EQ(r.gyro->stats().foreign, 0u);
  EXPECT_EQ(r.gyro->stats().remote, 0u);
  EXPECT_EQ(r.gyro->read(r.clock.now()).counters.saturated, 2u);
}

// A cyclic sender (cangen, every 5 ms) beside a foreign one; the loop reads at 100 Hz. Once our
// sender is killed the gyro is stale at the first read more than stale_timeout after the last
// frame's receive stamp: within (timeout, timeout + one period] plus how late that read woke.
TEST(CanGyroKernel, StoppedSenderIsStaleWithinTheTimeoutPlusOnePeriod) {
  ODO_REQUIRE_VM();
  ODO_REQUIRE_ROOT();
  Vcan v("vcgy2");
  ASSERT_TRUE(v.ok);
  CanGyroConfig c = base_config();
  c.field = CanCountLayout{0x1A0, false, 0, 16, true, true};  // int16 BE at byte 0, DLC 2
  c.sign = -1;
  c.stale_timeout = 100 * kMs;
  Rig r;
  ASSERT_TRUE(r.open(v.name, c));
  const FifoScope fifo;  // the senders started below run at normal priority
  // Ours: 0x0C00 = 3072 -> 0.75 rad/s on the device, -0.75 about z. Foreign: 0x1A1, same rate.
  Background ours("cangen vcgy2 -g 5 -I 1A0 -L 2 -D 0C00");
  Background foreign("cangen vcgy2 -g 5 -I 1A1 -L 2 -D 0C00");
  ASSERT_GT(ours.pid, 0);
  ASSERT_GT(foreign.pid, 0);
  const TimeNs period = 10 * kMs;
  TimeNs t = r.clock.now();
  int waited = 0;
  for (; waited < 1000; ++waited) {  // the sender's start: at most 10 s
    t += period;
    r.clock.sleep_until(t);
    if (r.gyro->read(r.clock.now()).flags == 0) break;
  }
  ASSERT_LT(waited, 1000) << "the sender's frames never made the gyro fresh in 10 s";
  // A sender slower to start than stale_timeout (under emulation) made the gyro stale once
  // before its first frame: the stop below is the next event.
  const std::uint64_t events = r.gyro->read(r.clock.now()).counters.stale_events;
  EXPECT_LE(events, 1u);
  // 0.5 s fresh at every tick, the rate as sent, stamps increasing and never after the read.
  TimeNs prev_stamp = 0;
  for (int i = 0; i < 50; ++i) {
    t += period;
    r.clock.sleep_until(t);
    const GyroSample s = r.gyro->read(r.clock.now());
    EXPECT_EQ(s.flags, 0u) << "tick " << i;
    EXPECT_EQ(s.rate_z, -0.75) << "tick " << i;
    EXPECT_GE(s.stamp, prev_stamp) << "tick " << i;
    EXPECT_LE(s.stamp, r.clock.now()) << "tick " << i;
    prev_stamp = s.stamp;
  }
  ours.stop();
  const TimeNs stopped = r.clock.now();
  TimeNs seen = -1, late = 0, max_late = 0, last_frame = 0;
  for (int i = 0; i < 100 && seen < 0; ++i) {
    t += period;
    r.clock.sleep_until(t);
    const TimeNs now = r.clock.now();
    max_late = std::max(max_late, now - t);
    const GyroSample s = r.gyro->read(now);
    if (s.flags & kGyroStale) {
      seen = now;
      last_frame = s.stamp;  // the newest frame's receive stamp
      late = now - t;        // how late this tick woke (emulator, host load)
    }
  }
  ASSERT_GT(seen, 0) << "never flagged stale";
  const double from_last = to_seconds(seen - last_frame);
  const double from_kill = to_seconds(seen - stopped);
  std::printf(
      "gyro stale detection (%s loop): %.1f ms after the last frame, %.1f ms after the "
      "sender was killed (timeout 100 ms, period 10 ms, tick woke %.2f ms late)\n",
      fifo.on ? "SCHED_FIFO" : "SCHED_OTHER", from_last * 1e3, from_kill * 1e3,
      to_seconds(late) * 1e3);
  RecordProperty("gyro_stale_after_last_frame_ms", std::to_string(from_last * 1e3));
  EXPECT_GT(from_last, 0.100);
  EXPECT_LE(from_last, 0.100 + 0.010 + to_seconds(late));
  // The last frame was taken at the latest by the first read after the kill (one period, plus
  // its lateness, plus 1 ms for the reads themselves): a few reads after the timeout.
  EXPECT_LE(from_kill, 0.100 + 2 * 0.010 + 2 * to_seconds(max_late) + 0.001);
  // Stays stale with one event for the stop; the foreign sender (still running) never reached
  // user space.
  for (int i = 0; i < 5; ++i) {
    t += period;
    r.clock.sleep_until(t);
    const GyroSample s = r.gyro->read(r.clock.now());
    EXPECT_EQ(s.flags, static_cast<std::uint32_t>(kGyroStale));
    EXPECT_EQ(s.counters.stale_events, events + 1);
  }
  EXPECT_EQ(r.gyro->stats().foreign, 0u);
}

}  // namespace
}  // namespace odo::test
