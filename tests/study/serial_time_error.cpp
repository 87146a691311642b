// serial_time_error: the error the sample times of the serial backend leave in v and omega at a
// 100 Hz loop (issue 37; BENCHMARKS.md "Serial counts: sample times"). A robot drives an arc
// with varying speed (v = 0.5 + 0.3 sin(2 pi 0.5 t) m/s, omega = 0.8 cos(2 pi 0.3 t) rad/s);
// its counts (the default robot: 0.15 m wheels, 2048 x 16 counts/rev, 0.34 m wheelbase) go
// through the real SerialCountsSource over an in-memory link at the times bytes would arrive;
// the loop reads at 100 Hz and computes v, omega from count and stamp differences, as
// OdometryLoop does. Compared with the truth at the middle of each interval, RMS and max over
// 600 s, for: the diffodom stream (100 Hz, controller clock 80 ppm fast, USB delay 1 ms + up to
// 1 ms of frame jitter + a 5-30 ms spike on 2 % of records) stamped with the ClockMap, the same
// stamped with the loop's read time instead (what a backend without the controller's clock
// gets), and arduino-bridge (polled at 100 Hz, 57600 baud, latched 0.35-1.35 ms after the
// request) stamped with the request/answer midpoint. "ideal" is the counts' own quantisation:
// the same counts with their exact latch times. Each with the bytes stamped at their arrival (as
// SerialPort's reader thread does) and, for comparison, at the loop tick that reads them (a link
// read on the loop thread).
// usage: serial_time_error [seconds]
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <numbers>
#include <random>
#include <string>

#include "odo/protocol/serial_counts.hpp"
#include "odo/protocol/serial_counts_source.hpp"

