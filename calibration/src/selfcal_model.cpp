#include "selfcal_model.hpp"

#include <Eigen/Cholesky>
#include <Eigen/LU>
#include <cmath>

namespace odo::calib::detail {
namespace {

// dsinc(h): d/dh sin(h)/h = (cos h - sinc h) / h; series below 0.05 (first omitted term
// h^9/3991680 < 5e-19).
double dsinc(double h, const HalfAngle& a) {
  if (std::fabs(h) < kHalfAngleSeriesLimit) {
    const double h2 = h * h;
    return h * (-1.0 / 3.0 + h2 * (1.0 / 30.0 - h2 * (1.0 / 840.0 - h2 / 45360.0)));
  }
  return (a.c - a.sinc) / h;
}

// Carried start heading of the next excursion.
template <int N>
struct Heading {
  bool known = false;
  double theta = 0.0;
  VecP<N> d = VecP<N>::Zero();  // d theta / d p
  double var = 0.0;             // [rad^2]
};

Mat3 start_propagation(const Pose2& start, const Pose2& end) {
  // d end / d start of a rigid excursion: translation passes through, a heading change
  // rotates the displacement (end - start) by 90 degrees. Also with x_ICR: its term
  // x (u(theta0) - u(theta1)) turns with the start heading like the rest (add_icr).
  Mat3 g = Mat3::Identity();
  g(0, 2) = -(end.y - start.y);
  g(1, 2) = end.x - start.x;
  return g;
}

// add_icr: the plain excursion `pr` (from `start`, start heading derivative dth0) made that of
// a body turning about the point x_icr ahead of its centre C (Mandow et al. 2007).
// Derivation: that point P = C + x u(theta), u = (cos, sin), has no sideways velocity (C's is
// -x omega, P's -x omega + omega x = 0), so P moves exactly as a plain base's centre over the
// same wheel travels: P_end = P_start + D, D the plain displacement (what integrate computed for
// C). Hence C_end = C_start + D + x (u(theta0) - u(theta1)), whatever the path between: only
// the net heading change shows x, by 2 x sin(dtheta/2) across the mean heading; a net turn of
// 0 or 2 pi (a closed square, a dock drive back to its heading) does not. Derivatives:
// d C_end / d x = (cos theta0 - cos theta1, sin theta0 - sin theta1, 0), and through the headings
// x (u'(theta0) d theta0/dp - u'(theta1) d theta1/dp), u' = (-sin, cos). The odometry noise is
// the plain arc's about P (the same arcs) moved to C = P - x u(theta1) (shift_point, e = -x).
template <int N>
void add_icr(Prediction<N>& pr, const Pose2& start, const VecP<N>& dth0, double x, bool with_cov) {
  const double c0 = std::cos(start.theta), s0 = std::sin(start.theta);
  const double c1 = std::cos(pr.end.theta), s1 = std::sin(pr.end.theta);
  const VecP<N> dth1 = pr.d_param.row(2).transpose();
  pr.d_param.row(0) += (x * (-s0 * dth0 + s1 * dth1)).transpose();
  pr.d_param.row(1) += (x * (c0 * dth0 - c1 * dth1)).transpose();
  if constexpr (N == 4) {
    pr.d_param(0, 3) += c0 - c1;
    pr.d_param(1, 3) += s0 - s1;
  }
  pr.end.x += x * (c0 - c1);
  pr.end.y += x * (s0 - s1);
  if (!with_cov) return;
  Mat3 shift = Mat3::Identity();  // d C_end / d P_end
  shift(0, 2) = x * s1;
  shift(1, 2) = -x * c1;
  pr.odo_cov = shift * pr.odo_cov * shift.transpose();
}

}  // namespace

template <int N>
Prediction<N> integrate(const FixTrack& t, int from, int to, const Pose2& start,
                        const VecP<N>& dtheta0, const VecP<N>& p, double x_icr, double c_m,
                        const ErrorModelParams* with_cov) {
  using V = VecP<N>;
  Prediction<N> out;
  Pose2 q = start;
  V dx = V::Zero(), dy = V::Zero(), dth = dtheta0;
  Cov3 cov{};
  const double b = p(2);
  for (int leg = from; leg < to; ++leg) {
    for (const LegCounts& s : t.legs[static_cast<std::size_t>(leg)]) {
      const double d_l = p(0) * c_m * s.n_left, d_r = p(1) * c_m * s.n_right;
      const double ds = 0.5 * (d_l + d_r), turn = (d_r - d_l) / b, h = 0.5 * turn;
      const HalfAngle ha = half_angle(h);
      const double chord = ds * ha.sinc, a = q.theta + h;
      const double ca = std::cos(a), sa = std::sin(a);
      // Partial derivatives with respect to (c_L, c_R, b) (x_ICR: none, added by add_icr).
      V d_ds = V::Zero(), d_turn = V::Zero();
      d_ds.template head<3>() = Vec3(0.5 * c_m * s.n_left, 0.5 * c_m * s.n_right, 0.0);
      d_turn.template head<3>() = Vec3(-c_m * s.n_left / b, c_m * s.n_right / b, -turn / b);
      const V d_chord = d_ds * ha.sinc + (0.5 * ds * dsinc(h, ha)) * d_turn;
      const V d_a = dth + 0.5 * d_turn;
      dx += d_chord * ca - (chord * sa) * d_a;
      dy += d_chord * sa + (chord * ca) * d_a;
      dth += d_turn;
      if (with_cov != nullptr) propagate_arc(cov, q.theta, d_l, d_r, b, *with_cov);
      q = {q.x + chord * ca, q.y + chord * sa, q.theta + turn};
    }
  }
  out.end = q;
  out.d_param.row(0) = dx.transpose();
  out.d_param.row(1) = dy.transpose();
  out.d_param.row(2) = dth.transpose();
  out.odo_cov = Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(cov.data());
  // The plain fit with no offset in use keeps the plain arcs' numbers bit for bit.
  if (N == 4 || x_icr != 0.0) add_icr(out, start, dtheta0, x_icr, with_cov != nullptr);
  return out;
}

template <int N>
std::vector<Eval<N>> evaluate_chain(const FixTrack& t, std::span<const int> accepted,
                                    const VecP<N>& p, const SelfCalConfig& c, bool with_cov) {
  std::vector<Eval<N>> out;
  Heading<N> h;
  for (std::size_t k = 0; k + 1 < accepted.size(); ++k) {
    const PoseFix& fs = t.fixes[static_cast<std::size_t>(accepted[k])];
    const PoseFix& fe = t.fixes[static_cast<std::size_t>(accepted[k + 1])];
    if (fs.theta) h = Heading<N>{true, *fs.theta, VecP<N>::Zero(), fs.sigma_theta * fs.sigma_theta};
    Eval<N> e;
    e.from = accepted[k];
    e.to = accepted[k + 1];
    e.dof = fe.theta ? 3 : 2;
    e.usable = h.known;
    if (!h.known) {
      out.push_back(e);
      continue;
    }
    const Pose2 start{fs.x, fs.y, h.theta};
    const Prediction<N> pr =
        integrate<N>(t, e.from, e.to, start, h.d, p, x_icr_of<N>(p, c), c.metres_per_count,
                     with_cov ? &c.odometry_noise : nullptr);
    e.r = Vec3(fe.x - pr.end.x, fe.y - pr.end.y,
               fe.theta ? wrap_angle(*fe.theta - pr.end.theta) : 0.0);
    e.j = pr.d_param;
    e.g = start_propagation(start, pr.end);
    if (with_cov) {
      const Mat3& g = e.g;
      const Vec3 s0(fs.sigma_xy * fs.sigma_xy, fs.sigma_xy * fs.sigma_xy, h.var);
      const double v1 = fe.sigma_xy * fe.sigma_xy;
      const Vec3 s1(v1, v1, fe.theta ? fe.sigma_theta * fe.sigma_theta : 0.0);
      e.s = Mat3(s1.asDiagonal()) + g * s0.asDiagonal() * g.transpose() + pr.odo_cov;
    }
    out.push_back(e);
    h = Heading<N>{true, pr.end.theta, pr.d_param.row(2).transpose(), h.var};
  }
  return out;
}

template <int N>
double chi2(const Eval<N>& e, const Mat3& extra) {
  const Mat3 s = e.s + extra;
  if (e.dof == 3) return e.r.dot(s.ldlt().solve(e.r));
  const Eigen::Vector2d r = e.r.template head<2>();
  const Eigen::Matrix2d s2 = s.topLeftCorner<2, 2>();
  return r.dot(s2.ldlt().solve(r));
}

template Prediction<3> integrate<3>(const FixTrack&, int, int, const Pose2&, const VecP<3>&,
                                    const VecP<3>&, double, double, const ErrorModelParams*);
template Prediction<4> integrate<4>(const FixTrack&, int, int, const Pose2&, const VecP<4>&,
                                    const VecP<4>&, double, double, const ErrorModelParams*);
template std::vector<Eval<3>> evaluate_chain<3>(const FixTrack&, std::span<const int>,
                                                const VecP<3>&, const SelfCalConfig&, bool);
template std::vector<Eval<4>> evaluate_chain<4>(const FixTrack&, std::span<const int>,
                                                const VecP<4>&, const SelfCalConfig&, bool);
template double chi2<3>(const Eval<3>&, const Mat3&);
template double chi2<4>(const Eval<4>&, const Mat3&);

}  // namespace odo::calib::detail
