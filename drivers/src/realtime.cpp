#include "odo/drivers/realtime.hpp"

#include <alloca.h>
#include <fcntl.h>
#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <sys/resource.h>
#include <unistd.h>

#include <atomic>
#include <cstdint>

#include <cerrno>
#include <cstring>
#include <string>

namespace odo::drivers {
namespace {

std::string errno_text(int e) {
  return std::string(strerrorname_np(e) ? strerrorname_np(e) : "?") + ": " + std::strerror(e);
}

std::string rlimit_text(int resource) {
  rlimit l{};
  if (getrlimit(resource, &l) != 0) return "?";
  if (l.rlim_cur == RLIM_INFINITY) return "unlimited";
  return std::to_string(static_cast<unsigned long long>(l.rlim_cur));
}

RealtimeItem set_fifo(int prio) {
  RealtimeItem it{"SCHED_FIFO priority " + std::to_string(prio), RtOutcome::kOff, ""};
  if (prio <= 0) {
    it.what = "SCHED_FIFO";
    it.detail = "off (priority = 0): normal time-sharing scheduling";
    return it;
  }
  sched_param sp{};
  sp.sched_priority = prio;
  const int e = pthread_setschedparam(pthread_self(), SCHED_FIFO, &sp);
  if (e == 0) {
    it.outcome = RtOutcome::kApplied;
  } else if (e == EPERM) {
    it.outcome = RtOutcome::kNotPermitted;
    it.detail = "not permitted (" + errno_text(e) +
                "; needs CAP_SYS_NICE or RLIMIT_RTPRIO >= " + std::to_string(prio) + ", limit is " +
                rlimit_text(RLIMIT_RTPRIO) + "); the thread runs with normal scheduling";
  } else {
    it.outcome = RtOutcome::kFailed;
    it.detail = errno_text(e);
  }
  return it;
}

RealtimeItem lock_memory(bool want) {
  RealtimeItem it{"mlockall", RtOutcome::kOff, ""};
  if (!want) {
    it.detail = "off (lock_memory = false): page faults may delay ticks";
    return it;
  }
#if defined(__SANITIZE_ADDRESS__)
  // AddressSanitizer's interceptor turns mlockall into a no-op that reports success.
  it.outcome = RtOutcome::kFailed;
  it.detail = "not available in an AddressSanitizer build (its mlockall does nothing)";
  return it;
#elif defined(__SANITIZE_THREAD__)
  // ThreadSanitizer shares that interceptor (sanitizer_common): a no-op reporting success.
  it.outcome = RtOutcome::kFailed;
  it.detail = "not available in a ThreadSanitizer build (its mlockall does nothing)";
  return it;
#endif
  if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) {
    it.outcome = RtOutcome::kApplied;
    return it;
  }
  const int e = errno;
  // ENOMEM for an unprivileged process means RLIMIT_MEMLOCK is smaller than the process.
  it.outcome = (e == EPERM || e == ENOMEM) ? RtOutcome::kNotPermitted : RtOutcome::kFailed;
  it.detail = "not permitted (" + errno_text(e) + "; needs CAP_IPC_LOCK or RLIMIT_MEMLOCK above " +
              "the process size, limit is " + rlimit_text(RLIMIT_MEMLOCK) +
              " bytes); memory stays pageable, page faults may delay ticks";
  if (it.outcome == RtOutcome::kFailed) it.detail = errno_text(e);
  return it;
}

RealtimeItem pin_cpu(int cpu) {
  RealtimeItem it{"CPU affinity", RtOutcome::kOff, ""};
  if (cpu < 0) {
    it.detail = "off (cpu = -1): the scheduler may move the loop between CPUs";
    return it;
  }
  it.what = "CPU affinity " + std::to_string(cpu);
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  if (sched_getaffinity(0, sizeof allowed, &allowed) != 0 || cpu >= CPU_SETSIZE ||
      !CPU_ISSET(cpu, &allowed)) {
    it.outcome = RtOutcome::kFailed;
    it.detail = "CPU " + std::to_string(cpu) + " is not available to this process (" +
                std::to_string(online_cpus()) + " CPUs allowed)";
    return it;
  }
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(cpu, &set);
  const int e = pthread_setaffinity_np(pthread_self(), sizeof set, &set);
  if (e == 0) {
    it.outcome = RtOutcome::kApplied;
  } else {
    it.outcome = e == EPERM ? RtOutcome::kNotPermitted : RtOutcome::kFailed;
    it.detail = errno_text(e);
  }
  return it;
}

// touch_stack: writes one byte per page of `bytes` of fresh stack, so those pages are mapped
// (and, after mlockall, locked) before the loop needs them.
__attribute__((noinline)) void touch_stack(std::size_t bytes) {
  auto* p = static_cast<volatile unsigned char*>(alloca(bytes));
  for (std::size_t i = 0; i < bytes; i += 4096) p[i] = 0;
  p[bytes - 1] = 0;
}

RealtimeItem prefault(std::size_t bytes) {
  RealtimeItem it{"stack pre-fault", RtOutcome::kOff, ""};
  if (bytes == 0) {
    it.detail = "off (prefault_stack = 0)";
    return it;
  }
  it.what = "stack pre-fault " + std::to_string(bytes) + " bytes";
  // An unlimited stack rlimit does not make a huge request safe: the stack mapping still ends
  // somewhere, so anything beyond kMaxPrefault is refused outright (the config allows 4 MiB).
  constexpr std::size_t kMaxPrefault = std::size_t{256} << 20;
  if (bytes > kMaxPrefault) {
    it.outcome = RtOutcome::kFailed;
    it.detail = "larger than the supported maximum of " + std::to_string(kMaxPrefault) + " bytes";
    return it;
  }
  rlimit l{};
  // Keep 64 KiB for what is already on the stack; more than the limit would be SIGSEGV.
  if (getrlimit(RLIMIT_STACK, &l) == 0 && l.rlim_cur != RLIM_INFINITY &&
      bytes + 65536 > l.rlim_cur) {
    it.outcome = RtOutcome::kFailed;
    it.detail = "larger than the stack limit " + std::to_string(l.rlim_cur) + " bytes minus 64 KiB";
    return it;
  }
  touch_stack(bytes);
  it.outcome = RtOutcome::kApplied;
  return it;
}

RealtimeItem hold_cpu_latency(int us) {
  RealtimeItem it{"CPU wake-up latency (PM QoS)", RtOutcome::kOff, ""};
  if (us < 0) {
    it.detail = "off (cpu_latency_us = -1): idle CPUs may sleep as deep as the governor likes";
    return it;
  }
  it.what = "CPU wake-up latency (PM QoS) " + std::to_string(us) + " us";
  // The kernel keeps the request only while the file is open (Documentation/power/pm_qos_
  // interface.rst), so the descriptor is held for the life of the process and never closed:
  // the kernel drops the request when the process exits, however it exits.
  static std::atomic<int> held{-1};
  int fd = held.load();
  if (fd < 0) {
    fd = ::open("/dev/cpu_dma_latency", O_WRONLY | O_CLOEXEC);
    if (fd < 0) {
      const int e = errno;
      it.outcome = (e == EACCES || e == EPERM) ? RtOutcome::kNotPermitted : RtOutcome::kFailed;
      it.detail = "/dev/cpu_dma_latency: " + errno_text(e) +
                  (it.outcome == RtOutcome::kNotPermitted
                       ? " (needs write access: root, and DeviceAllow= under systemd's "
                         "DevicePolicy=closed); idle CPUs keep their deep sleep states"
                       : "");
      return it;
    }
    int expected = -1;
    // Another thread got there first: keep its descriptor (one request per process).
    if (!held.compare_exchange_strong(expected, fd)) {
      ::close(fd);
      fd = expected;
    }
  }
  // The binary form (a native-endian 32-bit integer): the text form needs a trailing parse.
  const std::int32_t v = us;
  if (::write(fd, &v, sizeof v) != static_cast<ssize_t>(sizeof v)) {
    it.outcome = RtOutcome::kFailed;
    it.detail = "/dev/cpu_dma_latency: write: " + errno_text(errno);
    return it;
  }
  it.outcome = RtOutcome::kApplied;
  return it;
}

}  // namespace

int online_cpus() noexcept {
  cpu_set_t s;
  CPU_ZERO(&s);
  if (sched_getaffinity(0, sizeof s, &s) != 0) return 1;
  return CPU_COUNT(&s);
}

std::vector<RealtimeItem> apply_realtime(const RealtimeRequest& r) {
  std::vector<RealtimeItem> items;
  items.reserve(5);
  items.push_back(set_fifo(r.fifo_priority));
  // Lock before touching the stack so the touched pages stay resident.
  items.push_back(lock_memory(r.lock_memory));
  items.push_back(pin_cpu(r.cpu));
  items.push_back(prefault(r.prefault_stack));
  items.push_back(hold_cpu_latency(r.cpu_latency_us));
  return items;
}

}  // namespace odo::drivers