namespace {

using odo::TimeNs;
constexpr double kPi = std::numbers::pi;
constexpr double kMpc = kPi * 0.15 / (2048.0 * 16.0);  // metres per count
constexpr double kB = 0.34;

// Truth: integrated wheel travel [m] at t [s] (closed forms of the integrals of v -+ w b / 2).
double travel(double t, int side) {
  const double s = 0.5 * t + 0.3 * (1 - std::cos(2 * kPi * 0.5 * t)) / (2 * kPi * 0.5);
  const double th = 0.8 * std::sin(2 * kPi * 0.3 * t) / (2 * kPi * 0.3);
  return side == 0 ? s - th * kB / 2 : s + th * kB / 2;
}
std::int64_t counts(double t, int side) {
  return static_cast<std::int64_t>(std::floor(travel(t, side) / kMpc));
}

struct Link final : odo::ByteLink {
  std::deque<std::pair<TimeNs, std::uint8_t>> q;  // bytes with their arrival times
  TimeNs now = 0;
  std::deque<TimeNs> requests;  // arduino-bridge: times requests reached the board
  bool stamped = true;          // as SerialPort's reader thread: each arrival with its time
  int read(std::span<std::uint8_t> out, TimeNs& arrival) noexcept override {
    std::size_t n = 0;
    const TimeNs first = q.empty() ? 0 : q.front().first;
    while (n < out.size() && !q.empty() && q.front().first <= now &&
           (!stamped || q.front().first == first)) {
      out[n++] = q.front().second;
      q.pop_front();
    }
    if (stamped && n > 0) arrival = first;
    return static_cast<int>(n);
  }
  bool write(std::span<const std::uint8_t>) noexcept override {
    requests.push_back(now);
    return true;
  }
  bool reopen() noexcept override { return true; }
};

struct Err {
  double sv = 0, sw = 0, mv = 0, mw = 0;
  int n = 0;
  void add(double ev, double ew) {
    sv += ev * ev;
    sw += ew * ew;
    mv = std::max(mv, std::fabs(ev));
    mw = std::max(mw, std::fabs(ew));
    ++n;
  }
  void print(const char* name) const {
    std::printf("%-34s v: rms %.2f max %.2f mm/s   omega: rms %.2f max %.2f mrad/s   (%d)\n", name,
                std::sqrt(sv / n) * 1e3, mv * 1e3, std::sqrt(sw / n) * 1e3, mw * 1e3, n);
  }
};

// Tracks the loop's v, omega from successive (counts, stamp) and compares with the truth.
struct Meter {
  std::int64_t l = 0, r = 0;
  TimeNs stamp = -1;
  double t_true_prev = 0;
  Err err;
  void sample(std::int64_t nl, std::int64_t nr, TimeNs st, double t_true, bool measure) {
    if (stamp >= 0 && st > stamp && measure) {
      const double dt = (st - stamp) * 1e-9;
      const double dl = (nl - l) * kMpc, dr = (nr - r) * kMpc;
      const double v = (dl + dr) / 2 / dt, w = (dr - dl) / kB / dt;
      // Truth: mean v, omega over the latch interval.
      const double T = t_true - t_true_prev;
      const double tv = (travel(t_true, 0) + travel(t_true, 1) - travel(t_true_prev, 0) -
                         travel(t_true_prev, 1)) /
                        2 / T;
      const double tw = (travel(t_true, 1) - travel(t_true, 0) - travel(t_true_prev, 1) +
                         travel(t_true_prev, 0)) /
                        kB / T;
      err.add(v - tv, w - tw);
    }
    if (st > stamp) {
      l = nl;
      r = nr;
      stamp = st;
      t_true_prev = t_true;
    }
  }
};

void stream(double seconds, bool stamped) {
  std::mt19937_64 rng(37);
  std::uniform_real_distribution<double> u(0, 1);
  Link link;
  link.stamped = stamped;
  odo::protocol::SerialSourceConfig c;
  c.max_counts_per_s = 1e7;
  odo::protocol::SerialCountsSource src(link, c);
  Meter mapped, naive, ideal;
  const double drift = 80e-6;
  std::uint16_t seq = 0;
  double next_rec = 0.0037;
  std::deque<double> latch_times;  // host time each queued record was latched
  for (int k = 1; k * 0.01 < seconds; ++k) {
    const double now = k * 0.01;
    for (; next_rec <= now; next_rec += 0.01 / (1 + drift)) {  // the controller's 10 ms, fast
      odo::protocol::SerialCounts r{
          .seq = seq++,
          .time_us = static_cast<std::uint32_t>(next_rec * (1 + drift) * 1e6),
          .left = static_cast<std::int32_t>(counts(next_rec, 0)),
          .right = static_cast<std::int32_t>(counts(next_rec, 1))};
      double delay = 1e-3 + 1e-3 * u(rng);
      if (u(rng) < 0.02) delay += 5e-3 + 25e-3 * u(rng);
      std::array<std::uint8_t, odo::protocol::kSerialCountsFrameMax> f{};
      const std::size_t n = odo::protocol::encode_serial_counts(r, f);
      // Delivery in order (a later record cannot overtake a delayed one on one line).
      TimeNs at = static_cast<TimeNs>((next_rec + delay) * 1e9);
      if (!link.q.empty()) at = std::max(at, link.q.back().first);
      for (std::size_t i = 0; i < n; ++i) link.q.emplace_back(at, f[i]);
      ideal.sample(r.left, r.right, static_cast<TimeNs>(next_rec * 1e9), next_rec, next_rec > 5);
      latch_times.push_back(next_rec);
    }
    link.now = static_cast<TimeNs>(now * 1e9);
    const std::uint64_t before = src.stats().samples;
    const odo::EncoderSample s = src.read(link.now);
    const std::uint64_t got = src.stats().samples - before;
    double t_true = mapped.t_true_prev;
    for (std::uint64_t i = 0; i < got; ++i) {
      t_true = latch_times.front();
      latch_times.pop_front();
    }
    const bool measure = now > 5;  // after the clock mapping's first windows
    mapped.sample(s.left, s.right, s.stamp, t_true, measure);
    if (got > 0) naive.sample(s.left, s.right, link.now, t_true, measure);
  }
  if (stamped) {
    ideal.err.print("ideal (exact latch times)");
    mapped.err.print("diffodom, ClockMap of arrival stamps");
  } else {
    mapped.err.print("diffodom, ClockMap of tick times");
    naive.err.print("diffodom, tick time as the stamp");
  }
}

void bridge(double seconds, bool stamped) {
  std::mt19937_64 rng(38);
  std::uniform_real_distribution<double> u(0, 1);
  Link link;
  link.stamped = stamped;
  odo::protocol::SerialSourceConfig c;
  c.protocol = odo::protocol::SerialProtocol::kArduinoBridge;
  c.poll_period = 10'000'000;
  c.max_counts_per_s = 1e7;
  odo::protocol::SerialCountsSource src(link, c);
  Meter mid;
  std::deque<double> latch_times;
  for (int k = 1; k * 0.01 < seconds; ++k) {
    const double now = k * 0.01;
    link.now = static_cast<TimeNs>(now * 1e9);
    const std::uint64_t before = src.stats().samples;
    const odo::EncoderSample s = src.read(link.now);
    if (src.stats().samples > before) {
      mid.sample(s.left, s.right, s.stamp, latch_times.front(), now > 5);
      latch_times.pop_front();
    }
    // Requests written by this read: the board latches 0.35-1.35 ms later (2 characters at
    // 57600 baud, then up to a USB frame), answers ~2 ms later (12 characters).
    for (; !link.requests.empty(); link.requests.pop_front()) {
      const double t_req = link.requests.front() * 1e-9;
      const double latch = t_req + 0.35e-3 + 1e-3 * u(rng);
      char txt[40];
      const int n =
          std::snprintf(txt, sizeof txt, "%lld %lld\r\n", static_cast<long long>(counts(latch, 0)),
                        static_cast<long long>(counts(latch, 1)));
      const auto at = static_cast<TimeNs>((latch + 2.1e-3 + 1e-3 * u(rng)) * 1e9);
      for (int i = 0; i < n; ++i) link.q.emplace_back(at, static_cast<std::uint8_t>(txt[i]));
      latch_times.push_back(latch);
    }
  }
  mid.err.print(stamped ? "arduino-bridge, midpoint to arrival"
                        : "arduino-bridge, midpoint to tick");
}

}  // namespace

int main(int argc, char** argv) {
  const double seconds = argc > 1 ? std::atof(argv[1]) : 600.0;
  std::printf("serial_time_error: %.0f s at a 100 Hz loop\n", seconds);
  stream(seconds, true);
  stream(seconds, false);
  bridge(seconds, true);
  bridge(seconds, false);
  return 0;
}
