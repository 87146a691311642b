// SimGyro: a MEMS rate gyro on the simulated robot. It samples the robot's TRUE heading (bumps,
// roughness and slip act on the wheels, not on the gyro) at its output data rate and adds the
// error terms of a real part: angle random walk (white rate noise), a bias offset, bias
// instability (a random walk of the bias), a scale-factor error, quantisation to a signed
// `bits`-wide word over +-full_scale (saturating there), and an output delay. Faults can be
// injected: a device that goes silent (stale), saturates, or a backend that returns NaN.
// Deterministic for a given seed.
#pragma once

#include <array>
#include <cstdint>

#include "odo/hal/gyro.hpp"
#include "odo/hal/result.hpp"
#include "odo/sim/robot.hpp"
#include "odo/sim/ziggurat.hpp"

namespace odo::sim {

// GyroModel: the error terms of one part (SI units; datasheets' deg and hours converted).
struct GyroModel {
  double full_scale = 0.0;     // measuring range +- [rad/s]
  int bits = 16;               // output word width
  double noise_density = 0.0;  // rate noise density N [rad/s/sqrt(Hz)]; ARW = N [rad/sqrt(s)]
  double bias_offset = 0.0;    // zero-rate offset at switch-on [rad/s]
  double bias_walk = 0.0;      // rate random walk K [rad/s/sqrt(s)]: bias instability
  double scale_error = 0.0;    // output = (1 + scale_error) * true rate + ...
  double odr = 1000.0;         // output data rate [Hz]
  double delay = 0.0;          // from the motion to the sample's availability [s]
};

// consumer_gyro: a Bosch BMI088-class consumer IMU gyro (BMI088 data sheet BST-BMI088-DS001):
// range +-2000 deg/s in 16 bits (16.384 LSB/(deg/s)), rate noise density 0.014 deg/s/sqrt(Hz),
// zero-rate offset +-1 deg/s (the model takes the full 1 deg/s), bias stability 2 deg/h (as a
// random walk that moves the bias by 2 deg/h in 100 s: K = 2 deg/h / 10 s^0.5), sensitivity
// tolerance +-1 % (the model takes +0.5 %: the ICM-20948 class is +-1.5 %), ODR 1000 Hz and a
// 2 ms output delay (116 Hz filter bandwidth at that ODR: group delay of about 1.4 ms plus the
// sample period).
GyroModel consumer_gyro();
// industrial_gyro: an Analog Devices ADIS16470-class industrial IMU gyro (ADIS16470 data sheet):
// range +-2000 deg/s in 16 bits (10 LSB/(deg/s)), angle random walk 0.34 deg/sqrt(h)
// (N = 0.34/60 = 0.00567 deg/s/sqrt(Hz)), in-run bias stability 8 deg/h, initial bias error
// +-0.2 deg/s, sensitivity error taken as 0.2 %, ODR 2000 Hz, 1 ms delay.
GyroModel industrial_gyro();

// check_gyro_model: every field finite and in range; the error names the field.
Status check_gyro_model(const GyroModel& m);

// What a SimGyro injected so far.
struct InjectedGyroFaults {
  std::uint64_t silent_samples = 0;     // samples the device did not deliver (stale)
  std::uint64_t saturated_samples = 0;  // samples forced to the end of the range
  std::uint64_t nan_reads = 0;          // reads that returned NaN (unflagged)
};

class SimGyro final : public YawRateSource {
 public:
  // create: checks the model; the gyro starts at the robot's current time and heading.
  // stale_timeout: the source flags kGyroStale when no sample arrived for this long [ns].
  static Result<SimGyro> create(SimRobot& robot, const GyroModel& m, std::uint64_t seed,
                                TimeNs stale_timeout = 20'000'000);

  // read: advances the robot to `now` and returns the mean of the samples that became
  // available since the previous read.
  GyroSample read(TimeNs now) noexcept override;
  // read_into: read() written into `out` in place.
  void read_into(TimeNs now, GyroSample& out) noexcept override;
  double full_scale() const noexcept override { return m_.full_scale; }

