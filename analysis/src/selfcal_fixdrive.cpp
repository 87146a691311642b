// Fixes taken anywhere (issue 34): a robot whose c_L, c_R and b are drawn at random drives
// excursions (open, or back to a dock) with Chong-Kleeman wheel noise, stands still 0.5 s at the
// end of each, and gets a fix of its true pose there. Shared by sim_selfcal_open, its study and
// `odomctl selfcal simulate --scenario open`.
#include <cmath>
#include <iomanip>
#include <numbers>
#include <optional>
#include <sstream>

#include "odo/analysis/selfcal_tools.hpp"
#include "odo/analysis/skid_tools.hpp"
#include "odo/sim/skid_steer.hpp"
#include "odo/sim/wheel_noise.hpp"

namespace odo::analysis {
namespace {

constexpr TimeNs kTick = 10'000'000;  // 100 Hz
constexpr double kStop = 0.5;         // [s] the robot stands still at every fix

// piece: wheel angular velocities [rad/s] for centre speed v [m/s] and turn rate w [rad/s], as
// the robot commands them (its nominal wheel diameter and wheelbase n).
sim::Segment piece(double duration, double v, double w, const KinematicParams& n) {
  return {duration, (v - w * n.wheelbase / 2) / (n.wheel_diameter / 2),
          (v + w * n.wheelbase / 2) / (n.wheel_diameter / 2)};
}

// open_excursion: 4 to 9 pieces: turns on the spot (0.3-3 rad at 0.5 rad/s), straights (1-4 m
// at 0.2 m/s) and arcs (radius 0.5-2 m, 0.8-2.4 rad at 0.2 m/s), then the stop.
sim::Scenario open_excursion(std::mt19937_64& rng, const KinematicParams& nominal) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  sim::Scenario s;
  const int n = 4 + static_cast<int>(6 * u(rng));
  for (int i = 0; i < n; ++i) {
    const double kind = u(rng), sign = u(rng) < 0.5 ? -1.0 : 1.0;
    if (kind < 0.3) {
      s.push_back(piece((0.3 + 2.7 * u(rng)) / 0.5, 0.0, sign * 0.5, nominal));
    } else if (kind < 0.65) {
      s.push_back(piece((1.0 + 3.0 * u(rng)) / 0.2, 0.2, 0.0, nominal));
    } else {
      const double radius = 0.5 + 1.5 * u(rng), angle = 0.8 + 1.6 * u(rng);
      s.push_back(piece(angle * radius / 0.2, 0.2, sign * 0.2 / radius, nominal));
    }
  }
  s.push_back({kStop, 0.0, 0.0});
  return s;
}

// draw_truth: the true geometry of the drive (see FixDriveOptions).
sim::RobotGeometry draw_truth(const FixDriveOptions& o, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::normal_distribution<double> n01;
  sim::RobotGeometry g;
  const bool prior = o.prior_sigma_factor > 0.0;
  const double cl =
      prior ? 1.0 + o.prior_sigma_factor * n01(rng) : 1.0 + o.max_factor_error * u(rng);
  const double cr =
      prior ? 1.0 + o.prior_sigma_factor * n01(rng) : 1.0 + o.max_factor_error * u(rng);
  g.wheelbase = prior ? kSelfCalBn + o.prior_sigma_wheelbase * n01(rng)
                      : kSelfCalBn * (1.0 + o.max_wheelbase_error * u(rng));
  g.wheel_diameter_left = cl * kSelfCalDn;
  g.wheel_diameter_right = cr * kSelfCalDn;
  g.counts_per_rev = o.direct_drive ? 4096 : 2048;
  g.gear_ratio = o.direct_drive ? 1 : 16;
  return g;
}

// Plan: the whole drive as one scenario and the fix moments (the middle of every stop).
struct Plan {
  sim::Scenario scenario;
  std::vector<TimeNs> fix_times;
};

TimeNs stop_middle(const sim::Scenario& s) {
  const double mid = sim::scenario_duration(s) - 0.5 * kStop;
  return static_cast<TimeNs>(std::llround(mid * 100.0)) * kTick;  // on a tick
}

Plan plan(const FixDriveOptions& o, const sim::RobotGeometry& g, const KinematicParams& nominal,
          std::mt19937_64& rng) {
  Plan p;
  p.scenario.push_back({kStop, 0.0, 0.0});
  p.fix_times.push_back(stop_middle(p.scenario));
  Pose2 pose;
  for (int e = 0; e < o.excursions; ++e) {
    // Dock excursions are planned from the noise-free pose (the planner's view).
    const sim::Scenario ex = o.dock ? random_excursion(rng, pose) : open_excursion(rng, nominal);
    p.scenario.insert(p.scenario.end(), ex.begin(), ex.end());
    if (o.dock) p.scenario.push_back({kStop, 0.0, 0.0});
    p.fix_times.push_back(stop_middle(p.scenario));
    if (o.dock) {
      auto r = *sim::SimRobot::create(g, p.scenario);
      r.advance_to(from_seconds(sim::scenario_duration(p.scenario)));
      pose = r.true_pose();
    }
  }
  return p;
}

// make_fix: the true pose plus the fix noise; with probability o.outliers (not the first fix)
// moved 0.5-5 m in a random direction.
calib::PoseFix make_fix(const FixDriveOptions& o, const Pose2& truth, TimeNs t, bool may_corrupt,
                        std::mt19937_64& rng, bool& corrupted) {
  std::normal_distribution<double> n01;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  calib::PoseFix f{t,
                   truth.x + o.sigma_xy * n01(rng),
                   truth.y + o.sigma_xy * n01(rng),
                   wrap_angle(truth.theta + o.sigma_theta * n01(rng)),
                   o.sigma_xy,
                   o.sigma_theta};
  corrupted = may_corrupt && u(rng) < o.outliers;
  if (corrupted) {
    const double r = 0.5 + 4.5 * u(rng), a = 2 * std::numbers::pi * u(rng);
    f.x += r * std::cos(a);
    f.y += r * std::sin(a);
  }
  return f;
}

// skid_body: the friction body of a kSkid4 drive (none for the LabMate).
std::optional<sim::SkidSteerBody> skid_body(const FixDriveOptions& o) {
  if (o.robot != UmbmarkRobot::kSkid4) return std::nullopt;
  sim::SkidSteerParams p = sim::jackal_skid_params();
  p.com_x = o.com_x;
  auto body = sim::SkidSteerBody::create(p);
  if (!body) return std::nullopt;  // com_x out of range: the caller checks it first
  return std::move(body).value();
}

}  // namespace

