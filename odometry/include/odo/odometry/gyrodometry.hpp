// Gyrodometry (Borenstein & Feng, ICRA 1996) made robust to coarse encoders: odometry's heading
// increment on every tick, except over the intervals where gyro and odometry disagree (a bump, a
// crack, a slip) or the wheels do what the robot cannot; there the gyro's increment. Pure math:
// time and inputs are arguments; configure allocates, step() never does and never throws.
//
// Why a window and not tick by tick. With 2048 counts per revolution on a direct-drive 0.15 m
// wheel read at 200 Hz a wheel moves one or two counts a tick: odometry's heading increment of a
// tick is quantised to q_tick = (m_L + m_R)/b = 1.35 mrad (m = pi D / 2048 = 0.23 mm, b = 0.34 m),
// 5x the whole increment of a 0.05 rad/s turn. A tick-by-tick comparison sees that as
// disagreement, and choosing per tick biases the heading (it picks the ticks where the counts
// happened to lead). But the error of a count difference does not grow with the interval: the
// heading increment over ANY window, from two cumulative readings, is off by less than one count
// on each wheel, i.e. by less than q = (m_L + m_R)/b, however long the window. The gyro's angle
// noise over a window of T_w seconds grows as N sqrt(T_w). So the comparison is made on the sum of
// the disagreements over the last n = T_w / tick ticks, E = sum (dtheta_gyro' - dtheta_odo).
//
// Why the gyro is re-timed. A gyro's samples lag the motion by d (its filter's group delay plus
// transport; 2 ms for the consumer part). Compared tick by tick with odometry of the same tick, a
// turn that starts or stops shows omega d of disagreement for a window's length (1 mrad at
// 0.5 rad/s, twice the LabMate's threshold). So odometry is compared with the gyro's view of the
// same moments: write d = m tick - g tick with m = ceil(d / tick) and 0 <= g < 1. Odometry's tick
// of age m (it covers [t_m+1, t_m], ages count back from the newest tick, 0) happened, on the
// gyro's clock, over [t_1 - g tick, t_0 - g tick]: the last g of the gyro's tick 1 and the first
// 1 - g of its tick 0. Its aligned gyro increment is (1 - g) dtheta_gyro,0 + g dtheta_gyro,1, and
// the window's sum of those telescopes to the gyro's heading change between two points, t_0 - g
// tick and t_n - g tick, read by linear interpolation inside gyro ticks 0 and n. Odometry's side
// stays whole ticks (ages m .. m + n - 1), so its quantisation stays one count on each wheel.
// What the interpolation can miss: a change of the turn rate inside an edge tick. If the rate
// steps by delta omega at fraction s of a tick and the point sits at fraction p = 1 - g, the true
// heading there differs from the interpolated one by p (1 - s) delta omega tick (s >= p) or
// s (1 - p) delta omega tick (s < p). The jumps of the gyro's increments around that tick,
// J_old = |dtheta_a - dtheta_a+1| = (1 - s) delta omega tick and J_new = |dtheta_a-1 - dtheta_a|
// = s delta omega tick, give it exactly as min(p J_old, (1 - p) J_new): for s >= p the error is
// p J_old and p (1 - s) <= (1 - p) s; for s < p it is (1 - p) J_new and s (1 - p) <= p (1 - s).
// The newest edge (tick 0) has no newer neighbour: p J_old there. A ramp (constant
// angular acceleration alpha) is covered too: its error p (1 - p) alpha tick^2 / 2 is below
// p J_old = p alpha tick^2. With g = 0 the points are tick boundaries and these terms vanish.
// The gyro's jumps, not odometry's, because they carry its noise (5 N sqrt(2 tick), 1.7e-4 rad
// at 100 Hz) instead of a count (1.35e-3 rad on the direct drive). The configured d itself is
// only known to within delta_d: that shifts both points and leaves delta_d (omega_0 - omega_n).
//
// Why odometry's own noise is in the threshold. A floor's small irregularities turn odometry's
// heading a little all the time (Chong & Kleeman's wheel noise, variance k^2 |d| per wheel: the
// pose covariance's k_L, k_R). With the gyro's noise alone in T, the windows where such noise
// happens to cross T are replaced and the others are not: when anything shifts E a little (a
// bias estimate off by 2e-4 rad/s moves E by 2e-5 rad per window) the crossings come mostly from
// one side, and correcting one side of a zero-mean noise is a drift. On the simulated LabMate's
// rough floor (--noise paper) that made the fused heading worse than odometry alone (95 events a
// square, 28 mrad). With both sensors' noise, whose variances add, only what neither explains is
// an event: k_sigma sqrt(N^2 T_w + sum (k_L^2 |d_L| + k_R^2 |d_R|) / b^2). At 0.2 m/s with the
// paper's k this is 1.5 mrad against the 7.7 mrad of a 10 mm bump.
//
// The threshold is
//
//   T = q + k_sigma sqrt(N^2 T_w + V_odo) + B_res T_w + s_tol |sum dtheta_odo| + e_new + e_old
//       + delta_d |omega_0 - omega_n|
//
// (N rate noise density [rad/s/sqrt(Hz)], V_odo odometry's heading variance over the compared
// ticks, B_res the residual bias [rad/s], s_tol the residual scale-factor error, e_new and e_old
// the interpolation bounds above, omega_0 and omega_n the gyro's rates at the two edges; the
// terms that are not random add, as bounds). When |E| > T, or a wheel's speed or acceleration
// exceeds the configured limits, a flagged interval begins: the heading takes the gyro's aligned
// increments for every tick of the window that odometry had supplied (one correction, so the whole
// disturbance is replaced, not just the part after detection), then every tick the difference
// between the gyro's aligned increment and odometry's m ticks ago, until the window is quiet
// again. The fused heading is thus odometry's, with the disturbed ticks' odometry replaced by the
// gyro's view of the same moments: leaving an interval makes no jump of omega d. The quantisation
// error introduced is below q once per interval and has no sign preference; nothing is chosen per
// tick.
//
// The travel, too. Bumps and slips make a wheel's encoder count more than the ground moved it
// (Borenstein 1994b), so a heading correction c is also one wheel's excess: the left wheel's
// b c or the right wheel's -b c. Only one of the two can point the way that wheel moved (on a
// straight run forward, c > 0 means the left over-counted; the right would have to be short), and
// then the centre travel is corrected by minus half of it. In a turn on the spot (wheels opposite)
// both or neither can, and the travel is left alone. The attribution uses the interval's total
// correction, so the ticks' noise does not pick a wheel by its sign.
//
// Thresholds for the two reference set-ups (T_w = 0.1 s, k_sigma = 5, consumer gyro of the
// BMI088 class: N = 0.014 deg/s/sqrt(Hz) = 2.4435e-4 rad/s/sqrt(Hz), bias instability 2 deg/h =
// 9.70e-6 rad/s; bias averaged over the default still_time of 0.5 s, so
// B_res = 9.70e-6 + N / sqrt(0.5 s) = 3.5525e-4 rad/s; a straight leg, so the scale term is 0):
//   noise term  5 * 2.4435e-4 * sqrt(0.1)                 = 3.8635e-4 rad
//   bias term   3.5525e-4 * 0.1                           = 3.5525e-5 rad
//   LabMate (2048 cpr x 16 gear, D = 0.15 m, b = 0.34 m): q = 2 (pi 0.15 / 32768) / 0.34
//                                                         = 8.4595e-5 rad -> T = 5.0647e-4 rad
//   direct drive (2048 cpr, D = 0.15 m, b = 0.34 m):     q = 1.3535e-3 rad -> T = 1.7754e-3 rad
// (tests/unit/test_gyrodometry.cpp checks both; standing still, so V_odo = 0). The per-tick
// noise term would be only 5 N sqrt(0.005 s) = 8.64e-5 rad: a sixteenth of the direct drive's
// count quantum. Moving straight at 0.2 m/s with the paper's k_L = 4.0e-4, k_R = 5.8e-4 m^(1/2),
// V_odo = 8.59e-8 rad^2 and the random term grows from 3.86e-4 to 1.52e-3 rad: T = 1.64e-3 rad
// on the LabMate, 2.9e-3 rad on the direct drive. A 10 mm bump under one LabMate wheel turns
// odometry's heading by 0.44 deg = 7.7e-3 rad within the 0.1-0.2 s the wheel needs to cross it:
// 15x (LabMate) and 4.3x (direct drive) the threshold standing still, 4.7x and 2.7x at 0.2 m/s. As
// rates: T / T_w = 5 mrad/s and 18 mrad/s against the bump's apparent 40-77 mrad/s. Gyro noise
// alone exceeds 5 sigma with probability 5.7e-7 per window (Gaussian); windows that overlap are
// strongly correlated, so an hour holds about 3600 s / 0.1 s = 3.6e4 independent ones: one false
// alarm in about 50 h from noise alone, before the quantisation margin q.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "odo/hal/field_range.hpp"
#include "odo/hal/gyro.hpp"
#include "odo/hal/result.hpp"
#include "odo/odometry/error_model.hpp"

