// Monte Carlo validation of the Chong-Kleeman model on the simulated robot, with the firmware's
// own loop, and the fit of k_L, k_R from simulated out-and-back runs.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "../unit/loglog_slope.hpp"
#include "odo/analysis/error_model_tools.hpp"
#include "odo/sim/wheel_noise.hpp"
#include "sim_fixture.hpp"

namespace odo::test {
namespace {

// 4000 runs: the relative standard error of a sample variance is sqrt(2/(n-1)) = 2.2%, so the
// 10% bound is 4.5 standard errors away even with the model's own second-order bias (on the
// out-and-back path the along-track variance gets ~4% from the (1/2) theta^2 terms the first-order
// model leaves out: 10000 runs give predicted/sample = 0.957 there, 0.999 for the others).
// Seed 1 is the command's default, not a chosen one.
constexpr int kRuns = 4000;

void expect_within_10_percent(const analysis::McResult& r, const char* path) {
  for (int i = 0; i < 3; ++i) {
    EXPECT_LT(r.rel_error[i], 0.10) << path << " variance " << i << ": predicted "
                                    << r.predicted[4 * i] << " sample " << r.sample[4 * i];
  }
  EXPECT_EQ(r.runs, kRuns);
  EXPECT_EQ(r.errors.size(), static_cast<std::size_t>(kRuns));
}

TEST(ErrorMonteCarlo, OutbackVariancesWithin10PercentOfSample) {
  analysis::McOptions o;
  o.runs = kRuns;
  o.path = analysis::McPath::kOutback;
  auto r = analysis::run_error_monte_carlo(o);
  ASSERT_TRUE(r.ok()) << r.error().message;
  expect_within_10_percent(*r, "outback");
  // The loop's covariance at the end equals the two-segment closed form (consistency through the
  // loop's 4000 ticks; quantised counts make the ticks slightly uneven).
  const Cov3 closed = analysis::outback_covariance(10.0, 0.34, o.k);
  for (int i = 0; i < 9; ++i) {
    const double scale = std::sqrt(closed[4 * (i / 3)] * closed[4 * (i % 3)]);
    EXPECT_NEAR(r->predicted[i], closed[i], 1e-4 * scale) << "entry " << i;
  }
}

TEST(ErrorMonteCarlo, ArcVariancesWithin10PercentOfSample) {
  analysis::McOptions o;
  o.runs = kRuns;
  o.path = analysis::McPath::kArc;
  auto r = analysis::run_error_monte_carlo(o);
  ASSERT_TRUE(r.ok()) << r.error().message;
  expect_within_10_percent(*r, "arc");
}

TEST(ErrorMonteCarlo, NoNoiseNoSpread) {
  // k = 0: every run is identical, both covariances vanish and agree.
  analysis::McOptions o;
  o.runs = 3;
  o.k = {0.0, 0.0};
  auto r = analysis::run_error_monte_carlo(o);
  ASSERT_TRUE(r.ok()) << r.error().message;
  for (double v : r->predicted) EXPECT_EQ(v, 0.0);
  for (double v : r->sample) EXPECT_NEAR(v, 0.0, 1e-24);
  EXPECT_EQ(r->max_rel_error_diag, 0.0);
}

TEST(ErrorMonteCarlo, RejectsBadOptions) {
  const std::pair<analysis::McOptions, const char*> cases[] = {
      {{.runs = 1}, "--runs = 1 is outside the allowed range [2, 1000000]"},
      {{.k = {-1e-4, 0.00058}}, "--k-left = -0.0001 m^(1/2) is outside the allowed range"},
      {{.k = {1e-4, 0.5}}, "--k-right = 0.5 m^(1/2) is outside"},
      {{.wheelbase = 0.0}, "--wheelbase = 0 m is outside the allowed range [0.05, 5] m"},
  };
  for (const auto& [o, expect] : cases) {
    auto r = analysis::run_error_monte_carlo(o);
    ASSERT_FALSE(r.ok()) << expect;
    EXPECT_NE(r.error().message.find(expect), std::string::npos) << r.error().message;
  }
  // The path is a choice, read from its text once (odomctl --path).
  auto p = analysis::parse_mc_path("square");
  ASSERT_FALSE(p.ok());
  EXPECT_NE(p.error().message.find("--path = 'square' must be outback or arc"), std::string::npos)
      << p.error().message;
}

// StraightLineSlopes: sample variances of the along-track (x) and lateral (y) error of a straight
// run at 0.5, 1, 2, 4 and 8 m; Sec. 4.1 predicts ~ d and ~ d^3.
class ErrorAt final : public loop::TickObserver {
 public:
  ErrorAt(const sim::SimRobot& robot, std::vector<std::uint64_t> ticks)
      : robot_(robot), ticks_(std::move(ticks)) {}
  void on_tick(const loop::LoopSnapshot& s) noexcept override {
    if (next_ < ticks_.size() && s.tick == ticks_[next_]) {
      errors[next_] = {robot_.true_pose().x - s.pose.x, robot_.true_pose().y - s.pose.y,
                       robot_.true_pose().theta - s.pose.theta};
      ++next_;
    }
  }
  std::array<analysis::PoseError, 5> errors{};

