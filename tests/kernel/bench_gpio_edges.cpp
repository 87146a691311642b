// bench_gpio_edges: the highest sustained edge rate the GPIO quadrature decoder follows without
// losing counts, next to what a bare libgpiod 1.6 reader sees on the same stream.
// Runs inside the VM harness (needs gpio-sim), see BENCHMARKS.md:
//   ODO_IN_VM=1 tools/vm-run.sh --cpus 1 --mem 1G -- build/default/tests/bench_gpio_edges
// For each target rate, a writer drives N quadrature steps forward through the gpio-sim pull
// attributes, paced with absolute deadlines; afterwards (100 ms quiet) the bare reader's event
// count and the decoder's count are compared with N.
#include <gpiod.h>
#include <time.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>

#include "gpio_sim.hpp"
#include "odo/drivers/gpio_quadrature.hpp"
#include "odo/hal/quadrature.hpp"

namespace {

using odo::TimeNs;

TimeNs now_ns() {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return static_cast<TimeNs>(t.tv_sec) * 1'000'000'000 + t.tv_nsec;
}

void sleep_until(TimeNs t) {
  timespec ts{static_cast<time_t>(t / 1'000'000'000), static_cast<long>(t % 1'000'000'000)};
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) != 0) {
  }
}

// drive: n forward quadrature steps on lines 0 (A) and 1 (B) at `rate` edges/s (0: unpaced),
// continuing from position `pos`; returns the achieved rate.
double drive(odo::test::GpioSim& sim, std::int64_t& pos, int n, double rate) {
  const TimeNs t0 = now_ns();
  for (int i = 0; i < n; ++i) {
    if (rate > 0) sleep_until(t0 + static_cast<TimeNs>(i * 1e9 / rate));
    const odo::QuadState from = odo::quad_state_at(pos);
    const odo::QuadState to = odo::quad_state_at(++pos);
    if ((from ^ to) & 2u) sim.pull(0, (to & 2u) != 0);
    if ((from ^ to) & 1u) sim.pull(1, (to & 1u) != 0);
  }
  return n / (static_cast<double>(now_ns() - t0) * 1e-9);
}

// BareReader: both-edge events on lines 0 and 1, read in batches, only counted.
struct BareReader {
  explicit BareReader(const std::string& chip_path) {
    chip = gpiod_chip_open(chip_path.c_str());
    gpiod_line_bulk_init(&bulk);
    gpiod_line_bulk_add(&bulk, gpiod_chip_get_line(chip, 0));
    gpiod_line_bulk_add(&bulk, gpiod_chip_get_line(chip, 1));
    if (gpiod_line_request_bulk_both_edges_events(&bulk, "bench-bare") != 0) std::abort();
    th = std::thread([this] {
      gpiod_line_event ev[64];
      while (!stop) {
        timespec to{0, 100'000'000};
        gpiod_line_bulk evb;
        if (gpiod_line_event_wait_bulk(&bulk, &to, &evb) <= 0) continue;
        for (unsigned k = 0; k < gpiod_line_bulk_num_lines(&evb); ++k) {
          gpiod_line* l = gpiod_line_bulk_get_line(&evb, k);
          const int got = gpiod_line_event_read_multiple(l, ev, 64);
          if (got <= 0) continue;
          seen += static_cast<unsigned>(got);
          // The v1 uAPI takes an edge's direction from the line level when the kernel's IRQ
          // thread runs; two edges in a row of the same direction on one line mean the
          // stream as delivered is inconsistent (one edge lost or mislabelled).
          const int li = l == gpiod_line_bulk_get_line(&bulk, 0) ? 0 : 1;
          for (int e = 0; e < got; ++e) {
            if (ev[e].event_type == last_type[li]) ++repeated;
            last_type[li] = ev[e].event_type;
          }
        }
      }
    });
  }
  ~BareReader() {
    stop = true;
    th.join();
    gpiod_chip_close(chip);
  }
  gpiod_chip* chip = nullptr;
  gpiod_line_bulk bulk{};
  std::atomic<bool> stop{false};
  std::atomic<std::uint64_t> seen{0};
  std::atomic<std::uint64_t> repeated{0};
  int last_type[2] = {0, 0};
  std::thread th;
};

// settle: waits until `count` has not changed for 200 ms.
template <class F>
std::uint64_t settle(F count) {
  std::uint64_t last = count();
  for (;;) {
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    const std::uint64_t c = count();
    if (c == last) return c;
    last = c;
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (const char* v = std::getenv("ODO_IN_VM"); v == nullptr || std::string(v) != "1") {
    std::fprintf(stderr, "bench_gpio_edges: needs gpio-sim: run inside tools/vm-run.sh\n");
    return 2;
  }
  const int n = argc > 1 ? std::atoi(argv[1]) : 4000;
  const double reorder_ms = argc > 2 ? std::atof(argv[2]) : 20.0;  // decoder's reorder window
  const double rates[] = {500, 1000, 2000, 5000, 10000, 20000, 0};
  odo::test::GpioSim sim("odo_bench", 4);
  std::printf("decoder reorder window %.1f ms\n", reorder_ms);
  std::printf("%-10s %-7s | %-30s | %-30s\n", "target/s", "edges", "bare libgpiod reader",
              "quadrature decoder");
  std::printf("%-10s %-7s | %-10s %-9s %-9s | %-10s %-9s %-9s\n", "", "", "achieved/s", "seen",
              "repeated", "achieved/s", "count", "invalid");
  std::int64_t pos = 0;
  for (double r : rates) {
    double bare_rate = 0, dec_rate = 0;
    std::uint64_t bare_seen = 0;
    std::uint64_t bare_repeated = 0;
    {
      BareReader bare(sim.chip());
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      bare_rate = drive(sim, pos, n, r);
      bare_seen = settle([&] { return bare.seen.load(); });
      bare_repeated = bare.repeated.load();
    }
    std::int64_t count = 0;
    std::uint64_t invalid = 0;
    {
      odo::drivers::GpioQuadratureConfig c;
      c.chip = sim.chip();
      c.left = {0, 1, -1, false};
      c.right = {2, 3, -1, false};
      c.consumer = "bench-decoder";
      c.reorder_window = static_cast<TimeNs>(reorder_ms * 1e6);
      auto enc = odo::drivers::GpioQuadratureEncoder::open(c);
      if (!enc) {
        std::fprintf(stderr, "%s\n", enc.error().message.c_str());
        return 1;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      const std::int64_t start = (*enc)->wheel(0).count;
      dec_rate = drive(sim, pos, n, r);
      settle([&] { return static_cast<std::uint64_t>((*enc)->wheel(0).edges); });
      count = (*enc)->wheel(0).count - start;
      invalid = (*enc)->wheel(0).invalid;
    }
    char target[32];
    std::snprintf(target, sizeof target, r > 0 ? "%.0f" : "unpaced", r);
    std::printf("%-10s %-7d | %-10.0f %-9llu %-9llu | %-10.0f %-9lld %-9llu\n", target, n,
                bare_rate, static_cast<unsigned long long>(bare_seen),
                static_cast<unsigned long long>(bare_repeated), dec_rate,
                static_cast<long long>(count), static_cast<unsigned long long>(invalid));
    std::fflush(stdout);
  }
  return 0;
}
