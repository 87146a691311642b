// The simulated LabMate of issue 18: random excursions from a dock and the UMBmark E_max,syst
// that scores a calibration (shared by sim_selfcal and odomctl selfcal simulate).
#include <cmath>

#include "odo/analysis/selfcal_tools.hpp"
#include "odo/analysis/umbmark_tools.hpp"
#include "odo/calibration/umbmark.hpp"
#include "odo/sim/floor.hpp"

namespace odo::analysis {
namespace {

constexpr TimeNs kTick = 10'000'000;  // 100 Hz

const sim::RobotGeometry& truth_geometry() {
  static const sim::RobotGeometry g = sim::labmate_geometry(kSelfCalDn);
  return g;
}

// piece: wheel angular velocities [rad/s] for centre speed v [m/s] and turn rate w [rad/s].
sim::Segment piece(double duration, double v, double w) {
  return {duration, (v - w * kSelfCalBn / 2) / (kSelfCalDn / 2),
          (v + w * kSelfCalBn / 2) / (kSelfCalDn / 2)};
}

void turn_to(sim::Scenario& s, double angle) {
  const double rate = 0.5;
  s.push_back(piece(std::fabs(angle) / rate, 0.0, angle > 0 ? rate : -rate));
  s.push_back({0.5, 0.0, 0.0});
}

Pose2 end_pose(const sim::Scenario& s, const Pose2& start) {
  auto r = *sim::SimRobot::create(truth_geometry(), s, start);
  r.advance_to(from_seconds(sim::scenario_duration(s) + 0.01));
  return r.true_pose();
}

}  // namespace

calib::Factors selfcal_truth() {
  const sim::RobotGeometry& g = truth_geometry();
  return {g.wheel_diameter_left / kSelfCalDn, g.wheel_diameter_right / kSelfCalDn, g.wheelbase};
}

Kinematics selfcal_kinematics(const calib::Factors& f) {
  KinematicParams p = sim::nominal_params(kSelfCalDn, kSelfCalBn, truth_geometry());
  p.c_l = f.c_l;
  p.c_r = f.c_r;
  p.wheelbase = f.wheelbase;
  return *Kinematics::create(p);
}

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

double selfcal_e_max_syst(const calib::Factors& f, bool rough, int n, std::uint64_t floor_seed) {
  const Kinematics k = selfcal_kinematics(f);
  std::vector<calib::UmbmarkRun> runs;
  for (int i = 0; i < 2 * n; ++i) {
    sim::SquareOptions so;
    so.direction = i < n ? sim::Turn::kClockwise : sim::Turn::kCounterClockwise;
    auto robot = *sim::SimRobot::create(truth_geometry(), sim::square_scenario(k, so));
    sim::UmbmarkFloor::Options fo;
    fo.roughness_height = rough ? kPaperRoughness : 0.0;
    sim::UmbmarkFloor floor(fo, floor_seed + static_cast<std::uint64_t>(i));
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
    runs.push_back({i < n ? calib::Direction::kCw : calib::Direction::kCcw,
                    robot.true_pose().x - odo.pose().x, robot.true_pose().y - odo.pose().y,
                    std::nullopt, false});
  }
  return calib::e_max_syst(calib::centre_of_gravity(runs, calib::Direction::kCw),
                           calib::centre_of_gravity(runs, calib::Direction::kCcw));
}

}  // namespace odo::analysis
