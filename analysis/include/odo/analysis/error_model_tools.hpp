// Tools around the Chong-Kleeman error model (odomctl errormodel): a Monte Carlo validation on the
// simulated robot, the fit of k_L and k_R from repeated out-and-back runs, and the SVG plot of
// 95% error ellipses (like Fig. 4 of the paper).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <istream>
#include <string>
#include <vector>

#include "odo/hal/choice.hpp"
#include "odo/hal/result.hpp"
#include "odo/odometry/error_model.hpp"

namespace odo::analysis {

// One run's end-of-path error: true pose minus odometry pose (x [m], y [m], theta [rad]).
using PoseError = std::array<double, 3>;

// McPath: the Monte Carlo path; kMcPaths spells it (odomctl --path).
enum class McPath : std::uint8_t {
  kOutback,  // 10 m forward, 10 m back
  kArc,      // see path_description()
};
inline constexpr Choice<McPath> kMcPaths[] = {{McPath::kOutback, "outback"}, {McPath::kArc, "arc"}};

// name_of: the spelling of p ("outback", "arc").
constexpr std::string_view name_of(McPath p) {
  return choice_name(kMcPaths, p);
}
// parse_mc_path: the path spelt `text`; the error names --path and the choices.
Result<McPath> parse_mc_path(std::string_view text);

struct McOptions {
  int runs = 2000;  // 2 .. 1e6
  McPath path = McPath::kOutback;
  ErrorModelParams k;            // noise injected into the simulated wheels [m^(1/2)]
  double wheelbase = 0.34;       // true = believed wheelbase [m], 0.05 .. 5
  std::uint64_t seed = 1;        // run i uses the noise sequence of (seed, i)
  double wheel_diameter = 0.15;  // [m]
  double speed = 0.5;            // centre speed along the path [m/s]
  double rate_hz = 100.0;        // loop rate [Hz]
};

struct McResult {
  int runs = 0;
  Cov3 predicted{};                   // the loop's own covariance at the end of the path
  Cov3 sample{};                      // sample covariance of the run errors (divisor runs - 1)
  PoseError mean{};                   // mean run error
  std::array<double, 3> rel_error{};  // |predicted_ii - sample_ii| / sample_ii
  double max_rel_error_diag = 0.0;
  std::vector<PoseError> errors;  // every run's error
};

// check_mc_options: validates every field; the message names the option and its range.
Status check_mc_options(const McOptions& o);

// path_description: one line describing the path, for reports.
std::string path_description(McPath path);

// run_error_monte_carlo: drives the simulated robot (true geometry = believed) `runs` times along
// the path with per-wheel white noise of variance k^2 |d| on its true wheel travel, integrates
// the encoder counts with the firmware's own loop, and compares the loop's covariance with the
// sample covariance of the final errors. progress(done, total) is called now and then.
Result<McResult> run_error_monte_carlo(const McOptions& o,
                                       const std::function<void(int, int)>& progress = {});

// sample_covariance: unbiased sample covariance (divisor n - 1) and mean of the errors.
Cov3 sample_covariance(const std::vector<PoseError>& e, PoseError* mean = nullptr);

// outback_covariance: the closed-form covariance at the end of the out-and-back path (distance d
// [m] forward, then d back, no turn) for wheelbase b [m].
Cov3 outback_covariance(double d, double b, const ErrorModelParams& k);

struct TwistMcResult {
  int runs = 0;
  std::array<double, 4> predicted{};  // 2x2 over (v, omega), row-major [(m/s)^2, m rad/s^2, ...]
  std::array<double, 4> sample{};     // sample covariance of true - measured (divisor runs - 1)
  std::array<double, 2> mean{};       // mean error [m/s, rad/s]
  std::array<double, 2> rel_error{};  // |predicted_ii - sample_ii| / sample_ii, v then omega
  double max_rel_error_diag = 0.0;
};

// run_twist_monte_carlo: the twist covariance that the ROS 2 output publishes
// (twist_covariance, odometry/error_model.hpp) against a Monte Carlo: the simulated robot (true =
// believed) drives a circle of 2 m radius at o.speed with wheel noise k^2 |d| on its true travel,
// and the loop's (v, omega) over the tick after 1 s is compared with the true twist over the
// same interval, o.runs times. o.path is not used.
Result<TwistMcResult> run_twist_monte_carlo(const McOptions& o);

struct FitResult {
  int runs = 0;
  ErrorModelParams k;  // the fitted k_L, k_R [m^(1/2)]
  Cov3 predicted{};    // outback_covariance with the fitted k
  Cov3 sample{};       // sample covariance of the runs
  PoseError mean{};    // mean error (systematic part, removed before the fit)
};

// read_run_errors: the CSV of `errormodel fit` (header ex,ey,etheta, optional run column).
Result<std::vector<PoseError>> read_run_errors(std::istream& in, const std::string& source);

// write_run_errors: the same format, one row per run.
void write_run_errors(std::ostream& out, const std::vector<PoseError>& e);

// fit_error_model: maximum-likelihood k_L, k_R for out-and-back runs of distance d [m] each way
// and wheelbase b [m]: the errors minus their mean are taken as Gaussian with the model
// covariance k_L^2 A + k_R^2 B (the model is linear in k_L^2 and k_R^2).
Result<FitResult> fit_error_model(const std::vector<PoseError>& errors, double d, double b);

// error_ellipse_svg: three panels (ex-ey, ex-etheta, ey-etheta) with the runs as dots and the 95%
// ellipses of the sample (solid) and predicted (dashed) covariances around the sample mean.
std::string error_ellipse_svg(const std::vector<PoseError>& errors, const Cov3& predicted,
                              const Cov3& sample, const PoseError& mean, const std::string& title);

}  // namespace odo::analysis
