// Helpers for tests that need a kernel facility (vcan, gpio-sim, mtdram). They run inside the
// VM harness (tools/vm-run.sh, which sets ODO_IN_VM=1); anywhere else they skip with the reason.
#pragma once

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

namespace odo::test {

// in_vm: true inside the project's VM harness.
inline bool in_vm() {
  const char* v = std::getenv("ODO_IN_VM");
  return v != nullptr && std::string(v) == "1";
}

// slurp: the whole content of a file ("" when it cannot be read).
inline std::string slurp(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

// spawn: runs `cmd` through sh in the background, in a process group of its own (kill(-pid, ...)
// stops it with its children); returns its pid.
inline pid_t spawn(const std::string& cmd) {
  const pid_t pid = fork();
  if (pid == 0) {
    setpgid(0, 0);
    execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    _exit(127);
  }
  return pid;
}

// wait_until: whether `done()` becomes true within `seconds` (asked every 20 ms). Tests wait on
// what the program prints once it is ready instead of sleeping a guess: under TCG on a loaded
// host a start has taken over 3 s.
template <class Done>
bool wait_until(Done done, double seconds) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  for (;;) {
    if (done()) return true;
    if (std::chrono::steady_clock::now() >= end) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

// wait_for_text: whether the file `path` holds `text` within `seconds`.
inline bool wait_for_text(const std::string& path, const std::string& text, double seconds = 30.0) {
  return wait_until([&] { return slurp(path).find(text) != std::string::npos; }, seconds);
}

// run: a shell command in the guest; returns its exit status.
inline int run(const std::string& cmd) {
  const int rc = std::system(cmd.c_str());
  return WIFEXITED(rc) ? WEXITSTATUS(rc) : 128;
}

// kI2cStubChips: every address at which a kernel test puts a chip on i2c-stub (the calibration
// store's 24C02 EEPROM at 0x50, the BMG160 gyro at 0x68).
inline constexpr std::array<int, 2> kI2cStubChips = {0x50, 0x68};

// i2c_stub_bus: i2c-stub loaded with a chip at every address of kI2cStubChips; returns its
// adapter (i2c-N), or "" when it cannot be loaded so. The module makes its chips only when it is
// loaded (a second modprobe with other addresses does nothing), so every test loads it with the
// whole list, and a module loaded with another list is unloaded first: the tests run in any order.
inline std::string i2c_stub_bus() {
  std::string list;
  for (const int a : kI2cStubChips) list += (list.empty() ? "" : ",") + std::to_string(a);
  // The module prints its (ten) addresses in decimal: "80,104,0,...".
  const std::string loaded = slurp("/sys/module/i2c_stub/parameters/chip_addr");
  if (!loaded.empty() && loaded.rfind(list + ",", 0) != 0 && run("rmmod i2c-stub") != 0) return "";
  if (run("modprobe i2c-stub chip_addr=" + list) != 0) return "";
  for (const auto& e : std::filesystem::directory_iterator("/sys/bus/i2c/devices")) {
    if (slurp((e.path() / "name").string()).rfind("SMBus stub", 0) == 0)
      return e.path().filename().string();
  }
  return "";
}

}  // namespace odo::test

// ODO_REQUIRE_VM: first statement of every kernel-tier test.
#define ODO_REQUIRE_VM()                                                                  \
  do {                                                                                    \
    if (!::odo::test::in_vm())                                                            \
      GTEST_SKIP() << "needs the VM harness (tools/vm-run.sh): this kernel has no vcan, " \
                      "gpio-sim or mtdram; tools/test.sh runs the kernel tier in the VM"; \
  } while (0)
