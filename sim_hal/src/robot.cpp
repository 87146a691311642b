#include "odo/sim/robot.hpp"

#include <cmath>
#include <numbers>
#include <string>

#include "odo/hal/format.hpp"
#include "odo/sim/skid_steer.hpp"

namespace odo::sim {
namespace {

// Re-derive sin/cos of the true heading from theta every this many steps (and at every segment
// boundary). A cached rotation repeats the same rounding every step, so the drift grows linearly
// with the interval: at 32 steps the truth stays within 1.3e-12 m of a sin/cos per step after an
// hour at 1 kHz (850 m of arc), for about 3 instructions per step.
constexpr std::uint32_t kResyncSteps = 32;

}  // namespace

RobotGeometry labmate_geometry(double nominal_diameter) {
  // D_R / D_L = 0.9985 with (D_L + D_R) / 2 = Dn, so the scaling error E_s is 1.
  constexpr double kRatio = 0.9985;
  RobotGeometry g;
  g.wheel_diameter_left = 2.0 * nominal_diameter / (1.0 + kRatio);
  g.wheel_diameter_right = kRatio * g.wheel_diameter_left;
  g.wheelbase = 0.337;
  return g;
}

KinematicParams nominal_params(double wheel_diameter, double wheelbase, const RobotGeometry& g) {
  KinematicParams p;
  p.wheel_diameter = wheel_diameter;
  p.counts_per_rev = g.counts_per_rev;
  p.gear_ratio = g.gear_ratio;
  p.wheelbase_nominal = wheelbase;
  p.wheelbase = wheelbase;
  return p;
}

Scenario square_scenario(const Kinematics& k, const SquareOptions& o) {
  const KinematicParams& p = k.params();
  // A real robot drives each leg and turn until its encoders reach whole-count targets, sized
  // with what it believes (factors c_L, c_R, wheelbase b; Eq. 6.35). The commanded wheel angle is
  // therefore a whole number of counts; the true geometry decides where the robot really goes.
  const double counts_per_wheel_rad = p.counts_per_rev * p.gear_ratio / (2.0 * std::numbers::pi);
  auto wheel_angle = [&](double distance, double c) {
    return std::round(distance / (c * k.metres_per_count())) / counts_per_wheel_rad;
  };
  const double turn_sign = o.direction == Turn::kCounterClockwise ? 1.0 : -1.0;
  // On-the-spot 90 degree turn: each wheel travels b/2 * pi/2 (believed) in opposite senses.
  const double turn_arc = k.wheelbase() / 2.0 * std::numbers::pi / 2.0;
  const double turn_time = (std::numbers::pi / 2.0) / o.turn_rate;
  const double leg_time = o.side / o.speed;
  const double leg_l = wheel_angle(o.side, p.c_l), leg_r = wheel_angle(o.side, p.c_r);
  const double turn_l = wheel_angle(turn_arc, p.c_l), turn_r = wheel_angle(turn_arc, p.c_r);
  Scenario s;
  for (int leg = 0; leg < 4; ++leg) {
    s.push_back({leg_time, leg_l / leg_time, leg_r / leg_time});
    s.push_back({o.pause, 0.0, 0.0});
    s.push_back({turn_time, -turn_sign * turn_l / turn_time, turn_sign * turn_r / turn_time});
    s.push_back({o.pause, 0.0, 0.0});
  }
  return s;
}

Scenario squares_scenario(const Kinematics& believed, SquareOptions o, SquareSet set) {
  Scenario out;
  auto add = [&](Turn dir) {
    o.direction = dir;
    const Scenario sq = square_scenario(believed, o);
    out.insert(out.end(), sq.begin(), sq.end());
  };
  if (set == SquareSet::kCcw || set == SquareSet::kBoth) add(Turn::kCounterClockwise);
  if (set == SquareSet::kCw || set == SquareSet::kBoth) add(Turn::kClockwise);
  return out;
}

RobotGeometry simulated_geometry(bool labmate, const KinematicParams& p) {
  RobotGeometry g;
  g.counts_per_rev = p.counts_per_rev;
  g.gear_ratio = p.gear_ratio;
  if (labmate) {
    const RobotGeometry lm = labmate_geometry(p.wheel_diameter);
    g.wheel_diameter_left = lm.wheel_diameter_left;
    g.wheel_diameter_right = lm.wheel_diameter_right;
    g.wheelbase = lm.wheelbase;
  } else {
    g.wheel_diameter_left = g.wheel_diameter_right = p.wheel_diameter;
    g.wheelbase = p.wheelbase_nominal;
  }
  return g;
}

double scenario_duration(const Scenario& s) {
  double d = 0.0;
  for (const Segment& seg : s) d += seg.duration;
  return d;
}

Result<SimRobot> SimRobot::create(const RobotGeometry& g, Scenario scenario, const Pose2& start) {
  auto bad = [](const char* f, double v) {
    return make_error(Errc::kInvalidArgument, std::string("sim robot ") + f + " = " +
                                                  general_text(v) + " must be finite and > 0");
  };
  if (!(g.wheel_diameter_left > 0 && std::isfinite(g.wheel_diameter_left)))
    return bad("wheel_diameter_left", g.wheel_diameter_left);
  if (!(g.wheel_diameter_right > 0 && std::isfinite(g.wheel_diameter_right)))
    return bad("wheel_diameter_right", g.wheel_diameter_right);
  if (!(g.wheelbase > 0 && std::isfinite(g.wheelbase))) return bad("wheelbase", g.wheelbase);
  if (!(g.counts_per_rev > 0 && std::isfinite(g.counts_per_rev)))
    return bad("counts_per_rev", g.counts_per_rev);
  if (!(g.gear_ratio > 0 && std::isfinite(g.gear_ratio))) return bad("gear_ratio", g.gear_ratio);
  for (const Segment& seg : scenario) {
    if (!(seg.duration >= 0 && std::isfinite(seg.duration) && std::isfinite(seg.omega_left) &&
          std::isfinite(seg.omega_right)))
      return make_error(Errc::kInvalidArgument, "sim scenario segment is not finite");
  }
  return SimRobot(g, std::move(scenario), start);
}

SimRobot::SimRobot(const RobotGeometry& g, Scenario s, const Pose2& start)
    : g_(g), scenario_(std::move(s)), pose_(start), heading_(kResyncSteps) {
  counts_per_wheel_rad_ = g.counts_per_rev * g.gear_ratio / (2.0 * std::numbers::pi);
  if (!scenario_.empty()) seg_end_ = from_seconds(scenario_[0].duration);
  heading_.reset(pose_.theta);
}

void SimRobot::move(double dt, const Segment& seg) noexcept {
  const double da_l = seg.omega_left * dt;
  const double da_r = seg.omega_right * dt;
  angle_l_ += da_l;
  angle_r_ += da_r;
  double d_l = da_l * g_.wheel_diameter_left / 2.0;
  double d_r = da_r * g_.wheel_diameter_right / 2.0;
  if (perturbation_ != nullptr) {
    // Only these copies have their address taken: d_l, d_r stay in registers otherwise.
    double p_l = d_l, p_r = d_r;
    perturbation_->perturb(p_l, p_r);
    d_l = p_l;
    d_r = p_r;
  }
  if (skid_ != nullptr) {
    pose_ = skid_->step(pose_, d_l, d_r, dt);
    return;
  }
  // Constant wheel speeds give a constant-curvature arc: the exact arc step is the truth. The
  // centre moves along the chord ds * sinc(h) at the mean heading theta + h, h = dtheta / 2.
  if (d_l != step_d_l_ || d_r != step_d_r_) {
    const double ds = 0.5 * (d_l + d_r);
    const double dth = (d_r - d_l) / g_.wheelbase;
    const double h = 0.5 * dth;
    if (!(std::fabs(h) < kHalfAngleSeriesLimit)) {
      // A large turn in one step (coarse test steps): real trigonometry, then a fresh sin/cos.
      pose_ = arc_step(pose_, d_l, d_r, g_.wheelbase);
      heading_.reset(pose_.theta);
      return;
    }
    const HalfAngle a = half_angle(h);  // the series branch
    step_cos_h_ = a.c;
    step_sin_h_ = a.s;
    step_chord_ = ds * a.sinc;
    step_dth_ = dth;
    step_d_l_ = d_l;
    step_d_r_ = d_r;
  }
  // cos/sin of the mean heading by the angle-sum identities instead of a sin and cos per step.
  double cm = 0.0, sm = 0.0;
  heading_.mean(step_cos_h_, step_sin_h_, cm, sm);
  pose_.x += step_chord_ * cm;
  pose_.y += step_chord_ * sm;
  pose_.theta += step_dth_;
  heading_.finish(pose_.theta, cm, sm, step_cos_h_, step_sin_h_);
}

void SimRobot::advance_across(TimeNs t) noexcept {
  while (t_ < t) {
    if (seg_ >= scenario_.size()) {
      t_ = t;  // standing still after the last segment
      return;
    }
    const TimeNs until = t < seg_end_ ? t : seg_end_;
    move(to_seconds(until - t_), scenario_[seg_]);
    t_ = until;
    if (t_ >= seg_end_) {
      ++seg_;
      seg_start_ = seg_end_;
      seg_end_ = seg_ < scenario_.size() ? seg_start_ + from_seconds(scenario_[seg_].duration)
                                         : kNoSegment;
      // Segment boundary: the rotated sin/cos restart from the exact heading.
      heading_.reset(pose_.theta);
    }
  }
}

}  // namespace odo::sim
