#include "odo/sim/side_wheels_sim.hpp"

#include <cmath>
#include <numbers>
#include <string>

#include "odo/hal/field_range.hpp"
#include "odo/hal/side_sample.hpp"

namespace odo::sim {
namespace {

constexpr RangeRow kWheels{"wheels_per_side", 1, kMaxWheelsPerSide, ""};
constexpr RangeRow kTolerance{"radius_tolerance", 0.0, 0.1, ""};
constexpr RangeRow kCountNoise{"count_noise", 0.0, 0.1, "m^(1/2)"};
constexpr RangeRow kLoad{"load_fraction", 0.0, 0.9, ""};
constexpr RangeRow kSpinUp{"spin_up_time", 0.0, 10.0, "s", true};

}  // namespace

Status check_side_wheels_sim(const SideWheelsSimParams& p) {
  const std::pair<const RangeRow*, double> rows[] = {{&kWheels, p.wheels_per_side},
                                                     {&kTolerance, p.radius_tolerance},
                                                     {&kCountNoise, p.count_noise},
                                                     {&kLoad, p.load_fraction},
                                                     {&kSpinUp, p.spin_up_time}};
  for (const auto& [row, v] : rows)
    if (auto s = check_row(*row, "sim wheels: ", v); !s) return s;
  return Ok{};
}

Result<SideWheelsSim> SideWheelsSim::create(const SideWheelsSimParams& p, const RobotGeometry& g) {
  if (auto s = check_side_wheels_sim(p); !s) return std::move(s).error();
  return SideWheelsSim(p, g);
}

SideWheelsSim::SideWheelsSim(const SideWheelsSimParams& p, const RobotGeometry& g)
    : p_(p), normal_(p.seed), garbage_(~p.seed) {
  radius_ = {0.5 * g.wheel_diameter_left, 0.5 * g.wheel_diameter_right};
  counts_per_rad_ = g.counts_per_rev * g.gear_ratio / (2.0 * std::numbers::pi);
  for (auto& side : wheels_)
    for (int i = 0; i < p.wheels_per_side; ++i) {
      Wheel& w = side[static_cast<std::size_t>(i)];
      // r_i = r (1 + e), e uniform in [-tol, tol]: the wheel turns r / r_i per turn of r.
      w.ratio = 1.0 / (1.0 + p.radius_tolerance * (2.0 * normal_.uniform() - 1.0));
      w.phase = normal_.uniform();
    }
}

SideWheelsSim::Wheel& SideWheelsSim::wheel_at(int side, int wheel) noexcept {
  return wheels_[static_cast<std::size_t>(side)][static_cast<std::size_t>(wheel)];
}

const SideWheelsSim::Wheel& SideWheelsSim::wheel_at(int side, int wheel) const noexcept {
  return wheels_[static_cast<std::size_t>(side)][static_cast<std::size_t>(wheel)];
}

void SideWheelsSim::inject(int side, int wheel, WheelFault fault, TimeNs start, TimeNs end,
                           double remaining_load) noexcept {
  Wheel& w = wheel_at(side, wheel);
  w.fault = fault;
  w.start = start;
  w.end = end;
  const double l = p_.load_fraction;
  w.x_max = (1.0 - remaining_load * l) / (1.0 - l) - 1.0;
}

double SideWheelsSim::excess_integral(const Wheel& w, TimeNs t0, TimeNs t1) const noexcept {
  // Only the part of [t0, t1] inside the fault; x(t') = x_max (1 - exp(-t' / tau_m)).
  const TimeNs a = t0 > w.start ? t0 : w.start, b = t1 < w.end ? t1 : w.end;
  if (b <= a) return 0.0;
  const double tau = p_.spin_up_time;
  const double ta = to_seconds(a - w.start), tb = to_seconds(b - w.start);
  return w.x_max * ((tb - ta) - tau * (std::exp(-ta / tau) - std::exp(-tb / tau)));
}

void SideWheelsSim::move_wheel(Wheel& w, double d_angle, double radius, TimeNs t0,
                               TimeNs t1) noexcept {
  double turn = d_angle * w.ratio;
  // Chong-Kleeman per wheel: travel noise of variance k_w^2 |d|, as rotation of this wheel.
  const double d = std::fabs(d_angle) * radius;
  turn += p_.count_noise * std::sqrt(d) * normal_() / radius * w.ratio;
  if (w.fault == WheelFault::kUnloaded && t1 > t0)
    turn += d_angle * w.ratio * excess_integral(w, t0, t1) / to_seconds(t1 - t0);
  w.angle += turn;
  w.faulted = w.fault == WheelFault::kCounter && t1 >= w.start && t1 < w.end;
  // A faulting decoder counts garbage: up to 300 counts either way per read (from a generator
  // of its own, so a fault leaves the other wheels' noise as it was).
  if (w.faulted) w.garbage += static_cast<std::int64_t>(garbage_() % 601u) - 300;
}

void SideWheelsSim::update(TimeNs t, double angle_left, double angle_right) noexcept {
  const double angles[2] = {angle_left, angle_right};
  if (!started_) {
    started_ = true;
    last_t_ = t;
    last_angle_[0] = angle_left;
    last_angle_[1] = angle_right;
    return;
  }
  for (std::size_t s = 0; s < 2; ++s) {
    const double d_angle = angles[s] - last_angle_[s];
    for (int i = 0; i < p_.wheels_per_side; ++i)
      move_wheel(wheels_[s][static_cast<std::size_t>(i)], d_angle, radius_[s], last_t_, t);
    last_angle_[s] = angles[s];
  }
  last_t_ = t;
}

std::int64_t SideWheelsSim::counts(int side, int wheel) const noexcept {
  const Wheel& w = wheel_at(side, wheel);
  return static_cast<std::int64_t>(std::floor(w.angle * counts_per_rad_ + w.phase)) + w.garbage;
}

bool SideWheelsSim::faulted(int side, int wheel) const noexcept {
  return wheel_at(side, wheel).faulted;
}

Result<SimSideWheelsSource> SimSideWheelsSource::create(SimRobot& robot, SideWheelsSim model,
                                                        SideWheelsConfig combine, int bits) {
  combine.wheels_per_side = model.params().wheels_per_side;
  combine.counter_bits = bits;
  auto c = SideCombiner::create(combine);
  if (!c) return std::move(c).error();
  return SimSideWheelsSource(robot, std::move(model), std::move(c).value(), bits);
}

EncoderSample SimSideWheelsSource::read(TimeNs now) noexcept {
  robot_->advance_to(now);
  model_.update(now, robot_->wheel_angle_left(), robot_->wheel_angle_right());
  for (int s = 0; s < 2; ++s) {
    SideReadings& r = readings_[static_cast<std::size_t>(s)];
    r.faulted = 0;
    for (int i = 0; i < model_.params().wheels_per_side; ++i) {
      // The register keeps the low bits_ bits; wrap_delta from 0 sign-extends them.
      r.counts[static_cast<std::size_t>(i)] = wrap_delta(0, model_.counts(s, i), bits_);
      if (model_.faulted(s, i)) r.faulted |= static_cast<std::uint8_t>(1u << i);
    }
  }
  last_ = combiner_.step(readings_[0], readings_[1]);
  EncoderSample out;
  out.stamp = now;
  apply_side_step(last_, combiner_.counters(), out);
  return out;
}

}  // namespace odo::sim
