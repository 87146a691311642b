#include "odo/calibration/umbmark.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "odo/calibration/record.hpp"

namespace odo::calib {
namespace {

std::string name(Direction d) {
  return std::string(choice_name(kDirections, d));
}

// factor_range: a correction factor outside the record's [kFactorMin, kFactorMax].
Error factor_range(std::string field, double v) {
  return range_error({std::move(field), v, RecordLimits::kFactorMin, RecordLimits::kFactorMax});
}

// angle_range: |alpha| or |beta| beyond kMaxAngle, almost always millimetres typed as metres.
Error angle_range(const char* field, double v) {
  FieldRange r{field, v, -kMaxAngle, kMaxAngle, "rad", false};
  r.note = "(check the units: metres)";
  return range_error(std::move(r));
}

}  // namespace

CentreOfGravity centre_of_gravity(std::span<const UmbmarkRun> runs, Direction dir) {
  CentreOfGravity g;
  for (const UmbmarkRun& r : runs) {
    if (r.direction != dir || r.bumps) continue;
    g.x += r.ex;
    g.y += r.ey;
    ++g.n;
  }
  if (g.n > 0) {
    g.x /= g.n;
    g.y /= g.n;
  }
  g.r = std::hypot(g.x, g.y);
  return g;
}

double e_max_syst(const CentreOfGravity& cw, const CentreOfGravity& ccw) {
  return std::max(cw.r, ccw.r);
}

TypeAB type_ab(const CentreOfGravity& cw, const CentreOfGravity& ccw, double side) {
  TypeAB t;
  const double k = -4.0 * side;
  // Eq. 6.26a/b and 6.22a/b without the 180/pi: alpha and beta stay in radians.
  t.alpha_x = (cw.x + ccw.x) / k;
  t.alpha_y = (cw.y - ccw.y) / k;
  t.beta_x = (cw.x - ccw.x) / k;
  t.beta_y = (cw.y + ccw.y) / k;
  // Footnote 2 of Sec. 6.3 / Chong & Kleeman Eq. 6, 7: average the x and the y estimate.
  t.alpha = 0.5 * (t.alpha_x + t.alpha_y);
  t.beta = 0.5 * (t.beta_x + t.beta_y);
  return t;
}

std::optional<double> curvature_radius(double beta, double side) {
  if (beta == 0.0) return std::nullopt;
  return (side / 2.0) / std::sin(beta / 2.0);
}

double diameter_ratio(std::optional<double> radius, double wheelbase) {
  if (!radius) return 1.0;
  return (*radius + wheelbase / 2.0) / (*radius - wheelbase / 2.0);
}

double wheelbase_factor(double alpha, WheelbaseFormula f) {
  // Eq. 6.27: the rotation is proportional to 1/b, and a nominal 90 deg corner turned only
  // 90 deg - alpha. Chong & Kleeman's Eq. 9 uses pi instead of pi/2 (see the header).
  const double q = f == WheelbaseFormula::kUmbmark629 ? std::numbers::pi / 2.0 : std::numbers::pi;
  return q / (q - alpha);
}

PassFactors wheel_factors(double e_d) {
  return PassFactors{2.0 / (e_d + 1.0), 2.0 / (1.0 / e_d + 1.0), 1.0};
}

Factors compose(const Factors& current, const PassFactors& pass) {
  return Factors{current.c_l * pass.c_l, current.c_r * pass.c_r, current.wheelbase * pass.e_b};
}

std::optional<double> return_spread(std::span<const UmbmarkRun> runs, const CentreOfGravity& cw,
                                    const CentreOfGravity& ccw) {
  const int dof = cw.n + ccw.n - 2;  // one centre of gravity estimated per direction
  if (dof < 1) return std::nullopt;
  double ss = 0.0;
  for (const UmbmarkRun& r : runs) {
    if (r.bumps) continue;
    const CentreOfGravity& g = r.direction == Direction::kCw ? cw : ccw;
    ss += (r.ex - g.x) * (r.ex - g.x) + (r.ey - g.y) * (r.ey - g.y);
  }
  return std::sqrt(ss / dof);
}

bool second_pass_recommended(double e_max, double sem) {
  return e_max > 3.0 * sem;
}

SetSpread set_spread(std::span<const UmbmarkRun> runs, const CentreOfGravity& cw,
                     const CentreOfGravity& ccw) {
  SetSpread s;
  s.sigma = return_spread(runs, cw, ccw);
  // The c.g. with fewer runs is the less certain one: SEM with the smaller n.
  if (s.sigma) s.sem = *s.sigma / std::sqrt(std::min(cw.n, ccw.n));
  s.worthwhile = second_pass_recommended(e_max_syst(cw, ccw), s.sem);
  return s;
}

Result<std::optional<double>> eps_theta_nonsys(std::span<const UmbmarkRun> runs) {
  std::optional<double> total;
  for (Direction d : {Direction::kCw, Direction::kCcw}) {
    double mu = 0.0, dev = 0.0;
    int n_sys = 0, n_bump = 0;
    for (const UmbmarkRun& r : runs) {
      if (r.direction != d) continue;
      if (r.bumps) {
        ++n_bump;
        if (!r.etheta) {
          return make_error(Errc::kInvalidArgument, std::string("field 'etheta' is missing on a ") +
                                                        name(d) + " run with bumps = 1");
        }
      } else if (r.etheta) {
        mu += *r.etheta;
        ++n_sys;
      }
    }
    if (n_bump == 0) continue;
    if (n_sys == 0) {
      return make_error(Errc::kInvalidArgument,
                        std::string("field 'etheta': the ") + name(d) +
                            " runs with bumps need plain " + name(d) +
                            " runs with etheta for the systematic bias (Eq. 3.6)");
    }
    mu /= n_sys;  // Eq. 3.6: the arithmetic mean, a fixed bias
    for (const UmbmarkRun& r : runs) {
      // Eq. 3.5: absolute values, so that errors of opposite sign do not cancel.
      if (r.direction == d && r.bumps) dev += std::fabs(*r.etheta - mu);
    }
    total = total.value_or(0.0) + dev / n_bump;
  }
  return total;
}

Result<UmbmarkResult> umbmark_compute(const UmbmarkInput& in) {
  using L = RecordLimits;
  if (!(std::isfinite(in.side) && in.side > 0.0))
    return range_error(positive_range("side", in.side, "m"));
  if (!(std::isfinite(in.current.wheelbase) && in.current.wheelbase > 0.0))
    return range_error(positive_range("wheelbase", in.current.wheelbase, "m"));
  for (auto [f, v] : {std::pair{"current c_l", in.current.c_l}, {"current c_r", in.current.c_r}}) {
    if (!(v >= L::kFactorMin && v <= L::kFactorMax)) return factor_range(f, v);
  }
  for (std::size_t i = 0; i < in.runs.size(); ++i) {
    const UmbmarkRun& r = in.runs[i];
    if (!std::isfinite(r.ex) || !std::isfinite(r.ey) || (r.etheta && !std::isfinite(*r.etheta))) {
      return make_error(Errc::kInvalidArgument,
                        "run " + std::to_string(i + 1) + ": a value is not a finite number");
    }
  }
  UmbmarkResult out;
  out.cw = centre_of_gravity(in.runs, Direction::kCw);
  out.ccw = centre_of_gravity(in.runs, Direction::kCcw);
  for (const CentreOfGravity* g : {&out.cw, &out.ccw}) {
    const std::string d = name(g == &out.cw ? Direction::kCw : Direction::kCcw);
    if (g->n == 0) {
      return make_error(Errc::kInvalidArgument,
                        std::string("field 'direction': no ") + d + " run without bumps");
    }
    if (g->n < kRecommendedRuns) {
      out.warnings.push_back(std::string("only ") + std::to_string(g->n) + " " + d +
                             " runs; the report uses 5 a direction");
    }
  }
  out.e_max_syst = e_max_syst(out.cw, out.ccw);
  out.ab = type_ab(out.cw, out.ccw, in.side);
  if (!(std::fabs(out.ab.alpha) <= kMaxAngle)) return angle_range("alpha", out.ab.alpha);
  if (!(std::fabs(out.ab.beta) <= kMaxAngle)) return angle_range("beta", out.ab.beta);
  out.radius = curvature_radius(out.ab.beta, in.side);
  // Eq. 6.24 with the wheelbase the robot used, as the report does (the true one differs by
  // E_b, a second-order change of E_d - 1 that the next pass would absorb).
  out.e_d = diameter_ratio(out.radius, in.current.wheelbase);
  out.e_b = wheelbase_factor(out.ab.alpha, in.formula);
  out.pass = wheel_factors(out.e_d);
  out.pass.e_b = out.e_b;
  out.composed = compose(in.current, out.pass);
  for (auto [f, v] : {std::pair{"c_l", out.composed.c_l}, {"c_r", out.composed.c_r}}) {
    if (!(v >= L::kFactorMin && v <= L::kFactorMax))
      return factor_range(std::string("resulting ") + f, v);
  }
  out.spread = set_spread(in.runs, out.cw, out.ccw);
  auto eps = eps_theta_nonsys(in.runs);
  if (!eps) return std::move(eps).error();
  out.eps_theta_nonsys = *eps;
  return out;
}

std::optional<Factors> factor_sigmas(const UmbmarkInput& in, const UmbmarkResult& r) {
  if (!r.spread.sigma) return std::nullopt;
  double v_l = 0.0, v_r = 0.0, v_b = 0.0;  // variances
  UmbmarkInput moved = in;                 // allocates: a report's computation, not the loop's
  for (const auto& [d, n] :
       {std::pair{Direction::kCw, r.cw.n}, std::pair{Direction::kCcw, r.ccw.n}})
    for (const bool in_x : {true, false}) {
      const double sem = *r.spread.sigma / std::sqrt(static_cast<double>(n));
      moved.runs = in.runs;
      // Bump runs are not part of the centre of gravity (centre_of_gravity): not moved.
      for (UmbmarkRun& run : moved.runs)
        if (run.direction == d && !run.bumps) (in_x ? run.ex : run.ey) += sem;
      auto m = umbmark_compute(moved);
      if (!m) return std::nullopt;
      v_l += (m->composed.c_l - r.composed.c_l) * (m->composed.c_l - r.composed.c_l);
      v_r += (m->composed.c_r - r.composed.c_r) * (m->composed.c_r - r.composed.c_r);
      v_b += (m->composed.wheelbase - r.composed.wheelbase) *
             (m->composed.wheelbase - r.composed.wheelbase);
    }
  return Factors{std::sqrt(v_l), std::sqrt(v_r), std::sqrt(v_b)};
}

}  // namespace odo::calib
