// Fuzz target: the loop's state record (issue 17; version 2 carries the gyro's calibration) and
// what a restart does with it: the resume decision and the fusion's restore. The bytes are read
// twice: as a state file as they are (torn or damaged: the CRC rejects nearly all of them), and
// as one slot whose header and CRC are made right, so that every field value reaches the checks,
// decide_resume and Gyrodometry::restore. Properties: never crashes, overflows or hits undefined
// behaviour (ASan, UBSan); an invalid record is Errc::kCorrupt (an empty or all-zero file
// kNotFound); a decoded record holds only values a loop writes, and encodes to bytes that decode
// to the same bytes again; a resume's gap is never negative and its counts within the bound it
// checked; a restored fusion has a finite bias and threshold.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>

#include "fuzz_check.hpp"
#include "odo/calibration/record.hpp"
#include "odo/hal/crc.hpp"
#include "odo/loop/state_record.hpp"
#include "odo/odometry/count_delta.hpp"
#include "odo/odometry/gyrodometry.hpp"

namespace {

using odo::fuzz::require;
namespace loop = odo::loop;

// valid_values: what decode_state promises about a record it returns.
void require_valid_values(const loop::StateRecord& r) {
  require(r.sequence != 0 && r.stamp >= 0, "decoded record with sequence 0 or negative stamp");
  require(odo::check_counter_bits(r.counter_bits).ok(), "decoded record with a bad counter width");
  require(r.metres_per_count_left > 0.0 && r.metres_per_count_right > 0.0 && r.wheelbase > 0.0,
          "decoded record with kinematics that are not positive");
  require(std::isfinite(r.pose.x) && std::isfinite(r.pose.y) && std::isfinite(r.pose.theta) &&
              std::isfinite(r.distance) &&
              std::all_of(r.cov.begin(), r.cov.end(), [](double v) { return std::isfinite(v); }),
          "decoded record with a non-finite pose");
  require(std::isfinite(r.gyro.bias) && r.gyro.bias_time >= 0.0 && r.gyro.scale > 0.0 &&
              r.gyro.scale < 2.0,
          "decoded record with a gyro part out of range");
}

// check_round_trip: encode(r) decodes, and encodes to the same bytes (nothing invented or lost).
void check_round_trip(const loop::StateRecord& r) {
  loop::StateBytes a{}, b{};
  loop::encode_state(r, a);
  auto back = loop::decode_state(a);
  require(back.ok(), "an encoded record does not decode:", back ? "" : back.error().message);
  loop::encode_state(*back, b);
  require(a == b, "encode(decode(encode(r))) differs from encode(r)");
}

// check_resume: the decision for a loop that matches the record, on a reading taken from the
// fuzz bytes after the slot, and the restore of its gyro part into a fusion.
void check_resume(const loop::StateRecord& r, std::span<const std::uint8_t> tail) {
  loop::ResumeContext c;
  c.boot_id = r.boot_id;
  c.clock_epoch = r.clock_epoch;
  c.max_age = odo::from_seconds(5.0);
  c.backend = r.backend;
  c.backend_continuous = true;
  c.counter_bits = r.counter_bits;
  c.calibration_sequence = r.calibration_sequence;
  c.metres_per_count_left = r.metres_per_count_left;
  c.metres_per_count_right = r.metres_per_count_right;
  c.wheelbase = r.wheelbase;
  c.gyro_id = r.gyro_id;
  std::array<std::uint8_t, 24> t{};
  std::copy_n(tail.begin(), std::min(tail.size(), t.size()), t.begin());
  odo::EncoderSample s;
  std::memcpy(&s.left, t.data(), 8);
  std::memcpy(&s.right, t.data() + 8, 8);
  std::uint64_t ahead = 0;  // how long after the record the reading is: 0 .. 2^40 ns (18 min)
  std::memcpy(&ahead, t.data() + 16, 8);
  ahead &= (std::uint64_t{1} << 40) - 1;
  // A clock reading is never near INT64_MAX (292 years of uptime): the fuzz input's stamp is.
  if (r.stamp > INT64_MAX - static_cast<std::int64_t>(ahead)) return;
  s.stamp = r.stamp + static_cast<std::int64_t>(ahead);
  c.now = s.stamp;
  const loop::ResumeDecision d = loop::decide_resume(r, c, s);
  // The context matches the record's boot, clock and age: only the id decides the gyro's match.
  require(d.reason == loop::ResumeReason::kStale || d.gyro_matches == (r.gyro_id != 0),
          "the same gyro did not match (or none did)");
  if (!d.resumed()) return;
  require(d.gap >= 0, "resume with a negative gap");
  const double gap_s = odo::to_seconds(d.gap);
  require(std::fabs(static_cast<double>(d.dl)) <=
              c.max_wheel_speed * gap_s / c.metres_per_count_left + 1.0,
          "resumed with more counts than the gap allows");
  odo::GyrodometryParams p;
  auto g = odo::Gyrodometry::create(p);
  require(g.ok(), "default fusion parameters rejected");
  g->restore(r.gyro);
  require(std::isfinite(g->bias()) && std::isfinite(g->threshold()) && g->scale() > 0.0,
          "restored fusion not finite");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> bytes(data, size);
  auto f = loop::decode_state_file(bytes);
  if (f) {
    require_valid_values(*f);
  } else {
    const bool blank = std::all_of(data, data + size, [](std::uint8_t v) { return v == 0; });
    require(f.error().code == (blank ? odo::Errc::kNotFound : odo::Errc::kCorrupt),
            "a bad state file is not reported corrupt (or an empty or blank one not found):",
            f.error().message);
  }
  // One slot with its header and CRC made right: version 1 when the input's byte 4 is odd.
  if (size < 8) return 0;
  std::array<std::uint8_t, loop::kStateRecordBytes> slot{};
  std::copy_n(data, std::min(size, slot.size()), slot.begin());
  const bool v1 = (data[4] & 1) != 0;
  const std::size_t len = v1 ? loop::kStateRecordBytesV1 : loop::kStateRecordBytes;
  const std::uint32_t magic = loop::kStateMagic;
  for (int i = 0; i < 4; ++i) slot[i] = static_cast<std::uint8_t>(magic >> (8 * i));
  slot[4] = v1 ? 1 : 2;
  slot[5] = 0;
  slot[6] = static_cast<std::uint8_t>(len);
  slot[7] = 0;
  const std::uint32_t crc = odo::crc32(std::span<const std::uint8_t>(slot.data(), len - 4));
  for (int i = 0; i < 4; ++i) slot[len - 4 + i] = static_cast<std::uint8_t>(crc >> (8 * i));
  auto r = loop::decode_state(std::span<const std::uint8_t>(slot.data(), len));
  if (!r) {
    require(r.error().code == odo::Errc::kCorrupt, "a rejected slot is not reported corrupt");
    return 0;
  }
  require_valid_values(*r);
  require(!v1 || (r->gyro_id == 0 && r->gyro.bias_time == 0.0), "a version-1 record has a gyro");
  check_round_trip(*r);
  check_resume(*r, size > len ? bytes.subspan(len) : std::span<const std::uint8_t>{});
  return 0;
}