namespace odo {

// The gyro's noise model (see the parameter sets in sim_hal/sim_gyro.hpp for datasheet figures).
struct GyroNoiseModel {
  double rate_noise_density = 2.443e-4;  // N [rad/s/sqrt(Hz)]; angle std after T s: N sqrt(T)
  double bias_instability = 9.7e-6;      // in-run bias drift [rad/s] (BMI088: 2 deg/h)
  double scale_tolerance = 0.01;         // |scale-factor error| left in use (fraction)
};

// Configuration of the fusion; every field is checked by Gyrodometry::create().
struct GyrodometryParams {
  GyroNoiseModel noise;
  ErrorModelParams odometry_noise;  // Chong-Kleeman k_L, k_R: odometry's own heading noise
  double tick = 0.005;              // nominal loop period [s]
  double window = 0.1;              // comparison window T_w [s] (rounded to whole ticks)
  double k_sigma = 5.0;             // noise multiples in the threshold
  double gyro_delay =
      0.002;  // lag of the gyro's samples behind the motion [s] (filter + transport)
  double delay_tolerance = 0.0005;  // how far gyro_delay may be off [s]
  double heading_quantum = 0.0;     // q = (m_L + m_R)/b [rad]: one count on each wheel
  double max_wheel_speed = 2.0;     // |wheel speed| the robot cannot exceed [m/s]
  double max_wheel_accel = 10.0;    // |wheel acceleration| the robot cannot exceed [m/s^2]
  double still_time = 0.5;          // [s] of unchanged counts before the gyro's mean is its bias
  double bias_tau = 60.0;           // averaging horizon of the bias estimate [s]
  double turn_rate_min = 0.1;       // [rad/s]: ticks turning at least this fast calibrate the scale
  double scale_angle = 6.283185307179586;  // [rad] of such turns before the scale is applied
  double scale_max_error = 0.05;           // scale estimates beyond 1 +- this are rejected
};

// GyroParam: every number of GyrodometryParams the fusion checks. The first kGyroConfigParams are
// set by the user (odometryd's [gyro] keys, by the names of gyrodometry_range); the rest come
// from the loop (tick), the encoders (heading_quantum) or stay at the fusion's defaults.
enum class GyroParam : std::uint8_t {
  kNoiseDensity,
  kBiasInstability,
  kScaleTolerance,
  kDelay,
  kDelayTolerance,
  kWindow,
  kKSigma,
  kMaxWheelSpeed,
  kMaxWheelAccel,
  kStillTime,
  kBiasTau,
  kTick,
  kHeadingQuantum,
  kTurnRateMin,
  kScaleAngle,
  kScaleMaxError,
};
inline constexpr std::size_t kGyroConfigParams = 11;  // kNoiseDensity .. kBiasTau
inline constexpr std::size_t kGyroParams = 16;

// gyrodometry_range: the key, allowed range and unit of `k`: the one table of the fusion's
// limits. window's range depends on the loop tick [s] (at least two ticks), bias_tau's on
// still_time [s] (at least that long).
RangeRow gyrodometry_range(GyroParam k, double tick, double still_time) noexcept;

// gyrodometry_value: the field of `p` that `k` names.
double& gyrodometry_value(GyrodometryParams& p, GyroParam k) noexcept;

// check_gyrodometry: every field finite and in its gyrodometry_range; the error is a range error
// (Error::range) under the field's key.
Status check_gyrodometry(const GyrodometryParams& p);

// What happened on one tick (several bits may be set).
enum FusionFlag : std::uint32_t {
  kFusionGyroUsed = 1u << 0,    // the heading increment is the gyro's (a flagged interval)
  kFusionDisagree = 1u << 1,    // |E| > T on this tick's window
  kFusionSpeedLimit = 1u << 2,  // a wheel faster than max_wheel_speed
  kFusionAccelLimit = 1u << 3,  // a wheel accelerating beyond max_wheel_accel
  kFusionGyroFault = 1u << 4,   // the gyro sample was flagged or not finite: odometry used
  kFusionNoBias = 1u << 5,      // no bias estimate yet: odometry only, no detection
  kFusionStill = 1u << 6,       // the encoders say the robot stands still
  kFusionEventStart = 1u << 7,  // a flagged interval started on this tick
  kFusionWheelSlip = 1u << 8,   // the encoders flag a within-side slip (FusionInput::slip)
};

// Events since start; they only grow.
struct FusionCounters {
  std::uint64_t disagreements = 0;    // flagged intervals started by gyro/odometry disagreement
  std::uint64_t speed_events = 0;     // ... by a wheel speed beyond the limit
  std::uint64_t accel_events = 0;     // ... by a wheel acceleration beyond the limit
  std::uint64_t slip_events = 0;      // ... by a within-side slip of several encoders per side
  std::uint64_t gyro_faults = 0;      // transitions of the gyro into a faulty state (a gyro still
                                      // starting, kGyroStarting, is not faulty)
  std::uint64_t gyro_used_ticks = 0;  // ticks whose heading came from the gyro
};

// One tick's input: the wheels' travels and the gyro's reading.
struct FusionInput {
  double dt = 0.0;         // tick length [s]
  double d_left = 0.0;     // left wheel travel of the tick [m] (calibrated)
  double d_right = 0.0;    // right wheel travel [m]
  double wheelbase = 0.0;  // b [m]
  GyroSample gyro;         // rate_z: mean rate over the tick [rad/s]
  // The wheels of a side disagree (hal/side_wheels.hpp, kEncoderSlipLeft/Right): the tick is
  // flagged like one beyond the kinematic limits, so the heading is the gyro's (both cues).
  bool slip = false;
};

// One tick's output.
struct FusedTick {
  double dtheta = 0.0;       // heading increment to integrate this tick [rad]
  double dtheta_odo = 0.0;   // odometry's own increment (d_R - d_L)/b [rad]
  double ds = 0.0;           // correction of the centre travel (d_L + d_R)/2 [m] (see top)
  double var_heading = 0.0;  // heading variance the gyro adds when kFusionGyroUsed [rad^2]
  std::uint32_t flags = 0;   // FusionFlag bits
};

// What the fusion has learnt about its gyro: kept across a restart (the loop's state record) so
// that detection resumes at once instead of waiting for the next standstill.
struct GyroCalibration {
  double bias = 0.0;         // [rad/s]
  double bias_time = 0.0;    // [s] of standstill averaged into bias (0: never learnt)
  double scale = 1.0;        // multiplies the bias-corrected rate
  bool scale_valid = false;  // scale was estimated from turns
};

class Gyrodometry {
 public:
  // create: validates the parameters and sizes the window (the only allocation).
  static Result<Gyrodometry> create(const GyrodometryParams& p);

