// Real-time set-up of the calling thread on Linux: SCHED_FIFO, mlockall, CPU affinity, a
// pre-faulted stack and a PM QoS CPU wake-up latency request. Each part reports what happened, so
// the daemon can say so and carry on (or refuse) when it lacks the privilege.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace odo::drivers {

struct RealtimeRequest {
  int fifo_priority = 0;           // 1..99: SCHED_FIFO at this priority; 0: leave the policy
  bool lock_memory = false;        // mlockall(MCL_CURRENT | MCL_FUTURE), process-wide
  int cpu = -1;                    // pin the calling thread to this CPU; -1: no pinning
  std::size_t prefault_stack = 0;  // bytes of the calling thread's stack to touch now; 0: none
  int cpu_latency_us = -1;  // [us] hold /dev/cpu_dma_latency at this for the process; -1: don't
};

enum class RtOutcome {
  kApplied,       // done
  kOff,           // not requested
  kNotPermitted,  // EPERM / resource limit: runs without it
  kFailed,        // other error (e.g. the CPU does not exist)
};

struct RealtimeItem {
  std::string what;  // e.g. "SCHED_FIFO priority 80"
  RtOutcome outcome = RtOutcome::kOff;
  std::string detail;  // why, and what is needed, when not applied
};

// apply_realtime: applies `r` to the calling thread (mlockall to the whole process). Never
// throws; every part is attempted even when an earlier one failed. Five items, in the order
// scheduling, memory lock, affinity, stack, CPU wake-up latency (the last is process-wide: the
// request stays until the process exits).
std::vector<RealtimeItem> apply_realtime(const RealtimeRequest& r);

// online_cpus: number of CPUs the calling thread may run on.
int online_cpus() noexcept;

}  // namespace odo::drivers
