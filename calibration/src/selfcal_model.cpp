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
struct Heading {
  bool known = false;
  double theta = 0.0;
  Vec3 d = Vec3::Zero();  // d theta / d p
  double var = 0.0;       // [rad^2]
};

Mat3 start_propagation(const Pose2& start, const Pose2& end) {
  // d end / d start of a rigid excursion: translation passes through, a heading change
  // rotates the displacement (end - start) by 90 degrees.
  Mat3 g = Mat3::Identity();
  g(0, 2) = -(end.y - start.y);
  g(1, 2) = end.x - start.x;
  return g;
}

}  // namespace

Prediction integrate(const FixTrack& t, int from, int to, const Pose2& start, const Vec3& dtheta0,
                     const Vec3& p, double c_m, const ErrorModelParams* with_cov) {
  Prediction out;
  Pose2 q = start;
  Vec3 dx = Vec3::Zero(), dy = Vec3::Zero(), dth = dtheta0;
  Cov3 cov{};
  const double b = p(2);
  for (int leg = from; leg < to; ++leg) {
    for (const LegCounts& s : t.legs[static_cast<std::size_t>(leg)]) {
      const double d_l = p(0) * c_m * s.n_left, d_r = p(1) * c_m * s.n_right;
      const double ds = 0.5 * (d_l + d_r), turn = (d_r - d_l) / b, h = 0.5 * turn;
      const HalfAngle ha = half_angle(h);
      const double chord = ds * ha.sinc, a = q.theta + h;
      const double ca = std::cos(a), sa = std::sin(a);
      // Partial derivatives with respect to (c_L, c_R, b).
      const Vec3 d_ds(0.5 * c_m * s.n_left, 0.5 * c_m * s.n_right, 0.0);
      const Vec3 d_turn(-c_m * s.n_left / b, c_m * s.n_right / b, -turn / b);
      const Vec3 d_chord = d_ds * ha.sinc + (0.5 * ds * dsinc(h, ha)) * d_turn;
      const Vec3 d_a = dth + 0.5 * d_turn;
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
  return out;
}

std::vector<Eval> evaluate_chain(const FixTrack& t, std::span<const int> accepted, const Vec3& p,
                                 const SelfCalConfig& c, bool with_cov) {
  std::vector<Eval> out;
  Heading h;
  for (std::size_t k = 0; k + 1 < accepted.size(); ++k) {
    const PoseFix& fs = t.fixes[static_cast<std::size_t>(accepted[k])];
    const PoseFix& fe = t.fixes[static_cast<std::size_t>(accepted[k + 1])];
    if (fs.theta) h = Heading{true, *fs.theta, Vec3::Zero(), fs.sigma_theta * fs.sigma_theta};
    Eval e;
    e.from = accepted[k];
    e.to = accepted[k + 1];
    e.dof = fe.theta ? 3 : 2;
    e.usable = h.known;
    if (!h.known) {
      out.push_back(e);
      continue;
    }
    const Pose2 start{fs.x, fs.y, h.theta};
    const Prediction pr = integrate(t, e.from, e.to, start, h.d, p, c.metres_per_count,
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
    h = Heading{true, pr.end.theta, pr.d_param.row(2).transpose(), h.var};
  }
  return out;
}

double chi2(const Eval& e, const Mat3& extra) {
  const Mat3 s = e.s + extra;
  if (e.dof == 3) return e.r.dot(s.ldlt().solve(e.r));
  const Eigen::Vector2d r = e.r.head<2>();
  const Eigen::Matrix2d s2 = s.topLeftCorner<2, 2>();
  return r.dot(s2.ldlt().solve(r));
}

Mat3 weight(const Eval& e) {
  if (e.dof == 3) return e.s.inverse();
  Mat3 w = Mat3::Zero();
  w.topLeftCorner<2, 2>() = e.s.topLeftCorner<2, 2>().inverse();
  return w;
}

}  // namespace odo::calib::detail
