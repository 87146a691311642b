#include "odo/sim/skid_steer.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <array>
#include <cmath>

#include "odo/hal/field_range.hpp"

namespace odo::sim {
namespace {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

constexpr int kMaxIterations = 60;
constexpr int kMaxHalvings = 40;
// Twist change [m/s, rad/s] per unit of rim speed below which Newton has converged: the
// quadratic phase then leaves errors far below 1e-12 of the rim speed.
constexpr double kStepTolerance = 1e-13;

// Contact: one wheel's contact point [m], normal load [N] and rim speed [m/s].
struct Contact {
  double x, y, n, rim;
};

std::array<Contact, 4> contacts(const SkidSteerParams& p, double v_left, double v_right) {
  const double a = p.half_wheelbase, c = 0.5 * p.track;
  const double nf = wheel_load(p, true), nr = wheel_load(p, false);
  return {{{a, c, nf, v_left}, {-a, c, nr, v_left}, {a, -c, nf, v_right}, {-a, -c, nr, v_right}}};
}

// Potential: D(q) = sum_i N_i sqrt(mu_l^2 sx_i^2 + mu_t^2 sy_i^2 + eps^2), with slip s_i the
// contact point's velocity minus its rim's. Its gradient is minus the floor's wrench on the body
// (each wheel's force -N (mu_l^2 sx, mu_t^2 sy) / r lies on the friction ellipse of semi-axes
// mu_l N, mu_t N once |s| >> eps: the maximum-dissipation law of an elliptic limit surface). D is
// convex in q (a sum of norms of affine maps), so the force balance is D's minimum and damped
// Newton on it converges from any warm start.
struct Potential {
  double value = 0.0;
  Vec3 grad = Vec3::Zero();
  Mat3 hess = Mat3::Zero();
};

Potential potential(const SkidSteerParams& p, const std::array<Contact, 4>& cs, const Vec3& q) {
  const double wx = p.mu_long * p.mu_long, wy = p.mu_lat * p.mu_lat;
  const double e2 = p.slip_eps * p.slip_eps;
  Potential out;
  for (const Contact& c : cs) {
    // Contact-point velocity of a rigid body: v + omega x r = (vx - omega y, vy + omega x).
    const double sx = q(0) - q(2) * c.y - c.rim, sy = q(1) + q(2) * c.x;
    const double r = std::sqrt(wx * sx * sx + wy * sy * sy + e2);
    Eigen::Matrix<double, 2, 3> j;
    j << 1.0, 0.0, -c.y, 0.0, 1.0, c.x;
    const Eigen::Vector2d ws(wx * sx, wy * sy);
    const Eigen::Matrix2d w = Eigen::Vector2d(wx, wy).asDiagonal();
    out.value += c.n * r;
    out.grad += c.n / r * j.transpose() * ws;
    out.hess += c.n * j.transpose() * (w / r - ws * ws.transpose() / (r * r * r)) * j;
  }
  return out;
}

// newton_step: the damped Newton direction. The tiny Levenberg term keeps a direction D is flat
// in (mu_lat = 0 leaves vy free) at its warm-started value instead of making H singular.
Vec3 newton_step(const Potential& d) {
  const double lambda = 1e-12 * d.hess.trace() + 1e-300;
  return -(d.hess + lambda * Mat3::Identity()).ldlt().solve(d.grad);
}

// Limits of the parameters (check_skid_params); com_x is checked against a itself.
constexpr RangeRow kHalfWheelbase{"half_wheelbase", 0.0, 10.0, "m", true};
constexpr RangeRow kTrack{"track", 0.0, 10.0, "m", true};
constexpr RangeRow kMass{"mass", 0.0, 1e4, "kg", true};
constexpr RangeRow kGravity{"gravity", 0.0, 100.0, "m/s^2", true};
constexpr RangeRow kMuLong{"mu_long", 0.0, 5.0, "", true};
constexpr RangeRow kMuLat{"mu_lat", 0.0, 5.0, ""};
constexpr RangeRow kSlipEps{"slip_eps", 0.0, 1.0, "m/s", true};

}  // namespace

SkidSteerParams jackal_skid_params() {
  // Clearpath's jackal_control/config/control.yaml: wheel_separation 0.37559 m (the geometric
  // track), wheel_radius 0.098 m, wheel_separation_multiplier 1.5; wheelbase 0.262 m as issue
  // 38 gives it (not checked against Clearpath's URDF here), a = 0.131 m; mass 17 kg (Jackal
  // datasheet). Centre of mass at the geometric centre. Rubber on a hard floor mu ~ 0.8 in both
  // directions, as the isotropic Coulomb model of Kozlowski & Pazderski assumes; the twist
  // depends only on mu_lat / mu_long (scaling both scales every force alike), which sets the
  // spot-turn track t (1 + (mu_lat a / (mu_long c))^2) with c = t/2: 1.4866 t here, the order
  // of Clearpath's multiplier 1.5.
  return SkidSteerParams{};
}

RobotGeometry skid4_geometry() {
  RobotGeometry g;
  g.wheel_diameter_left = g.wheel_diameter_right = 2.0 * 0.098;
  g.wheelbase = jackal_skid_params().track;
  return g;
}

Status check_skid_params(const SkidSteerParams& p) {
  const std::pair<const RangeRow*, double> rows[] = {{&kHalfWheelbase, p.half_wheelbase},
                                                     {&kTrack, p.track},
                                                     {&kMass, p.mass},
                                                     {&kGravity, p.gravity},
                                                     {&kMuLong, p.mu_long},
                                                     {&kMuLat, p.mu_lat},
                                                     {&kSlipEps, p.slip_eps}};
  for (const auto& [row, v] : rows) {
    if (!row->contains(v)) return range_error(row->range(row->key, v));
  }
  if (!(std::fabs(p.com_x) < p.half_wheelbase)) {
    FieldRange r{"com_x", p.com_x, -p.half_wheelbase, p.half_wheelbase, "m"};
    r.lo_open = r.hi_open = true;
    return range_error(r);
  }
  return Ok{};
}

double wheel_load(const SkidSteerParams& p, bool front) noexcept {
  // Moments about the other axle: the front axle carries m g (a + com_x) / (2a), two wheels.
  const double arm = front ? p.half_wheelbase + p.com_x : p.half_wheelbase - p.com_x;
  return p.mass * p.gravity * arm / (4.0 * p.half_wheelbase);
}

Wrench skid_wrench(const SkidSteerParams& p, const BodyTwist& q, double v_left,
                   double v_right) noexcept {
  const Potential d = potential(p, contacts(p, v_left, v_right), Vec3(q.vx, q.vy, q.omega));
  return Wrench{-d.grad(0), -d.grad(1), -d.grad(2)};
}

SkidSolution solve_skid_twist(const SkidSteerParams& p, double v_left, double v_right,
                              const BodyTwist& warm) noexcept {
  const std::array<Contact, 4> cs = contacts(p, v_left, v_right);
  const double tol = kStepTolerance * (1.0 + std::fabs(v_left) + std::fabs(v_right));
  Vec3 q(warm.vx, warm.vy, warm.omega);
  SkidSolution out;
  for (out.iterations = 1; out.iterations <= kMaxIterations; ++out.iterations) {
    const Potential d = potential(p, cs, q);
    const Vec3 step = newton_step(d);
    if (step.norm() < tol) {
      q += step;
      out.converged = true;
      break;
    }
    // Backtracking (Armijo): the full step overshoots where the law turns from viscous to
    // Coulomb within it (slips crossing eps). Near the minimum D's decrease drowns in rounding,
    // so a step that halves the wrench is accepted too (the quadratic phase).
    double s = 1.0;
    const double slope = d.grad.dot(step);
    for (int h = 0; h < kMaxHalvings; ++h, s *= 0.5) {
      const Potential t = potential(p, cs, q + s * step);
      if (t.value <= d.value + 1e-4 * s * slope || t.grad.norm() < 0.5 * d.grad.norm()) break;
    }
    q += s * step;
  }
  out.twist = BodyTwist{q(0), q(1), q(2)};
  return out;
}

double effective_track(const SkidSolution& s, double v_left, double v_right) noexcept {
  return s.twist.omega != 0.0 ? (v_right - v_left) / s.twist.omega : 0.0;
}

double skid_effective_track(const SkidSteerParams& p, double v_left, double v_right) noexcept {
  return effective_track(solve_skid_twist(p, v_left, v_right), v_left, v_right);
}

Pose2 twist_step(const Pose2& pose, const BodyTwist& q, double dt) noexcept {
  // Body-frame displacement of a constant twist: (vx S - vy C, vx C + vy S) with
  // S = sin(w dt) / w, C = (1 - cos(w dt)) / w = 2 sin^2(w dt / 2) / w (no cancellation);
  // series below 1e-4 rad (first dropped terms < 1e-20 dt).
  const double th = q.omega * dt;
  double sd = 0.0, cd = 0.0;
  if (std::fabs(th) < 1e-4) {
    sd = dt * (1.0 - th * th / 6.0);
    cd = dt * th / 2.0 * (1.0 - th * th / 12.0);
  } else {
    sd = std::sin(th) / q.omega;
    const double sh = std::sin(0.5 * th);
    cd = 2.0 * sh * sh / q.omega;
  }
  const double dx = q.vx * sd - q.vy * cd, dy = q.vx * cd + q.vy * sd;
  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  return Pose2{pose.x + c * dx - s * dy, pose.y + s * dx + c * dy, pose.theta + th};
}

Result<SkidSteerBody> SkidSteerBody::create(const SkidSteerParams& p) {
  if (auto s = check_skid_params(p); !s) return std::move(s).error();
  return SkidSteerBody(p);
}

Pose2 SkidSteerBody::step(const Pose2& pose, double d_left, double d_right, double dt) noexcept {
  if (!(dt > 0.0)) return pose;
  const double vl = d_left / dt, vr = d_right / dt;
  if (vl != key_l_ || vr != key_r_) {
    const SkidSolution s = solve_skid_twist(p_, vl, vr, twist_);
    if (!s.converged) ++unconverged_;
    twist_ = s.twist;
    key_l_ = vl;
    key_r_ = vr;
  }
  if (d_left * d_right < 0.0) {
    turn_rim_ += std::fabs(d_right - d_left);
    turn_angle_ += std::fabs(twist_.omega * dt);
  }
  return twist_step(pose, twist_, dt);
}

}  // namespace odo::sim
