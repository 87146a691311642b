#include "odo/odometry/gyrodometry.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

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

struct Bound {
  const char* field;
  double value, lo, hi;
  bool lo_open;  // lo itself excluded
};

Status check_bound(const Bound& b) {
  const bool above = b.lo_open ? b.value > b.lo : b.value >= b.lo;
  if (std::isfinite(b.value) && above && b.value <= b.hi) return Ok{};
  std::ostringstream m;
  m << "gyrodometry " << b.field << " = " << b.value << " is outside the allowed range "
    << (b.lo_open ? "(" : "[") << b.lo << ", " << b.hi << "]";
  return make_error(Errc::kInvalidArgument, m.str());
}

}  // namespace

Status check_gyrodometry(const GyrodometryParams& p) {
  const Bound table[] = {
      {"rate_noise_density", p.noise.rate_noise_density, 0.0, 0.1, false},
      {"bias_instability", p.noise.bias_instability, 0.0, 0.1, false},
      {"scale_tolerance", p.noise.scale_tolerance, 0.0, 0.5, false},
      {"tick", p.tick, 0.0, 1.0, true},
      {"window", p.window, 2.0 * p.tick, std::max(10.0, 2.0 * p.tick), false},
      {"k_sigma", p.k_sigma, 1.0, 20.0, false},
      {"gyro_delay", p.gyro_delay, 0.0, 1.0, false},
      {"heading_quantum", p.heading_quantum, 0.0, 0.1, false},
      {"max_wheel_speed", p.max_wheel_speed, 0.0, 100.0, true},
      {"max_wheel_accel", p.max_wheel_accel, 0.0, 1000.0, true},
      {"still_time", p.still_time, 0.0, 60.0, true},
      {"bias_tau", p.bias_tau, p.still_time, 86400.0, false},
      {"turn_rate_min", p.turn_rate_min, 0.0, 100.0, true},
      {"scale_angle", p.scale_angle, 0.0, 1e6, true},
      {"scale_max_error", p.scale_max_error, 0.0, 0.5, true},
  };
  for (const Bound& b : table) {
    if (auto s = check_bound(b); !s) return s;
  }
  if (p.window / p.tick > 100000.0)
    return make_error(Errc::kInvalidArgument,
                      "gyrodometry window / tick must not exceed 100000 ticks");
  return Ok{};
}

Result<Gyrodometry> Gyrodometry::create(const GyrodometryParams& p) {
  if (auto s = check_gyrodometry(p); !s) return std::move(s).error();
  return Gyrodometry(p);
}

Gyrodometry::Gyrodometry(const GyrodometryParams& p) : p_(p) {
  // An even number of ticks, so the window splits into two equal halves for accelerations.
  const auto half = static_cast<std::size_t>(std::max(1.0, std::round(0.5 * p.window / p.tick)));
  half_ = half;
  ring_.assign(2 * half, Entry{});
  const double t_w = static_cast<double>(ring_.size()) * p.tick;
  noise_term_ = p.k_sigma * p.noise.rate_noise_density * std::sqrt(t_w);
  const double t_h = static_cast<double>(half_) * p.tick;
  inv_t_h_ = 1.0 / t_h;
  v_max_tick_ = p.max_wheel_speed * p.tick;
  dv_max_ = p.max_wheel_accel * t_h * t_h;  // in metres of half-window travel
  update_b_res();
}

void Gyrodometry::update_b_res() noexcept {
  // The bias estimate's own noise: N / sqrt(seconds averaged), plus its drift since.
  b_res_ = p_.noise.bias_instability +
           p_.noise.rate_noise_density / std::sqrt(std::max(bias_time_, p_.still_time));
  // The part of T that does not change from tick to tick while moving.
  const double t_w = static_cast<double>(ring_.size()) * p_.tick;
  base_threshold_ = p_.heading_quantum + noise_term_ + b_res_ * t_w;
}

void Gyrodometry::reset() noexcept {
  std::fill(ring_.begin(), ring_.end(), Entry{});
  head_ = 0;
  filled_ = 0;
  resum();
  in_interval_ = false;
  interval_ticks_ = 0;
  still_for_ = 0.0;
}

Gyrodometry::Entry& Gyrodometry::at(std::size_t age) noexcept {
  // age < ring size: one conditional wrap instead of a division.
  return ring_[head_ >= age ? head_ - age : head_ + ring_.size() - age];
}

double Gyrodometry::threshold() const noexcept {
  // Change of the rate of turn across the window: the halves' mean rates differ by half of it
  // on a steady ramp.
  const double turn_new = sum_new_r_ - sum_new_l_, turn_old = sum_old_r_ - sum_old_l_;
  const double d_omega =
      filled_ == ring_.size() ? 2.0 * std::fabs(turn_new - turn_old) * inv_t_h_ / wheelbase_ : 0.0;
  return base_threshold_ + p_.noise.scale_tolerance * std::fabs(sum_odo_) + p_.gyro_delay * d_omega;
}