 private:
  const sim::SimRobot& robot_;
  std::vector<std::uint64_t> ticks_;
  std::size_t next_ = 0;
};

TEST(ErrorMonteCarlo, StraightLineLateralCubicAlongTrackLinear) {
  // 0.5 m/s at 100 Hz: 5 mm per tick, so distance d is reached at tick 200 d (+1 for the first
  // reading). The longest distance is 8 m: beyond it the theta^2 terms the first-order model
  // leaves out start to add to the along-track variance (~5% at 16 m).
  const std::vector<double> dist{0.5, 1.0, 2.0, 4.0, 8.0};
  std::vector<std::uint64_t> ticks;
  for (double d : dist) ticks.push_back(static_cast<std::uint64_t>(std::llround(200 * d)));
  const auto k = *Kinematics::create(nominal_labmate());
  const double w = 0.5 / 0.075;
  sim::WheelNoise noise(0.00040, 0.00058, 0);
  std::vector<std::vector<analysis::PoseError>> per_dist(dist.size());
  for (int run = 0; run < kRuns; ++run) {
    SimRun sim(sim::RobotGeometry{}, k, {{8.0 / 0.5 + 0.1, w, w}});
    noise.reseed(1000 + static_cast<std::uint64_t>(run));
    sim.robot.set_travel_perturbation(&noise);
    ErrorAt obs(sim.robot, ticks);
    sim.loop->add_observer(&obs);
    std::atomic<bool> stop{false};
    sim.loop->run(from_seconds(8.0 / 0.5 + 0.05), stop);
    for (std::size_t i = 0; i < dist.size(); ++i) per_dist[i].push_back(obs.errors[i]);
  }
  std::vector<double> along, lateral;
  for (const auto& e : per_dist) {
    const Cov3 c = analysis::sample_covariance(e);
    along.push_back(c[0]);
    lateral.push_back(c[4]);
  }
  const double s_lat = loglog_slope(dist, lateral), s_along = loglog_slope(dist, along);
  RecordProperty("lateral_slope", std::to_string(s_lat));
  RecordProperty("along_slope", std::to_string(s_along));
  std::cout << "fitted log-log slopes: lateral " << s_lat << ", along-track " << s_along << "\n";
  EXPECT_NEAR(s_lat, 3.0, 0.02 * 3.0);
  EXPECT_NEAR(s_along, 1.0, 0.02 * 1.0);
}

TEST(ErrorModelFit, RecoversCoefficientsFromSimulatedRuns) {
  // 2000 simulated out-and-back runs with k_L = 0.0004, k_R = 0.00058, written in the CSV format
  // of `errormodel fit` and read back: the maximum-likelihood fit recovers both within 5%
  // (k^2 has a relative standard error of about sqrt(2/2000) = 3%, so k about 1.6%).
  analysis::McOptions o;
  o.runs = 2000;
  o.seed = 5;
  auto r = analysis::run_error_monte_carlo(o);
  ASSERT_TRUE(r.ok()) << r.error().message;
  std::stringstream csv;
  analysis::write_run_errors(csv, r->errors);
  auto read = analysis::read_run_errors(csv, "runs.csv");
  ASSERT_TRUE(read.ok()) << read.error().message;
  ASSERT_EQ(read->size(), 2000u);
  auto fit = analysis::fit_error_model(*read, 10.0, 0.34);
  ASSERT_TRUE(fit.ok()) << fit.error().message;
  EXPECT_NEAR(fit->k.k_left, 0.00040, 0.05 * 0.00040);
  EXPECT_NEAR(fit->k.k_right, 0.00058, 0.05 * 0.00058);
}

TEST(ErrorModelFit, RecoversExactCovariance) {
  // Errors built so that their sample covariance is exactly the model's for k_L = 0.0003,
  // k_R = 0.0007 (points mean +- sqrt(3) L e_i with L the Cholesky factor, n = 6: the sample
  // covariance with divisor n is L L^T): the maximum-likelihood fit must return those k.
  const Cov3 c = analysis::outback_covariance(10.0, 0.34, {0.0003, 0.0007});
  // Cholesky of c by hand (3 x 3).
  const double l00 = std::sqrt(c[0]);
  const double l10 = c[3] / l00, l20 = c[6] / l00;
  const double l11 = std::sqrt(c[4] - l10 * l10);
  const double l21 = (c[7] - l20 * l10) / l11;
  const double l22 = std::sqrt(c[8] - l20 * l20 - l21 * l21);
  const double cols[3][3] = {{l00, l10, l20}, {0, l11, l21}, {0, 0, l22}};
  std::vector<analysis::PoseError> e;
  const double s = std::sqrt(3.0);
  for (const auto& col : cols) {
    e.push_back({s * col[0], s * col[1], s * col[2]});
    e.push_back({-s * col[0], -s * col[1], -s * col[2]});
  }
  auto fit = analysis::fit_error_model(e, 10.0, 0.34);
  ASSERT_TRUE(fit.ok()) << fit.error().message;
  EXPECT_NEAR(fit->k.k_left, 0.0003, 1e-8);
  EXPECT_NEAR(fit->k.k_right, 0.0007, 1e-8);
}

TEST(ErrorModelFit, BadInputNamesFileLineAndField) {
  const std::pair<const char*, const char*> cases[] = {
      {"", "runs.csv:1: empty file: expected a header line"},
      {"ex,ey\n", "runs.csv:1: missing column 'etheta'"},
      {"ex,ey,etheta,z\n", "runs.csv:1: unknown column 'z'"},
      {"ex,ey,etheta\n0.1,0.2,abc\n", "runs.csv:2: field 'etheta'"},
      {"ex,ey,etheta\n0.1,0.2\n", "runs.csv:2: expected 3 fields, found 2"},
      {"ex,ey,etheta\n# c\n0.1,2000,0.1\n",
       "runs.csv:3: field 'ey' = 2000 is outside the allowed range [-1000, 1000] m"},
      {"ex,ey,etheta\n0,0,0\n0,0,0\n", "runs.csv: 2 runs found; the fit needs at least 5"},
  };
  for (const auto& [text, expect] : cases) {
    std::stringstream in(text);
    auto r = analysis::read_run_errors(in, "runs.csv");
    ASSERT_FALSE(r.ok()) << text;
    EXPECT_NE(r.error().message.find(expect), std::string::npos) << r.error().message;
  }
  // Identical runs: a singular sample covariance, nothing to fit.
  std::vector<analysis::PoseError> same(6, analysis::PoseError{0.01, 0.02, 0.003});
  auto f = analysis::fit_error_model(same, 10.0, 0.34);
  ASSERT_FALSE(f.ok());
  EXPECT_NE(f.error().message.find("singular"), std::string::npos) << f.error().message;
}

}  // namespace
}  // namespace odo::test
