#include "odo/odometry/gyrodometry.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

// Covariance of a tick whose heading comes from the gyro (propagate_gyro_arc). In the frame of the
// tick's start pose, with arc parameter u in [0, 1], centre travel D u and heading phi u (as in
// error_model.cpp, whose notation and integrals I_f, J_f this reuses): Chong-Kleeman's wheel noise
// enters through a_L = p + q, a_R = p - q with the along-track push p = (c/2, s/2, 0) and the
// heading push q = (Y/b, -X/b, -1/b). Split that way, the wheels contribute
//   W+ int p p^T du = var_ds [I_cc, I_cs, 0; I_cs, I_ss, 0; 0, 0, 0]     (var_ds = W+/4)
// to the along-track direction, plus W+/b^2 int (Y, -X, -1)(Y, -X, -1)^T du through the heading,
// plus the cross terms W- int (p q^T + q p^T) that correlate the two. On a gyro tick the heading
// noise is the gyro's, independent of the wheels: the heading push keeps its shape, its intensity
// W+/b^2 becomes the gyro's var_heading, and the cross terms vanish:
//   xx = var_ds I_cc + v D^2 J_yy    xy = var_ds I_cs - v D^2 J_xy    xt = -v D J_y
//   yy = var_ds I_ss + v D^2 J_xx    yt = v D J_x                      tt = v
// Straight line (phi = 0: J_yy = J_xy = J_y = 0, J_xx = 1/3, J_x = 1/2): xx = var_ds,
// yy = v D^2/3, yt = v D/2, tt = v, the lateral error of a heading random walk along a line.

