// The effective-track model against the ICR model of Mandow et al. 2007 on the friction model's
// skid-steer base (issue 38, item 3).
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <cmath>

#include "odo/analysis/skid_tools.hpp"

namespace odo::analysis {
namespace {

constexpr double kSpeed = 0.2;       // [m/s] centre speed of straights and arcs
constexpr double kTurnRate = 0.5;    // [rad/s] of spot turns
constexpr double kHeadingArm = 1.0;  // [m] weight of the heading error against the position's
constexpr int kIterations = 20;

RimPiece piece(double duration, double v, double w, double track) {
  return {duration, v - w * track / 2.0, v + w * track / 2.0};
}

// end_pose: the excursion from the origin with the twist `twist(piece)` held over each piece.
template <class TwistOf>
Pose2 end_pose(const RimExcursion& e, TwistOf twist) {
  Pose2 pose;
  for (const RimPiece& p : e) pose = sim::twist_step(pose, twist(p), p.duration);
  return pose;
}

// residual: one excursion's end-pose error of the ICR model k against its true end pose.
Eigen::Vector3d residual(const RimExcursion& e, const Pose2& truth, const IcrParams& k) {
  const Pose2 m = end_pose(e, [&](const RimPiece& p) { return icr_twist(k, p.v_left, p.v_right); });
  return Eigen::Vector3d(m.x - truth.x, m.y - truth.y,
                         kHeadingArm * wrap_angle(m.theta - truth.theta));
}

// rms_position: rms end-position error [m] over the excursions with the ICR model k.
double rms_position(const std::vector<RimExcursion>& ex, const std::vector<Pose2>& truth,
                    const IcrParams& k) {
  double sum = 0.0;
  for (std::size_t i = 0; i < ex.size(); ++i)
    sum += residual(ex[i], truth[i], k).head<2>().squaredNorm();
  return ex.empty() ? 0.0 : std::sqrt(sum / static_cast<double>(ex.size()));
}

template <int N>
using Vec = Eigen::Matrix<double, N, 1>;

// fit: Gauss-Newton on the end-pose residuals of the model to_icr(x) (N free parameters) from x.
template <int N, class ToIcr>
Vec<N> fit(const std::vector<RimExcursion>& ex, const std::vector<Pose2>& truth, Vec<N> x,
           ToIcr to_icr) {
  constexpr double h = 1e-6;  // [m] central differences: error ~h^2, rounding ~1e-16 / h
  for (int it = 0; it < kIterations; ++it) {
    Eigen::Matrix<double, N, N> jtj = Eigen::Matrix<double, N, N>::Zero();
    Vec<N> jtr = Vec<N>::Zero();
    for (std::size_t i = 0; i < ex.size(); ++i) {
      Eigen::Matrix<double, 3, N> j;
      for (int c = 0; c < N; ++c) {
        Vec<N> up = x, down = x;
        up(c) += h;
        down(c) -= h;
        j.col(c) =
            (residual(ex[i], truth[i], to_icr(up)) - residual(ex[i], truth[i], to_icr(down))) /
            (2.0 * h);
      }
      jtj += j.transpose() * j;
      jtr += j.transpose() * residual(ex[i], truth[i], to_icr(x));
    }
    const Vec<N> step = -jtj.ldlt().solve(jtr);
    x += step;
    if (step.norm() < 1e-10) break;
  }
  return x;
}

}  // namespace

sim::BodyTwist icr_twist(const IcrParams& k, double v_left, double v_right) noexcept {
  const double b = k.y_left - k.y_right;
  return {(v_right * k.y_left - v_left * k.y_right) / b, k.x_icr * (v_left - v_right) / b,
          (v_right - v_left) / b};
}

IcrParams icr_of(const sim::BodyTwist& q, double v_left, double v_right) noexcept {
  if (q.omega == 0.0) return {};
  return {(q.vx - v_left) / q.omega, (q.vx - v_right) / q.omega, -q.vy / q.omega};
}

RimExcursion mixed_excursion(std::mt19937_64& rng, double track) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  RimExcursion e;
  const int n = 4 + static_cast<int>(6 * u(rng));
  for (int i = 0; i < n; ++i) {
    const double kind = u(rng), sign = u(rng) < 0.5 ? -1.0 : 1.0;
    if (kind < 0.3) {
      e.push_back(piece((0.3 + 2.7 * u(rng)) / kTurnRate, 0.0, sign * kTurnRate, track));
    } else if (kind < 0.65) {
      e.push_back(piece((1.0 + 3.0 * u(rng)) / kSpeed, kSpeed, 0.0, track));
    } else {
      const double radius = 0.5 + 1.5 * u(rng), angle = 0.8 + 1.6 * u(rng);
      e.push_back(piece(angle * radius / kSpeed, kSpeed, sign * kSpeed / radius, track));
    }
  }
  return e;
}

SkidModelFit fit_skid_models(const sim::SkidSteerParams& p,
                             const std::vector<RimExcursion>& excursions) {
  SkidModelFit out;
  std::vector<Pose2> truth;
  for (const RimExcursion& e : excursions) {
    truth.push_back(end_pose(e, [&](const RimPiece& r) {
      const sim::SkidSolution s = sim::solve_skid_twist(p, r.v_left, r.v_right);
      if (!s.converged) ++out.unconverged;
      return s.twist;
    }));
  }
  const sim::SkidSolution spin = sim::solve_skid_twist(p, -kSpeed, kSpeed);
  if (!spin.converged) ++out.unconverged;
  out.spot = icr_of(spin.twist, -kSpeed, kSpeed);
  const double b0 = out.spot.y_left - out.spot.y_right;
  auto plain = [](double b) { return IcrParams{b / 2.0, -b / 2.0, 0.0}; };
  out.rms_spot = rms_position(excursions, truth, plain(b0));
  out.track =
      fit<1>(excursions, truth, Vec<1>(b0), [&](const Vec<1>& v) { return plain(v(0)); })(0);
  out.rms_track = rms_position(excursions, truth, plain(out.track));
  const Vec<2> y = fit<2>(excursions, truth, Eigen::Vector2d(b0, 0.0), [](const Vec<2>& v) {
    return IcrParams{v(0) / 2.0, -v(0) / 2.0, v(1)};
  });
  out.icr_sym = {y(0) / 2.0, -y(0) / 2.0, y(1)};
  out.rms_icr_sym = rms_position(excursions, truth, out.icr_sym);
  const Vec<3> x =
      fit<3>(excursions, truth, Eigen::Vector3d(b0 / 2.0, -b0 / 2.0, 0.0), [](const Vec<3>& v) {
        return IcrParams{v(0), v(1), v(2)};
      });
  out.icr = {x(0), x(1), x(2)};
  out.rms_icr = rms_position(excursions, truth, out.icr);
  return out;
}

}  // namespace odo::analysis