  // step: fuse one tick; never allocates, never throws, never returns a non-finite dtheta for
  // finite travels.
  FusedTick step(const FusionInput& in) noexcept;
  // reset: forget the window and any flagged interval (a set-pose); bias and scale are kept.
  void reset() noexcept;
  // set_scale_estimation: estimate the gyro's scale factor from turns (once odometry is
  // calibrated: the estimate trusts odometry's heading on clean turns).
  void set_scale_estimation(bool on) noexcept { scale_estimation_ = on; }

  // threshold: T of the current window [rad] (see the top of this file).
  double threshold() const noexcept;
  // disagreement: E of the current window, sum of aligned gyro minus odometry increments [rad].
  double disagreement() const noexcept { return sums_.err; }
  // delay_ticks: m, odometry's lag in whole ticks behind the newest gyro tick.
  std::size_t delay_ticks() const noexcept { return m_; }
  // gyro_weight: g, the weight of the older gyro tick in an aligned increment.
  double gyro_weight() const noexcept { return g_; }
  double bias() const noexcept { return bias_; }  // [rad/s]
  bool bias_valid() const noexcept { return bias_valid_; }
  double scale() const noexcept { return scale_; }  // multiplies the bias-corrected rate
  bool scale_valid() const noexcept { return scale_valid_; }
  // calibration: the bias and scale as learnt so far.
  GyroCalibration calibration() const noexcept { return {bias_, bias_time_, scale_, scale_valid_}; }
  // restore: continue from a calibration learnt before a restart (same gyro, same boot). The
  // averaging time is capped at bias_tau; a bias averaged for less than still_time stays invalid,
  // a non-finite value or a scale beyond 1 +- scale_max_error is ignored. Returns whether the
  // bias is now valid.
  bool restore(const GyroCalibration& c) noexcept;
  bool in_interval() const noexcept { return in_interval_; }
  const FusionCounters& counters() const noexcept { return counters_; }
  const GyrodometryParams& params() const noexcept { return p_; }
  std::size_t window_ticks() const noexcept { return n_; }

