// The real-time set-up and the systemd notifier against the real kernel of the test machine.
#include <gtest/gtest.h>

#include <pthread.h>
#include <sched.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>
#include <limits>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <thread>
#include <vector>

#include "odo/drivers/realtime.hpp"
#include "odo/firmware/watchdog.hpp"

namespace odo {
namespace {

using drivers::RtOutcome;

TEST(Realtime, NothingRequestedIsReportedOff) {
  const auto items = drivers::apply_realtime({});
  ASSERT_EQ(items.size(), 5u);
  for (const auto& it : items) {
    EXPECT_EQ(it.outcome, RtOutcome::kOff) << it.what;
    EXPECT_NE(it.detail.find("off"), std::string::npos) << it.detail;
  }
}

TEST(Realtime, MissingCpuFailsWithTheReasonAndStackIsTouched) {
  drivers::RealtimeRequest r;
  r.cpu = 1000;
  r.prefault_stack = 128 * 1024;
  const auto items = drivers::apply_realtime(r);
  EXPECT_EQ(items[2].outcome, RtOutcome::kFailed);
  EXPECT_NE(items[2].detail.find("CPU 1000 is not available"), std::string::npos)
      << items[2].detail;
  EXPECT_EQ(items[3].outcome, RtOutcome::kApplied);
  drivers::RealtimeRequest huge;
  // Far beyond any stack limit, on 32-bit targets too (armhf: size_t is 32 bits, so the former
  // 1 << 40 was undefined and became 0, "off"): refused, no crash.
  huge.prefault_stack = std::numeric_limits<std::size_t>::max() / 2;
  EXPECT_EQ(drivers::apply_realtime(huge)[3].outcome, RtOutcome::kFailed);
}

// read_cpu_latency: the kernel's current PM QoS CPU latency target [us] (the smallest request
// held by any process), or -1 when the device cannot be read.
int read_cpu_latency() {
  FILE* f = std::fopen("/dev/cpu_dma_latency", "rb");
  if (f == nullptr) return -1;
  std::int32_t v = -1;
  const bool ok = std::fread(&v, sizeof v, 1, f) == 1;
  std::fclose(f);
  return ok ? v : -1;
}

TEST(Realtime, CpuLatencyRequestIsHeldOrReportedNotPermitted) {
  drivers::RealtimeRequest r;
  r.cpu_latency_us = 0;
  const drivers::RealtimeItem item = drivers::apply_realtime(r)[4];
  EXPECT_NE(item.what.find("PM QoS) 0 us"), std::string::npos) << item.what;
  if (item.outcome == RtOutcome::kApplied) {
    // Held after apply_realtime returned: the descriptor stays open for the process, and no
    // request can be below 0, so the kernel's target is exactly 0 now.
    EXPECT_EQ(read_cpu_latency(), 0);
    // A second request from this process replaces the first (one descriptor per process).
    EXPECT_EQ(drivers::apply_realtime(r)[4].outcome, RtOutcome::kApplied);
  } else {
    // Not root, or a kernel without PM QoS: said with the device's name, and the reason.
    EXPECT_NE(item.detail.find("/dev/cpu_dma_latency"), std::string::npos) << item.detail;
    EXPECT_NE(item.outcome, RtOutcome::kOff);
  }
}

TEST(Realtime, FifoIsAppliedOrReportedNotPermitted) {
  // On a thread of its own so the test process keeps its policy.
  drivers::RealtimeItem item;
  int policy = -1;
  std::thread t([&] {
    drivers::RealtimeRequest r;
    r.fifo_priority = 10;
    r.cpu = 0;
    item = drivers::apply_realtime(r)[0];
    sched_param sp{};
    pthread_getschedparam(pthread_self(), &policy, &sp);
  });
  t.join();
  if (item.outcome == RtOutcome::kApplied) {
    EXPECT_EQ(policy, SCHED_FIFO);
  } else {
    // Without CAP_SYS_NICE: said clearly, and the thread kept its normal policy.
    EXPECT_EQ(item.outcome, RtOutcome::kNotPermitted);
    EXPECT_NE(item.detail.find("CAP_SYS_NICE"), std::string::npos) << item.detail;
    EXPECT_EQ(policy, SCHED_OTHER);
  }
}

// A datagram socket in the abstract namespace standing in for systemd's notify socket.
class NotifySocket {
 public:
  NotifySocket() : name_("@odo-test-notify-" + std::to_string(::getpid())) {
    fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_un sa{};
    sa.sun_family = AF_UNIX;
    std::memcpy(sa.sun_path + 1, name_.data() + 1, name_.size() - 1);
    bound_ = ::bind(fd_, reinterpret_cast<sockaddr*>(&sa),
                    static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + name_.size())) == 0;
    timeval tv{0, 100'000};
    setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof tv);
  }
  ~NotifySocket() { ::close(fd_); }
  bool bound() const { return bound_; }
  const std::string& name() const { return name_; }
  // receive_for: every message arriving within `ms` milliseconds.
  std::vector<std::string> receive_for(int ms) {
    std::vector<std::string> out;
    const auto end = std::chrono::steady_clock::now() + std::chrono::milliseconds(ms);
    char buf[256];
    while (std::chrono::steady_clock::now() < end) {
      const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
      if (n > 0) out.emplace_back(buf, static_cast<std::size_t>(n));
    }
    return out;
  }

