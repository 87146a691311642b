// Several driven wheels per side of the simulated robot (4WD, 6WD), each with its own encoder
// counter, and the faults of issue 38 at count level: a wheel lifted or spinning, a counter that
// faults. SideWheelsSim follows a SimRobot's side wheel angles; SimSideWheelsSource reads it as a
// backend with several encoders per side does (hal/side_wheels.hpp's SideCombiner).
//
// The wheels of one side (independent motors under the same voltage command) on the ground. A
// rigid body moves every wheel of a side over the ground by the same distance d, so a loaded
// wheel i of rolling radius r_i turns d / r_i: with the robot's side wheel (the single wheel of
// the plain simulation, radius r) turning by dA, wheel i turns dA r / r_i = dA / (1 + e_i). e_i is
// drawn once, uniform in [-radius_tolerance, radius_tolerance] (tyre tolerance and wear). On top,
// each wheel's rotation gets its own Chong-Kleeman noise, variance count_noise^2 |d| [m^2] as
// travel (floor irregularities under each tyre, independent per wheel), and its encoder disc
// starts at its own random phase inside a count.
//
// A lifted or spinning wheel (the motor model). A permanent-magnet DC motor under voltage V turns
// at omega = (V - R tau / k_t) / k_e: its speed falls linearly with the torque tau it delivers,
// from the no-load speed omega_0 = V / k_e to 0 at the stall torque. The loaded wheels of a side
// run at the ground's speed with the torque share l = tau / tau_stall (load_fraction), so the
// voltage that drives them corresponds to omega_0 = omega / (1 - l). A wheel whose load drops to
// a fraction rho of it (rho = 0: lifted off the ground; 0 < rho < 1: on a slippery patch where
// traction delivers only rho of the torque) accelerates towards omega_0 (1 - rho l) =
// omega (1 - rho l) / (1 - l), with the motor's mechanical time constant
// tau_m (spin_up_time: rotor and wheel inertia against the motor's speed-torque slope), and its
// excess over the ground speed is
//   x(t) = x_max (1 - exp(-t / tau_m)),   x_max = (1 - rho l) / (1 - l) - 1.
// With l = 0.25 a lifted wheel spins 33 % faster than its neighbours, one on a patch of rho = 0.5
// 17 % faster. The excess rotation over a read interval [t0, t1] (constant side speed within it)
// is dA / (t1 - t0) times the integral of x, x_max ((t1 - t0) - tau_m (exp(-t0'/tau_m) -
// exp(-t1'/tau_m))) with t' the time since the fault began. At touchdown the ground's friction
// brakes the wheel to the ground speed at once (far faster than tau_m): the excess counted so far
// stays in its counter. Standing still (V = 0) a lifted wheel does not turn.
//
// A counter fault: over the interval the wheel's decoder sees illegal transitions (a broken line,
// noise), its counter gains garbage counts and the backend marks the wheel faulted; afterwards
// the counter counts correctly again from its corrupted value.
#pragma once

#include <array>
#include <cstdint>

#include "odo/hal/encoder.hpp"
#include "odo/hal/result.hpp"
#include "odo/hal/side_wheels.hpp"
#include "odo/hal/time.hpp"
#include "odo/sim/robot.hpp"
#include "odo/sim/ziggurat.hpp"

namespace odo::sim {

struct SideWheelsSimParams {
  int wheels_per_side = 2;          // 1..4
  double radius_tolerance = 0.003;  // each wheel's rolling radius within +- this of the side's
  double count_noise = 1.0e-4;      // per-wheel travel noise k_w [m^(1/2)] (variance k_w^2 |d|)
  double load_fraction = 0.25;      // l: share of the stall torque a loaded wheel delivers
  double spin_up_time = 0.05;       // tau_m: mechanical time constant of an unloaded wheel [s]
  std::uint64_t seed = 1;           // radii, phases and noise (runs are repeatable)
};

// check_side_wheels_sim: every parameter finite and in range (wheels 1..4, tolerance [0, 0.1],
// count_noise [0, 0.1] m^(1/2), load_fraction [0, 0.9], spin_up_time (0, 10] s).
Status check_side_wheels_sim(const SideWheelsSimParams& p);

enum class WheelFault : std::uint8_t {
  kNone,
  kUnloaded,  // lifted (remaining load 0) or spinning on a slippery patch (0 < load < 1)
  kCounter,   // the wheel's counter faults (garbage counts, flagged by its decoder)
};

class SideWheelsSim {
 public:
  // create: validates p; the wheels' radii and phases are drawn from p.seed.
  static Result<SideWheelsSim> create(const SideWheelsSimParams& p, const RobotGeometry& g);