void Gyrodometry::resum() noexcept {
  // Re-add the window from the ring so that the running sums' rounding cannot accumulate.
  sum_err_ = sum_odo_ = 0.0;
  sum_new_l_ = sum_new_r_ = sum_old_l_ = sum_old_r_ = 0.0;
  bad_ = 0;
  for (std::size_t age = 0; age < filled_; ++age) {
    const Entry& e = at(age);
    sum_odo_ += e.odo;
    if (e.gyro_ok)
      sum_err_ += e.gyro - e.odo;
    else
      ++bad_;
    if (age < half_) {
      sum_new_l_ += e.d_left;
      sum_new_r_ += e.d_right;
    } else {
      sum_old_l_ += e.d_left;
      sum_old_r_ += e.d_right;
    }
  }
}

void Gyrodometry::push(const Entry& e) noexcept {
  const std::size_t n = ring_.size();
  const std::size_t next = head_ + 1 == n ? 0 : head_ + 1;
  if (filled_ == n) {  // the oldest entry (older half) leaves the window
    const Entry& old = ring_[next];
    sum_odo_ -= old.odo;
    if (old.gyro_ok)
      sum_err_ -= old.gyro - old.odo;
    else
      --bad_;
    sum_old_l_ -= old.d_left;
    sum_old_r_ -= old.d_right;
  }
  if (filled_ >= half_) {  // the entry of age half_ - 1 moves from the newer to the older half
    const Entry& mid = at(half_ - 1);
    sum_new_l_ -= mid.d_left;
    sum_new_r_ -= mid.d_right;
    sum_old_l_ += mid.d_left;
    sum_old_r_ += mid.d_right;
  }
  ring_[next] = e;
  head_ = next;
  if (filled_ < n) ++filled_;
  sum_odo_ += e.odo;
  if (e.gyro_ok)
    sum_err_ += e.gyro - e.odo;
  else
    ++bad_;
  sum_new_l_ += e.d_left;
  sum_new_r_ += e.d_right;
  // Re-sum every kResumWraps passes of the ring: the running sums' rounding stays far below a
  // count (1e-16 relative per addition, a few thousand additions), at 1/16 of the cost.
  if (head_ == 0 && ++wraps_ % kResumWraps == 0) resum();
}

void Gyrodometry::update_bias(const FusionInput& in, bool rate_ok, bool still, double dt) noexcept {
  if (!still) {
    still_for_ = 0.0;
    return;
  }
  still_for_ += dt;
  // The first still_time of a standstill only confirms it (the robot may still rock after
  // braking); after that the gyro's mean is its bias: a running mean over the seconds averaged so
  // far, which becomes an exponential average of horizon bias_tau to follow the bias's drift.
  if (!rate_ok || still_for_ < p_.still_time) return;
  bias_time_ = std::min(bias_time_ + dt, p_.bias_tau);
  bias_ += (in.gyro.rate_z - bias_) * dt / bias_time_;
  update_b_res();
}

void Gyrodometry::update_scale(double odo, double raw_gyro, double dt) noexcept {
  if (std::fabs(odo) < p_.turn_rate_min * dt) return;
  // Sign-weighted sums: a residual bias adds to clockwise and subtracts from counter-clockwise
  // turns' gyro angle, so it cancels over turns both ways.
  const double sign = odo > 0.0 ? 1.0 : -1.0;
  scale_odo_ += sign * odo;
  scale_gyro_ += sign * raw_gyro;
  if (scale_odo_ < p_.scale_angle || !(scale_gyro_ > 0.0)) return;
  const double s = scale_odo_ / scale_gyro_;
  if (std::fabs(s - 1.0) <= p_.scale_max_error) {
    scale_ = s;
    scale_valid_ = true;
  }
}

std::uint32_t Gyrodometry::limit_flags() const noexcept {
  std::uint32_t f = 0;
  const Entry& e = ring_[head_];
  // Speeds per tick: one count of quantisation is m / tick (0.046 m/s for 0.23 mm at 200 Hz),
  // far below any useful limit.
  if (std::fabs(e.d_left) > v_max_tick_ || std::fabs(e.d_right) > v_max_tick_)
    f |= kFusionSpeedLimit;
  if (filled_ == ring_.size()) {
    // Accelerations from the mean speeds of the two halves of the window: a count per half is
    // 2 m / T_h^2 of acceleration (0.18 m/s^2 for 0.23 mm and T_h = 0.05 s), per tick it would be
    // 2 m / tick^2 = 18 m/s^2.
    if (std::fabs(sum_new_l_ - sum_old_l_) > dv_max_ ||
        std::fabs(sum_new_r_ - sum_old_r_) > dv_max_)
      f |= kFusionAccelLimit;
  }
  return f;
}

