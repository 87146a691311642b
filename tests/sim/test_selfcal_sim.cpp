// Self-calibration from dock fixes on the simulated LabMate (issue 18): true wheelbase 0.337 m
// against 0.340 nominal, diameter ratio 0.9985. The robot drives random excursions from a dock
// (turns on the spot, straights, arcs, then back to the dock); a fix of the true pose (plus its
// noise) is taken at the dock after every excursion. The loop's recording is done here by
// hand, tick by tick (SimEncoderSource + CountRecorder at 100 Hz), as the daemon will do it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <set>
#include <vector>

#include "odo/calibration/count_recorder.hpp"
#include "odo/calibration/selfcal.hpp"
#include "odo/calibration/umbmark.hpp"
#include "odo/firmware/umbmark_tools.hpp"
#include "odo/odometry/pose.hpp"
#include "odo/sim/floor.hpp"
#include "odo/sim/robot.hpp"
#include "odo/sim/sim_encoder.hpp"

namespace odo {
namespace {

using calib::Factors;
constexpr double kDn = 0.15, kBn = 0.34;  // nominal diameter and wheelbase [m]
constexpr TimeNs kTick = 10'000'000;      // 100 Hz
constexpr double kPi = std::numbers::pi;

const sim::RobotGeometry kTruthGeometry = sim::labmate_geometry(kDn);

// The true absolute factors: c = D_true / Dn per wheel (Eq. 6.35), b = 0.337 m.
Factors true_factors() {
  return {kTruthGeometry.wheel_diameter_left / kDn, kTruthGeometry.wheel_diameter_right / kDn,
          kTruthGeometry.wheelbase};
}

Kinematics kinematics(const Factors& f) {
  KinematicParams p = sim::nominal_params(kDn, kBn, kTruthGeometry);
  p.c_l = f.c_l;
  p.c_r = f.c_r;
  p.wheelbase = f.wheelbase;
  return *Kinematics::create(p);
}

// Wheel angular velocities [rad/s] for centre speed v [m/s] and turn rate w [rad/s], as the
// robot commands them with its nominal geometry.
sim::Segment piece(double duration, double v, double w) {
  return {duration, (v - w * kBn / 2) / (kDn / 2), (v + w * kBn / 2) / (kDn / 2)};
}

void turn_to(sim::Scenario& s, double angle) {
  const double rate = 0.5;
  s.push_back(piece(std::fabs(angle) / rate, 0.0, angle > 0 ? rate : -rate));
  s.push_back({0.5, 0.0, 0.0});
}

Pose2 end_pose(const sim::Scenario& s, const Pose2& start) {
  auto r = *sim::SimRobot::create(kTruthGeometry, s, start);
  r.advance_to(from_seconds(sim::scenario_duration(s) + 0.01));
  return r.true_pose();
}

// random_excursion: two to four random pieces, then turn towards the dock (origin), drive
// there and turn back to heading 0 (planned from the true pose: any planner will do).
sim::Scenario random_excursion(std::mt19937_64& rng, const Pose2& start) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  sim::Scenario s;
  const int n = 2 + static_cast<int>(3 * u(rng));
  for (int i = 0; i < n; ++i) {
    const double kind = u(rng);
    if (kind < 0.35) {
      turn_to(s, (u(rng) < 0.5 ? -1 : 1) * (0.5 + 2.6 * u(rng)));
    } else if (kind < 0.7) {
      s.push_back(piece((1.0 + 3.0 * u(rng)) / 0.2, 0.2, 0.0));
      s.push_back({0.5, 0.0, 0.0});
    } else {
      const double radius = 0.5 + 1.5 * u(rng), angle = 0.8 + 1.6 * u(rng);
      const double w = (u(rng) < 0.5 ? -1 : 1) * 0.2 / radius;
      s.push_back(piece(angle / std::fabs(w), 0.2, w));
    }
  }
  Pose2 p = end_pose(s, start);
  turn_to(s, wrap_angle(std::atan2(-p.y, -p.x) - p.theta));
  p = end_pose(s, start);
  s.push_back(piece(std::hypot(p.x, p.y) / 0.2, 0.2, 0.0));
  s.push_back({0.5, 0.0, 0.0});
  p = end_pose(s, start);
  turn_to(s, wrap_angle(-p.theta));
  return s;
}

struct Drive {
  std::vector<calib::CountSegment> segments;
  std::vector<calib::PoseFix> fixes;
  std::vector<Pose2> truth;  // true pose at every fix
};

struct DriveOptions {
  int excursions = 20;
  double sigma_xy = 0.0;  // fix noise [m]
  double sigma_th = 0.0;  // [rad]
  bool rough_floor = false;
  std::uint64_t seed = 1;
};

// drive: the excursions with a dock fix after each one (and one at the start).
Drive drive(const DriveOptions& o) {
  std::mt19937_64 rng(o.seed);
  std::normal_distribution<double> n01;
  calib::CountRecorder rec(*calib::recorder_limits(kinematics({1.0, 1.0, kBn})));
  Drive d;
  Pose2 pose;  // true pose, the dock at the origin
  TimeNs t0 = 0;
  auto take_fix = [&](TimeNs t) {
    d.truth.push_back(pose);
    // Declared sigmas of noise-free fixes: 0.1 mm, 0.1 mrad (a sigma must be positive).
    d.fixes.push_back({t, pose.x + o.sigma_xy * n01(rng), pose.y + o.sigma_xy * n01(rng),
                       wrap_angle(pose.theta + o.sigma_th * n01(rng)), std::max(o.sigma_xy, 1e-4),
                       std::max(o.sigma_th, 1e-4)});
  };
  rec.start(0);
  take_fix(0);
  for (int e = 0; e < o.excursions; ++e) {
    auto robot = *sim::SimRobot::create(kTruthGeometry, random_excursion(rng, pose), pose);
    sim::UmbmarkFloor::Options fo;
    fo.roughness_height = o.rough_floor ? fw::kPaperRoughness : 0.0;
    sim::UmbmarkFloor floor(fo, o.seed * 1000 + static_cast<std::uint64_t>(e));
    robot.set_travel_perturbation(&floor);
    sim::SimEncoderSource enc(robot, 32);
    EncoderSample prev = enc.read(0);
    const TimeNs end = from_seconds(sim::scenario_duration(robot.scenario()) + 1.0);
    calib::CountSegment seg;
    TimeNs t = kTick;
    for (; t <= end; t += kTick) {
      const EncoderSample s = enc.read(t);
      if (rec.add_tick(t0 + t, s.left - prev.left, s.right - prev.right, seg))
        d.segments.push_back(seg);
      prev = s;
    }
    if (rec.flush(seg)) d.segments.push_back(seg);
    t0 += t - kTick;
    pose = robot.true_pose();
    take_fix(t0);
  }
  return d;
}

calib::SelfCalConfig config(bool noise) {
  calib::SelfCalConfig c;
  c.metres_per_count = kinematics({1.0, 1.0, kBn}).metres_per_count();
  c.in_use = {1.0, 1.0, kBn};
  if (!noise) c.odometry_noise = {1e-5, 1e-5};  // count quantisation only
  return c;
}

Result<calib::SelfCalResult> fit(const Drive& d, const calib::SelfCalConfig& c, std::size_t n) {
  auto t = calib::build_track(d.segments, std::span(d.fixes).first(n));
  if (!t) return std::move(t).error();
  return calib::fit_fixes(*t, c);
}

// e_max_syst: UMBmark of a robot using factors f: 5 cw + 5 ccw 4 m squares on the same floor
// (same seeds for every f), return error = true pose - the robot's odometry (per tick, 100 Hz).
double e_max_syst(const Factors& f, bool rough) {
  const Kinematics k = kinematics(f);
  std::vector<calib::UmbmarkRun> runs;
  for (int i = 0; i < 10; ++i) {
    sim::SquareOptions so;
    so.direction = i < 5 ? sim::Turn::kClockwise : sim::Turn::kCounterClockwise;
    auto robot = *sim::SimRobot::create(kTruthGeometry, sim::square_scenario(k, so));
    sim::UmbmarkFloor::Options fo;
    fo.roughness_height = rough ? fw::kPaperRoughness : 0.0;
    sim::UmbmarkFloor floor(fo, 500 + static_cast<std::uint64_t>(i));
    robot.set_travel_perturbation(&floor);
    Odometry odo(k);
    std::int64_t pl = robot.counts_left(), pr = robot.counts_right();
    const TimeNs end = from_seconds(sim::scenario_duration(robot.scenario()) + 1.0);
    for (TimeNs t = kTick; t <= end; t += kTick) {
      robot.advance_to(t);
      odo.update(robot.counts_left() - pl, robot.counts_right() - pr, 0.01);
      pl = robot.counts_left();
      pr = robot.counts_right();
    }
    runs.push_back({i < 5 ? calib::Direction::kCw : calib::Direction::kCcw,
                    robot.true_pose().x - odo.pose().x, robot.true_pose().y - odo.pose().y,
                    std::nullopt, false});
  }
  return calib::e_max_syst(calib::centre_of_gravity(runs, calib::Direction::kCw),
                           calib::centre_of_gravity(runs, calib::Direction::kCcw));
}

double rel_err(double v, double truth) {
  return std::fabs(v / truth - 1.0);
}

TEST(SelfCalSim, NoiseFreeFixesWithinFiveHundredthsOfAPercent) {
  const Drive d = drive({20, 0.0, 0.0, false, 1});
  const Factors tr = true_factors();
  std::printf("truth c_l %.6f c_r %.6f b %.6f m; %zu segments for 20 excursions\n", tr.c_l, tr.c_r,
              tr.wheelbase, d.segments.size());
  for (std::size_t n : {3U, 5U, 9U, 21U}) {
    auto r = fit(d, config(false), n);
    ASSERT_TRUE(r) << r.error().message;
    std::printf(
        "%2zu excursions: c_l %+.4f %% c_r %+.4f %% b %+.4f %% (sigma %.2g %.2g, b %.3g mm) %s\n",
        n - 1, 100 * (r->estimate.c_l / tr.c_l - 1), 100 * (r->estimate.c_r / tr.c_r - 1),
        100 * (r->estimate.wheelbase / tr.wheelbase - 1), r->sigma[0], r->sigma[1],
        1e3 * r->sigma[2], calib::verdict_name(r->verdict));
    if (n == 21U) {
      EXPECT_LT(rel_err(r->estimate.c_l, tr.c_l), 5e-4);
      EXPECT_LT(rel_err(r->estimate.c_r, tr.c_r), 5e-4);
      EXPECT_LT(rel_err(r->estimate.wheelbase, tr.wheelbase), 5e-4);
      EXPECT_EQ(r->fixes_rejected, 0);
      EXPECT_EQ(r->verdict, calib::Verdict::kAccepted);
    }
  }
}

TEST(SelfCalSim, NoisyFixesBeatOneManualUmbmarkPass) {
  // Fixes with sigma 5 mm and 0.5 deg, the report's floor (roughness up to 1.3 mm every ~2 cm)
  // under the excursions and under every UMBmark square. The manual pass is the firmware's
  // UMBmark simulation at the report's noise (floor + 2 mm / 0.4 deg reference), 5 + 5 runs.
  const Drive d = drive({20, 0.005, 0.5 * kPi / 180.0, true, 2});
  fw::UmbmarkSimOptions uo;
  uo.noise = "paper";
  auto manual = fw::run_umbmark_simulation(uo);
  ASSERT_TRUE(manual) << manual.error().message;
  const Factors m = manual->passes[0].result.composed;
  const double e_nominal = e_max_syst({1.0, 1.0, kBn}, true);
  const double e_manual = e_max_syst(m, true);
  std::printf(
      "nominal: E_max,syst %.2f mm; manual UMBmark pass: c_l %.6f c_r %.6f b %.3f mm, "
      "E_max,syst %.2f mm (its own verification: %.2f mm)\n",
      1e3 * e_nominal, m.c_l, m.c_r, 1e3 * m.wheelbase, 1e3 * e_manual,
      1e3 * manual->passes[0].after.e_max_syst);
  double e_last = 0.0;
  for (std::size_t n : {5U, 9U, 13U, 17U, 21U}) {
    auto r = fit(d, config(true), n);
    ASSERT_TRUE(r) << r.error().message;
    e_last = e_max_syst(r->estimate, true);
    std::printf(
        "%2zu excursions: c_l %.6f c_r %.6f b %.3f mm (sigma %.2g %.2g %.3f mm) "
        "E_max,syst %.2f mm, rejected %d, held-out chi2/dof %.2f vs %.2f in use: %s\n",
        n - 1, r->estimate.c_l, r->estimate.c_r, 1e3 * r->estimate.wheelbase, r->sigma[0],
        r->sigma[1], 1e3 * r->sigma[2], 1e3 * e_last, r->fixes_rejected, r->score_candidate,
        r->score_in_use, calib::verdict_name(r->verdict));
    if (n == 21U) {
      // The rough floor shortens the true travel by about 0.3 % and the dock cannot see the
      // scale, which stays at 1: the effective b is 0.337 / 0.997 = 338.0 mm (the manual pass
      // finds 338.2 mm too). So b is not compared with the geometric 337 mm here.
      EXPECT_EQ(r->fixes_rejected, 0);
      EXPECT_TRUE(r->scale_held);
      EXPECT_EQ(r->verdict, calib::Verdict::kAccepted);
    }
  }
  EXPECT_LE(e_last, e_manual);
}

}  // namespace
}  // namespace odo
