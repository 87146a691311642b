// State record (issue 17): encoding, torn and corrupt records, and every reason of the resume
// decision. Numbers are chosen so that each expected value follows from the comment beside it.
#include <gtest/gtest.h>

#include <cstring>

#include "odo/calibration/record.hpp"
#include "odo/hal/crc.hpp"
#include "odo/loop/state_record.hpp"

namespace odo::loop {
namespace {

constexpr double kMpc = 0.001;  // 1 mm per count on both wheels

StateRecord sample_record(std::uint64_t seq) {
  StateRecord r;
  r.sequence = seq;
  for (std::size_t i = 0; i < r.boot_id.size(); ++i)
    r.boot_id[i] = static_cast<std::uint8_t>(i + 1);
  r.clock_epoch = 0;
  r.stamp = 10'000'000'000;  // 10 s
  r.left = 65530;            // near the top of a 16-bit counter
  r.right = -12;
  r.counter_bits = 16;
  r.backend = 1;
  r.calibration_state = 2;
  r.calibration_sequence = 5;
  r.metres_per_count_left = kMpc;
  r.metres_per_count_right = kMpc;
  r.wheelbase = 0.5;
  r.pose = {1.5, -2.25, 7.0};  // theta beyond 2 pi: cumulative heading kept
  for (std::size_t i = 0; i < 9; ++i) r.cov[i] = 1e-6 * static_cast<double>(i + 1);
  r.distance = 12.5;
  r.gyro_id = 0x12345678;
  r.gyro = {1.5e-3, 30.0, 1.01, true};  // bias [rad/s], 30 s averaged, scale 1.01 estimated
  return r;
}

ResumeContext matching_context(const StateRecord& r) {
  ResumeContext c;
  c.boot_id = r.boot_id;
  c.clock_epoch = r.clock_epoch;
  c.now = r.stamp + 1'000'000'000;  // 1 s later
  c.max_age = 10'000'000'000;       // 10 s
  c.backend = r.backend;
  c.backend_continuous = true;
  c.counter_bits = r.counter_bits;
  c.calibration_sequence = r.calibration_sequence;
  c.metres_per_count_left = r.metres_per_count_left;
  c.metres_per_count_right = r.metres_per_count_right;
  c.wheelbase = r.wheelbase;
  c.max_wheel_speed = 3.0;
  c.gyro_id = r.gyro_id;
  return c;
}

EncoderSample reading(const StateRecord& r, std::int64_t left, std::int64_t right, double gap_s) {
  EncoderSample s;
  s.left = left;
  s.right = right;
  s.stamp = r.stamp + static_cast<TimeNs>(gap_s * 1e9);
  return s;
}

bool same(const StateRecord& a, const StateRecord& b) {
  StateBytes x{}, y{};
  encode_state(a, x);
  encode_state(b, y);
  return x == y;
}

TEST(StateRecord, RoundTripKeepsEveryField) {
  const StateRecord r = sample_record(42);
  StateBytes b{};
  encode_state(r, b);
  auto d = decode_state(b);
  ASSERT_TRUE(d) << d.error().message;
  EXPECT_EQ(d->sequence, 42U);
  EXPECT_EQ(d->boot_id, r.boot_id);
  EXPECT_EQ(d->stamp, r.stamp);
  EXPECT_EQ(d->left, 65530);
  EXPECT_EQ(d->right, -12);
  EXPECT_EQ(d->counter_bits, 16);
  EXPECT_EQ(d->calibration_sequence, 5U);
  EXPECT_EQ(d->pose.theta, 7.0);
  EXPECT_EQ(d->cov[8], 9e-6);
  EXPECT_EQ(d->distance, 12.5);
  EXPECT_EQ(d->gyro_id, 0x12345678U);
  EXPECT_EQ(d->gyro.bias, 1.5e-3);
  EXPECT_EQ(d->gyro.bias_time, 30.0);
  EXPECT_EQ(d->gyro.scale, 1.01);
  EXPECT_TRUE(d->gyro.scale_valid);
  // Byte 0..3: "ODST"; 4..5: version 2; 6..7: length 244 = 0x00F4 little endian; 208..211 the
  // gyro id 0x12345678 little endian; 212 flags (bit 0: scale valid).
  EXPECT_EQ(std::memcmp(b.data(), "ODST", 4), 0);
  EXPECT_EQ(b[4], 2);
  EXPECT_EQ(b[6], 0xF4);
  EXPECT_EQ(b[7], 0x00);
  EXPECT_EQ(b[208], 0x78);
  EXPECT_EQ(b[211], 0x12);
  EXPECT_EQ(b[212], 1);
}

// A version-1 record (212 bytes, written before the gyro part existed) is still read, so an
// update does not lose the pose: everything but the gyro part, which reads as no gyro.
TEST(StateRecord, VersionOneRecordIsStillRead) {
  StateBytes b{};
  encode_state(sample_record(42), b);
  // Version 1's bytes are version 2's first 208 with version 1, length 212 and the CRC of
  // bytes [0, 208) at 208.
  b[4] = 1;
  b[6] = 212;
  const std::uint32_t crc = odo::crc32(std::span<const std::uint8_t>(b.data(), 208));
  for (int i = 0; i < 4; ++i) b[208 + i] = static_cast<std::uint8_t>(crc >> (8 * i));
  auto d = decode_state(std::span<const std::uint8_t>(b.data(), kStateRecordBytesV1));
  ASSERT_TRUE(d) << d.error().message;
  EXPECT_EQ(d->sequence, 42U);
  EXPECT_EQ(d->pose.theta, 7.0);
  EXPECT_EQ(d->distance, 12.5);
  EXPECT_EQ(d->gyro_id, 0U);
  EXPECT_EQ(d->gyro.bias_time, 0.0);
  EXPECT_FALSE(d->gyro.scale_valid);
  // In a two-slot file beside an older version-2 record, the newer version-1 one wins.
  std::array<std::uint8_t, kStateFileBytes> file{};
  StateBytes older{};
  encode_state(sample_record(41), older);
  std::memcpy(file.data() + kStateSlotBytes, older.data(), older.size());
  std::memcpy(file.data(), b.data(), kStateRecordBytesV1);
  EXPECT_EQ(decode_state_file(file)->sequence, 42U);
  // A version-1 header on a slot cut before 212 bytes is torn.
  EXPECT_FALSE(decode_state(std::span<const std::uint8_t>(b.data(), kStateRecordBytesV1 - 1)));
}

// A write of record `next` over record `prev` in the same slot, torn after k bytes: the slot
// holds next's first k bytes and prev's remaining ones. Decoding must fail or give exactly one
// of the two records, at every k, never a mixture.
TEST(StateRecord, WriteTornAtEveryByteIsDetected) {
  StateRecord prev = sample_record(6);
  StateRecord next = sample_record(8);
  next.pose = {1.75, -2.0, 7.125};
  next.left = 65535;
  next.stamp += 20'000'000;
  StateBytes a{}, b{};
  encode_state(prev, a);
  encode_state(next, b);
  int rejected = 0;
  for (std::size_t k = 0; k <= kStateRecordBytes; ++k) {
    StateBytes torn = a;
    std::memcpy(torn.data(), b.data(), k);
    auto d = decode_state(torn);
    if (!d) {
      EXPECT_EQ(d.error().code, Errc::kCorrupt) << "k=" << k;
      ++rejected;
      continue;
    }
    EXPECT_TRUE(same(*d, prev) || same(*d, next)) << "k=" << k;
    if (k < kStateRecordBytes && !same(*d, prev)) ADD_FAILURE() << "k=" << k;
  }
  // Bytes 0..7 (magic, version, length) are the same in both records, so k <= 8 leaves prev
  // intact; from k = 9 on the sequence's byte 8 differs (6 vs 8) and k = 244 is next intact:
  // the 235 slots k = 9..243 are torn and all rejected.
  EXPECT_EQ(rejected, 235);
}

// Two-slot file: a torn write into one slot leaves the other slot's record, the newest valid.
TEST(StateRecord, FileWithOneTornSlotGivesTheOtherSlot) {
  std::array<std::uint8_t, kStateFileBytes> file{};
  StateBytes a{}, b{};
  encode_state(sample_record(7), a);  // slot 1 (odd)
  encode_state(sample_record(8), b);  // slot 0 (even), torn below
  std::memcpy(file.data() + kStateSlotBytes, a.data(), a.size());
  for (std::size_t k = 0; k < kStateRecordBytes; ++k) {
    auto f = file;
    std::memcpy(f.data(), b.data(), k);
    auto d = decode_state_file(f);
    ASSERT_TRUE(d) << "k=" << k;
    // A write cut where the bytes still to come already hold their values (the zeros of a new
    // file) is not torn: the slot is record 8 intact. Otherwise it is torn and 7 remains.
    const bool intact = std::memcmp(f.data(), b.data(), b.size()) == 0;
    EXPECT_EQ(d->sequence, intact ? 8U : 7U) << "k=" << k;
  }
  std::memcpy(file.data(), b.data(), b.size());
  EXPECT_EQ(decode_state_file(file)->sequence, 8U);
}

// A file cut short at every length: a single slot shorter than a record is corrupt.
TEST(StateRecord, TruncatedFileIsCorruptOrEmpty) {
  StateBytes b{};
  encode_state(sample_record(3), b);
  EXPECT_EQ(decode_state_file({}).error().code, Errc::kNotFound);
  for (std::size_t n = 1; n < kStateRecordBytes; ++n) {
    auto d = decode_state_file(std::span<const std::uint8_t>(b.data(), n));
    ASSERT_FALSE(d) << "n=" << n;
    EXPECT_EQ(d.error().code, Errc::kCorrupt);
  }
  EXPECT_TRUE(decode_state_file(b));
}

// The persister sizes a new file with zeros; a daemon stopped before its first record leaves it
// blank: no record yet (a fresh start `no-record`), not `corrupt`. One nonzero byte is damage.
TEST(StateRecord, BlankFileIsNoRecordYet) {
  std::array<std::uint8_t, kStateFileBytes> file{};
  auto d = decode_state_file(file);
  ASSERT_FALSE(d);
  EXPECT_EQ(d.error().code, Errc::kNotFound);
  EXPECT_NE(d.error().message.find("blank"), std::string::npos);
  file[300] = 1;
  EXPECT_EQ(decode_state_file(file).error().code, Errc::kCorrupt);
}

TEST(StateRecord, CorruptValuesAreRejected) {
  StateBytes b{};
  encode_state(sample_record(3), b);
  for (std::size_t i = 0; i < kStateRecordBytes; ++i) {
    StateBytes c = b;
    c[i] ^= 0x10;  // one flipped bit anywhere: CRC-32 detects every single-bit error
    EXPECT_FALSE(decode_state(c)) << "byte " << i;
  }
  StateRecord bad = sample_record(3);
  bad.pose.x = std::numeric_limits<double>::quiet_NaN();
  encode_state(bad, b);
  EXPECT_NE(decode_state(b).error().message.find("non-finite"), std::string::npos);
  bad = sample_record(3);
  bad.counter_bits = 8;
  encode_state(bad, b);
  EXPECT_NE(decode_state(b).error().message.find("counter width"), std::string::npos);
  // The gyro part: values the fusion never holds are damage, with a valid CRC or not.
  bad = sample_record(3);
  bad.gyro.bias = std::numeric_limits<double>::infinity();
  encode_state(bad, b);
  EXPECT_NE(decode_state(b).error().message.find("non-finite gyro bias"), std::string::npos);
  bad = sample_record(3);
  bad.gyro.bias_time = -1.0;
  encode_state(bad, b);
  EXPECT_NE(decode_state(b).error().message.find("averaging time"), std::string::npos);
  bad = sample_record(3);
  bad.gyro.scale = 0.0;
  encode_state(bad, b);
  EXPECT_NE(decode_state(b).error().message.find("gyro scale"), std::string::npos);
  // No loop writes these: a stamp before its clock's zero, kinematics that are none.
  bad = sample_record(3);
  bad.stamp = -1;
  encode_state(bad, b);
  EXPECT_NE(decode_state(b).error().message.find("negative sample time"), std::string::npos);
  bad = sample_record(3);
  bad.wheelbase = 0.0;
  encode_state(bad, b);
  EXPECT_NE(decode_state(b).error().message.find("not positive"), std::string::npos);
  bad = sample_record(3);
  bad.metres_per_count_right = -kMpc;
  encode_state(bad, b);
  EXPECT_NE(decode_state(b).error().message.find("not positive"), std::string::npos);
}

TEST(ResumeDecision, ResumesAcrossTheWrapWithTheGapsCounts) {
  const StateRecord r = sample_record(9);
  // Left: 65530 -> 20 on a 16-bit counter is +26 counts across the wrap (65536 - 65530 + 20);
  // right: -12 -> 88 is +100. Gap 0.5 s: at most 3 m/s * 0.5 s / 1 mm + 1 = 1501 counts.
  const auto d = decide_resume(r, matching_context(r), reading(r, 20, 88, 0.5));
  EXPECT_EQ(d.reason, ResumeReason::kResumed);
  EXPECT_EQ(d.dl, 26);
  EXPECT_EQ(d.dr, 100);
  EXPECT_EQ(d.gap, 500'000'000);
  EXPECT_EQ(resume_reason_name(d.reason), "resumed");
}

// Issue 39: the record holds the counters' own values and a backend reports the counts of the
// jumps it rejected (left/right_rejected); the decision compares counter with counter, so a
// rejected jump is neither motion during the gap nor a counter jump.
TEST(ResumeDecision, RejectedJumpsAreNotMotionDuringTheGap) {
  const StateRecord r = sample_record(9);  // counters 65530 (left) and -12 (right), 16 bits
  // The restarted backend rejected a jump of +700 counts on the right before its first
  // reading: it reports 88 - 700 = -612 and right_rejected 700; the counter holds 88, i.e.
  // +100 since the record (as in ResumesAcrossTheWrapWithTheGapsCounts).
  EncoderSample s = reading(r, 20, -612, 0.5);
  s.right_rejected = 700;
  const auto d = decide_resume(r, matching_context(r), s);
  EXPECT_EQ(d.reason, ResumeReason::kResumed);
  EXPECT_EQ(d.dl, 26);
  EXPECT_EQ(d.dr, 100);
  // Left rejected -30000 on a 16-bit counter (wrap rule): reported 20 + 30000 = 30020, counter
  // 30020 - 30000 = 20: still +26 across the wrap.
  s.left = 30020;
  s.left_rejected = -30000;
  EXPECT_EQ(decide_resume(r, matching_context(r), s).dl, 26);
  // Without the rejected counts (the reading before issue 39) the right wheel would have moved
  // -612 - (-12) = -600 counts, under the 1501 bound: a resume with motion that never happened.
  s.right_rejected = 0;
  EXPECT_EQ(decide_resume(r, matching_context(r), s).dr, -600);
}

// The gyro's calibration goes only to the gyro it was learnt on (same nonzero id), in the same
// boot and clock and within max_age; whether the pose resumes is another matter (the bias is
// the chip's, not the encoders').
TEST(ResumeDecision, GyroCalibrationGoesOnlyToTheSameGyro) {
  StateRecord r = sample_record(9);
  const EncoderSample ok = reading(r, 20, 88, 0.5);
  ResumeContext c = matching_context(r);
  EXPECT_TRUE(decide_resume(r, c, ok).gyro_matches);
  c.gyro_id = 0x12345679;  // another gyro (another device, axis, sign, ...)
  auto d = decide_resume(r, c, ok);
  EXPECT_TRUE(d.resumed());  // the pose still resumes
  EXPECT_FALSE(d.gyro_matches);
  c.gyro_id = 0;  // no gyro now
  EXPECT_FALSE(decide_resume(r, c, ok).gyro_matches);
  r.gyro_id = 0;  // neither then nor now: nothing to restore
  EXPECT_FALSE(decide_resume(r, c, ok).gyro_matches);
  // The pose starts fresh, the same gyro's calibration still goes: GPIO quadrature (counts
  // lost while down), another calibration, a counter gone backwards.
  r = sample_record(9);
  auto matches_when = [&](auto&& change_ctx, EncoderSample s, ResumeReason why) {
    ResumeContext x = matching_context(r);
    change_ctx(x);
    const ResumeDecision e = decide_resume(r, x, s);
    EXPECT_EQ(e.reason, why);
    return e.gyro_matches;
  };
  EXPECT_TRUE(matches_when([](ResumeContext& x) { x.backend_continuous = false; }, ok,
                           ResumeReason::kNotContinuous));
  EXPECT_TRUE(matches_when([](ResumeContext& x) { x.calibration_sequence = 6; }, ok,
                           ResumeReason::kOtherCalibration));
  EXPECT_TRUE(
      matches_when([](ResumeContext&) {}, reading(r, 20, -1600, 0.5), ResumeReason::kCounterJump));
  // Not from another boot or clock, nor older than max_age: the chip may have cooled, been
  // power-cycled or be another one.
  EXPECT_FALSE(
      matches_when([](ResumeContext& x) { x.boot_id[0] ^= 1; }, ok, ResumeReason::kOtherBoot));
  EXPECT_FALSE(
      matches_when([](ResumeContext& x) { x.clock_epoch = 1; }, ok, ResumeReason::kOtherClock));
  EXPECT_FALSE(
      matches_when([](ResumeContext& x) { x.max_age = 999'000'000; }, ok, ResumeReason::kStale));
  EXPECT_FALSE(decide_resume(r, matching_context(r), ok).gyro_restored);  // the loop's to set
}

TEST(ResumeDecision, EveryFreshStartReason) {
  const StateRecord r = sample_record(9);
  const EncoderSample ok = reading(r, 20, 88, 0.5);
  auto reason = [&](auto&& change_ctx, EncoderSample s) {
    ResumeContext c = matching_context(r);
    change_ctx(c);
    return decide_resume(r, c, s).reason;
  };
  auto none = [](ResumeContext&) {};
  EXPECT_EQ(reason([](ResumeContext& c) { c.boot_id[0] ^= 1; }, ok), ResumeReason::kOtherBoot);
  EXPECT_EQ(reason([](ResumeContext& c) { c.clock_epoch = 1; }, ok), ResumeReason::kOtherClock);
  // Age 1 s against max_age 0.999 s: stale; a record from the future (now before its stamp).
  EXPECT_EQ(reason([](ResumeContext& c) { c.max_age = 999'000'000; }, ok), ResumeReason::kStale);
  EXPECT_EQ(reason([&](ResumeContext& c) { c.now = r.stamp - 1; }, ok), ResumeReason::kStale);
  EXPECT_EQ(reason([](ResumeContext& c) { c.backend = 2; }, ok), ResumeReason::kOtherBackend);
  EXPECT_EQ(reason([](ResumeContext& c) { c.counter_bits = 32; }, ok), ResumeReason::kOtherBackend);
  // GPIO quadrature: its counts are lost while the daemon is down, never resumed.
  EXPECT_EQ(reason([](ResumeContext& c) { c.backend_continuous = false; }, ok),
            ResumeReason::kNotContinuous);
  EXPECT_EQ(reason([](ResumeContext& c) { c.wheelbase = 0.5000001; }, ok),
            ResumeReason::kOtherKinematics);
  EXPECT_EQ(reason([](ResumeContext& c) { c.metres_per_count_right = 0.00101; }, ok),
            ResumeReason::kOtherKinematics);
  EXPECT_EQ(reason([](ResumeContext& c) { c.calibration_sequence = 6; }, ok),
            ResumeReason::kOtherCalibration);
  EncoderSample stale = ok;
  stale.flags = kEncoderStaleLeft;
  EXPECT_EQ(reason(none, stale), ResumeReason::kEncoderNotReady);
  stale.flags = kEncoderReadError;
  EXPECT_EQ(reason(none, stale), ResumeReason::kEncoderNotReady);
  // Right counter gone backwards: -12 -> -1600 is -1588 counts in 0.5 s, more than the 1501 a
  // wheel at 3 m/s can make (a controller that restarted counting, or a wrong counter).
  EXPECT_EQ(reason(none, reading(r, 20, -1600, 0.5)), ResumeReason::kCounterJump);
  // Forwards beyond the bound too: +1502 counts.
  EXPECT_EQ(reason(none, reading(r, 20, -12 + 1502, 0.5)), ResumeReason::kCounterJump);
  // A gap of 11 s (max_age raised to 20 s): 3 m/s * 11 s / 1 mm + 1 = 33001 counts >= 32768,
  // half a 16-bit counter's range: the wrap rule cannot tell the direction any more.
  EXPECT_EQ(reason(
                [](ResumeContext& c) {
                  c.max_age = 20'000'000'000;
                  c.now += 10'000'000'000;
                },
                reading(r, 20, 88, 11.0)),
            ResumeReason::kStale);
  // A serial controller that says it rebooted (diffodom booted flag): fresh, even though its
  // counts lie within the gap's bound (they restarted from 0 near the record's counts).
  EncoderSample rebooted = ok;
  rebooted.flags = kEncoderControllerReset;
  EXPECT_EQ(reason(none, rebooted), ResumeReason::kControllerReset);
  EXPECT_EQ(resume_reason_name(ResumeReason::kCounterJump), "counter-jump");
  EXPECT_EQ(resume_reason_name(ResumeReason::kControllerReset), "controller-reset");
  EXPECT_EQ(std::size(kResumeReasonNames),
            static_cast<std::size_t>(ResumeReason::kControllerReset) + 1);
}

}  // namespace
}  // namespace odo::loop