namespace odo {
namespace {

constexpr std::uint32_t kResumWraps = 16;

// The fusion's limits, in GyroParam order. Open lower limits where zero would divide or stall
// (speeds, times, the tick); window and bias_tau get their lower limits from the tick and
// still_time in gyrodometry_range.
constexpr RangeRow kGyroRows[kGyroParams] = {
    {"noise_density", 0.0, 0.1, "rad/s/sqrt(Hz)"},
    {"bias_instability", 0.0, 0.1, "rad/s"},
    {"scale_tolerance", 0.0, 0.5, ""},
    {"delay", 0.0, 1.0, "s"},
    {"delay_tolerance", 0.0, 1.0, "s"},
    {"window", 0.0, 10.0, "s"},  // lo: two ticks (one per half of the window)
    {"k_sigma", 1.0, 20.0, ""},
    {"max_wheel_speed", 0.0, 100.0, "m/s", true},
    {"max_wheel_accel", 0.0, 1000.0, "m/s^2", true},
    {"still_time", 0.0, 60.0, "s", true},
    {"bias_tau", 0.0, 86400.0, "s"},  // lo: still_time (the first average already spans it)
    {"tick", 0.0, 1.0, "s", true},
    {"heading_quantum", 0.0, 0.1, "rad"},
    {"turn_rate_min", 0.0, 100.0, "rad/s", true},
    {"scale_angle", 0.0, 1e6, "rad", true},
    {"scale_max_error", 0.0, 0.5, "", true},
};

}  // namespace

RangeRow gyrodometry_range(GyroParam k, double tick, double still_time) noexcept {
  RangeRow r = kGyroRows[static_cast<std::size_t>(k)];
  if (k == GyroParam::kWindow) {
    r.lo = 2.0 * tick;
    r.hi = std::max(r.hi, r.lo);  // a slow loop still has a window of two ticks
  }
  if (k == GyroParam::kBiasTau) r.lo = still_time;
  return r;
}

double& gyrodometry_value(GyrodometryParams& p, GyroParam k) noexcept {
  switch (k) {
    case GyroParam::kNoiseDensity:
      return p.noise.rate_noise_density;
    case GyroParam::kBiasInstability:
      return p.noise.bias_instability;
    case GyroParam::kScaleTolerance:
      return p.noise.scale_tolerance;
    case GyroParam::kDelay:
      return p.gyro_delay;
    case GyroParam::kDelayTolerance:
      return p.delay_tolerance;
    case GyroParam::kWindow:
      return p.window;
    case GyroParam::kKSigma:
      return p.k_sigma;
    case GyroParam::kMaxWheelSpeed:
      return p.max_wheel_speed;
    case GyroParam::kMaxWheelAccel:
      return p.max_wheel_accel;
    case GyroParam::kStillTime:
      return p.still_time;
    case GyroParam::kBiasTau:
      return p.bias_tau;
    case GyroParam::kTick:
      return p.tick;
    case GyroParam::kHeadingQuantum:
      return p.heading_quantum;
    case GyroParam::kTurnRateMin:
      return p.turn_rate_min;
    case GyroParam::kScaleAngle:
      return p.scale_angle;
    case GyroParam::kScaleMaxError:
      break;
  }
  return p.scale_max_error;
}

Status check_gyrodometry(const GyrodometryParams& p) {
  GyrodometryParams q = p;  // gyrodometry_value hands out references into a mutable struct
  for (std::size_t i = 0; i < kGyroParams; ++i) {
    const auto k = static_cast<GyroParam>(i);
    const RangeRow r = gyrodometry_range(k, p.tick, p.still_time);
    const double v = gyrodometry_value(q, k);
    if (!r.contains(v)) return range_error(r.range(r.key, v));
  }
  if (p.window / p.tick > 100000.0 || p.gyro_delay / p.tick > 100000.0)
    return make_error(Errc::kInvalidArgument,
                      "window / tick and delay / tick must not exceed 100000 ticks");
  return Ok{};
}

Result<Gyrodometry> Gyrodometry::create(const GyrodometryParams& p) {
  if (auto s = check_gyrodometry(p); !s) return std::move(s).error();
  return Gyrodometry(p);
}

Gyrodometry::Gyrodometry(const GyrodometryParams& p) : p_(p) {
  // An even number of ticks, so the window splits into two equal halves for accelerations.
  half_ = static_cast<std::size_t>(std::max(1.0, std::round(0.5 * p.window / p.tick)));
  n_ = 2 * half_;
  // d = m tick - g tick. The 1e-9 keeps a delay of whole ticks (2 ms at 1 kHz: 1.9999999999999998
  // ticks in doubles) from becoming m = 3, g = 0.9999999999999998.
  const double ticks = p.gyro_delay / p.tick;
  m_ = static_cast<std::size_t>(std::ceil(ticks - 1e-9));
  g_ = std::max(0.0, static_cast<double>(m_) - ticks);
  one_minus_g_ = 1.0 - g_;
  // The window, the two ticks beyond its old edge (J_old there), and odometry m ticks back.
  size_ = std::max(n_ + 2, m_ + 1);
  // Capacity a power of two, so that an age's index is a subtraction and a mask.
  mask_ = std::bit_ceil(size_) - 1;
  ring_.assign(mask_ + 1, Entry{});
  resum_in_ = kResumWraps * size_;
  const double t_w = static_cast<double>(n_) * p.tick;
  noise_term_ = p.k_sigma * p.noise.rate_noise_density * std::sqrt(t_w);
  gyro_var_ = p.noise.rate_noise_density * p.noise.rate_noise_density * t_w;
  k2_left_ = p.odometry_noise.k_left * p.odometry_noise.k_left;
  k2_right_ = p.odometry_noise.k_right * p.odometry_noise.k_right;
  delay_per_tick_ = p.delay_tolerance / p.tick;
  const double t_h = static_cast<double>(half_) * p.tick;
  v_max_tick_ = p.max_wheel_speed * p.tick;
  dv_max_ = p.max_wheel_accel * t_h * t_h;  // in metres of half-window travel
  update_b_res();
}

void Gyrodometry::update_b_res() noexcept {
  // The bias estimate's own noise: N / sqrt(seconds averaged), plus its drift since.
  b_res_ = p_.noise.bias_instability +
           p_.noise.rate_noise_density / std::sqrt(std::max(bias_time_, p_.still_time));
  // The part of T that does not change from tick to tick while moving.
  const double t_w = static_cast<double>(n_) * p_.tick;
  base_threshold_ = p_.heading_quantum + noise_term_ + b_res_ * t_w;
}

void Gyrodometry::reset() noexcept {
  std::fill(ring_.begin(), ring_.end(), Entry{});
  head_ = 0;
  // The re-sum's schedule restarts its pass of the ring (not its count of passes): up to the
  // next multiple of size_ pushes.
  resum_in_ = (resum_in_ + size_ - 1) / size_ * size_;
  filled_ = 0;
  resum();
  in_interval_ = false;
  interval_ticks_ = 0;
  hold_ = 0;
  still_for_ = 0.0;
}

double Gyrodometry::threshold() const noexcept {
  // The two sensors' random errors are independent: their variances add (sums_.var is never
  // negative in exact arithmetic; the running sum's rounding could make it -1e-20).
  const double random = p_.k_sigma * std::sqrt(gyro_var_ + std::max(0.0, sums_.var)) - noise_term_;
  return base_threshold_ + random + p_.noise.scale_tolerance * std::fabs(sums_.odo) + edge_bounds();
}

double Gyrodometry::edge_bounds() const noexcept {
  // Before the ring is full the edges' neighbours are missing; step() compares only full rings.
  if (filled_ < size_) return 0.0;
  const Entry &g0 = at(0), &g1 = at(1);
  const Entry &gn1 = at(n_ - 1), &gn = at(n_), &gn2 = at(n_ + 1);
  double e = delay_per_tick_ * std::fabs(g0.gyro - gn.gyro);
  if (g_ == 0.0) return e;  // both points are tick boundaries: nothing is interpolated
  const double p = one_minus_g_;
  e += p * std::fabs(g0.gyro - g1.gyro);  // the newest edge: only the older neighbour exists
  // The old edge: the tighter of the two bounds; a neighbour without a usable increment (its
  // stored 0 is no rate) leaves the other one.
  const double by_old = gn2.gyro_ok ? p * std::fabs(gn.gyro - gn2.gyro) : HUGE_VAL;
  const double by_new = g_ * std::fabs(gn1.gyro - gn.gyro);
  return e + std::min(by_old, by_new);
}

void Gyrodometry::WindowSums::add(const Entry& e) noexcept {
  odo += e.odo_cmp;
  var += e.var_cmp;
  if (e.err_ok)
    err += e.err;
  else
    ++bad;
}

void Gyrodometry::WindowSums::remove(const Entry& e) noexcept {
  odo -= e.odo_cmp;
  var -= e.var_cmp;
  if (e.err_ok)
    err -= e.err;
  else
    --bad;
}

void Gyrodometry::resum() noexcept {
  // Re-add the window from the ring so that the running sums' rounding cannot accumulate.
  WindowSums s;
  for (std::size_t age = 0; age < std::min(filled_, n_); ++age) {
    const Entry& e = at(age);
    s.add(e);
    if (age < half_) {
      s.new_l += e.d_left;
      s.new_r += e.d_right;
    } else {
      s.old_l += e.d_left;
      s.old_r += e.d_right;
    }
  }
  sums_ = s;
}

// slide, push and limit_flags run on every tick and are called from this file only: inline, so
// that step() pays no call (and register saves) for them.
template <bool kFull>
[[gnu::always_inline]] inline void Gyrodometry::slide(Entry& e) noexcept {
  // The newest entry e is in the ring (age 0): its aligned gyro increment and odometry's of m
  // ticks ago (see the top of gyrodometry.hpp). Comparable only when everything it reads is
  // there; a full ring (kFull) holds it all.
  const Entry& prev = at(1);
  const bool have = kFull || filled_ > std::max<std::size_t>(m_, 1);
  if (have) {
    const Entry& cmp = at(m_);
    e.odo_cmp = cmp.odo;
    e.var_cmp = cmp.var;
  } else {
    e.odo_cmp = e.var_cmp = 0.0;
  }
  // prev.gyro_ok first: it is nearly always true and decides without the comparison of g_.
  e.err_ok = have && e.gyro_ok && (prev.gyro_ok || g_ == 0.0);
  e.err = e.err_ok ? one_minus_g_ * e.gyro + g_ * prev.gyro - e.odo_cmp : 0.0;
  // The sums in a local: the ring's stores could alias the members, which would be reloaded.
  WindowSums s = sums_;
  s.add(e);
  s.new_l += e.d_left;
  s.new_r += e.d_right;
  if (kFull || filled_ > half_) {  // the entry now of age half_ moves from the newer half
    const Entry& mid = at(half_);
    s.new_l -= mid.d_left;
    s.new_r -= mid.d_right;
    s.old_l += mid.d_left;
    s.old_r += mid.d_right;
  }
  if (kFull || filled_ > n_) {  // the entry now of age n leaves the window (older half)
    const Entry& old = at(n_);
    s.remove(old);
    s.old_l -= old.d_left;
    s.old_r -= old.d_right;
  }
  sums_ = s;
}

[[gnu::always_inline]] inline Gyrodometry::Entry& Gyrodometry::push(const FusionInput& in,
                                                                    double odo, bool usable,
                                                                    double dt) noexcept {
  head_ = (head_ + 1) & mask_;
  const bool full = filled_ == size_;
  if (!full) ++filled_;
  // Written in place (not built and copied: 80 bytes a tick); slide() sets the comparison fields.
  Entry& e = ring_[head_];
  e.odo = odo;
  // Chong-Kleeman: wheel variances k^2 |d|; the heading difference divides by b twice.
  e.var = (k2_left_ * std::fabs(in.d_left) + k2_right_ * std::fabs(in.d_right)) /
          (in.wheelbase * in.wheelbase);
  e.d_left = in.d_left;
  e.d_right = in.d_right;
  e.gyro_ok = usable;
  e.raw = usable ? (in.gyro.rate_z - bias_) * dt : 0.0;
  e.gyro = scale_ * e.raw;
  e.replaced = false;
  if (full)
    slide<true>(e);
  else
    slide<false>(e);
  // Re-sum every kResumWraps passes of the ring: the running sums' rounding stays far below a
  // count (1e-16 relative per addition, a few thousand additions), at 1/16 of the cost.
  if (--resum_in_ == 0) {
    resum_in_ = kResumWraps * size_;
    resum();
  }
  return e;
}

inline void Gyrodometry::set_bias_time(double t) noexcept {
  bias_time_ = std::min(t, p_.bias_tau);
  bias_valid_ = bias_time_ >= p_.still_time;
  update_b_res();
}

inline void Gyrodometry::accept_scale(double s) noexcept {
  // Beyond 1 +- scale_max_error (or not a number) it is no scale error a gyro has: rejected.
  if (std::fabs(s - 1.0) <= p_.scale_max_error) {
    scale_ = s;
    scale_valid_ = true;
  }
}

void Gyrodometry::update_bias(double rate, bool rate_ok, double dt) noexcept {
  still_for_ += dt;
  // The first still_time of a standstill only confirms it (the robot may still rock after
  // braking); after that the gyro's mean is its bias: a running mean over the seconds averaged so
  // far, which becomes an exponential average of horizon bias_tau to follow the bias's drift.
  if (!rate_ok || still_for_ < p_.still_time) return;
  set_bias_time(bias_time_ + dt);
  bias_ += (rate - bias_) * dt / bias_time_;
}

bool Gyrodometry::restore(const GyroCalibration& c) noexcept {
  // A restart is a gap in the bias's learning like any drive without a standstill: the estimate
  // keeps the weight it had (its residual B_res included), capped as update_bias caps it.
  if (std::isfinite(c.bias) && std::isfinite(c.bias_time) && c.bias_time > 0.0) {
    bias_ = c.bias;
    set_bias_time(c.bias_time);
  }
  // Only a scale the estimator itself would have applied.
  if (c.scale_valid) accept_scale(c.scale);
  return bias_valid_;
}

void Gyrodometry::update_scale(double odo, double raw_gyro, double dt) noexcept {
  if (std::fabs(odo) < p_.turn_rate_min * dt) return;
  // Sign-weighted sums: a residual bias adds to clockwise and subtracts from counter-clockwise
  // turns' gyro angle, so it cancels over turns both ways.
  const double sign = odo > 0.0 ? 1.0 : -1.0;
  scale_odo_ += sign * odo;
  scale_gyro_ += sign * raw_gyro;
  if (scale_odo_ < p_.scale_angle || !(scale_gyro_ > 0.0)) return;
  accept_scale(scale_odo_ / scale_gyro_);
}

inline std::uint32_t Gyrodometry::limit_flags(double abs_left, double abs_right) const noexcept {
  // Speeds per tick: one count of quantisation is m / tick (0.046 m/s for 0.23 mm at 200 Hz),
  // far below any useful limit. The travels are finite (step() checked): max is the || of the two.
  std::uint32_t f =
      std::max(abs_left, abs_right) > v_max_tick_ ? kFusionSpeedLimit : std::uint32_t{0};
  if (filled_ == size_) {
    // Accelerations from the mean speeds of the two halves of the window: a count per half is
    // 2 m / T_h^2 of acceleration (0.18 m/s^2 for 0.23 mm and T_h = 0.05 s), per tick it would be
    // 2 m / tick^2 = 18 m/s^2.
    if (std::fabs(sums_.new_l - sums_.old_l) > dv_max_ ||
        std::fabs(sums_.new_r - sums_.old_r) > dv_max_)
      f |= kFusionAccelLimit;
  }
  return f;
}

double Gyrodometry::begin_interval() noexcept {
  // Replace every tick of the window that odometry still supplies: the disturbance began at most
  // a window ago, and detection waited for it to grow beyond the threshold.
  double correction = 0.0;
  for (std::size_t age = 0; age < std::min(filled_, n_); ++age) {
    Entry& e = at(age);
    if (e.replaced || !e.err_ok) continue;
    correction += e.err;
    e.replaced = true;
    ++interval_ticks_;
  }
  return correction;
}

std::uint32_t Gyrodometry::disagree_flag() const noexcept {
  // Only full rings are compared (edge_bounds needs the ticks beyond the window's old edge);
  // T >= base_threshold_: most ticks are decided without the window-dependent terms.
  const double abs_err = std::fabs(sums_.err);
  const bool flag =
      sums_.bad == 0 && filled_ == size_ && abs_err > base_threshold_ && abs_err > threshold();
  return flag ? kFusionDisagree : std::uint32_t{0};
}

FusedTick Gyrodometry::step(const FusionInput& in) noexcept {
  FusedTick out;
  // x - x is 0 for a finite x and NaN for an infinite or NaN one: one test for all three.
  const double nonfinite =
      (in.d_left - in.d_left) + (in.d_right - in.d_right) + (in.wheelbase - in.wheelbase);
  // Nothing sane to integrate (the loop never produces this).
  if (!(nonfinite == 0.0 && in.wheelbase > 0.0)) return out;
  // A positive dt is finite when it does not exceed the largest double.
  const double dt = in.dt > 0.0 && in.dt <= std::numeric_limits<double>::max() ? in.dt : p_.tick;
  const double odo = (in.d_right - in.d_left) / in.wheelbase;
  out.dtheta = out.dtheta_odo = odo;
  wheelbase_ = in.wheelbase;
  // The flags in a local: out is the caller's memory, each |= would be a load and a store.
  std::uint32_t flags = gyro_health(in.gyro);
  const bool rate_ok = flags == 0;
  const double abs_left = std::fabs(in.d_left), abs_right = std::fabs(in.d_right);
  if (abs_left + abs_right == 0.0) {  // both travels 0: a sum of magnitudes is 0 only then
    flags |= kFusionStill;
    update_bias(in.gyro.rate_z, rate_ok, dt);
  } else {
    still_for_ = 0.0;  // moving: a standstill starts over
  }
  const bool usable = rate_ok && bias_valid();
  if (!bias_valid()) flags |= kFusionNoBias;
  const Entry& fresh = push(in, odo, usable, dt);
  if (!usable) {
    in_interval_ = false;  // a faulty gyro ends any flagged interval: odometry from here on
    hold_ = 0;
    out.flags = flags;
    return out;
  }
  if (scale_estimation_ && !in_interval_ && fresh.err_ok)
    update_scale(fresh.odo_cmp, one_minus_g_ * fresh.raw + g_ * at(1).raw, dt);
  const std::uint32_t limits =
      limit_flags(abs_left, abs_right) | (in.slip ? kFusionWheelSlip : std::uint32_t{0});
  const std::uint32_t why = limits | disagree_flag();
  // Outside an interval hold_ is 0 (it is set with one and an interval ends only once it ran
  // out), so a quiet tick there changes nothing: the common case, decided first.
  if (why == 0 && !in_interval_) {
    out.flags = flags;
    return out;
  }
  // A tick beyond the kinematic limits is odometry's age 0, but the gyro replaces odometry m
  // ticks late: the interval lasts at least until that tick has been replaced.
  const bool hold = in_interval_ && hold_ > 0;
  hold_ = limits != 0 ? m_ : (hold_ > 0 ? hold_ - 1 : 0);
  if (why == 0 && !hold) {
    in_interval_ = false;
    out.flags = flags;
    return out;
  }
  out.flags = flags | why | kFusionGyroUsed;
  if (!in_interval_) {
    open_interval(why, odo, dt, out);
  } else {
    continue_interval(odo, fresh.err, dt, out);
  }
  return out;
}

std::uint32_t Gyrodometry::gyro_health(const GyroSample& g) noexcept {
  if (g.flags == kGyroOk && std::isfinite(g.rate_z)) {
    gyro_was_ok_ = true;
    return 0;
  }
  // A gyro still starting (no sample yet, within its timeout) cannot be used but has not
  // failed: no event, and the state is left as it was (its timeout, if it comes, is the event).
  if (g.flags != kGyroStarting) {
    if (gyro_was_ok_) ++counters_.gyro_faults;
    gyro_was_ok_ = false;
  }
  return kFusionGyroFault;
}

void Gyrodometry::open_interval(std::uint32_t why, double odo, double dt, FusedTick& out) noexcept {
  in_interval_ = true;
  interval_ticks_ = 0;
  out.flags |= kFusionEventStart;
  counters_.disagreements += (why & kFusionDisagree) != 0 ? 1 : 0;
  counters_.speed_events += (why & kFusionSpeedLimit) != 0 ? 1 : 0;
  counters_.accel_events += (why & kFusionAccelLimit) != 0 ? 1 : 0;
  counters_.slip_events += (why & kFusionWheelSlip) != 0 ? 1 : 0;
  const double c = begin_interval();
  out.dtheta = odo + c;
  interval_c_ = interval_ds_ = 0.0;
  interval_l_ = sums_.new_l + sums_.old_l;
  interval_r_ = sums_.new_r + sums_.old_r;
  out.ds = travel_step(c);
  // m ticks of gyro at once: white noise N^2 m dt, the bias error's (b_res m dt)^2.
  const double n2 = p_.noise.rate_noise_density * p_.noise.rate_noise_density;
  const double t = static_cast<double>(interval_ticks_) * dt;
  out.var_heading = n2 * t + b_res_ * b_res_ * t * t;
  counters_.gyro_used_ticks += interval_ticks_;
}

void Gyrodometry::continue_interval(double odo, double err, double dt, FusedTick& out) noexcept {
  ring_[head_].replaced = true;
  out.dtheta = odo + err;
  interval_l_ += ring_[head_].d_left;
  interval_r_ += ring_[head_].d_right;
  out.ds = travel_step(err);
  // Tick k of an interval: the bias part (b_res k dt)^2 grows by b_res^2 dt^2 (2k + 1).
  const double n2 = p_.noise.rate_noise_density * p_.noise.rate_noise_density;
  const double k = static_cast<double>(interval_ticks_);
  out.var_heading = n2 * dt + b_res_ * b_res_ * dt * dt * (2.0 * k + 1.0);
  ++interval_ticks_;
  ++counters_.gyro_used_ticks;
}

double Gyrodometry::travel_step(double c) noexcept {
  // Attributed on the interval's whole correction, not tick by tick: a tick's noise would pick a
  // wheel by its sign and always shorten the travel. The interval's wheel travels tell which
  // wheel could have over-counted by b |c| (see the top of gyrodometry.hpp): the excess must
  // point the way that wheel moved and not exceed its travel.
  interval_c_ += c;
  const double e_l = wheelbase_ * interval_c_, e_r = -e_l;
  const bool left =
      e_l != 0.0 && (e_l > 0.0) == (interval_l_ > 0.0) && std::fabs(e_l) <= std::fabs(interval_l_);
  const bool right =
      e_r != 0.0 && (e_r > 0.0) == (interval_r_ > 0.0) && std::fabs(e_r) <= std::fabs(interval_r_);
  // Neither, or both (a turn on the spot): no way to choose, no travel correction.
  const double total = left == right ? 0.0 : -0.5 * (left ? e_l : e_r);
  const double step = total - interval_ds_;
  interval_ds_ = total;
  return step;
}

void propagate_gyro_arc(Cov3& cov, double sin_theta0, double cos_theta0, double ds, double dtheta,
                        double var_ds, double var_heading) noexcept {
  if (!(std::isfinite(ds) && std::isfinite(dtheta) && std::isfinite(var_ds) &&
        std::isfinite(var_heading) && std::isfinite(sin_theta0) && std::isfinite(cos_theta0))) {
    return;  // a non-finite step would poison the covariance for good
  }
  const ArcTerms t = arc_terms(dtheta);
  const double v = var_heading, d = ds;
  Cov3 q{};
  q[0] = var_ds * t.i_cc + v * d * d * t.j_yy;
  q[1] = q[3] = var_ds * t.i_cs - v * d * d * t.j_xy;
  q[2] = q[6] = -v * d * t.j_y;
  q[4] = var_ds * t.i_ss + v * d * d * t.j_xx;
  q[5] = q[7] = v * d * t.j_x;
  q[8] = v;
  propagate_local(cov, sin_theta0, cos_theta0, d * t.i_c, d * t.i_s, q);
}

void PoseCovariance::step_gyro_sc(double sin_theta0, double cos_theta0, double d_left,
                                  double d_right, double dtheta, double var_heading,
                                  double extra_var_ds) noexcept {
  flush();  // the merged wheel ticks came before this one
  propagate_gyro_arc(cov_, sin_theta0, cos_theta0, 0.5 * (d_left + d_right), dtheta,
                     along_track_variance(d_left, d_right, k_) + extra_var_ds, var_heading);
}

}  // namespace odo