double Gyrodometry::begin_interval() noexcept {
  // Replace every tick of the window that odometry still supplies: the disturbance began at most
  // a window ago, and detection waited for it to grow beyond the threshold.
  double correction = 0.0;
  for (std::size_t age = 0; age < filled_; ++age) {
    Entry& e = at(age);
    if (e.replaced || !e.gyro_ok) continue;
    correction += e.gyro - e.odo;
    e.replaced = true;
    ++interval_ticks_;
  }
  return correction;
}

FusedTick Gyrodometry::step(const FusionInput& in) noexcept {
  FusedTick out;
  if (!(std::isfinite(in.d_left) && std::isfinite(in.d_right) && in.wheelbase > 0.0 &&
        std::isfinite(in.wheelbase))) {
    return out;  // nothing sane to integrate (the loop never produces this)
  }
  const double dt = in.dt > 0.0 && std::isfinite(in.dt) ? in.dt : p_.tick;
  const double odo = (in.d_right - in.d_left) / in.wheelbase;
  out.dtheta = out.dtheta_odo = odo;
  wheelbase_ = in.wheelbase;
  const bool rate_ok = in.gyro.flags == kGyroOk && std::isfinite(in.gyro.rate_z);
  if (!rate_ok) {
    out.flags |= kFusionGyroFault;
    if (gyro_was_ok_) ++counters_.gyro_faults;
  }
  gyro_was_ok_ = rate_ok;
  const bool still = in.d_left == 0.0 && in.d_right == 0.0;
  if (still) out.flags |= kFusionStill;
  update_bias(in, rate_ok, still, dt);
  const bool usable = rate_ok && bias_valid();
  if (!bias_valid()) out.flags |= kFusionNoBias;
  Entry e;
  e.odo = odo;
  e.d_left = in.d_left;
  e.d_right = in.d_right;
  e.gyro_ok = usable;
  const double raw = usable ? (in.gyro.rate_z - bias_) * dt : 0.0;
  e.gyro = scale_ * raw;
  push(e);
  if (!usable) {
    in_interval_ = false;  // a faulty gyro ends any flagged interval: odometry from here on
    return out;
  }
  if (scale_estimation_ && !in_interval_) update_scale(odo, raw, dt);
  std::uint32_t why = limit_flags();
  // T >= base_threshold_: most ticks are decided without the window-dependent terms.
  const double abs_err = std::fabs(sum_err_);
  if (bad_ == 0 && abs_err > base_threshold_ && abs_err > threshold()) why |= kFusionDisagree;
  if (why == 0) {
    in_interval_ = false;
    return out;
  }
  out.flags |= why | kFusionGyroUsed;
  if (!in_interval_) {
    open_interval(why, odo, dt, out);
  } else {
    continue_interval(e.gyro, dt, out);
  }
  return out;
}

void Gyrodometry::open_interval(std::uint32_t why, double odo, double dt, FusedTick& out) noexcept {
  in_interval_ = true;
  interval_ticks_ = 0;
  out.flags |= kFusionEventStart;
  counters_.disagreements += (why & kFusionDisagree) != 0 ? 1 : 0;
  counters_.speed_events += (why & kFusionSpeedLimit) != 0 ? 1 : 0;
  counters_.accel_events += (why & kFusionAccelLimit) != 0 ? 1 : 0;
  out.dtheta = odo + begin_interval();
  // m ticks of gyro at once: white noise N^2 m dt, the bias error's (b_res m dt)^2.
  const double n2 = p_.noise.rate_noise_density * p_.noise.rate_noise_density;
  const double t = static_cast<double>(interval_ticks_) * dt;
  out.var_heading = n2 * t + b_res_ * b_res_ * t * t;
  counters_.flagged_ticks += interval_ticks_;
}

void Gyrodometry::continue_interval(double gyro, double dt, FusedTick& out) noexcept {
  ring_[head_].replaced = true;
  out.dtheta = gyro;
  // Tick k of an interval: the bias part (b_res k dt)^2 grows by b_res^2 dt^2 (2k + 1).
  const double n2 = p_.noise.rate_noise_density * p_.noise.rate_noise_density;
  const double k = static_cast<double>(interval_ticks_);
  out.var_heading = n2 * dt + b_res_ * b_res_ * dt * dt * (2.0 * k + 1.0);
  ++interval_ticks_;
  ++counters_.flagged_ticks;
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
                                  double d_right, double dtheta, double var_heading) noexcept {
  propagate_gyro_arc(cov_, sin_theta0, cos_theta0, 0.5 * (d_left + d_right), dtheta,
                     along_track_variance(d_left, d_right, k_), var_heading);
}

}  // namespace odo