  // update: advance every wheel to time t [ns] from the robot's side wheel angles [rad] (the
  // robot advanced to t); the first call only takes the angles as the start.
  void update(TimeNs t, double angle_left, double angle_right) noexcept;
  // counts: wheel `wheel` of side `side` (0 left, 1 right): its cumulative count as its counter
  // holds it (64 bits; the reader keeps the low bits).
  std::int64_t counts(int side, int wheel) const noexcept;
  // faulted: the wheel's decoder flags its counter at the last update.
  bool faulted(int side, int wheel) const noexcept;
  // inject: `fault` on one wheel over [start, end) [ns]; remaining_load rho for kUnloaded
  // (0 lifted, in (0, 1) spinning). One fault per wheel at a time: a new one replaces it.
  void inject(int side, int wheel, WheelFault fault, TimeNs start, TimeNs end,
              double remaining_load = 0.0) noexcept;
  const SideWheelsSimParams& params() const noexcept { return p_; }
  // radius_ratio: r_side / r_i of a wheel (its turns per turn of the side's nominal wheel).
  double radius_ratio(int side, int wheel) const noexcept { return wheel_at(side, wheel).ratio; }

 private:
  struct Wheel {
    double ratio = 1.0;        // r / r_i
    double angle = 0.0;        // [rad] the wheel has turned
    double phase = 0.5;        // encoder disc phase in counts [0, 1)
    std::int64_t garbage = 0;  // counts a counter fault added
    WheelFault fault = WheelFault::kNone;
    TimeNs start = 0, end = 0;
    double x_max = 0.0;  // excess speed of an unloaded wheel, as a fraction
    bool faulted = false;
  };
  SideWheelsSim(const SideWheelsSimParams& p, const RobotGeometry& g);
  Wheel& wheel_at(int side, int wheel) noexcept;
  const Wheel& wheel_at(int side, int wheel) const noexcept;
  // excess_integral: integral of x over [t0, t1] [s] for an unloaded wheel (see the top).
  double excess_integral(const Wheel& w, TimeNs t0, TimeNs t1) const noexcept;
  void move_wheel(Wheel& w, double d_angle, double radius, TimeNs t0, TimeNs t1) noexcept;

  SideWheelsSimParams p_;
  std::array<std::array<Wheel, kMaxWheelsPerSide>, 2> wheels_{};
  std::array<double, 2> radius_{};  // the sides' nominal wheel radii [m]
  double counts_per_rad_ = 0.0;
  double last_angle_[2] = {0.0, 0.0};
  TimeNs last_t_ = 0;
  bool started_ = false;
  ZigguratNormal normal_;
  Xoshiro256pp garbage_;  // a counter fault's counts
};

// SimSideWheelsSource: the simulated robot's wheels read as N counters per side of `bits` bits
// each, combined by a SideCombiner (its config's wheels_per_side and counter_bits are the
// model's and `bits`); the combined counts never wrap (counter_bits() == 64).
class SimSideWheelsSource final : public EncoderSource {
 public:
  // create: the combiner's config checked (check_side_wheels) with wheels_per_side from the model.
  static Result<SimSideWheelsSource> create(SimRobot& robot, SideWheelsSim model,
                                            SideWheelsConfig combine, int bits);
  EncoderSample read(TimeNs now) noexcept override;
  int counter_bits() const noexcept override { return 64; }
  SideWheelsSim& model() noexcept { return model_; }
  const SideCombiner& combiner() const noexcept { return combiner_; }
  // last: the combiner's output of the last read (window spreads and ratios, for benchmarks).
  const SideStep& last() const noexcept { return last_; }
  // readings: every wheel's counter (low `bits` bits, sign-extended) and fault at the last read,
  // [0] left, [1] right (what a board sends the host as serial counts version 2).
  const std::array<SideReadings, 2>& readings() const noexcept { return readings_; }

 private:
  SimSideWheelsSource(SimRobot& robot, SideWheelsSim model, SideCombiner combiner, int bits)
      : robot_(&robot), model_(std::move(model)), combiner_(combiner), bits_(bits) {}
  SimRobot* robot_;
  SideWheelsSim model_;
  SideCombiner combiner_;
  int bits_;
  SideStep last_;
  std::array<SideReadings, 2> readings_{};
};

}  // namespace odo::sim
