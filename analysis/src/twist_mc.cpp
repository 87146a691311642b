// Monte Carlo of the twist covariance the ROS 2 output publishes (issue 19): the simulated robot
// with wheel noise on its true travel, the firmware's loop measuring (v, omega) over one tick,
// against twist_covariance for the wheel travels the loop measured on that tick.
#include <cmath>

#include "mc_robot.hpp"
#include "odo/analysis/error_model_tools.hpp"
#include "odo/analysis/seed.hpp"
#include "odo/sim/robot.hpp"
#include "odo/sim/sim_run.hpp"
#include "odo/sim/wheel_noise.hpp"

namespace odo::analysis {
namespace {

constexpr double kTwistArcRadius = 2.0;  // [m]: the centre's circle (both v and omega non-zero)
constexpr double kTwistWarmUp = 1.0;     // [s] of driving before the measured tick

// one_tick_error: true minus measured (v, omega) over the tick after the warm-up of one run;
// predicted: that tick's covariance from the wheel travels the loop counted.
Result<std::array<double, 2>> one_tick_error(const sim::RobotGeometry& g, const Kinematics& k,
                                             const sim::Scenario& path,
                                             const sim::SimRunOptions& so, const McOptions& o,
                                             std::array<double, 4>& predicted) {
  auto run = sim::SimRun::create(g, k, path, so);
  if (!run) return std::move(run).error();
  loop::OdometryLoop& loop = (*run)->loop();
  loop.start();
  const int warm = static_cast<int>(std::lround(kTwistWarmUp * o.rate_hz));
  for (int t = 0; t < warm; ++t) loop.tick();
  const Pose2 p0 = (*run)->robot().true_pose();
  const TimeNs t0 = loop.snapshot().stamp;
  loop.tick();
  const Pose2 p1 = (*run)->robot().true_pose();
  const double dt = to_seconds(loop.snapshot().stamp - t0);
  const double v = loop.odometry().linear_velocity(), w = loop.odometry().angular_velocity();
  // True twist over the same interval: heading change, and the travel along the mean heading
  // (the chord; its bias against the arc length is the same in every run, so it leaves the
  // sample covariance alone).
  const double dth = p1.theta - p0.theta, mid = p0.theta + 0.5 * dth;
  const double ds = (p1.x - p0.x) * std::cos(mid) + (p1.y - p0.y) * std::sin(mid);
  predicted = twist_covariance(loop.snapshot().motion, o.k);
  return std::array<double, 2>{ds / dt - v, dth / dt - w};
}

}  // namespace

Result<TwistMcResult> run_twist_monte_carlo(const McOptions& o) {
  if (auto s = check_mc_options(o); !s) return std::move(s).error();
  auto robot = mc_robot(o);  // true geometry = believed: only the noise
  if (!robot) return std::move(robot).error();
  // Wheel angular velocities for centre speed o.speed on the circle: v -+ omega b / 2 per wheel.
  const double omega = o.speed / kTwistArcRadius, rw = 0.5 * o.wheel_diameter;
  const sim::Scenario path{{2.0 * kTwistWarmUp, (o.speed - 0.5 * o.wheelbase * omega) / rw,
                            (o.speed + 0.5 * o.wheelbase * omega) / rw}};
  sim::WheelNoise noise(o.k.k_left, o.k.k_right, 0);
  const sim::SimRunOptions so = mc_run_options(o, noise);

  TwistMcResult r;
  r.runs = o.runs;
  std::array<double, 2> sum{};
  std::array<double, 4> sq{};
  std::vector<std::array<double, 2>> errors;
  errors.reserve(static_cast<std::size_t>(o.runs));
  for (int i = 0; i < o.runs; ++i) {
    noise.reseed(seed_of(o.seed, static_cast<std::uint64_t>(i)));
    auto e = one_tick_error(robot->truth, robot->believed, path, so, o, r.predicted);
    if (!e) return std::move(e).error();
    errors.push_back(*e);
    for (int a = 0; a < 2; ++a) sum[a] += (*e)[a];
  }
  const double n = static_cast<double>(o.runs);
  for (int a = 0; a < 2; ++a) r.mean[a] = sum[a] / n;
  for (const auto& e : errors)
    for (int a = 0; a < 2; ++a)
      for (int c = 0; c < 2; ++c) sq[2 * a + c] += (e[a] - r.mean[a]) * (e[c] - r.mean[c]);
  for (int i = 0; i < 4; ++i) r.sample[i] = sq[i] / (n - 1.0);
  for (int a = 0; a < 2; ++a) {
    const double pv = r.predicted[3 * a], sv = r.sample[3 * a];
    r.rel_error[a] = (pv <= 1e-30 && sv <= 1e-30) ? 0.0 : std::fabs(pv - sv) / sv;
    r.max_rel_error_diag = std::max(r.max_rel_error_diag, r.rel_error[a]);
  }
  return r;
}

}  // namespace odo::analysis
