// Kernel tier (issue 5, backend 3): CanEncoderSource on a SocketCanBus bound to a vcan
// interface in the VM harness, fed by can-utils (cansend, cangen: an independent sender, not our
// encoder). Checks the exact counts of both protocols, that the kernel filter keeps foreign ids
// away from user space, stale detection latency of a stopped sender, and a receive flood.
#include <gtest/gtest.h>
#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <sched.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <string>

#include "can_env.hpp"
#include "kernel_env.hpp"
#include "odo/drivers/can_encoder.hpp"
#include "odo/drivers/monotonic_clock.hpp"
#include "odo/drivers/socketcan_bus.hpp"
#include "odo/odometry/count_delta.hpp"

namespace odo::test {
namespace {

using drivers::CanCountLayout;
using drivers::CanEncoderConfig;
using drivers::CanEncoderSource;
using drivers::SocketCanBus;

constexpr TimeNs kMs = 1'000'000;
constexpr TimeNs kS = 1'000'000'000;

// Rig: a SocketCanBus with exact kernel filters for the two wheels (as the firmware's
// make_can_socketcan_backend installs them) and the encoder on it.
struct Rig {
  std::unique_ptr<SocketCanBus> bus;
  std::optional<CanEncoderSource> enc;
  drivers::MonotonicClock clock;
  bool open(const std::string& ifname, const CanEncoderConfig& c) {
    drivers::SocketCanOptions o;
    o.interface = ifname;
    for (int i = 0; i < drivers::can_wheel_count(c); ++i) {
      const CanCountLayout& l = drivers::can_wheel_layout(c, i);
      o.filters.push_back({l.id, l.extended ? 0x1FFFFFFFu : 0x7FFu, l.extended});
    }
    auto b = SocketCanBus::open(o);
    if (!b) {
      ADD_FAILURE() << b.error().message;
      return false;
    }
    bus = std::move(b).value();
    auto e = CanEncoderSource::create(*bus, c);
    if (!e) {
      ADD_FAILURE() << e.error().message;
      return false;
    }
    enc.emplace(std::move(e).value());
    return true;
  }
  // settle: reads for `ms` at 1 ms steps so that frames in flight are taken; returns the last.
  EncoderSample settle(int ms) {
    EncoderSample s;
    for (int i = 0; i < ms; ++i) {
      s = enc->read(clock.now());
      clock.sleep_until(clock.now() + kMs);
    }
    return s;
  }
};

CanEncoderConfig odrive_config() {
  CanEncoderConfig c;
  c.left = drivers::odrive_count_layout(0);   // 0x00A
  c.right = drivers::odrive_count_layout(1);  // 0x02A
  // The decoding tests send single frames and read them back after settle(); under emulation on a
  // loaded host those 50 one-millisecond sleeps have taken over 100 ms, and a frame that old is
  // (rightly) stale. Staleness has its own test with its own timeout; here it must not interfere.
  c.timeout = 10 * kS;
  c.max_counts_per_s = 1e9;  // these hand-made steps are not physical motion
  return c;
}

TEST(CanEncoderKernel, OdriveCountsFromCansendAndForeignIdsFilteredByTheKernel) {
  ODO_REQUIRE_VM();
  Vcan v("vcce0");
  ASSERT_TRUE(v.ok);
  Rig r;
  ASSERT_TRUE(r.open(v.name, odrive_config()));
  // Read before the first frames: the wheels are 0 and stale.
  const EncoderSample before = r.enc->read(r.clock.now());
  EXPECT_EQ(before.flags, kEncoderStaleLeft | kEncoderStaleRight);
  EXPECT_EQ(before.left, 0);
  // Reference frames: left shadow 0x76543210 (bytes 10 32 54 76, little endian), count in CPR
  // 0xFFFFFFFF (ignored); right shadow 0xFFFFFFFE = -2.
  ASSERT_EQ(run("cansend vcce0 00A#10325476FFFFFFFF && cansend vcce0 02A#FEFFFFFF00000000"), 0);
  const EncoderSample a = r.settle(50);
  EXPECT_EQ(a.flags, 0u);
  EXPECT_EQ(a.left, 0x76543210);  // the controller's counts as sent
  EXPECT_EQ(a.right, -2);
  // Foreign frames: other ids, our id as a 29-bit frame, a remote request of our id.
  ASSERT_EQ(run("cansend vcce0 0AB#1122334455667788 && cansend vcce0 0000000A#0100000000000000"
                " && cansend vcce0 04A#0100000000000000 && cansend vcce0 00A#R"),
            0);
  // Counts: left 0x76544210 = 0x76543210 + 0x1000 (+4096); right 0x00000005 = -2 + 7. Both
  // wheels are reported at one instant (issue 39: the older newest frame, the other wheel
  // interpolated): the left controller repeats its count after the right's frame, so that the
  // instant is the right's frame and both counts are exact.
  ASSERT_EQ(run("cansend vcce0 00A#1042547600000000 && cansend vcce0 02A#0500000005000000"
                " && cansend vcce0 00A#1042547600000000"),
            0);
  const EncoderSample s = r.settle(50);
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(s.left, 0x76544210);
  EXPECT_EQ(s.right, 5);
  EXPECT_EQ(wrap_delta(a.left, s.left, 32), 4096);
  EXPECT_EQ(wrap_delta(a.right, s.right, 32), 7);
  // Exactly our five data frames reached user space: the kernel dropped the other four.
  EXPECT_EQ(r.bus->counters().received, 5u);
  EXPECT_EQ(r.enc->stats().foreign, 0u);
  EXPECT_EQ(r.enc->stats().decoded, 5u);
}

TEST(CanEncoderKernel, GenericLayoutBothWheelsInOneExtendedBigEndianFrame) {
  ODO_REQUIRE_VM();
  Vcan v("vcce1");
  ASSERT_TRUE(v.ok);
  CanEncoderConfig c = odrive_config();
  c.left = CanCountLayout{0x18FF0010, true, 0, 32, false, true};  // unsigned, big endian
  c.right = CanCountLayout{0x18FF0010, true, 4, 32, false, true};
  Rig r;
  ASSERT_TRUE(r.open(v.name, c));
  // First frame before any read: left 0xFFFFFFF0, right 0x00000010, reported as the
  // controller's 32-bit counters hold them, sign-extended for the loop's wrap rule:
  // 0xFFFFFFF0 = 4294967280 - 2^32 = -16, and 16.
  ASSERT_EQ(run("cansend vcce1 18FF0010#FFFFFFF000000010"), 0);
  const EncoderSample a = r.settle(50);
  EXPECT_EQ(a.flags, 0u);
  EXPECT_EQ(a.left, -16);
  EXPECT_EQ(a.right, 16);
  // left 0xFFFFFFF0 -> 0x00000020 wraps: 0x20 + 2^32 - 0xFFFFFFF0 = 32 + 16 = +48;
  // right 0x10 -> 0x08 = -8; 0x18FF0011 (one id off) is dropped by the kernel.
  ASSERT_EQ(run("cansend vcce1 18FF0011#0000000000000000 && "
                "cansend vcce1 18FF0010#0000002000000008"),
            0);
  const EncoderSample s = r.settle(50);
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(s.left, 32);
  EXPECT_EQ(s.right, 8);
  EXPECT_EQ(wrap_delta(a.left, s.left, 32), 48);
  EXPECT_EQ(wrap_delta(a.right, s.right, 32), -8);
  EXPECT_EQ(r.bus->counters().received, 2u);
}

// RawSender: a raw CAN socket on `ifname` that sends ODrive Get_Encoder_Count frames at once
// (in-process: the send time is known to within a system call, unlike cansend's process start).
struct RawSender {
  int fd = -1;
  explicit RawSender(const std::string& ifname) {
    fd = ::socket(PF_CAN, SOCK_RAW, CAN_RAW);
    sockaddr_can a{};
    a.can_family = AF_CAN;
    a.can_ifindex = static_cast<int>(if_nametoindex(ifname.c_str()));
    if (fd >= 0 && ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
      ::close(fd);
      fd = -1;
    }
  }
  ~RawSender() {
    if (fd >= 0) ::close(fd);
  }
  RawSender(const RawSender&) = delete;
  RawSender& operator=(const RawSender&) = delete;
  bool send(std::uint32_t node, std::int32_t shadow) const {
    can_frame f{};
    f.can_id = node << 5 | 0x00A;
    f.can_dlc = 8;
    const auto u = static_cast<std::uint32_t>(shadow);
    for (int i = 0; i < 4; ++i) f.data[i] = static_cast<std::uint8_t>(u >> (8 * i));
    return ::write(fd, &f, sizeof f) == static_cast<ssize_t>(sizeof f);
  }
};

// Issue 39, "done means": the jump check on the frames' own (kernel) stamps. Frame A of the left
// wheel arrives and waits 15 ms in the socket (the loop is late); frame B arrives 20 ms after A
// and is read at once. Limit at max 100 000 counts/s: 100 000 * (20 ms + 5 ms slack) + 1 = 2501
// counts (more if B was sent later). Measured from the reads (A read 15 ms late) it would be
// 100 000 * (5 + 5) ms + 1 = 1001: the 2400 counts of the first case, real motion at 96 % of
// the physical limit, were dropped before. The second case's 3000 counts are over the limit
// as long as the kernel put B less than 25 ms after A (checked on the stamps; a case the VM
// made slower is repeated, at most 5 times).
TEST(CanEncoderKernel, JumpCheckOnTheFramesKernelStampsLateThenEarly) {
  ODO_REQUIRE_VM();
  Vcan v("vcce4");
  ASSERT_TRUE(v.ok);
  CanEncoderConfig c = odrive_config();
  c.max_counts_per_s = 100'000;
  RawSender tx(v.name);
  ASSERT_GE(tx.fd, 0);
  for (const std::int32_t step : {2400, 3000}) {
    bool judged = false;
    for (int attempt = 0; attempt < 5 && !judged; ++attempt) {
      Rig r;
      ASSERT_TRUE(r.open(v.name, c));
      ASSERT_TRUE(tx.send(0, 0) && tx.send(1, 0));
      r.settle(20);  // both primed; the next frame is at least 20 ms later
      ASSERT_TRUE(tx.send(0, 1000) && tx.send(1, 0));  // A: 1000 counts in >= 20 ms, plausible
      const TimeNs sent_a = r.clock.now();
      r.clock.sleep_until(sent_a + 15 * kMs);  // the loop is late: A waits in the socket
      EXPECT_EQ(r.enc->read(r.clock.now()).flags, 0u);
      const TimeNs stamp_a = r.enc->last_frame(0);
      r.clock.sleep_until(sent_a + 20 * kMs);
      ASSERT_TRUE(tx.send(0, 1000 + step) && tx.send(1, 0));  // B, read at once
      const EncoderSample s = r.enc->read(r.clock.now());
      const double dt = to_seconds(r.enc->last_frame(0) - stamp_a);
      const bool over = step > 100'000 * (dt + 0.005) + 1;
      std::printf("step %d counts, frames %.3f ms apart (kernel stamps): %s, flags %u\n", step,
                  dt * 1e3, over ? "over the limit" : "within the limit", s.flags);
      EXPECT_GE(dt, 0.0199);
      EXPECT_EQ(s.flags, over ? static_cast<std::uint32_t>(kEncoderImplausibleJump) : 0u);
      EXPECT_EQ(s.left_rejected, over ? step : 0);
      EXPECT_EQ(r.enc->stats().decoded, 6u);
      judged = step == 2400 || over;  // the 3000-count case must be judged over the limit
    }
    EXPECT_TRUE(judged) << step;
  }
}

TEST(CanEncoderKernel, StoppedSenderIsStaleWithinTheTimeoutPlusOnePeriod) {
  ODO_REQUIRE_VM();
  Vcan v("vcce2");
  ASSERT_TRUE(v.ok);
  CanEncoderConfig c = odrive_config();
  c.timeout = 100 * kMs;
  Rig r;
  ASSERT_TRUE(r.open(v.name, c));
  const FifoScope fifo;  // the senders started below run at normal priority
  // Two independent senders, one frame every 10 ms each, constant counts (a wheel at rest).
  Background left("cangen vcce2 -I 00A -L 8 -D 0100000000000000 -g 10");
  Background right("cangen vcce2 -I 02A -L 8 -D 0200000000000000 -g 10");
  ASSERT_GT(left.pid, 0);
  ASSERT_GT(right.pid, 0);
  // The loop: 100 Hz on absolute deadlines. It ticks until both wheels are fresh (the senders'
  // start-up is a process start each, slow and unbounded under emulation: waited for, at most
  // 10 s), then 0.5 s more in which they must stay fresh at every tick.
  const TimeNs period = 10 * kMs;
  TimeNs t = r.clock.now();
  int waited = 0;
  for (; waited < 1000; ++waited) {
    t += period;
    r.clock.sleep_until(t);
    if (r.enc->read(r.clock.now()).flags == 0) break;
  }
  ASSERT_LT(waited, 1000) << "the senders' frames never made both wheels fresh in 10 s";
  for (int i = 0; i < 50; ++i) {
    t += period;
    r.clock.sleep_until(t);
    EXPECT_EQ(r.enc->read(r.clock.now()).flags, 0u) << "tick " << i << " after both were fresh";
  }
  // Stop the left sender; tick on until the loop sees stale-left.
  left.stop();
  const TimeNs stopped = r.clock.now();
  TimeNs seen = -1, late = 0;
  for (int i = 0; i < 100 && seen < 0; ++i) {
    t += period;
    r.clock.sleep_until(t);
    const TimeNs now = r.clock.now();
    const EncoderSample s = r.enc->read(now);
    EXPECT_EQ(s.flags & kEncoderStaleRight, 0u);
    if (s.flags & kEncoderStaleLeft) {
      seen = now;
      late = now - t;  // how late this tick woke (emulator, host load)
    }
  }
  ASSERT_GT(seen, 0) << "never flagged stale";
  const double from_kill = to_seconds(seen - stopped);
  const double from_last = to_seconds(seen - r.enc->last_frame(0));
  std::printf(
      "stale detection (%s loop): %.1f ms after the left wheel's last frame, %.1f ms "
      "after the sender was killed (timeout 100 ms, period 10 ms, tick woke %.2f ms "
      "late)\n",
      fifo.on ? "SCHED_FIFO" : "SCHED_OTHER", from_last * 1e3, from_kill * 1e3,
      to_seconds(late) * 1e3);
  RecordProperty("stale_after_last_frame_ms", std::to_string(from_last * 1e3));
  // Flagged at the first tick after last frame + timeout: within (timeout, timeout + one
  // period] of the last frame, plus however late that tick woke.
  EXPECT_GT(from_last, 0.100);
  EXPECT_LE(from_last, 0.100 + 0.010 + to_seconds(late));
  EXPECT_EQ(r.enc->read(r.clock.now()).counters.stale_events, 1u);
}

// Issue 38: two ODrive axes per side (nodes 0 and 2 left, 1 and 3 right) on vcan, frames sent
// in-process on a raw socket. Each side is the mean of its wheels' travel; then node 2 falls
// silent: once its newest frame is older than the other wheels' kept frames (8 frames: 80 ms
// here, before the 200 ms timeout) it is dropped (wheel-dropped, the left side not stale) and
// node 0 alone carries the left side.
TEST(CanEncoderKernel, TwoWheelsPerSideMeanThenASilentControllerIsDropped) {
  ODO_REQUIRE_VM();
  Vcan v("vcce5");
  ASSERT_TRUE(v.ok);
  CanEncoderConfig c = odrive_config();
  c.timeout = 200 * kMs;
  c.wheels.wheels_per_side = 2;
  c.more_left[0] = drivers::odrive_count_layout(2);
  c.more_right[0] = drivers::odrive_count_layout(3);
  Rig r;
  ASSERT_TRUE(r.open(v.name, c));
  EXPECT_EQ(r.enc->counter_bits(), 64);
  RawSender tx(v.name);
  ASSERT_GE(tx.fd, 0);
  // send4: the four counts, twice: every wheel's newest two frames then hold the same count, so
  // its count at the common instant (the oldest newest frame) is exact, however the frames'
  // stamps interleave.
  auto send4 = [&](std::int32_t l0, std::int32_t l1, std::int32_t r0, std::int32_t r1) {
    for (int k = 0; k < 2; ++k)
      ASSERT_TRUE(tx.send(0, l0) && tx.send(2, l1) && tx.send(1, r0) && tx.send(3, r1));
  };
  send4(1000, 5000, -100, 300);
  EncoderSample s = r.settle(20);
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(s.left, 0);  // the combined counts start at 0 (each wheel's first frame: reference)
  EXPECT_EQ(s.right, 0);
  // Left +40 and +60: mean 50. Right -30 and -40: mean -35.
  send4(1040, 5060, -130, 260);
  s = r.settle(20);
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(s.left, 50);
  EXPECT_EQ(s.right, -35);
  // Node 2 silent; the others move every 10 ms for 40 steps (> 400 ms, twice the timeout): node 0
  // +10, nodes 1 and 3 -6 each per step. Until node 2 lags beyond node 0's 8 kept frames it holds
  // the instant at its last frame (no count moves); then it is dropped and the left side is node
  // 0's whole travel (not half of it, as a mean with a held wheel would make it).
  std::int32_t l0 = 1040, r0 = -130, r1 = 260;
  for (int i = 0; i < 40; ++i) {
    l0 += 10;
    r0 -= 6;
    r1 -= 6;
    ASSERT_TRUE(tx.send(0, l0) && tx.send(1, r0) && tx.send(3, r1));
    s = r.enc->read(r.clock.now());
    EXPECT_EQ(s.flags & (kEncoderStaleLeft | kEncoderStaleRight), 0u) << "step " << i;
    r.clock.sleep_until(r.clock.now() + 10 * kMs);
  }
  ASSERT_TRUE(tx.send(0, l0) && tx.send(1, r0) && tx.send(3, r1));
  s = r.settle(20);
  // Left: 50 + 40 * 10 = 450 (node 0 alone); right: -35 + 40 * -6 = -275 (both wheels).
  EXPECT_EQ(s.flags, kEncoderWheelDropped);
  EXPECT_EQ(s.left, 450);
  EXPECT_EQ(s.right, -275);
  EXPECT_EQ(s.counters.wheel_drops, 1u);
  EXPECT_EQ(s.counters.stale_events, 0u);
  EXPECT_EQ(r.enc->stats().foreign, 0u);
}

// rx_packets: frames the interface carried so far (the kernel's counter).
std::uint64_t rx_packets(const std::string& ifname) {
  std::uint64_t n = 0;
  std::ifstream("/sys/class/net/" + ifname + "/statistics/rx_packets") >> n;
  return n;
}

// FloodRun: one 100 Hz loop run of `ticks` reads.
struct FloodRun {
  TimeNs worst_read = 0;
  int late_ticks = 0;   // woke more than one period after the deadline
  int stale_ticks = 0;  // after the first 10 ticks
  int jump_ticks = 0;
  double seconds = 0;
};

FloodRun loop_100hz(Rig& r, int ticks) {
  FloodRun out;
  const TimeNs period = 10 * kMs;
  TimeNs t = r.clock.now();
  const TimeNs t0 = t;
  for (int i = 0; i < ticks; ++i) {
    t += period;
    r.clock.sleep_until(t);
    const TimeNs a = r.clock.now();
    if (a - t > period) ++out.late_ticks;
    const EncoderSample s = r.enc->read(a);
    out.worst_read = std::max(out.worst_read, r.clock.now() - a);
    if (i >= 10 && (s.flags & (kEncoderStaleLeft | kEncoderStaleRight)) != 0) ++out.stale_ticks;
    if ((s.flags & kEncoderImplausibleJump) != 0) ++out.jump_ticks;
  }
  out.seconds = to_seconds(r.clock.now() - t0);
  return out;
}

TEST(CanEncoderKernel, ReceiveFloodDecoderKeepsUpLoopNeverBlocks) {
  ODO_REQUIRE_VM();
  Vcan v("vcce3");
  ASSERT_TRUE(v.ok);
  CanEncoderConfig c = odrive_config();
  c.timeout = 100 * kMs;  // a wheel that the flood starves for 100 ms must show as stale here
  Rig r;
  ASSERT_TRUE(r.open(v.name, c));
  // The loop runs SCHED_FIFO, else the busy senders on the VM's single CPU would preempt it
  // and the test would measure the scheduler.
  const FifoScope fifo;
  // Phase A, 2 s: foreign traffic from two senders with a 0.2 ms gap each, about 10 000
  // frames/s in all (more than a saturated 1 Mbit/s bus carries, ~7 600) (random 29-bit ids, and
  // the 11-bit id 0x7FF with random data; random 11-bit ids would hit our own ids with random
  // counts, which are rightly flagged as jumps), and our two ids at 1 kHz each (an ODrive's
  // fastest cyclic rate). Our senders stand for separate controllers on the bus, so they run
  // SCHED_FIFO 50 (chrt) and the flood cannot starve them on the VM's single CPU.
  const std::uint64_t rx0 = rx_packets(v.name);
  Background foreign_ext("cangen vcce3 -e -g 0.2");
  Background foreign_std("cangen vcce3 -I 7FF -g 0.2");
  Background ours_l("chrt -f 50 cangen vcce3 -I 00A -L 8 -D 0100000000000000 -g 1");
  Background ours_r("chrt -f 50 cangen vcce3 -I 02A -L 8 -D 0200000000000000 -g 1");
  ASSERT_GT(foreign_ext.pid, 0);
  // Starting four processes under the flood takes a while in the emulated VM: wait (up to 3 s)
  // until both wheels are fresh, then measure.
  for (int i = 0; i < 3000 && r.enc->read(r.clock.now()).flags != 0; ++i)
    r.clock.sleep_until(r.clock.now() + kMs);
  const FloodRun a = loop_100hz(r, 200);
  foreign_ext.stop();
  foreign_std.stop();
  ours_l.stop();
  ours_r.stop();
  const std::uint64_t rx_frames = rx_packets(v.name) - rx0;
  const drivers::CanEncoderStats sa = r.enc->stats();
  std::printf(
      "flood A (%.0f frames/s on the interface, loop %s): %.0f of our frames/s "
      "decoded, foreign frames in user space %llu, worst read %.1f us, late ticks %d, "
      "stale ticks %d, jump ticks %d\n",
      static_cast<double>(rx_frames) / a.seconds, fifo.on ? "SCHED_FIFO 80" : "SCHED_OTHER",
      static_cast<double>(sa.decoded) / a.seconds, static_cast<unsigned long long>(sa.foreign),
      to_seconds(a.worst_read) * 1e6, a.late_ticks, a.stale_ticks, a.jump_ticks);
  EXPECT_EQ(sa.foreign, 0u);  // the kernel filter dropped every foreign id
  // Fresh counts on every tick despite the flood. When the whole VM stalls (the host's qemu
  // thread not scheduled: the SCHED_FIFO loop itself then wakes more than a period late), the
  // senders stall too; a stale tick is accepted only alongside such stalls.
  if (a.late_ticks == 0)
    EXPECT_EQ(a.stale_ticks, 0);
  else
    EXPECT_LE(a.stale_ticks, a.late_ticks);
  EXPECT_EQ(a.jump_ticks, 0);
  // A read is at most 64 non-blocking recv calls; under TCG emulation the kernel's softirq
  // work for the flood lands inside it too. It never takes a whole period.
  EXPECT_LT(a.worst_read, 10 * kMs);

  // Phase B, 1 s: our own ids at full rate, more than the 64 frames a read takes: reads stop
  // at the cap (the rest waits in the socket buffer), the loop keeps its period.
  Background flood_l("cangen vcce3 -I 00A -L 8 -D 0100000000000000 -g 0");
  Background flood_r("cangen vcce3 -I 02A -L 8 -D 0200000000000000 -g 0");
  const FloodRun b = loop_100hz(r, 100);
  flood_l.stop();
  flood_r.stop();
  const drivers::CanEncoderStats sb = r.enc->stats();
  std::printf(
      "flood B (our ids at full rate): %.0f frames/s decoded (cap 64 per 10 ms read = "
      "6400/s), %llu of %d reads capped, worst read %.1f us, late ticks %d\n",
      static_cast<double>(sb.frames - sa.frames) / b.seconds,
      static_cast<unsigned long long>(sb.capped_reads - sa.capped_reads), 100,
      to_seconds(b.worst_read) * 1e6, b.late_ticks);
  EXPECT_GT(sb.capped_reads, sa.capped_reads);  // the flood exceeded the cap
  EXPECT_LT(b.worst_read, 10 * kMs);
  EXPECT_EQ(b.jump_ticks, 0);
}

}  // namespace
}  // namespace odo::test
