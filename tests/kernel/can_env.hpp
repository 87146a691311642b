// Helpers of the CAN kernel tests (in the VM harness): a vcan interface per test, a background
// sender (can-utils) killed at the end, and the loop's SCHED_FIFO for the reading thread.
#pragma once

#include <sched.h>
#include <signal.h>
#include <unistd.h>

#include <fstream>
#include <string>

#include "kernel_env.hpp"

namespace odo::test {

// Vcan: a vcan interface for one test, removed at the end; ok: it was created and is up.
struct Vcan {
  std::string name;
  bool ok = false;
  explicit Vcan(std::string n) : name(std::move(n)) {
    run("ip link del " + name + " 2>/dev/null");
    ok = run("ip link add dev " + name + " type vcan && ip link set " + name + " up") == 0;
  }
  ~Vcan() { run("ip link del " + name + " 2>/dev/null"); }
  Vcan(const Vcan&) = delete;
  Vcan& operator=(const Vcan&) = delete;
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
  Background(const Background&) = delete;
  Background& operator=(const Background&) = delete;
};

// FifoScope: the calling thread runs SCHED_FIFO 80 as the firmware's loop does (README,
// [realtime]) while it lives; RESET_ON_FORK: processes started meanwhile run normally.
struct FifoScope {
  bool on = false;
  FifoScope() {
    sched_param sp{};
    sp.sched_priority = 80;
    on = sched_setscheduler(0, SCHED_FIFO | SCHED_RESET_ON_FORK, &sp) == 0;
  }
  ~FifoScope() {
    sched_param sp{};
    if (on) sched_setscheduler(0, SCHED_OTHER, &sp);
  }
  FifoScope(const FifoScope&) = delete;
  FifoScope& operator=(const FifoScope&) = delete;
};

}  // namespace odo::test