 private:
  // Entry: one tick. odo and var, and odo_cmp and var_cmp, are adjacent: a later entry copies
  // the first pair as its second, and the window's sums add and remove the second pair together.
  struct Entry {
    double odo = 0.0;      // odometry's heading increment of this tick [rad]
    double var = 0.0;      // odometry's heading variance of this tick [rad^2]
    double odo_cmp = 0.0;  // odometry's increment m ticks before this one [rad]
    double var_cmp = 0.0;  // its variance [rad^2]
    double d_left = 0.0, d_right = 0.0;
    double gyro = 0.0;      // the gyro's (bias- and scale-corrected) increment of this tick [rad]
    double raw = 0.0;       // the gyro's bias-corrected increment before the scale [rad]
    double err = 0.0;       // aligned gyro increment minus odo_cmp [rad]
    bool gyro_ok = false;   // this tick's gyro increment is usable
    bool err_ok = false;    // err was computed from usable increments
    bool replaced = false;  // err already integrated as a correction
  };
  // WindowSums: the window's running sums (re-summed from the ring every kResumWraps passes).
  struct WindowSums {
    double odo = 0.0;                      // sum odo_cmp
    double var = 0.0;                      // sum var_cmp
    double new_l = 0.0, new_r = 0.0;       // travels of the newer half [m]
    double old_l = 0.0, old_r = 0.0;       // travels of the older half [m]
    double err = 0.0;                      // sum err of entries with err_ok
    std::size_t bad = 0;                   // entries without err_ok
    void add(const Entry& e) noexcept;     // e enters the window
    void remove(const Entry& e) noexcept;  // e leaves it
  };
  explicit Gyrodometry(const GyrodometryParams& p);
  // update_bias: a still tick of length dt [s] with the gyro's rate [rad/s] (usable if rate_ok).
  void update_bias(double rate, bool rate_ok, double dt) noexcept;
  void update_scale(double odo, double raw_gyro, double dt) noexcept;
  // set_bias_time: t [s] of averaging behind bias_ (capped at bias_tau), and what follows from it
  // (bias_valid_, B_res). accept_scale: s as the scale when within 1 +- scale_max_error.
  void set_bias_time(double t) noexcept;
  void accept_scale(double s) noexcept;
  void update_b_res() noexcept;
  // travel_step: the centre-travel correction [m] of this tick, after the interval's heading
  // corrections reached c [rad] (see the top of this file).
  double travel_step(double c) noexcept;
  std::uint32_t disagree_flag() const noexcept;  // kFusionDisagree when |E| > T
  // push: this tick's entry (travels, odometry's increment odo [rad] and variance, the gyro's),
  // written in place as the newest, aligned and added to the window's sums.
  Entry& push(const FusionInput& in, double odo, bool usable, double dt) noexcept;
  // slide: the window moves by the new entry e (aligned here); kFull: the ring was full before.
  template <bool kFull>
  void slide(Entry& e) noexcept;
  void resum() noexcept;
  double edge_bounds() const noexcept;
  // limit_flags: kFusionSpeedLimit, kFusionAccelLimit for the newest tick's |d_L|, |d_R| [m].
  std::uint32_t limit_flags(double abs_left, double abs_right) const noexcept;
  double begin_interval() noexcept;
  // gyro_health: kFusionGyroFault when the sample cannot be used (a fault counted on the
  // transition from healthy, none while the gyro is still starting), 0 when it can.
  std::uint32_t gyro_health(const GyroSample& g) noexcept;
  // open_interval: the first flagged tick: the window's odometry increments are replaced by the
  // gyro's (out.dtheta, out.var_heading [rad^2]); why: the kFusion* reasons.
  void open_interval(std::uint32_t why, double odo, double dt, FusedTick& out) noexcept;
  // continue_interval: a further flagged tick replaces odometry's increment of m ticks ago by the
  // gyro's aligned one (err [rad]).
  void continue_interval(double odo, double err, double dt, FusedTick& out) noexcept;
  // index: ring index of an age (0: the newest); age < size_ <= the ring's power-of-two
  // capacity, so a mask wraps it.
  std::size_t index(std::size_t age) const noexcept { return (head_ - age) & mask_; }
  Entry& at(std::size_t age) noexcept { return ring_[index(age)]; }
  const Entry& at(std::size_t age) const noexcept { return ring_[index(age)]; }

