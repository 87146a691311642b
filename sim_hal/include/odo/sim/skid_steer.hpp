// Skid-steer body (issue 38): a four-wheel base whose sideways slip comes from the friction of its
// wheels on the floor, not from the estimator's effective-track formula. Quasi-static force
// balance after Kozlowski & Pazderski 2004 ("Modeling and control of a 4-wheel skid-steering
// mobile robot", Int. J. Appl. Math. Comput. Sci. 14(4)): at the low speeds of UMBmark the
// inertial forces are small against the friction forces, so at every instant the floor's total
// force and yaw moment on the body vanish; the body twist that makes them vanish is the one the
// robot moves with. The effective track then emerges from the wheel layout and the friction law;
// Mandow et al. 2007 ("Experimental kinematics for wheeled skid-steer mobile robots", IROS)
// measure the resulting instantaneous centres of rotation on a real 4WD base.
#pragma once

#include <cstdint>

#include "odo/hal/result.hpp"
#include "odo/odometry/pose.hpp"
#include "odo/sim/robot.hpp"

namespace odo::sim {

// SkidSteerParams: wheel layout, load and friction. Wheels sit at (+-a, +-t/2) from the
// geometric centre; x forward, y left.
struct SkidSteerParams {
  double half_wheelbase = 0.131;  // a [m], front axle to centre
  double track = 0.37559;         // t [m], geometric track (left to right contact points)
  double mass = 17.0;             // [kg]
  double com_x = 0.0;             // centre of mass ahead of the geometric centre [m], |.| < a
  double gravity = 9.81;          // [m/s^2]
  // Friction ellipse of a tyre (the limit force mu_long N along the wheel, mu_lat N across it).
  double mu_long = 0.8;
  double mu_lat = 0.8;
  // Regularisation of the Coulomb law [m/s of mu-weighted slip]: below it the force grows
  // linearly with the slip (a tyre's elastic range), above it the force is mu N.
  double slip_eps = 1e-3;
};

// BodyTwist: the body-frame velocity of the geometric centre.
struct BodyTwist {
  double vx = 0.0;     // [m/s] forward
  double vy = 0.0;     // [m/s] left
  double omega = 0.0;  // [rad/s] CCW
};

// Wrench: the floor's total force on the body and its yaw moment about the geometric centre.
struct Wrench {
  double fx = 0.0;  // [N]
  double fy = 0.0;  // [N]
  double mz = 0.0;  // [N m]
};

// jackal_skid_params: the Jackal-sized 4WD base of README "Skid-steer bases" (sources there).
SkidSteerParams jackal_skid_params();
// skid4_geometry: the same base's encoders and wheels as a RobotGeometry: wheel diameter
// 0.196 m both sides, wheelbase = the geometric track (what SimRobot validates and odometry
// with the geometric track believes).
RobotGeometry skid4_geometry();

// check_skid_params: every field finite, masses and lengths > 0, |com_x| < a, mu >= 0 with
// mu_long > 0, slip_eps > 0; the error names the field and its range.
Status check_skid_params(const SkidSteerParams& p);

// wheel_load: static normal load [N] of one wheel (front true/false); the axle loads follow the
// centre of mass's longitudinal position, left and right share them equally.
double wheel_load(const SkidSteerParams& p, bool front) noexcept;

// skid_wrench: the floor's force and moment on the body moving with twist q while the left and
// right rims turn at rim speeds v_left, v_right [m/s].
Wrench skid_wrench(const SkidSteerParams& p, const BodyTwist& q, double v_left,
                   double v_right) noexcept;

// SkidSolution: the quasi-static twist and how Newton got there.
struct SkidSolution {
  BodyTwist twist;
  int iterations = 0;
  bool converged = false;
};

// solve_skid_twist: the twist at which skid_wrench vanishes for rim speeds v_left, v_right
// [m/s], by damped Newton from `warm` (the previous step's twist). p must pass
// check_skid_params.
SkidSolution solve_skid_twist(const SkidSteerParams& p, double v_left, double v_right,
                              const BodyTwist& warm = {}) noexcept;

// effective_track: (v_right - v_left) / omega [m] of the solved twist s for rim speeds v_left,
// v_right [m/s]; 0 when the body does not turn (omega == 0).
double effective_track(const SkidSolution& s, double v_left, double v_right) noexcept;
// skid_effective_track: effective_track of the quasi-static twist for rim speeds v_left, v_right.
double skid_effective_track(const SkidSteerParams& p, double v_left, double v_right) noexcept;

// twist_step: the pose after moving with the body twist q held constant for dt [s] (exact
// integration of a constant body-frame twist).
Pose2 twist_step(const Pose2& pose, const BodyTwist& q, double dt) noexcept;

// SkidSteerBody: the stateful body SimRobot moves with in place of its differential-drive arc:
// the twist is solved when the rim speeds change (warm-started from the last one) and reused
// while they stay; on-the-spot turns (rims in opposite senses) are metered from the truth.
class SkidSteerBody {
 public:
  // create: a body with parameters p (check_skid_params).
  static Result<SkidSteerBody> create(const SkidSteerParams& p);
  // step: the pose after dt [s] with rim travels d_left, d_right [m] over that step.
  Pose2 step(const Pose2& pose, double d_left, double d_right, double dt) noexcept;
  const SkidSteerParams& params() const noexcept { return p_; }
  // spot_turn_rim / spot_turn_angle: sum over on-the-spot turn steps of |d_right - d_left| [m]
  // and of the true |heading change| [rad]; their ratio is the track the turns show.
  double spot_turn_rim() const noexcept { return turn_rim_; }
  double spot_turn_angle() const noexcept { return turn_angle_; }
  // unconverged: steps whose Newton solve did not converge (0 in every test).
  std::uint64_t unconverged() const noexcept { return unconverged_; }

 private:
  explicit SkidSteerBody(const SkidSteerParams& p) : p_(p) {}
  SkidSteerParams p_;
  double key_l_ = 0.0, key_r_ = 0.0;  // rim speeds [m/s] of the cached twist
  BodyTwist twist_;                   // the cached (and warm-start) twist
  double turn_rim_ = 0.0, turn_angle_ = 0.0;
  std::uint64_t unconverged_ = 0;
};

}  // namespace odo::sim
