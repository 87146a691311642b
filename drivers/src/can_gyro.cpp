#include "odo/drivers/can_gyro.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace odo::drivers {

CanGyroSource::CanGyroSource(CanBus& bus, const CanGyroConfig& cfg) : bus_(&bus), cfg_(cfg) {
  const int w = cfg.field.width_bits;
  // Two's complement spans -2^(w-1) .. 2^(w-1) - 1, an unsigned field 0 .. 2^w - 1 (w <= 32:
  // both fit an int64 and convert to double exactly).
  v_min_ = cfg.field.is_signed ? -(std::int64_t{1} << (w - 1)) : 0;
  v_max_ = cfg.field.is_signed ? (std::int64_t{1} << (w - 1)) - 1 : (std::int64_t{1} << w) - 1;
  const double lo = static_cast<double>(v_min_) * cfg.scale + cfg.offset;
  const double hi = static_cast<double>(v_max_) * cfg.scale + cfg.offset;
  full_scale_ = std::min(std::fabs(lo), std::fabs(hi));
  book_.stale_timeout = cfg.stale_timeout;
}

Result<CanGyroSource> CanGyroSource::create(CanBus& bus, const CanGyroConfig& cfg) {
  auto bad = [](const std::string& m) { return make_error(Errc::kInvalidArgument, m); };
  if (Status s = check_layout(cfg.field); !s) return bad("CAN gyro: " + s.error().message);
  if (cfg.field.width_bits > 32)
    return bad("CAN gyro: width " + std::to_string(cfg.field.width_bits) +
               " must be 16, 24 or 32 bits for a rate");
  if (!(std::isfinite(cfg.scale) && cfg.scale > 0.0 && cfg.scale <= 1.0))
    return bad("CAN gyro: scale must be in (0, 1] rad/s per LSB");
  if (!(std::isfinite(cfg.offset) && std::fabs(cfg.offset) <= 1e3))
    return bad("CAN gyro: offset must be in [-1000, 1000] rad/s");
  if (cfg.sign != 1 && cfg.sign != -1) return bad("CAN gyro: sign must be +1 or -1");
  if (cfg.stale_timeout <= 0) return bad("CAN gyro: stale_timeout must be > 0 s");
  if (auto s = check_row(kCanMaxFramesPerRead, "CAN gyro: ", cfg.max_frames_per_read); !s)
    return std::move(s).error();
  CanGyroSource g(bus, cfg);
  // A range that does not contain 0 cannot report a robot at rest (an unsigned field without
  // its offset): every sample would be flagged or wrong.
  if (!(static_cast<double>(g.v_min_) * cfg.scale + cfg.offset < 0.0 &&
        static_cast<double>(g.v_max_) * cfg.scale + cfg.offset > 0.0))
    return bad("CAN gyro: the field's range (scale, offset) must contain 0 rad/s");
  return g;
}

double CanGyroSource::take(std::int64_t v, TimeNs stamp, GyroSample& s) noexcept {
  ++s.samples;
  if (v <= v_min_ || v >= v_max_) {
    s.flags |= kGyroSaturated;
    ++book_.counters.saturated;
  }
  // Frames come in receive order: the last one taken is the newest.
  book_.last_stamp = std::max(book_.last_stamp, stamp);
  return cfg_.sign * (static_cast<double>(v) * cfg_.scale + cfg_.offset);
}

GyroSample CanGyroSource::read(TimeNs now) noexcept {
  GyroSample s;
  read_into(now, s);
  return s;
}

void CanGyroSource::read_into(TimeNs now, GyroSample& s) noexcept {
  // Every field of s is written here or by close() (rate_z, stamp, counters).
  s.samples = 0;
  s.flags = kGyroOk;
  double sum = 0.0;
  CanFrame f;
  int n = 0;
  for (; n < cfg_.max_frames_per_read && bus_->receive(f); ++n) {
    ++stats_.frames;
    std::int64_t v = 0;
    switch (decode_count(f, cfg_.field, v)) {
      case CanDecode::kOk:
        sum += take(v, f.stamp != 0 ? f.stamp : now, s);
        break;
      case CanDecode::kShortFrame:  // our id, but the rate is not in it: undecodable
        s.flags |= kGyroInvalid;
        ++book_.counters.invalid;
        break;
      case CanDecode::kRemote:
        ++stats_.remote;
        break;
      case CanDecode::kOtherId:
        ++stats_.foreign;
        break;
    }
  }
  if (n == cfg_.max_frames_per_read) ++stats_.capped_reads;
  book_.close(s, now, s.samples > 0 ? sum / s.samples : 0.0);
}

}  // namespace odo::drivers
