// CountingGyro: a yaw-rate source that costs what reading a decoded sample from memory costs,
// plus the bookkeeping every real backend does (GyroReadBook::close, as the IIO backend).
// With CountingEncoder it separates the firmware's own cost of a tick with the gyro fusion
// from the simulated gyro's (its noise, quantisation and delay model).
#pragma once

#include "odo/hal/gyro.hpp"

namespace odo::bench {

class CountingGyro final : public YawRateSource {
 public:
  // still_reads: reads at rate 0 (the encoder stands still meanwhile, so the fusion learns its
  // bias); after them every read returns `rate` [rad/s], one device sample a read.
  CountingGyro(long still_reads, double rate) : still_left_(still_reads), rate_(rate) {
    book_.stale_timeout = 1'000'000'000;  // never stale: one sample arrives every read
  }
  GyroSample read(TimeNs now) noexcept override {
    GyroSample s;
    read_into(now, s);
    return s;
  }
  void read_into(TimeNs now, GyroSample& s) noexcept override {
    s.samples = 1;
    s.flags = kGyroOk;
    book_.last_stamp = now;
    book_.close(s, now, still_left_ > 0 ? (--still_left_, 0.0) : rate_);
  }
  double full_scale() const noexcept override { return 35.0; }

 private:
  long still_left_;
  double rate_;
  GyroReadBook book_;
};

}  // namespace odo::bench
