#include "odo/loop/state_record.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdlib>
#include <string>

#include "odo/hal/bytes.hpp"
#include "odo/hal/crc.hpp"
#include "odo/loop/loop.hpp"
#include "odo/odometry/count_delta.hpp"

namespace odo::loop {
namespace {

constexpr std::size_t kCrcOffset = kStateRecordBytes - 4;
// Version 2's gyro part.
constexpr std::size_t kGyroId = 208, kGyroFlags = 212, kGyroBias = 216, kGyroBiasTime = 224,
                      kGyroScale = 232;
constexpr std::uint8_t kGyroScaleValid = 1;

template <class T>
void put(StateBytes& b, std::size_t off, T v) noexcept {
  put_le(std::span<std::uint8_t>(b), off, v);
}

template <class T>
T get(std::span<const std::uint8_t> b, std::size_t off) noexcept {
  return get_le<T>(b, off);
}

Error corrupt(const std::string& why) {
  return make_error(Errc::kCorrupt, "state record: " + why);
}

// The doubles of a record in layout order (offset 80 on), for encoding, decoding and checks.
constexpr std::size_t kFirstDouble = 80;
constexpr std::size_t kDoubles = 16;

template <class R>  // StateRecord or const StateRecord
auto doubles(R& r) noexcept {
  return std::array{&r.metres_per_count_left,
                    &r.metres_per_count_right,
                    &r.wheelbase,
                    &r.pose.x,
                    &r.pose.y,
                    &r.pose.theta,
                    &r.cov[0],
                    &r.cov[1],
                    &r.cov[2],
                    &r.cov[3],
                    &r.cov[4],
                    &r.cov[5],
                    &r.cov[6],
                    &r.cov[7],
                    &r.cov[8],
                    &r.distance};
}

}  // namespace

void encode_state(const StateRecord& r, StateBytes& b) noexcept {
  put(b, 0, kStateMagic);
  put(b, 4, kStateVersion);
  put(b, 6, static_cast<std::uint16_t>(kStateRecordBytes));
  put(b, 8, r.sequence);
  for (std::size_t i = 0; i < r.boot_id.size(); ++i) b[16 + i] = r.boot_id[i];
  put(b, 32, r.clock_epoch);
  put(b, 40, r.stamp);
  put(b, 48, r.left);
  put(b, 56, r.right);
  put(b, 64, r.counter_bits);
  put(b, 65, r.backend);
  put(b, 66, r.calibration_state);
  put(b, 67, std::uint8_t{0});
  put(b, 68, std::uint32_t{0});
  put(b, 72, r.calibration_sequence);
  const auto d = doubles(r);
  for (std::size_t i = 0; i < kDoubles; ++i) put(b, kFirstDouble + 8 * i, *d[i]);
  put(b, kGyroId, r.gyro_id);
  put(b, kGyroFlags, r.gyro.scale_valid ? kGyroScaleValid : std::uint8_t{0});
  put(b, kGyroFlags + 1, std::uint8_t{0});
  put(b, kGyroFlags + 2, std::uint16_t{0});
  put(b, kGyroBias, r.gyro.bias);
  put(b, kGyroBiasTime, r.gyro.bias_time);
  put(b, kGyroScale, r.gyro.scale);
  put(b, kCrcOffset, odo::crc32(std::span<const std::uint8_t>(b.data(), kCrcOffset)));
}

// decode_gyro: version 2's gyro part of `b` into r.
Status decode_gyro(std::span<const std::uint8_t> b, StateRecord& r) {
  r.gyro_id = get<std::uint32_t>(b, kGyroId);
  r.gyro.scale_valid = (get<std::uint8_t>(b, kGyroFlags) & kGyroScaleValid) != 0;
  r.gyro.bias = get<double>(b, kGyroBias);
  r.gyro.bias_time = get<double>(b, kGyroBiasTime);
  r.gyro.scale = get<double>(b, kGyroScale);
  if (!std::isfinite(r.gyro.bias)) return corrupt("non-finite gyro bias");
  // Both are written by the fusion, which keeps them there: anything else is damage.
  if (!(r.gyro.bias_time >= 0.0 && r.gyro.bias_time <= 1e9))
    return corrupt("gyro bias averaging time outside [0, 1e9] s");
  if (!(r.gyro.scale > 0.0 && r.gyro.scale < 2.0)) return corrupt("gyro scale outside (0, 2)");
  return Ok{};
}

Result<StateRecord> decode_state(std::span<const std::uint8_t> b) {
  const auto version = b.size() >= 8 ? get<std::uint16_t>(b, 4) : std::uint16_t{0};
  const std::size_t length = version == 1 ? kStateRecordBytesV1 : kStateRecordBytes;
  if (b.size() < length)
    return corrupt("length " + std::to_string(b.size()) + " bytes, expected " +
                   std::to_string(length));
  if (get<std::uint32_t>(b, 0) != kStateMagic) return corrupt("bad magic (not a state record)");
  if ((version != 1 && version != kStateVersion) || get<std::uint16_t>(b, 6) != length)
    return corrupt("version " + std::to_string(version) + " length " +
                   std::to_string(get<std::uint16_t>(b, 6)) + ", expected version " +
                   std::to_string(kStateVersion) + " length " + std::to_string(kStateRecordBytes) +
                   " (or 1 and " + std::to_string(kStateRecordBytesV1) + ")");
  // The CRC covers everything else: a write torn at any byte fails here.
  const std::size_t crc_at = length - 4;
  if (get<std::uint32_t>(b, crc_at) != odo::crc32(b.first(crc_at)))
    return corrupt("CRC mismatch (torn or damaged write)");
  StateRecord r;
  r.sequence = get<std::uint64_t>(b, 8);
  for (std::size_t i = 0; i < r.boot_id.size(); ++i) r.boot_id[i] = b[16 + i];
  r.clock_epoch = get<std::uint64_t>(b, 32);
  r.stamp = get<std::int64_t>(b, 40);
  r.left = get<std::int64_t>(b, 48);
  r.right = get<std::int64_t>(b, 56);
  r.counter_bits = get<std::uint8_t>(b, 64);
  r.backend = get<std::uint8_t>(b, 65);
  r.calibration_state = get<std::uint8_t>(b, 66);
  r.calibration_sequence = get<std::uint64_t>(b, 72);
  const auto d = doubles(r);
  for (std::size_t i = 0; i < kDoubles; ++i) {
    *d[i] = get<double>(b, kFirstDouble + 8 * i);
    if (!std::isfinite(*d[i]))
      return corrupt("non-finite value at byte " + std::to_string(kFirstDouble + 8 * i));
  }
  if (!check_counter_bits(r.counter_bits))
    return corrupt("counter width " + std::to_string(r.counter_bits) + " outside [16, 64]");
  if (r.sequence == 0) return corrupt("sequence 0");
  // Values no loop writes: a sample time before its clock's zero (the resume decision subtracts
  // it from the clock's now, which must not overflow) and kinematics that are no kinematics.
  if (r.stamp < 0) return corrupt("negative sample time");
  if (!(r.metres_per_count_left > 0.0 && r.metres_per_count_right > 0.0 && r.wheelbase > 0.0))
    return corrupt("metres per count or wheelbase not positive");
  // Version 1 has no gyro part: gyro_id 0 matches no gyro, so nothing is restored from it.
  if (version == kStateVersion) {
    if (auto st = decode_gyro(b, r); !st) return std::move(st).error();
  }
  return r;
}

Result<StateRecord> decode_state_file(std::span<const std::uint8_t> bytes) {
  if (bytes.empty()) return make_error(Errc::kNotFound, "state file is empty");
  Result<StateRecord> best = corrupt("no slot holds a record");
  for (std::size_t off = 0; off < kStateFileBytes; off += kStateSlotBytes) {
    if (bytes.size() <= off) break;
    auto r = decode_state(bytes.subspan(off, std::min(kStateRecordBytes, bytes.size() - off)));
    if (!r) {
      if (!best) best = std::move(r);  // keep the first slot's reason when both fail
      continue;
    }
    if (!best || r->sequence > best->sequence) best = std::move(r);
  }
  // The persister sizes a new file with zeros: one whose daemon stopped before its first record
  // is blank, which is no record yet, not damage.
  if (!best && std::all_of(bytes.begin(), bytes.end(), [](std::uint8_t v) { return v == 0; }))
    return make_error(Errc::kNotFound, "state file is blank (no record written yet)");
  return best;
}

std::string_view resume_reason_name(ResumeReason r) noexcept {
  return choice_name(kResumeReasonNames, r);
}

ResumeDecision decide_resume(const StateRecord& rec, const ResumeContext& ctx,
                             const EncoderSample& current) noexcept {
  ResumeDecision d;
  d.gap = current.stamp - rec.stamp;
  auto fresh = [&d](ResumeReason why) {
    d.reason = why;
    return d;
  };
  if (rec.boot_id != ctx.boot_id) return fresh(ResumeReason::kOtherBoot);
  if (rec.clock_epoch != ctx.clock_epoch) return fresh(ResumeReason::kOtherClock);
  const TimeNs age = ctx.now - rec.stamp;
  if (age < 0 || age > ctx.max_age || d.gap < 0) return fresh(ResumeReason::kStale);
  // The gyro's bias belongs to the chip, not to the encoders: the same chip in the same boot,
  // drifted for a gap no longer than max_age, whatever the checks below decide for the pose.
  d.gyro_matches = ctx.gyro_id != 0 && rec.gyro_id == ctx.gyro_id;
  if (rec.backend != ctx.backend || rec.counter_bits != ctx.counter_bits)
    return fresh(ResumeReason::kOtherBackend);
  if (!ctx.backend_continuous) return fresh(ResumeReason::kNotContinuous);
  // Bitwise: the record's pose is only continued with exactly the numbers it was made with.
  if (rec.metres_per_count_left != ctx.metres_per_count_left ||
      rec.metres_per_count_right != ctx.metres_per_count_right || rec.wheelbase != ctx.wheelbase)
    return fresh(ResumeReason::kOtherKinematics);
  if (rec.calibration_sequence != ctx.calibration_sequence)
    return fresh(ResumeReason::kOtherCalibration);
  // The controller's counts restarted at its boot: whatever they read, they are not the
  // record's counts continued.
  if ((current.flags & kEncoderControllerReset) != 0) return fresh(ResumeReason::kControllerReset);
  if ((current.flags & (kEncoderReadError | kEncoderStaleLeft | kEncoderStaleRight)) != 0)
    return fresh(ResumeReason::kEncoderNotReady);
  // The record holds the counters' own values: compared with the counters' own values now (the
  // reported counts plus any jump this process rejected), so only real motion is seen.
  const int bits = ctx.counter_bits;
  d.dl = wrap_delta(rec.left, counter_value(current.left, current.left_rejected, bits), bits);
  d.dr = wrap_delta(rec.right, counter_value(current.right, current.right_rejected, bits), bits);
  // The most counts a wheel can make in the gap, plus one for quantisation; when that bound
  // reaches half the counter range the wrap rule can no longer tell the direction.
  const double gap_s = to_seconds(d.gap);
  const double max_l = ctx.max_wheel_speed * gap_s / ctx.metres_per_count_left + 1.0;
  const double max_r = ctx.max_wheel_speed * gap_s / ctx.metres_per_count_right + 1.0;
  const double half_range = std::ldexp(1.0, ctx.counter_bits - 1);
  d.max_dl = max_l;
  d.max_dr = max_r;
  if (max_l >= half_range || max_r >= half_range) return fresh(ResumeReason::kStale);
  if (std::fabs(static_cast<double>(d.dl)) > max_l || std::fabs(static_cast<double>(d.dr)) > max_r)
    return fresh(ResumeReason::kCounterJump);
  d.reason = ResumeReason::kResumed;
  return d;
}

void fill_state_record(const OdometryLoop& loop, StateRecord& r) noexcept {
  const Odometry& o = loop.odometry();
  r.stamp = loop.last_stamp();
  // The counters' own values, not the re-based counts the loop integrates: a jump this process
  // rejected stays rejected after a restart (issue 39).
  r.left = loop.last_counter_left();
  r.right = loop.last_counter_right();
  r.counter_bits = static_cast<std::uint8_t>(loop.counter_bits());
  r.calibration_state = static_cast<std::uint8_t>(loop.calibration());
  r.metres_per_count_left = o.kinematics().metres_per_count_left();
  r.metres_per_count_right = o.kinematics().metres_per_count_right();
  r.wheelbase = o.kinematics().wheelbase();
  r.pose = o.pose();
  r.cov = o.covariance();
  r.distance = o.distance();
  // gyro_id is the firmware's, like backend; the calibration is the fusion's (none: not learnt).
  if (const Gyrodometry* f = loop.fusion()) r.gyro = f->calibration();
}

}  // namespace odo::loop
