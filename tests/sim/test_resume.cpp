// Resume across restarts (issue 17) with the simulated HCTL-1100 backend: the chips keep
// counting while the loop is down, a new loop continues from the persisted record and ends at
// the pose of a run that was never interrupted.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <optional>
#include <random>
#include <vector>

#include "odo/drivers/can_encoder.hpp"
#include "odo/drivers/hctl1100_encoder.hpp"
#include "odo/loop/loop.hpp"
#include "odo/loop/state_record.hpp"
#include "odo/sim/hctl1100_model.hpp"
#include "odo/sim/sim_can_bus.hpp"
#include "odo/sim/virtual_clock.hpp"

namespace odo {
namespace {

using sim::Hctl1100Model;
using sim::SimHctlBus;

// The robot's wheels: count rates [counts/s] per segment of `seg` seconds; each segment is a
// constant-curvature arc (straight when both rates are equal), so an exact-arc step over a gap
// inside one segment is the same motion as the ticks it replaces.
struct Motion {
  double seg = 2.0;                              // [s]
  std::vector<std::pair<double, double>> rates;  // left, right [counts/s]
  // counts: cumulative counts of wheel i at time t [s] (integral of the piecewise rates).
  std::int64_t counts(int i, double t) const {
    double c = 0.0;
    for (std::size_t k = 0; k < rates.size() && t > 0.0; ++k) {
      const double dt = std::min(t, seg);
      c += (i == 0 ? rates[k].first : rates[k].second) * dt;
      t -= dt;
    }
    return static_cast<std::int64_t>(std::floor(c));
  }
  double duration() const { return seg * static_cast<double>(rates.size()); }
};

// The chips follow the motion at every bus cycle, loop running or not (they count on their own).
struct World final : sim::BusCycleHook {
  explicit World(const Motion& m) : motion(m), bus(&l, &r) { bus.set_hook(this); }
  void on_bus_cycle() noexcept override {
    const double t = to_seconds(clock.now());
    l.follow(motion.counts(0, t));
    r.follow(motion.counts(1, t));
  }
  Motion motion;
  Hctl1100Model l, r;
  SimHctlBus bus;
  sim::VirtualClock clock;
};

// c_m = pi * 0.15 / (16 * 2048) = 1.438e-5 m per count; wheelbase 0.34 m.
Kinematics kinematics() {
  return Kinematics::create(KinematicParams{0.15, 2048, 16, 0.34, 0.34, 1.0, 1.0}).value();
}

drivers::Hctl1100Config hctl_config() {
  drivers::Hctl1100Config c;
  c.max_counts_per_s = 200000;  // 3 m/s / 1.438e-5 m
  return c;
}

loop::ResumeContext context_for(const loop::OdometryLoop& l) {
  loop::ResumeContext c;
  const Kinematics& k = l.odometry().kinematics();
  c.max_age = from_seconds(5.0);
  c.backend = 1;
  c.backend_continuous = true;
  c.counter_bits = l.counter_bits();
  c.metres_per_count_left = k.metres_per_count_left();
  c.metres_per_count_right = k.metres_per_count_right();
  c.wheelbase = k.wheelbase();
  return c;
}

// make_loop: a loop at 100 Hz on the simulated chips.
std::unique_ptr<loop::OdometryLoop> make_loop(World& w, EncoderSource& enc) {
  return loop::OdometryLoop::create(loop::LoopConfig{100.0}, kinematics(), enc, w.clock).value();
}

void tick_until(loop::OdometryLoop& l, sim::VirtualClock& c, double end_s) {
  while (c.now() + l.period() <= from_seconds(end_s)) l.tick();
}

struct Outcome {
  Pose2 uninterrupted;
  Pose2 resumed;
  int resumes = 0;
};

// run_with_restarts: the motion once without interruption, once killed at `kills` [s] and
// restarted after `gaps` [s]: the state persisted at the last tick goes through its bytes.
Outcome run_with_restarts(const Motion& m, const std::vector<double>& kills,
                          const std::vector<double>& gaps) {
  Outcome o;
  {
    World w(m);
    auto enc = drivers::Hctl1100Encoder::create(w.bus, hctl_config()).value();
    auto l = make_loop(w, enc);
    l->start();
    tick_until(*l, w.clock, m.duration());
    o.uninterrupted = l->odometry().pose();
  }
  World w(m);
  std::unique_ptr<drivers::Hctl1100Encoder> enc;
  std::unique_ptr<loop::OdometryLoop> l;
  std::uint64_t seq = 0;
  for (std::size_t i = 0; i <= kills.size(); ++i) {
    // A restarted process: a new driver and a new loop on the same chips.
    enc = std::make_unique<drivers::Hctl1100Encoder>(
        drivers::Hctl1100Encoder::create(w.bus, hctl_config()).value());
    auto fresh = make_loop(w, *enc);
    if (l) {
      loop::StateRecord rec;
      loop::fill_state_record(*l, rec);
      rec.sequence = ++seq;
      rec.backend = 1;
      loop::StateBytes bytes{};
      loop::encode_state(rec, bytes);
      w.clock.advance(from_seconds(gaps[i - 1]));  // the downtime; the wheels keep turning
      fresh->resume_from(loop::decode_state(bytes).value(), context_for(*fresh));
    }
    l = std::move(fresh);
    l->start();
    if (i > 0) {
      EXPECT_TRUE(l->resume_decision().resumed())
          << loop::resume_reason_name(l->resume_decision().reason);
      o.resumes += l->resume_decision().resumed() ? 1 : 0;
    }
    tick_until(*l, w.clock, i < kills.size() ? kills[i] : m.duration());
  }
  o.resumed = l->odometry().pose();
  return o;
}

// Restart moments inside segments only (at least `gap_max` before a segment's end), in order.
std::vector<double> kill_times(const Motion& m, int n, double gap_max, std::mt19937& rng) {
  std::vector<double> k;
  std::uniform_real_distribution<double> u(0.05, m.seg - gap_max - 0.05);
  std::uniform_int_distribution<std::size_t> seg(0, m.rates.size() - 1);
  for (int i = 0; i < n; ++i) k.push_back(static_cast<double>(seg(rng)) * m.seg + u(rng));
  std::sort(k.begin(), k.end());
  return k;
}

// Straight legs: 20 restarts with gaps of 0.2..0.3 s. The gap's counts are integrated as one
// step; on a straight leg sum(d_i) * cos(theta) = (sum d_i) * cos(theta), so the pose is the
// uninterrupted one up to rounding (1e-12 m on ~1.4 m of travel).
TEST(Resume, StraightRunEndsWhereTheUninterruptedRunEnds) {
  Motion m;
  m.rates = {{20000, 20000}, {40000, 40000}, {-10000, -10000}, {0, 0}};
  std::mt19937 rng(17);
  const auto kills = kill_times(m, 20, 0.3, rng);
  std::vector<double> gaps;
  std::uniform_real_distribution<double> g(0.2, 0.3);
  for (std::size_t i = 0; i < kills.size(); ++i) gaps.push_back(g(rng));
  // The kills are sorted and may be closer than the gap; drop those that fall inside a gap.
  std::vector<double> k2, g2;
  double busy_until = 0.0;
  for (std::size_t i = 0; i < kills.size(); ++i) {
    if (kills[i] < busy_until + 0.05) continue;
    k2.push_back(kills[i]);
    g2.push_back(gaps[i]);
    busy_until = kills[i] + gaps[i];
  }
  const Outcome o = run_with_restarts(m, k2, g2);
  EXPECT_EQ(o.resumes, static_cast<int>(k2.size()));
  EXPECT_GE(o.resumes, 5);
  EXPECT_NEAR(o.resumed.x, o.uninterrupted.x, 1e-12);
  EXPECT_NEAR(o.resumed.y, o.uninterrupted.y, 1e-12);
  EXPECT_EQ(o.resumed.theta, 0.0);
}

// Arcs and turns on the spot. The heading depends only on the total counts, so it ends equal up
// to rounding (1e-12 rad). The position does not: the counts are whole, so the restarted loop's
// ticks (shifted in phase) see per-tick count ratios that differ from the uninterrupted run's
// by up to one count; one count of heading is 1.438e-5 m / 0.34 m = 4.2e-5 rad, over a gap's
// travel of at most 0.4 s * 25000 counts/s * 1.438e-5 m = 0.144 m that is <= 6.1e-6 m per
// gap: with at most 8 gaps the documented bound is 5e-5 m.
TEST(Resume, ArcsAndTurnsEndWhereTheUninterruptedRunEnds) {
  Motion m;
  m.rates = {{20000, 20000}, {-8000, 8000}, {15000, 25000}, {30000, 30000}, {0, 0}};
  std::mt19937 rng(4711);
  const auto kills = kill_times(m, 8, 0.5, rng);
  std::vector<double> k2, g2;
  double busy_until = 0.0;
  for (double k : kills) {
    if (k < busy_until + 0.05) continue;
    k2.push_back(k);
    g2.push_back(0.4);
    busy_until = k + 0.4;
  }
  const Outcome o = run_with_restarts(m, k2, g2);
  EXPECT_EQ(o.resumes, static_cast<int>(k2.size()));
  EXPECT_NEAR(o.resumed.x, o.uninterrupted.x, 5e-5);
  EXPECT_NEAR(o.resumed.y, o.uninterrupted.y, 5e-5);
  EXPECT_NEAR(o.resumed.theta, o.uninterrupted.theta, 1e-12);
}

// A record whose counter went backwards beyond what the wheels can do (the chips were reset):
// fresh start at the origin, never a pose from a wrong count.
TEST(Resume, ChipResetStartsFresh) {
  Motion m;
  m.rates = {{20000, 20000}};
  World w(m);
  auto enc = drivers::Hctl1100Encoder::create(w.bus, hctl_config()).value();
  auto a = make_loop(w, enc);
  a->start();
  tick_until(*a, w.clock, 1.0);
  loop::StateRecord rec;
  loop::fill_state_record(*a, rec);
  rec.sequence = 1;
  rec.backend = 1;
  rec.left += 5'000'000;  // as if the chip had counted 5e6 more before it was reset
  auto b = make_loop(w, enc);
  w.clock.advance(from_seconds(0.3));
  b->resume_from(rec, context_for(*b));
  b->start();
  EXPECT_EQ(b->resume_decision().reason, loop::ResumeReason::kCounterJump);
  EXPECT_EQ(b->odometry().pose().x, 0.0);
}

// Issue 39: a jump the running driver rejected stays rejected after a restart. The right chip's
// counter leaps by 100 000 counts at 1 s (far over 200 000 counts/s * 10 ms); the driver flags
// the tick's step and integrates nothing of it (that tick's 200 counts of real motion go with
// it: the step cannot be split). The record keeps the chip's own counter (the reported count
// plus the rejected step), so the restarted process, whose driver reports the chip's counter as
// it is, sees only the gap's motion: the run with a restart 0.5 s after the jump ends where the
// same run without a restart ends (straight legs: to rounding, as in
// StraightRunEndsWhereTheUninterruptedRunEnds), heading and all.
TEST(Resume, RejectedJumpThenRestartResumesWithoutTheJump) {
  Motion m;
  m.rates = {{20000, 20000}};
  auto drive = [&m](bool restart) {
    World w(m);
    auto first = drivers::Hctl1100Encoder::create(w.bus, hctl_config()).value();
    auto a = make_loop(w, first);
    a->start();
    tick_until(*a, w.clock, 1.0);
    w.r.inject_jump(100'000);
    tick_until(*a, w.clock, 1.5);
    // One tick's 200 counts of the right wheel lost with the jump: -200 * 1.438e-5 / 0.34 rad.
    EXPECT_NEAR(a->odometry().pose().theta, -200 * 1.438e-5 / 0.34, 1e-6);
    if (!restart) {
      tick_until(*a, w.clock, m.duration());
      return a->odometry().pose();
    }
    loop::StateRecord rec;
    loop::fill_state_record(*a, rec);
    rec.sequence = 1;
    rec.backend = 1;
    // The record holds the chips' counters, not the re-based readings: both wheels' real motion
    // (equal, straight) and the right's jump, right = left + 100 000.
    EXPECT_EQ(wrap_delta(rec.left, rec.right, 24), 100'000);
    loop::StateBytes bytes{};
    loop::encode_state(rec, bytes);
    w.clock.advance(from_seconds(0.3));
    auto second = drivers::Hctl1100Encoder::create(w.bus, hctl_config()).value();
    auto b = make_loop(w, second);
    b->resume_from(loop::decode_state(bytes).value(), context_for(*b));
    b->start();
    EXPECT_TRUE(b->resume_decision().resumed())
        << loop::resume_reason_name(b->resume_decision().reason);
    EXPECT_EQ(b->resume_decision().dl, b->resume_decision().dr);  // the gap's motion, straight
    tick_until(*b, w.clock, m.duration());
    return b->odometry().pose();
  };
  const Pose2 through = drive(false), restarted = drive(true);
  EXPECT_NEAR(restarted.x, through.x, 1e-12);
  EXPECT_NEAR(restarted.y, through.y, 1e-12);
  EXPECT_NEAR(restarted.theta, through.theta, 1e-12);
}

// A motor controller that starts sending only 30 ms after the loop starts: ODrive count frames
// of both axes every 10 ms, counts from 5000, +10 per frame, put on the port as time passes
// (each read first publishes what was sent up to then), read by the real CAN driver.
struct LateController final : EncoderSource {
  LateController() {
    drivers::CanEncoderConfig c;
    c.left = drivers::odrive_count_layout(0);
    c.right = drivers::odrive_count_layout(1);
    c.timeout = from_seconds(0.1);
    c.max_counts_per_s = 200000;
    enc.emplace(drivers::CanEncoderSource::create(port, c).value());
  }
  EncoderSample read(TimeNs now) noexcept override {
    for (; next <= now; next += from_seconds(0.01), count += 10) {
      for (std::uint32_t node = 0; node < 2; ++node) {
        CanFrame f;
        f.id = node << 5 | 0x00A;
        f.len = 8;
        for (int i = 0; i < 4; ++i)
          f.data[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(count >> (8 * i));
        f.stamp = next;
        port.inject(f);
      }
    }
    return enc->read(now);
  }
  int counter_bits() const noexcept override { return 32; }
  sim::SimCanPort port{8, 512};
  std::optional<drivers::CanEncoderSource> enc;
  TimeNs next = from_seconds(0.03);
  std::int32_t count = 5000;
};

// The loop's start waits (start_wait) for the controller's first frames, so that its reference
// is the controller's own count and a record made at 4900 counts resumes with the 100 counts of
// the gap; without the wait the reference is the driver's 0 before any frame: no resume
// (encoder-not-ready), and the loop counts the wheels from their first fresh count, never
// jumping from 0 to 5000.
TEST(ResumeCan, StartWaitsForTheControllersFirstFramesThenResumes) {
  const Kinematics k = kinematics();
  loop::StateRecord rec;
  rec.sequence = 1;
  rec.left = rec.right = 4900;
  rec.counter_bits = 32;
  rec.backend = 1;
  rec.metres_per_count_left = k.metres_per_count_left();
  rec.metres_per_count_right = k.metres_per_count_right();
  rec.wheelbase = k.wheelbase();
  rec.pose = Pose2{1.0, 2.0, 0.5};
  for (const bool wait : {true, false}) {
    sim::VirtualClock clock;
    LateController ctl;
    loop::LoopConfig cfg{100.0};
    cfg.start_wait = wait ? from_seconds(0.1) : 0;
    auto l = loop::OdometryLoop::create(cfg, k, ctl, clock).value();
    loop::ResumeContext c = context_for(*l);
    c.max_wheel_speed = 3.0;
    l->resume_from(rec, c);
    l->start();
    if (wait) {
      // First frames at 30 ms (count 5000): read at 30 ms, after 30 waits of 1 ms.
      EXPECT_EQ(l->last_left(), 5000);
      EXPECT_EQ(l->last_right(), 5000);
      EXPECT_EQ(l->last_stamp(), from_seconds(0.03));
      ASSERT_TRUE(l->resume_decision().resumed())
          << loop::resume_reason_name(l->resume_decision().reason);
      EXPECT_EQ(l->resume_decision().dl, 100);
      EXPECT_EQ(l->resume_decision().dr, 100);
      // Straight on from (1, 2) at 0.5 rad: 100 counts * 1.438e-5 m = 1.438 mm.
      const double d = 100 * k.metres_per_count_left();
      EXPECT_NEAR(l->odometry().pose().x, 1.0 + d * std::cos(0.5), 1e-12);
      EXPECT_NEAR(l->odometry().pose().y, 2.0 + d * std::sin(0.5), 1e-12);
    } else {
      EXPECT_EQ(l->last_left(), 0);
      EXPECT_EQ(l->resume_decision().reason, loop::ResumeReason::kEncoderNotReady);
      // Ticks up to 100 ms: frames at 30..100 ms, counts 5000..5070; the first fresh count is
      // the wheels' reference: 70 counts of motion, no jump from 0 to 5000.
      tick_until(*l, clock, 0.1);
      EXPECT_EQ(l->last_left(), 5070);
      EXPECT_EQ(l->last_right(), 5070);
      EXPECT_NEAR(l->odometry().distance(), 70 * k.metres_per_count_left(), 1e-15);
    }
  }
}

}  // namespace
}  // namespace odo