FixDrive simulate_fix_drive(const FixDriveOptions& o) {
  std::mt19937_64 rng(o.seed);
  FixDrive d;
  std::optional<sim::SkidSteerBody> body = skid_body(o);
  if (body) {
    // The wheels as built; the track is what the floor makes of it (centre speed 0.2 m/s).
    d.geometry = sim::skid4_geometry();
    const double dn = d.geometry.wheel_diameter_left, t = d.geometry.wheelbase;
    d.truth = {1.0, 1.0, sim::skid_effective_track(body->params(), -0.2, 0.2)};
    const sim::SkidSolution spot = sim::solve_skid_twist(body->params(), -0.2, 0.2);
    d.truth_x_icr = icr_of(spot.twist, -0.2, 0.2).x_icr + 0.0;  // + 0.0: -0 (centred) as 0
    d.nominal = sim::nominal_params(dn, kSkidTrackMultiplier * t, d.geometry);
  } else {
    d.geometry = draw_truth(o, rng);
    d.truth = {d.geometry.wheel_diameter_left / kSelfCalDn,
               d.geometry.wheel_diameter_right / kSelfCalDn, d.geometry.wheelbase};
    d.nominal = sim::nominal_params(kSelfCalDn, kSelfCalBn, d.geometry);
  }
  const Plan p = plan(o, d.geometry, d.nominal, rng);
  auto robot = *sim::SimRobot::create(d.geometry, p.scenario);
  if (body) robot.set_skid_body(&*body);
  sim::WheelNoise noise(o.wheel_noise.k_left, o.wheel_noise.k_right, o.seed * 7919 + 1);
  robot.set_travel_perturbation(&noise);
  calib::CountRecorder rec(*calib::recorder_limits(*Kinematics::create(d.nominal)));
  rec.start(0);
  d.ticks.push_back({0.0, robot.counts_left(), robot.counts_right()});
  calib::CountSegment seg;
  std::size_t next = 0;
  const TimeNs end = from_seconds(sim::scenario_duration(p.scenario));
  for (TimeNs t = 0; t <= end; t += kTick) {
    if (t > 0) {
      robot.advance_to(t);
      const CountRow prev = d.ticks.back();
      d.ticks.push_back({to_seconds(t), robot.counts_left(), robot.counts_right()});
      if (rec.add_tick(t, d.ticks.back().left - prev.left, d.ticks.back().right - prev.right, seg))
        d.segments.push_back(seg);
    }
    if (next < p.fix_times.size() && t == p.fix_times[next]) {
      bool bad = false;
      d.fixes.push_back(make_fix(o, robot.true_pose(), t, next > 0, rng, bad));
      d.true_poses.push_back(robot.true_pose());
      d.corrupted.push_back(bad);
      ++next;
    }
  }
  if (rec.flush(seg)) d.segments.push_back(seg);
  if (body) {
    d.spot_turn_rim = body->spot_turn_rim();
    d.spot_turn_angle = body->spot_turn_angle();
    d.unconverged = body->unconverged();
  }
  return d;
}

calib::SelfCalConfig fix_drive_config(const FixDrive& d, const FixDriveOptions& o,
                                      calib::SelfCalConfig base) {
  KinematicParams k = d.nominal;
  base.metres_per_count = Kinematics::create(k)->metres_per_count();
  base.in_use = {1.0, 1.0, d.nominal.wheelbase};
  base.odometry_noise = o.wheel_noise;
  if (o.robot == UmbmarkRobot::kSkid4) base.icr = calib::IcrFit::kFit;
  return base;
}

std::string count_log_csv(const std::vector<CountRow>& rows) {
  std::ostringstream s;
  s << "t,left,right\n" << std::fixed << std::setprecision(2);
  for (const CountRow& r : rows) s << r.t << ',' << r.left << ',' << r.right << '\n';
  return s.str();
}

std::string fixes_csv(const std::vector<calib::PoseFix>& fixes) {
  std::ostringstream s;
  s << "t,x,y,theta,sigma_xy,sigma_theta\n" << std::setprecision(17);
  for (const calib::PoseFix& f : fixes) {
    s << to_seconds(f.t) << ',' << f.x << ',' << f.y << ',';
    if (f.theta) s << *f.theta;
    s << ',' << f.sigma_xy << ',';
    if (f.theta) s << f.sigma_theta;
    s << '\n';
  }
  return s.str();
}

}  // namespace odo::analysis
