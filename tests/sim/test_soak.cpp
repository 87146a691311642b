// Soak: the firmware's loop drives the simulated robot in virtual time for ODO_SOAK_HOURS hours
// of random driving while FaultyEncoderSource injects faults at random. Checked on every tick:
//   - no NaN/inf anywhere in the snapshot;
//   - flags truthful: kEncoderReadError exactly on the ticks whose read was made to fail, the
//     read_errors counter equal to the number injected, no other flag ever raised;
//   - missed deadlines truthful: a read slowed by D adds exactly floor(D / period) (derivation at
//     expected_missed());
//   - no count lost: on every tick that integrated a correct reading the heading equals the true
//     heading to the quantisation of the counts (|error| <= c_m / b, derivation below), whatever
//     overruns, failed reads, frozen counters, glitches and 16-bit wraps came before;
// and at every stop (the robot stands still between random motions) the position error against
// ground truth is within a budget accumulated from the per-tick bound plus what the injected
// glitches explain; then the odometry's position is re-anchored to the truth (set-pose, as a
// docking station or the CAN set-pose command would) so that the budget covers one motion.
// Memory: no heap allocation at all while the loop runs (global operator new is counted), and the
// resident set size (/proc/self/statm) is sampled every simulated hour and must not grow.
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <new>
#include <random>
#include <vector>

#include "odo/sim/fault_encoder.hpp"
#include "sim_fixture.hpp"

// The loop must not allocate: operator new is counted (g_allocations).
#include "counting_new.hpp"

#ifndef ODO_SOAK_HOURS
#define ODO_SOAK_HOURS 0.25
#endif
#ifndef ODO_SOAK_NAME
#define ODO_SOAK_NAME QuarterHour
#endif