  // arm_silence: the device delivers no samples for `duration` [ns] from the next read on.
  void arm_silence(TimeNs duration) noexcept {
    silence_ = duration;
    faults_ = true;
  }
  // arm_saturation: the next `samples` samples read +full scale.
  void arm_saturation(int samples) noexcept {
    saturate_left_ = samples;
    faults_ = true;
  }
  // arm_nan: the next `reads` reads return rate_z = NaN with no flag (a broken backend).
  void arm_nan(int reads) noexcept {
    nan_left_ = reads;
    faults_ = true;
  }
  const InjectedGyroFaults& injected() const noexcept { return injected_; }
  // bias: the true bias at the last sample [rad/s] (offset + random walk).
  double bias() const noexcept { return m_.bias_offset + walk_; }
  // lsb: the output's resolution [rad/s].
  double lsb() const noexcept { return lsb_; }
  const GyroModel& model() const noexcept { return m_; }

 private:
  SimGyro(SimRobot& robot, const GyroModel& m, std::uint64_t seed, TimeNs stale_timeout);
  // heading_at: the true heading at time t [ns], interpolated in the history of reads.
  double heading_at(TimeNs t) noexcept;
  // sample: one output word for the true rate [rad/s]; sets `saturated`. kFaults: an armed
  // saturation is applied.
  template <bool kFaults>
  double sample(double true_rate, bool& saturated) noexcept;
  // read_samples: read_into() with (kFaults) or without the fault injection's checks.
  template <bool kFaults>
  void read_samples(TimeNs now, GyroSample& s) noexcept;

  struct Past {
    TimeNs t;
    double theta;
  };
  static constexpr std::size_t kHistory = 64;  // a power of two (indices wrap by a mask)
  // round_to_int: std::nearbyint in the default rounding mode (to nearest, ties to even) for
  // |v| <= 2^51, inline (nearbyint is a library call on baseline x86-64): v + 1.5 * 2^52 then
  // lies in [2^52, 2^53], where the spacing of doubles is 1, and subtracting 1.5 * 2^52 again is
  // exact. The caller keeps v in range (sample() saturates it to a word of at most 32 bits
  // first); NaN stays NaN. Only the sign of a zero can differ (-0.4 gives +0, nearbyint -0),
  // which no sum of samples keeps.
  static double round_to_int(double v) noexcept {
    constexpr double kShift = 0x1.8p52;
    return (v + kShift) - kShift;
  }
  SimRobot& robot_;
  GyroModel m_;
  ZigguratNormal normal_;
  double lsb_ = 0.0, sigma_ = 0.0, walk_step_ = 0.0;
  double walk_step1_ = 0.0;               // walk_step_ sqrt(3): a read's walk factor for one sample
  double gain_ = 1.0;                     // 1 + scale_error
  double inv_period_ = 0.0;               // 1 / sample period [1/s]
  double word_hi_ = 0.0, word_lo_ = 0.0;  // the output word's range [LSB]
  TimeNs period_ = 0, delay_ = 0;
  TimeNs next_t_ = 0;        // truth time of the next sample [ns]
  double last_theta_ = 0.0;  // true heading at the previous sample
  double walk_ = 0.0;        // bias random walk so far [rad/s]
  std::array<Past, kHistory> hist_{};
  std::size_t hist_head_ = 0, hist_n_ = 0;
  std::size_t hint_age_ = 1;  // age of the read heading_at found last
  // past: the read of an age (0: the newest), age < kHistory.
  const Past& past(std::size_t age) const noexcept {
    return hist_[(hist_head_ - age) & (kHistory - 1)];
  }
  GyroReadBook book_;
  TimeNs silence_ = 0, silent_until_ = -1;
  int saturate_left_ = 0, nan_left_ = 0;
  bool faults_ = false;  // a fault is armed or under way: reads check for them
  InjectedGyroFaults injected_;
};

}  // namespace odo::sim
