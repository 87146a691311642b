// Kernel tier (issue 5, backend 3): CanEncoderSource on a SocketCanBus bound to a vcan
// interface in the VM harness, fed by can-utils (cansend, cangen: an independent sender, not our
// encoder). Checks the exact counts of both protocols, that the kernel filter keeps foreign ids
// away from user space, stale detection latency of a stopped sender, and a receive flood.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <string>

#include "kernel_env.hpp"
#include "odo/drivers/can_encoder.hpp"
#include "odo/drivers/monotonic_clock.hpp"
#include "odo/drivers/socketcan_bus.hpp"

namespace odo::test {
namespace {

using drivers::CanCountLayout;
using drivers::CanEncoderConfig;
using drivers::CanEncoderSource;
using drivers::SocketCanBus;

constexpr TimeNs kMs = 1'000'000;

struct Vcan {
  std::string name;
  bool ok = false;
  explicit Vcan(std::string n) : name(std::move(n)) {
    run("ip link del " + name + " 2>/dev/null");
    ok = run("ip link add dev " + name + " type vcan && ip link set " + name + " up") == 0;
  }
  ~Vcan() { run("ip link del " + name + " 2>/dev/null"); }
};

// Background: a shell command started with `&`, killed by its pid at the end.
struct Background {
  int pid = -1;
  explicit Background(const std::string& cmd) {
    const std::string file = "/tmp/odo_bg_" + std::to_string(::getpid()) + ".pid";
    if (run(cmd + " >/dev/null 2>&1 & echo $! > " + file) == 0) std::ifstream(file) >> pid;
  }
  void stop() {
    if (pid > 0) ::kill(pid, SIGKILL);
    pid = -1;
  }
  ~Background() { stop(); }
};

// Rig: a SocketCanBus with exact kernel filters for the two wheels (as the firmware's
// make_can_socketcan_backend installs them) and the encoder on it.
struct Rig {
  std::unique_ptr<SocketCanBus> bus;
  std::optional<CanEncoderSource> enc;
  drivers::MonotonicClock clock;
  bool open(const std::string& ifname, const CanEncoderConfig& c) {
    drivers::SocketCanOptions o;
    o.interface = ifname;
    for (const CanCountLayout* l : {&c.left, &c.right})
      o.filters.push_back({l->id, l->extended ? 0x1FFFFFFFu : 0x7FFu, l->extended});
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
  c.timeout = 100 * kMs;
  c.max_counts_per_s = 1e9;  // these hand-made steps are not physical motion
  return c;
}

TEST(CanEncoderKernel, OdriveCountsFromCansendAndForeignIdsFilteredByTheKernel) {
  ODO_REQUIRE_VM();
  Vcan v("vcce0");
  ASSERT_TRUE(v.ok);
  Rig r;
  ASSERT_TRUE(r.open(v.name, odrive_config()));
  EXPECT_EQ(r.enc->read(r.clock.now()).flags, kEncoderStaleLeft | kEncoderStaleRight);
  // Reference frames: left shadow 0x76543210 (bytes 10 32 54 76, little endian), count in CPR
  // 0xFFFFFFFF (ignored); right shadow 0xFFFFFFFE = -2.
  ASSERT_EQ(run("cansend vcce0 00A#10325476FFFFFFFF && cansend vcce0 02A#FEFFFFFF00000000"), 0);
  EncoderSample s = r.settle(50);
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(s.left, 0);
  EXPECT_EQ(s.right, 0);
  // Foreign frames: other ids, our id as a 29-bit frame, a remote request of our id.
  ASSERT_EQ(run("cansend vcce0 0AB#1122334455667788 && cansend vcce0 0000000A#0100000000000000"
                " && cansend vcce0 04A#0100000000000000 && cansend vcce0 00A#R"),
            0);
  // Counts: left 0x76544210 = 0x76543210 + 0x1000 (+4096); right 0x00000005 = -2 + 7.
  ASSERT_EQ(run("cansend vcce0 00A#1042547600000000 && cansend vcce0 02A#0500000005000000"), 0);
  s = r.settle(50);
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(s.left, 4096);
  EXPECT_EQ(s.right, 7);
  // Exactly our four data frames reached user space: the kernel dropped the other four.
  EXPECT_EQ(r.bus->counters().received, 4u);
  EXPECT_EQ(r.enc->stats().foreign, 0u);
  EXPECT_EQ(r.enc->stats().decoded, 4u);
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
  // Reference: left 0xFFFFFFF0, right 0x00000010.
  ASSERT_EQ(run("cansend vcce1 18FF0010#FFFFFFF000000010"), 0);
  EncoderSample s = r.settle(50);
  EXPECT_EQ(s.flags, 0u);
  // left 0xFFFFFFF0 -> 0x00000020 wraps: 0x20 + 2^32 - 0xFFFFFFF0 = 32 + 16 = +48;
  // right 0x10 -> 0x08 = -8; 0x18FF0011 (one id off) is dropped by the kernel.
  ASSERT_EQ(run("cansend vcce1 18FF0011#0000000000000000 && "
                "cansend vcce1 18FF0010#0000002000000008"),
            0);
  s = r.settle(50);
  EXPECT_EQ(s.flags, 0u);
  EXPECT_EQ(s.left, 48);
  EXPECT_EQ(s.right, -8);
  EXPECT_EQ(r.bus->counters().received, 2u);
}

TEST(CanEncoderKernel, StoppedSenderIsStaleWithinTheTimeoutPlusOnePeriod) {
  ODO_REQUIRE_VM();
  Vcan v("vcce2");
  ASSERT_TRUE(v.ok);
  CanEncoderConfig c = odrive_config();
  c.timeout = 100 * kMs;
  Rig r;
  ASSERT_TRUE(r.open(v.name, c));
  // Two independent senders, one frame every 10 ms each, constant counts (a wheel at rest).
  Background left("cangen vcce2 -I 00A -L 8 -D 0100000000000000 -g 10");
  Background right("cangen vcce2 -I 02A -L 8 -D 0200000000000000 -g 10");
  ASSERT_GT(left.pid, 0);
  ASSERT_GT(right.pid, 0);
  // The loop: 100 Hz on absolute deadlines for 1 s: after the first frames never stale.
  const TimeNs period = 10 * kMs;
  TimeNs t = r.clock.now();
  int fresh = 0, stale = 0;
  for (int i = 0; i < 100; ++i) {
    t += period;
    r.clock.sleep_until(t);
    const EncoderSample s = r.enc->read(r.clock.now());
    (s.flags == 0 ? fresh : stale)++;
    if (fresh > 0) EXPECT_EQ(s.flags, 0u) << "tick " << i;
  }
  EXPECT_GE(fresh, 90);
  // Stop the left sender; measure until the loop sees stale-left.
  left.stop();
  const TimeNs stopped = r.clock.now();
  TimeNs seen = -1;
  for (int i = 0; i < 100 && seen < 0; ++i) {
    t += period;
    r.clock.sleep_until(t);
    const TimeNs now = r.clock.now();
    const EncoderSample s = r.enc->read(now);
    EXPECT_EQ(s.flags & kEncoderStaleRight, 0u);
    if (s.flags & kEncoderStaleLeft) seen = now;
  }
  ASSERT_GT(seen, 0) << "never flagged stale";
  const double latency = to_seconds(seen - stopped);
  std::printf(
      "stale detection: %.1f ms after the sender was killed (timeout 100 ms, period 10 ms)\n",
      latency * 1e3);
  RecordProperty("stale_latency_ms", std::to_string(latency * 1e3));
  // The last frame came at most one sender gap before the kill, so stale is flagged at the
  // first tick after last frame + timeout: <= timeout + one loop period after the kill (+2 ms
  // of scheduling allowance for the VM's timer).
  EXPECT_LE(latency, 0.100 + 0.010 + 0.002);
  EXPECT_GE(latency, 0.100 - 0.010 - 0.002);  // not before the timeout minus the sender gap
  EXPECT_EQ(r.enc->read(r.clock.now()).counters.stale_events, 1u);
}

TEST(CanEncoderKernel, ReceiveFloodDecoderKeepsUpLoopNeverBlocks) {
  ODO_REQUIRE_VM();
  Vcan v("vcce3");
  ASSERT_TRUE(v.ok);
  Rig r;
  ASSERT_TRUE(r.open(v.name, odrive_config()));
  // A flood of random foreign ids (no gap) and, at full speed too, our two ids.
  Background foreign("cangen vcce3 -g 0 -x");
  Background ours_l("cangen vcce3 -I 00A -L 8 -D 0100000000000000 -g 0 -x");
  Background ours_r("cangen vcce3 -I 02A -L 8 -D 0200000000000000 -g 0 -x");
  ASSERT_GT(foreign.pid, 0);
  const TimeNs period = 10 * kMs;
  TimeNs t = r.clock.now();
  const TimeNs t0 = t;
  TimeNs worst = 0;
  int stale_after_start = 0, missed = 0;
  for (int i = 0; i < 200; ++i) {
    t += period;
    r.clock.sleep_until(t);
    const TimeNs a = r.clock.now();
    if (a - t > period) ++missed;
    const EncoderSample s = r.enc->read(a);
    const TimeNs d = r.clock.now() - a;
    worst = std::max(worst, d);
    if (i >= 10 && s.flags != 0) ++stale_after_start;
  }
  const double secs = to_seconds(r.clock.now() - t0);
  foreign.stop();
  ours_l.stop();
  ours_r.stop();
  const auto& st = r.enc->stats();
  std::printf(
      "flood: %.0f frames/s decoded by the loop (%llu frames in %.2f s, %llu reads capped "
      "at 64), foreign frames in user space %llu, worst read %.1f us, late ticks %d\n",
      static_cast<double>(st.frames) / secs, static_cast<unsigned long long>(st.frames), secs,
      static_cast<unsigned long long>(st.capped_reads), static_cast<unsigned long long>(st.foreign),
      to_seconds(worst) * 1e6, missed);
  EXPECT_EQ(st.foreign, 0u);  // the kernel filter dropped every foreign id
  EXPECT_GT(st.decoded, 200u);
  EXPECT_EQ(stale_after_start, 0);  // fresh counts every tick despite the flood
  // One read is at most 64 non-blocking recv calls: far below the 10 ms period.
  EXPECT_LT(worst, 2 * kMs);
}

}  // namespace
}  // namespace odo::test