namespace odo::test {
namespace {

// A random wheel-velocity profile: straight runs, arcs and turns on the spot, forward and
// backward, each followed by a stop of at least 0.5 s (longer than any injected outage, so no
// tick ever integrates two different motions in one step; see the budget derivation).
struct Profile {
  sim::Scenario scenario;
  std::vector<TimeNs> stop_begin, stop_end;  // [ns] the stops, in order
};

Profile random_profile(std::mt19937_64& rng, double seconds) {
  std::uniform_real_distribution<double> omega(0.5, 4.0), dur(0.5, 8.0), pause(0.5, 2.0),
      sign(-1.0, 1.0);
  std::uniform_int_distribution<int> kind(0, 2);
  Profile p;
  double t = 0.0;
  while (t < seconds) {
    sim::Segment s;
    s.duration = dur(rng);
    const double w = omega(rng) * (sign(rng) < 0 ? -1.0 : 1.0);
    switch (kind(rng)) {
      case 0:
        s.omega_left = s.omega_right = w;
        break;  // straight
      case 1:
        s.omega_left = -w, s.omega_right = w;
        break;  // on the spot
      default:
        s.omega_left = w, s.omega_right = omega(rng) * (sign(rng) < 0 ? -1.0 : 1.0);
    }
    p.scenario.push_back(s);
    t += s.duration;
    const double stop = pause(rng);
    p.scenario.push_back({stop, 0.0, 0.0});
    p.stop_begin.push_back(from_seconds(t));
    t += stop;
    p.stop_end.push_back(from_seconds(t));
  }
  return p;
}

long rss_pages() {
  long size = 0, resident = 0;
  if (FILE* f = std::fopen("/proc/self/statm", "r")) {
    if (std::fscanf(f, "%ld %ld", &size, &resident) != 2) resident = -1;
    std::fclose(f);
  }
  return resident;
}

TEST(Soak, ODO_SOAK_NAME) {
  const double hours = ODO_SOAK_HOURS;
  std::uint64_t seed = 20261122;
  if (const char* s = std::getenv("ODO_SOAK_SEED")) seed = std::strtoull(s, nullptr, 10);
  std::mt19937_64 rng(seed);
  const Profile prof = random_profile(rng, hours * 3600.0);

  // The robot's true geometry equals the firmware's belief: every error left is quantisation or
  // a fault. 16-bit counters wrap every ~6 wheel turns, so wrap-around happens all the time.
  const auto k = *Kinematics::create(nominal_labmate());
  sim::RobotGeometry g;
  const int bits = 16;
  sim::VirtualClock clock;
  auto robot = *sim::SimRobot::create(g, prof.scenario);
  sim::SimEncoderSource counters(robot, bits, 32767 - 1000);
  sim::FaultyEncoderSource enc(counters, &clock);
  auto loop = loop::OdometryLoop::create(loop::LoopConfig{100.0}, k, enc, clock).value();
  const TimeNs period = loop->period();
  const double c_m = k.metres_per_count(), b = k.wheelbase();
  const double r = 0.5 * g.wheel_diameter_left;

  // Fault schedule: when no fault is armed, each tick arms one with probability 1/500 (about one
  // every 5 s). Outages last at most 40 reads (0.4 s): at the profile's top wheel speed of
  // 4 rad/s = 20 900 counts/s that is < 8 400 counts, far inside the 16-bit wrap horizon of
  // 32 768 counts (a longer outage would alias; see the fault matrix in TESTING.md).
  std::uniform_int_distribution<int> pick(0, 499), kind(0, 4), reads(1, 40), glitch(1, 5000);
  std::uniform_int_distribution<TimeNs> delay(1'000'000, 45'000'000);

  std::uint64_t expected_read_errors = 0, expected_missed = 0, anchors = 0;
  double max_heading_err = 0.0, max_pos_err = 0.0, max_pos_ratio = 0.0, budget = 0.0;
  double max_pos_err_clean = 0.0;  // at stops after a motion without freeze or glitch
  bool window_faulty = false;
  double worst_err = 0.0, worst_budget = 0.0;  // the stop closest to its budget
  bool worst_faulty = false;
  std::size_t stop = 0;
  TimeNs armed_delay = 0;
  bool freeze_l = false, freeze_r = false, frozen_since_correct = false;
  double prev_al = 0.0, prev_ar = 0.0;  // true wheel angles at the last correct reading [rad]
  std::int64_t prev_nl = robot.counts_left(), prev_nr = robot.counts_right();
  std::vector<long> rss;
  rss.reserve(static_cast<std::size_t>(hours) + 2);
  rss.push_back(rss_pages());

  loop->start();
  const std::uint64_t allocations_at_start = g_allocations.load();
  const TimeNs end = from_seconds(hours * 3600.0);
  TimeNs next_rss = from_seconds(3600.0);
  while (clock.now() < end) {
    // Arm a fault (only when none is active) for the coming reads.
    if (enc.idle() && pick(rng) == 0) {
      switch (kind(rng)) {
        case 0:
          armed_delay = delay(rng);
          enc.arm_slow_reads(reads(rng), armed_delay);
          break;
        case 1:
          enc.arm_read_errors(reads(rng));
          break;
        case 2:
        case 3:
          freeze_l = pick(rng) % 2 == 0;
          freeze_r = !freeze_l || pick(rng) % 2 == 0;
          enc.arm_freeze(reads(rng), freeze_l, freeze_r);
          break;
        default: {
          const std::int64_t gl = glitch(rng) * (pick(rng) % 2 ? 1 : -1);
          const std::int64_t gr = pick(rng) % 3 == 0 ? glitch(rng) : 0;
          enc.arm_glitch(gl, gr);
          // A glitch of n counts on a wheel moves the pose by at most n c_m / 2 and turns it by
          // n c_m / b; the next reading takes both back, the false turn having acted on at most
          // two ticks of true motion (< 0.1 m at these speeds): <= n c_m (1 + 0.1 / b).
          budget += static_cast<double>(std::llabs(gl) + std::llabs(gr)) * c_m * (1.0 + 0.1 / b);
        }
      }
    }
    const sim::InjectedFaults before = enc.injected();
    loop->tick();
    const sim::InjectedFaults& after = enc.injected();
    const bool read_fails = after.read_errors > before.read_errors;
    const bool glitched = after.glitches > before.glitches;
    const bool frozen = after.frozen_reads > before.frozen_reads;
    const bool slow = after.slow_reads > before.slow_reads;
    window_faulty = window_faulty || frozen || glitched;

    const loop::LoopSnapshot& s = loop->snapshot();
    const loop::LoopStats& st = loop->stats();
    ASSERT_TRUE(std::isfinite(s.pose.x) && std::isfinite(s.pose.y) && std::isfinite(s.pose.theta) &&
                std::isfinite(s.v) && std::isfinite(s.omega) && std::isfinite(s.distance))
        << "tick " << s.tick;

    // Flags: exactly the injected read errors, nothing else (frozen and glitched readings are
    // not detected by this backend: the wrapper models a chip that cannot know).
    if (read_fails) ++expected_read_errors;
    ASSERT_EQ(s.encoder_flags, read_fails ? std::uint32_t{kEncoderReadError} : 0u)
        << "tick " << s.tick;
    ASSERT_EQ(s.encoder_counters.read_errors, expected_read_errors);

    // Missed deadlines. The virtual clock wakes exactly at the deadline and the tick body costs
    // no virtual time except the read delay D, so the tick ends at deadline + D; the next
    // deadline is deadline + P and the loop skips ((D - P) / P) + 1 = D / P periods when
    // D >= P, none otherwise: floor(D / P) in both cases.
    if (slow) expected_missed += static_cast<std::uint64_t>(armed_delay / period);
    ASSERT_EQ(st.missed_deadlines, expected_missed) << "tick " << s.tick;

    // No count lost: when this tick integrated a correct reading, the integrated counts are the
    // robot's counts n = floor(a + 1/2) of its continuous angles a, |n - a| <= 1/2 per wheel, so
    // the heading c_m (n_R - n_L) / b is within c_m / b of the true c_m (a_R - a_L) / b.
    frozen_since_correct = frozen_since_correct || frozen;
    const bool correct = !read_fails && !glitched && !frozen;
    if (correct) {
      const double al = robot.wheel_angle_left(), ar = robot.wheel_angle_right();
      const std::int64_t nl = robot.counts_left(), nr = robot.counts_right();
      const double herr = std::fabs(s.pose.theta - robot.true_pose().theta);
      max_heading_err = std::max(max_heading_err, herr);
      ASSERT_LE(herr, c_m / b + 1e-9) << "tick " << s.tick << ": a count was lost";
      // Position budget of the motion since the last correct reading (one loop step when
      // nothing failed in between, a longer one after an outage). Within it the truth is one
      // constant-curvature arc (no stop fits in an outage) and so is the odometry's step; two
      // arcs of lengths s_o, s_t whose start headings and turns differ by dh and dphi end at
      // most |s_o - s_t| + max(s_o, s_t) (dh + dphi / 2) apart (first order; 1e-12 covers the
      // rest). dh <= c_m / b by the heading invariant at the previous correct reading.
      const double st_len = r * 0.5 * ((al - prev_al) + (ar - prev_ar));
      const double so_len = c_m * 0.5 * static_cast<double>((nl - prev_nl) + (nr - prev_nr));
      const double phi_t = r * ((ar - prev_ar) - (al - prev_al)) / b;
      const double phi_o = c_m * static_cast<double>((nr - prev_nr) - (nl - prev_nl)) / b;
      budget += std::fabs(so_len - st_len) +
                std::max(std::fabs(so_len), std::fabs(st_len)) *
                    (c_m / b + 0.5 * std::fabs(phi_o - phi_t)) +
                1e-12;
      if (frozen_since_correct) {
        // While a counter was frozen the odometry drove the other wheel's path with a heading
        // off by up to the m missing counts (m c_m / b), then caught up in one step of m
        // counts: <= m c_m (1 + S / b), S the path of the outage.
        const double m = static_cast<double>((freeze_l ? std::llabs(nl - prev_nl) : 0) +
                                             (freeze_r ? std::llabs(nr - prev_nr) : 0));
        const double path =
            c_m * 0.5 * static_cast<double>(std::llabs(nl - prev_nl) + std::llabs(nr - prev_nr));
        budget += m * c_m * (1.0 + path / b);
        frozen_since_correct = false;
      }
      prev_al = al, prev_ar = ar, prev_nl = nl, prev_nr = nr;
    }

    // At a stop: check the position against the truth, then re-anchor.
    while (stop < prof.stop_end.size() && prof.stop_end[stop] <= s.stamp) ++stop;
    const bool in_stop = stop < prof.stop_begin.size() && s.stamp >= prof.stop_begin[stop] &&
                         s.stamp + 3 * period < prof.stop_end[stop];
    if (in_stop && correct && enc.idle()) {
      const Pose2& t = robot.true_pose();
      const double perr = std::hypot(s.pose.x - t.x, s.pose.y - t.y);
      max_pos_err = std::max(max_pos_err, perr);
      if (!window_faulty) max_pos_err_clean = std::max(max_pos_err_clean, perr);
      window_faulty = false;
      if (budget > 0 && perr / budget > max_pos_ratio) {
        max_pos_ratio = perr / budget;
        worst_err = perr, worst_budget = budget, worst_faulty = window_faulty;
      }
      ASSERT_LE(perr, budget) << "tick " << s.tick << " at " << to_seconds(s.stamp) << " s";
      if (perr > 0.0) {
        loop->post(loop::SetPose{{t.x, t.y, s.pose.theta}});
        ++anchors;
      }
      budget = 0.0;
    }

    if (clock.now() >= next_rss) {
      rss.push_back(rss_pages());
      next_rss += from_seconds(3600.0);
    }
  }
  const std::uint64_t loop_allocations = g_allocations.load() - allocations_at_start;
  rss.push_back(rss_pages());

  const loop::LoopStats& st = loop->stats();
  const sim::InjectedFaults& inj = enc.injected();
  long rss_hourly_max = 0;
  for (std::size_t i = 1; i < rss.size(); ++i) rss_hourly_max = std::max(rss_hourly_max, rss[i]);
  std::printf(
      "soak: seed %" PRIu64 ", %.2f h virtual, %" PRIu64 " ticks, %zu motions; injected: %" PRIu64
      " slow reads, %" PRIu64 " failed reads, %" PRIu64 " frozen reads, %" PRIu64
      " glitches; missed deadlines %" PRIu64
      "; max heading error %.3g rad (bound %.3g); max "
      "position error at a stop %.3g m (%.3g m after motions without freeze or glitch; max share "
      "of budget %.2f: %.3g m of %.3g m, %s); %" PRIu64 " re-anchors; allocations in loop %" PRIu64
      "; RSS pages before start %ld, after 1 h %ld, max later %ld\n",
      seed, hours, st.ticks, prof.stop_begin.size(), inj.slow_reads, inj.read_errors,
      inj.frozen_reads, inj.glitches, st.missed_deadlines, max_heading_err, c_m / b, max_pos_err,
      max_pos_err_clean, max_pos_ratio, worst_err, worst_budget,
      worst_faulty ? "a motion with a freeze or glitch" : "a fault-free motion", anchors,
      loop_allocations, rss.front(), rss.size() > 2 ? rss[1] : -1L,
      rss.size() > 2 ? rss_hourly_max : -1L);
  EXPECT_EQ(loop_allocations, 0u);
  EXPECT_GT(inj.read_errors, 0u);
  EXPECT_GT(inj.glitches, 0u);
  EXPECT_GT(st.missed_deadlines, 0u);
  EXPECT_GT(anchors, 0u);
  // Memory flat: the resident set after the first hour never grows.
  for (std::size_t i = 2; i < rss.size(); ++i) EXPECT_LE(rss[i], rss[1]) << "hour " << i;
}

}  // namespace
}  // namespace odo::test
