// Fault matrix, "clock jump of the wall clock": odometryd's loop and its status thread run on
// CLOCK_MONOTONIC (absolute deadlines with clock_nanosleep, condition waits on steady_clock),
// so stepping the wall clock (CLOCK_REALTIME, what `date -s` or an NTP step does) by a day
// backwards and then forwards while the loop runs must change nothing: the run lasts its
// duration, ticks at its rate and integrates the same pose. Needs root and a throw-away clock,
// so it runs in the VM harness only.
#include <time.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "../sim/daemon_text.hpp"
#include "kernel_env.hpp"
#include "odo/firmware/daemon.hpp"

namespace odo::test {
namespace {

// step_wall_clock: moves CLOCK_REALTIME by `seconds`; returns the step actually observed [s].
double step_wall_clock(long seconds) {
  timespec before{};
  clock_gettime(CLOCK_REALTIME, &before);
  timespec to = before;
  to.tv_sec += seconds;
  if (clock_settime(CLOCK_REALTIME, &to) != 0) return 0.0;
  timespec after{};
  clock_gettime(CLOCK_REALTIME, &after);
  return static_cast<double>(after.tv_sec - before.tv_sec) +
         1e-9 * static_cast<double>(after.tv_nsec - before.tv_nsec);
}

TEST(ClockJump, WallClockStepsDoNotReachTheLoop) {
  ODO_REQUIRE_VM();
  // The simulated robot with its true geometry equal to the config (no systematic error), on
  // the real monotonic clock, status lines every 0.2 s from the status thread.
  const char* cfg_path = "/tmp/odo_clock_jump.toml";
  {
    std::ofstream f(cfg_path);
    f << "[loop]\nrate_hz = 100\nstatus_period = 0.2\n[sim]\nrobot = \"nominal\"\n";
  }
  fw::DaemonOptions o;
  o.config_path = cfg_path;
  o.duration = 3.0;
  o.json = true;
  std::atomic<bool> stop{false};
  std::ostringstream out;
  LockedText err_text;
  std::ostream err(&err_text);
  int rc = -1;
  const auto t0 = std::chrono::steady_clock::now();
  std::thread daemon([&] { rc = fw::run_daemon(o, stop, out, err); });

  // Each step waits for status lines, not for a guessed time: under TCG a start has taken over
  // 3 s, and a step before the loop runs would test nothing. The backward step comes after the
  // first status line (the loop and the status thread run), the forward one after two more
  // lines (both threads went on after the backward step); the lines after the forward step are
  // checked below. At most 60 s each.
  const bool running = wait_until([&] { return status_lines(err_text.text()) >= 1; }, 60.0);
  const double back = step_wall_clock(-86400);  // one day back
  const std::size_t after_back = status_lines(err_text.text());
  const bool went_on =
      wait_until([&] { return status_lines(err_text.text()) >= after_back + 2; }, 60.0);
  const double fwd = step_wall_clock(2 * 86400);  // two days forward
  const std::size_t after_fwd = status_lines(err_text.text());
  daemon.join();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  step_wall_clock(-86400);  // put it back
  const std::string e = err_text.text();

  ASSERT_TRUE(running) << "no status line within 60 s: " << e;
  ASSERT_TRUE(went_on) << "no status lines after the backward step: " << e;
  // The fault was really injected.
  EXPECT_NEAR(back, -86400.0, 1.0);
  EXPECT_NEAR(fwd, 2 * 86400.0, 1.0);

  ASSERT_EQ(rc, 0) << e;
  std::printf("clock jump: steps %+.0f s and %+.0f s; %.2f s monotonic wall time; odometryd: %s",
              back, fwd, wall, out.str().c_str());
  const auto j = nlohmann::json::parse(out.str());
  // Neither stopped early (forward step) nor hung (backward step): 3 s of loop time, taken in
  // about 3 s of monotonic time (the rest is start-up under the VM's emulated CPU).
  EXPECT_NEAR(j["loop_time"].get<double>(), 3.0, 0.02);
  EXPECT_GT(wall, 2.9);
  EXPECT_LT(wall, 8.0);
  // Every period either ticked or was counted as missed: 3 s at 100 Hz = 300 periods.
  const auto periods = j["ticks"].get<std::uint64_t>() + j["missed_deadlines"].get<std::uint64_t>();
  EXPECT_GE(periods, 299u);
  EXPECT_LE(periods, 301u);
  // The pose follows the truth to the encoder quantisation (about 1e-5 m per count).
  EXPECT_LT(j["position_error"].get<double>(), 1e-4) << out.str();
  // The status thread kept printing through both steps (about 15 lines at 0.2 s), and after
  // the forward step: the run's last ~2 s came after it.
  EXPECT_GE(status_lines(e), 10u) << e;
  EXPECT_GE(status_lines(e), after_fwd + 3) << e;
}

}  // namespace
}  // namespace odo::test