  GyrodometryParams p_;
  std::vector<Entry> ring_;
  std::size_t size_ = 0;                   // ages the fusion reads (0 .. size_ - 1)
  std::size_t mask_ = 0;                   // ring_.size() - 1 (the size a power of two >= size_)
  std::size_t head_ = 0;                   // index of the newest entry
  std::size_t resum_in_ = 0;               // pushes until the next re-sum
  std::size_t filled_ = 0;                 // entries in use (<= size_)
  std::size_t n_ = 2;                      // ticks in the window
  std::size_t half_ = 1;                   // ticks in each half of the window (accelerations)
  std::size_t m_ = 0;                      // odometry's lag behind the newest gyro tick [ticks]
  double g_ = 0.0;                         // weight of the older gyro tick in an aligned increment
  double one_minus_g_ = 1.0;               // 1 - g_, the newer gyro tick's weight
  double noise_term_ = 0.0;                // k_sigma N sqrt(T_w) [rad]
  double gyro_var_ = 0.0;                  // N^2 T_w [rad^2]
  double k2_left_ = 0.0, k2_right_ = 0.0;  // k_L^2, k_R^2 [m]
  double delay_per_tick_ = 0.0;            // delay_tolerance / tick: rate change per tick -> angle
  double wheelbase_ = 1.0;                 // b of the last tick [m]
  double b_res_ = 0.0;                     // residual bias B_res [rad/s], updated with the estimate
  double base_threshold_ = 0.0;  // q + k_sigma N sqrt(T_w) + B_res T_w [rad]: a lower bound of T
  double v_max_tick_ = 0.0;      // max_wheel_speed * tick [m]
  double dv_max_ = 0.0;          // max_wheel_accel * T_h^2 [m]
  WindowSums sums_;
  // Bias and scale.
  double still_for_ = 0.0;  // duration of the current run of zero travel [s]
  double bias_ = 0.0;
  double bias_time_ = 0.0;   // seconds of standstill averaged into bias_ (capped at bias_tau)
  bool bias_valid_ = false;  // bias_time_ >= still_time (kept with bias_time_, read every tick)
  double scale_ = 1.0;
  bool scale_valid_ = false;
  bool scale_estimation_ = false;
  double scale_odo_ = 0.0, scale_gyro_ = 0.0;  // sign-weighted sums over clean turns [rad]
  // Flagged interval.
  bool in_interval_ = false;
  std::uint64_t interval_ticks_ = 0;
  std::size_t hold_ = 0;      // ticks the interval lasts at least, after a kinematic-limit tick
  double interval_c_ = 0.0;   // heading corrections of the interval so far [rad]
  double interval_ds_ = 0.0;  // centre-travel corrections of the interval so far [m]
  double interval_l_ = 0.0, interval_r_ = 0.0;  // wheel travels the interval covers [m]
  bool gyro_was_ok_ = true;  // the previous sample was usable or the gyro still starting
  FusionCounters counters_;
};

// propagate_gyro_arc: the pose covariance of a tick whose heading came from the gyro: the same
// state Jacobian as the wheels' arc (heading theta0, centre travel ds [m], turn dtheta [rad]),
// the along-track noise of the wheels (variance var_ds [m^2], see wheel_travel_variance) and the
// gyro's heading noise var_heading [rad^2] spread evenly along the arc, instead of the wheels'
// differential noise (Chong-Kleeman's W+/b^2). Derivation in gyrodometry.cpp.
void propagate_gyro_arc(Cov3& cov, double sin_theta0, double cos_theta0, double ds, double dtheta,
                        double var_ds, double var_heading) noexcept;

// along_track_variance: var_ds of the centre travel (d_L + d_R)/2 under the Chong-Kleeman wheel
// noise (variance k^2 |d| per wheel): (k_L^2 |d_L| + k_R^2 |d_R|) / 4 [m^2].
inline double along_track_variance(double d_left, double d_right,
                                   const ErrorModelParams& k) noexcept {
  return 0.25 * (k.k_left * k.k_left * (d_left < 0 ? -d_left : d_left) +
                 k.k_right * k.k_right * (d_right < 0 ? -d_right : d_right));
}

}  // namespace odo
