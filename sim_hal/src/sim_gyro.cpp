#include "odo/sim/sim_gyro.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "odo/hal/angle.hpp"

namespace odo::sim {
namespace {

constexpr double kPerHour = 1.0 / 3600.0;

}  // namespace

GyroModel consumer_gyro() {
  GyroModel m;
  m.full_scale = 2000.0 * kRadPerDeg;
  m.bits = 16;
  m.noise_density = 0.014 * kRadPerDeg;                          // 2.443e-4 rad/s/sqrt(Hz)
  m.bias_offset = 1.0 * kRadPerDeg;                              // 1.745e-2 rad/s
  m.bias_walk = 2.0 * kRadPerDeg * kPerHour / std::sqrt(100.0);  // 9.70e-7 rad/s/sqrt(s)
  m.scale_error = 0.005;
  m.odr = 1000.0;
  m.delay = 0.002;
  return m;
}

GyroModel industrial_gyro() {
  GyroModel m;
  m.full_scale = 2000.0 * kRadPerDeg;
  m.bits = 16;
  m.noise_density = 0.34 / 60.0 * kRadPerDeg;                    // 9.89e-5 rad/s/sqrt(Hz)
  m.bias_offset = 0.2 * kRadPerDeg;                              // 3.49e-3 rad/s
  m.bias_walk = 8.0 * kRadPerDeg * kPerHour / std::sqrt(100.0);  // 3.88e-6 rad/s/sqrt(s)
  m.scale_error = 0.002;
  m.odr = 2000.0;
  m.delay = 0.001;
  return m;
}

Status check_gyro_model(const GyroModel& m) {
  struct Row {
    const char* field;
    double v, lo, hi;
  };
  const Row rows[] = {
      {"full_scale", m.full_scale, 1e-3, 1e3},
      {"bits", double(m.bits), 8, 32},
      {"noise_density", m.noise_density, 0, 1},
      {"bias_offset", m.bias_offset, -10, 10},
      {"bias_walk", m.bias_walk, 0, 1},
      {"scale_error", m.scale_error, -0.5, 0.5},
      {"odr", m.odr, 1, 100000},
      {"delay", m.delay, 0, 1},
  };
  for (const Row& r : rows) {
    if (std::isfinite(r.v) && r.v >= r.lo && r.v <= r.hi) continue;
    std::ostringstream s;
    s << "sim gyro " << r.field << " = " << r.v << " is outside [" << r.lo << ", " << r.hi << "]";
    return make_error(Errc::kInvalidArgument, s.str());
  }
  return Ok{};
}

Result<SimGyro> SimGyro::create(SimRobot& robot, const GyroModel& m, std::uint64_t seed,
                                TimeNs stale_timeout) {
  if (auto s = check_gyro_model(m); !s) return std::move(s).error();
  if (stale_timeout <= 0)
    return make_error(Errc::kInvalidArgument, "sim gyro stale_timeout must be > 0 ns");
  return SimGyro(robot, m, seed, stale_timeout);
}

SimGyro::SimGyro(SimRobot& robot, const GyroModel& m, std::uint64_t seed, TimeNs stale_timeout)
    : robot_(robot), m_(m), normal_(seed) {
  const std::int64_t raw_max = (std::int64_t{1} << (m.bits - 1)) - 1;
  lsb_ = m.full_scale / static_cast<double>(raw_max + 1);
  word_hi_ = static_cast<double>(raw_max);  // exact (at most 2^31 - 1), as is the - 1 below
  word_lo_ = -word_hi_ - 1.0;
  period_ = from_seconds(1.0 / m.odr);
  delay_ = from_seconds(m.delay);
  // White rate noise of density N sampled at f: per-sample sigma N sqrt(f), so that the mean of
  // the f T samples of T seconds, times T, has the angle random walk's sigma N sqrt(T).
  sigma_ = m.noise_density * std::sqrt(1.0 / to_seconds(period_));
  walk_step_ = m.bias_walk * std::sqrt(to_seconds(period_));
  walk_step1_ = walk_step_ * std::sqrt(3.0);  // read()'s walk factor for one sample
  gain_ = 1.0 + m.scale_error;
  inv_period_ = 1.0 / to_seconds(period_);
  next_t_ = robot.time() + period_;
  last_theta_ = robot.true_pose().theta;
  book_.stale_timeout = stale_timeout;
  hist_[0] = {robot.time(), last_theta_};
  hist_n_ = 1;
}

// heading_at and sample run for every sample and are called from read() only: inline.
inline double SimGyro::heading_at(TimeNs t) noexcept {
  // The newest read at or before t (age i >= 1; ages count back from the newest read, 0). Reads
  // and samples keep their pace, so it is nearly always at the age found for the previous sample:
  // the search starts there when no newer age can qualify (read times never decrease with
  // recency, so age i - 1 after t rules out every newer one), else at age 1.
  std::size_t i = hint_age_;
  if (!(i < hist_n_ && (i == 1 || past(i - 1).t > t))) i = 1;
  for (; i < hist_n_; ++i) {
    const Past& older = past(i);
    if (older.t <= t) {
      hint_age_ = i;
      // A sample at a read's time (the reads and samples on one clock): no interpolation (the
      // interpolation would add 0 * (newer - older) to it).
      if (older.t == t) return older.theta;
      const Past& newer = past(i - 1);
      const double span = static_cast<double>(newer.t - older.t);
      if (span <= 0.0) return newer.theta;
      const double f = static_cast<double>(t - older.t) / span;
      return older.theta + f * (newer.theta - older.theta);
    }
  }
  return past(hist_n_ - 1).theta;  // older than the history: the oldest known heading
}

template <bool kFaults>
inline double SimGyro::sample(double true_rate, bool& saturated) noexcept {
  double r = gain_ * true_rate + m_.bias_offset + walk_ + sigma_ * normal_();
  if (kFaults && saturate_left_ > 0) {
    --saturate_left_;
    ++injected_.saturated_samples;
    r = 2.0 * m_.full_scale;
  }
  // Saturated to the word's range before rounding: the same as rounding and then saturating (the
  // ends are integers), and it keeps round_to_int's argument where it is exact. NaN passes.
  const double hi = word_hi_, lo = word_lo_;
  const double q = round_to_int(std::min(std::max(r / lsb_, lo), hi));
  saturated = q >= hi || q <= lo;
  return q * lsb_;
}

GyroSample SimGyro::read(TimeNs now) noexcept {
  GyroSample s;
  read_into(now, s);
  return s;
}

void SimGyro::read_into(TimeNs now, GyroSample& s) noexcept {
  // Without armed or running faults (nearly every read) their checks are left out.
  if (faults_)
    read_samples<true>(now, s);
  else
    read_samples<false>(now, s);
}

template <bool kFaults>
inline void SimGyro::read_samples(TimeNs now, GyroSample& s) noexcept {
  // The encoder's read of the same tick has usually moved the robot to `now` already.
  if (robot_.time() < now) robot_.advance_to(now);
  hist_head_ = (hist_head_ + 1) & (kHistory - 1);
  hist_[hist_head_] = {robot_.time(), robot_.true_pose().theta};
  if (hist_n_ < kHistory) ++hist_n_;
  if (kFaults && silence_ > 0) {
    silent_until_ = now + silence_;
    silence_ = 0;
  }
  // Every field of s is written below (close() sets rate_z, stamp and counters).
  s.samples = 0;
  s.flags = kGyroOk;
  double sum = 0.0;
  // Every sample whose motion ended at next_t_ is available delay_ later.
  while (next_t_ + delay_ <= now) {
    const double theta = heading_at(next_t_);
    const double true_rate = (theta - last_theta_) * inv_period_;
    last_theta_ = theta;
    const TimeNs avail = next_t_ + delay_;
    next_t_ += period_;
    if (kFaults && avail < silent_until_) {
      ++injected_.silent_samples;
      continue;
    }
    bool sat = false;
    sum += sample<kFaults>(true_rate, sat);
    ++s.samples;
    book_.last_stamp = avail;
    if (sat) {
      s.flags |= kGyroSaturated;
      ++book_.counters.saturated;
    }
  }
  // The bias walks once per read by the samples' combined step (sigma K sqrt(n T_s)), drawn
  // uniform with that sigma (sqrt(3) (2u - 1)): summed over many reads it is the same Brownian
  // walk (central limit). u comes from the last sample's normal draw, from bits that draw did
  // not use: no generator call of its own. Without a walk (walk_step_ = 0: the model allows no
  // negative K) it adds a zero to the +0 it starts from, which leaves +0.
  double mean = 0.0;
  if (s.samples == 1) {  // the usual read (samples and reads at one rate): sum / 1 is sum
    walk_ += walk_step1_ * normal_.spare_signed();
    mean = sum;
  } else if (s.samples > 1) {
    walk_ += walk_step_ * std::sqrt(3.0 * static_cast<double>(s.samples)) * normal_.spare_signed();
    mean = sum / s.samples;
  }
  book_.close(s, now, mean);
  if (kFaults && nan_left_ > 0) {
    --nan_left_;
    ++injected_.nan_reads;
    s.rate_z = std::numeric_limits<double>::quiet_NaN();
  }
  // Faults stay checked while any is armed or a silence covers samples still to come (the next
  // sample is available at next_t_ + delay_, later ones later).
  if (kFaults)
    faults_ =
        silence_ > 0 || saturate_left_ > 0 || nan_left_ > 0 || next_t_ + delay_ < silent_until_;
}

}  // namespace odo::sim