 private:
  std::string name_;
  int fd_ = -1;
  bool bound_ = false;
};

int count(const std::vector<std::string>& msgs, const std::string& what) {
  int n = 0;
  for (const auto& m : msgs) n += m.find(what) != std::string::npos;
  return n;
}

TEST(Watchdog, PingsOnlyWhileTheLoopAdvancesThenStopping) {
  NotifySocket sock;
  ASSERT_TRUE(sock.bound());
  std::atomic<std::uint64_t> ticks{0};
  std::atomic<bool> run{true}, stall{false};
  // A stand-in loop: its tick counter advances every millisecond until told to stall.
  std::thread loop([&] {
    while (run) {
      if (!stall) ++ticks;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
  });
  auto wd = fw::LoopWatchdog::to_socket(sock.name(), 100'000'000, [&] { return ticks.load(); });
  ASSERT_TRUE(wd->enabled());
  wd->start();
  // 100 ms watchdog: a ping every 50 ms, so about 8 in 400 ms, READY=1 first.
  const auto alive = sock.receive_for(400);
  ASSERT_FALSE(alive.empty());
  EXPECT_EQ(alive.front().rfind("READY=1", 0), 0u) << alive.front();
  EXPECT_GE(count(alive, "WATCHDOG=1"), 5);
  stall = true;
  // The first check after the stall may still see progress and ping: wait for the check that
  // saw none (not a fixed 60 ms: under qemu-user the watchdog thread can wake much later).
  for (int i = 0; i < 5000 && wd->stalls() == 0; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  ASSERT_GE(wd->stalls(), 1u);
  const auto drained = sock.receive_for(10);
  const auto stalled = sock.receive_for(400);
  EXPECT_EQ(count(stalled, "WATCHDOG=1"), 0);  // the stuck loop gets no more pings
  // Said once per stall, in whichever window it arrived.
  EXPECT_EQ(count(drained, "STATUS=loop stalled") + count(stalled, "STATUS=loop stalled"), 1);
  EXPECT_GE(wd->stalls(), 5u);
  stall = false;
  const auto again = sock.receive_for(300);
  EXPECT_GE(count(again, "WATCHDOG=1"), 3);
  wd->stop();
  EXPECT_EQ(count(sock.receive_for(100), "STOPPING=1"), 1);
  run = false;
  loop.join();
}

TEST(Watchdog, DisabledWithoutNotifySocket) {
  ::unsetenv("NOTIFY_SOCKET");
  auto wd = fw::LoopWatchdog::from_environment([] { return std::uint64_t{1}; });
  EXPECT_FALSE(wd->enabled());
  wd->start();  // no thread, nothing sent
  wd->stop();
  EXPECT_EQ(wd->pings(), 0u);
}

}  // namespace
}  // namespace odo
