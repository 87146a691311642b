// Monte Carlo validation of the error model on the simulated robot, with the firmware's loop.
#include <atomic>
#include <cmath>
#include <numbers>
#include <sstream>

#include "mc_robot.hpp"
#include "odo/analysis/error_model_tools.hpp"
#include "odo/analysis/seed.hpp"
#include "odo/hal/field_range.hpp"
#include "odo/sim/robot.hpp"
#include "odo/sim/sim_run.hpp"
#include "odo/sim/wheel_noise.hpp"

namespace odo::analysis {
namespace {

constexpr double kOutbackDistance = 10.0;             // [m] each way (the paper's experiment)
constexpr double kArcRadius = 2.0;                    // [m] of the centre
constexpr double kArcAngle = 1.5 * std::numbers::pi;  // 270 deg counter-clockwise

// make_path: constant wheel speeds per segment for a robot with wheel radius rw and wheelbase b.
sim::Scenario make_path(const McOptions& o) {
  const double rw = o.wheel_diameter / 2.0;
  const double w = o.speed / rw;  // wheel angular velocity for the centre speed [rad/s]
  if (o.path == McPath::kOutback) {
    const double t = kOutbackDistance / o.speed;
    return {{t, w, w}, {t, -w, -w}};
  }
  // arc: the centre runs on a circle of radius kArcRadius; the wheels on kArcRadius -+ b/2.
  const double t = kArcRadius * kArcAngle / o.speed;
  const double q = o.wheelbase / (2.0 * kArcRadius);
  return {{t, w * (1.0 - q), w * (1.0 + q)}};
}

}  // namespace

Result<McPath> parse_mc_path(std::string_view text) {
  if (auto p = choice_value<McPath>(kMcPaths, text)) return *p;
  return make_error(Errc::kInvalidArgument, "--path = '" + std::string(text) + "' must be " +
                                                choice_join(kMcPaths, " or "));
}

std::string path_description(McPath path) {
  if (path == McPath::kOutback)
    return "10 m forward then 10 m backward, no turn (Chong & Kleeman Sec. 5.2)";
  return "counter-clockwise arc of 270 deg on a 2 m radius (9.42 m)";
}

Status check_mc_options(const McOptions& o) {
  if (o.runs < 2 || o.runs > 1000000)
    return range_error(integer_range("--runs", o.runs, 2, 1000000));
  if (!(o.wheelbase >= 0.05 && o.wheelbase <= 5.0))
    return range_error({"--wheelbase", o.wheelbase, 0.05, 5.0, "m"});
  if (!(o.wheel_diameter >= 0.01 && o.wheel_diameter <= 2.0))
    return range_error({"wheel diameter", o.wheel_diameter, 0.01, 2.0, "m"});
  if (!(o.speed > 0.0 && o.speed <= 5.0)) {
    FieldRange r{"speed", o.speed, 0.0, 5.0, "m/s"};
    r.lo_open = true;
    return range_error(std::move(r));
  }
  if (auto r = error_model_range(o.k)) {
    r->field = r->field == "k_left" ? "--k-left" : "--k-right";  // the options' names
    return range_error(std::move(*r));
  }
  return Ok{};
}

Cov3 sample_covariance(const std::vector<PoseError>& e, PoseError* mean) {
  PoseError mu{};
  for (const PoseError& r : e)
    for (int i = 0; i < 3; ++i) mu[i] += r[i];
  const double n = static_cast<double>(e.size());
  for (double& v : mu) v /= n;
  Cov3 c{};
  for (const PoseError& r : e)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) c[3 * i + j] += (r[i] - mu[i]) * (r[j] - mu[j]);
  for (double& v : c) v /= (n - 1.0);
  if (mean != nullptr) *mean = mu;
  return c;
}

Result<McResult> run_error_monte_carlo(const McOptions& o,
                                       const std::function<void(int, int)>& progress) {
  if (auto s = check_mc_options(o); !s) return std::move(s).error();
  auto robot = mc_robot(o);  // true geometry = believed: no systematic error, only the noise
  if (!robot) return std::move(robot).error();
  const sim::RobotGeometry& g = robot->truth;
  const Kinematics* k = &robot->believed;
  const sim::Scenario path = make_path(o);
  // Two periods of standstill after the path so that the last reading sees the robot stopped.
  const double standstill = 2.0 / o.rate_hz;
  sim::WheelNoise noise(o.k.k_left, o.k.k_right, 0);
  const sim::SimRunOptions so = mc_run_options(o, noise);

  McResult r;
  r.runs = o.runs;
  r.errors.reserve(static_cast<std::size_t>(o.runs));
  const int report_every = std::max(1, o.runs / 20);
  for (int i = 0; i < o.runs; ++i) {
    noise.reseed(seed_of(o.seed, static_cast<std::uint64_t>(i)));
    auto run = sim::SimRun::create(g, *k, path, so);
    if (!run) return std::move(run).error();
    (*run)->drive(standstill);
    const Pose2 e = (*run)->error();
    r.errors.push_back({e.x, e.y, e.theta});
    // The encoders count the wheels' rotation, which the noise does not touch, so every run's
    // odometry and covariance are the same; keep the last.
    r.predicted = (*run)->loop().snapshot().cov;
    if (progress && ((i + 1) % report_every == 0 || i + 1 == o.runs)) progress(i + 1, o.runs);
  }
  r.sample = sample_covariance(r.errors, &r.mean);
  for (int i = 0; i < 3; ++i) {
    const double pv = r.predicted[4 * i], sv = r.sample[4 * i];
    // With k = 0 both variances vanish (every run is identical); that is agreement, not 0/0.
    r.rel_error[i] = (pv <= 1e-30 && sv <= 1e-30) ? 0.0 : std::fabs(pv - sv) / sv;
    r.max_rel_error_diag = std::max(r.max_rel_error_diag, r.rel_error[i]);
  }
  return r;
}

Cov3 outback_covariance(double d, double b, const ErrorModelParams& k) {
  Cov3 c{};
  propagate_arc(c, 0.0, d, d, b, k);
  propagate_arc(c, 0.0, -d, -d, b, k);
  return c;
}

}  // namespace odo::analysis
