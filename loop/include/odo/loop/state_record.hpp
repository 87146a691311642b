// The loop's state record (issue 17): what a restarted odometryd needs to continue from the
// counters without a jump, its byte-exact CRC-protected encoding, and the resume decision.
// Pure code: time, boot id and the current encoder sample are arguments; no I/O.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

#include "odo/hal/choice.hpp"
#include "odo/hal/encoder.hpp"
#include "odo/hal/result.hpp"
#include "odo/hal/time.hpp"
#include "odo/odometry/error_model.hpp"
#include "odo/odometry/gyrodometry.hpp"
#include "odo/odometry/pose.hpp"

namespace odo::loop {

using BootId = std::array<std::uint8_t, 16>;  // /proc/sys/kernel/random/boot_id as 16 bytes

// StateRecord: the loop's state after one tick.
struct StateRecord {
  std::uint64_t sequence = 0;     // grows by one per record written (never 0 when valid)
  BootId boot_id{};               // boot the record was made in
  std::uint64_t clock_epoch = 0;  // which clock `stamp` is on (firmware: 0 = CLOCK_MONOTONIC)
  TimeNs stamp = 0;               // sample time of the counts [ns]
  std::int64_t left = 0;          // raw counter readings (counter_bits wide, sign-extended)
  std::int64_t right = 0;
  std::uint8_t counter_bits = 0;  // 16..64
  std::uint8_t backend = 0;       // the firmware's backend id (EncoderKind)
  std::uint8_t calibration_state = 0;
  std::uint64_t calibration_sequence = 0;  // of the calibration record in use (0: none)
  double metres_per_count_left = 0.0;      // kinematics in use [m/count]
  double metres_per_count_right = 0.0;     // [m/count]
  double wheelbase = 0.0;                  // [m]
  Pose2 pose;                              // cumulative heading
  Cov3 cov{};                              // (x, y, theta), row-major
  double distance = 0.0;                   // path length [m]
  // Version 2: the gyro fusion's calibration, and which gyro it belongs to (the firmware's
  // gyro id; 0: no gyro). A version-1 record reads as gyro_id 0.
  std::uint32_t gyro_id = 0;
  GyroCalibration gyro;
};

// Layout (little endian): 0 magic "ODST" u32, 4 version u16, 6 length u16, 8 sequence u64,
// 16 boot id [16], 32 clock_epoch u64, 40 stamp i64, 48 left i64, 56 right i64, 64 counter_bits
// u8, 65 backend u8, 66 calibration_state u8, 67 reserved u8 (0), 68 reserved u32 (0),
// 72 calibration_sequence u64, 80 m/count left, 88 m/count right, 96 wheelbase, 104 x, 112 y,
// 120 theta, 128 cov[9], 200 distance (f64); version 2 adds 208 gyro_id u32, 212 gyro flags u8
// (bit 0: scale valid), 213 reserved u8 u16 (0), 216 gyro bias, 224 its averaging time, 232
// gyro scale (f64); then the CRC-32 of all bytes before it: 240 (version 2, length 244), or 208
// (version 1, length 212, still read: a record written before an update resumes).
inline constexpr std::uint32_t kStateMagic = 0x5453444FU;  // bytes 'O' 'D' 'S' 'T'
inline constexpr std::uint16_t kStateVersion = 2;
inline constexpr std::size_t kStateRecordBytes = 244;
inline constexpr std::size_t kStateRecordBytesV1 = 212;
// A state file holds two slots (A at 0, B at kStateSlotBytes): record n goes to slot n % 2, so a
// write torn at any byte leaves the other slot's record intact.
inline constexpr std::size_t kStateSlotBytes = 256;
inline constexpr std::size_t kStateFileBytes = 2 * kStateSlotBytes;

using StateBytes = std::array<std::uint8_t, kStateRecordBytes>;

// encode_state: the bytes of `r` (no allocation; callable on any thread).
void encode_state(const StateRecord& r, StateBytes& out) noexcept;

// decode_state: the record in `bytes` (version 2, or 1 without the gyro part); Errc::kCorrupt
// naming the reason (length, magic, version, CRC, counter width, sequence 0, non-finite value,
// negative sample time, kinematics not positive, gyro scale or averaging time out of range)
// when it is not a valid record.
Result<StateRecord> decode_state(std::span<const std::uint8_t> bytes);

// decode_state_file: the newest valid record of a two-slot state file (kStateFileBytes, or
// shorter: a slot cut short counts as torn); Errc::kCorrupt when neither slot holds one,
// Errc::kNotFound when the file is empty or blank (all zeros: created, never written).
Result<StateRecord> decode_state_file(std::span<const std::uint8_t> bytes);

// Why the loop resumed or started fresh; spelt once in kResumeReasonNames.
enum class ResumeReason : std::uint8_t {
  kResumed,           // continued from the record
  kDisabled,          // [resume] enabled = false
  kNoRecord,          // no state file
  kCorrupt,           // torn or corrupt record
  kOtherBoot,         // made before a reboot
  kOtherClock,        // its sample time is on another clock (e.g. virtual time)
  kStale,             // older than max_age (or from the future)
  kOtherKinematics,   // made with other kinematics
  kOtherCalibration,  // made with another calibration record
  kOtherBackend,      // made with another encoder backend or counter width
  kNotContinuous,     // this backend's counts are lost while nobody listens (GPIO)
  kEncoderNotReady,   // the first reading is stale or failed
  kCounterJump,       // a counter went backwards (or forwards) beyond the wrap rule
  kControllerReset,   // the counting controller says it rebooted since (serial: booted flag)
};

inline constexpr Choice<ResumeReason> kResumeReasonNames[] = {
    {ResumeReason::kResumed, "resumed"},
    {ResumeReason::kDisabled, "disabled"},
    {ResumeReason::kNoRecord, "no-record"},
    {ResumeReason::kCorrupt, "corrupt"},
    {ResumeReason::kOtherBoot, "other-boot"},
    {ResumeReason::kOtherClock, "other-clock"},
    {ResumeReason::kStale, "stale"},
    {ResumeReason::kOtherKinematics, "other-kinematics"},
    {ResumeReason::kOtherCalibration, "other-calibration"},
    {ResumeReason::kOtherBackend, "other-backend"},
    {ResumeReason::kNotContinuous, "not-continuous"},
    {ResumeReason::kEncoderNotReady, "encoder-not-ready"},
    {ResumeReason::kCounterJump, "counter-jump"},
    {ResumeReason::kControllerReset, "controller-reset"}};

// resume_reason_name: how logs, --json and odomctl spell `r`.
std::string_view resume_reason_name(ResumeReason r) noexcept;

// What the restarted loop is: compared with the record field by field.
struct ResumeContext {
  BootId boot_id{};
  std::uint64_t clock_epoch = 0;
  TimeNs now = 0;      // [ns] on the record's clock
  TimeNs max_age = 0;  // [ns] oldest record resumed from
  std::uint8_t backend = 0;
  bool backend_continuous = false;  // counts keep counting while the daemon is down
  int counter_bits = 32;
  std::uint64_t calibration_sequence = 0;
  double metres_per_count_left = 0.0;
  double metres_per_count_right = 0.0;
  double wheelbase = 0.0;
  double max_wheel_speed = 3.0;  // [m/s] physical maximum: bounds the travel during the gap
  std::uint32_t gyro_id = 0;     // the firmware's id of the gyro now configured (0: none)
};

// ResumeDecision: the outcome; on kResumed the gap's count deltas to integrate as one step.
struct ResumeDecision {
  ResumeReason reason = ResumeReason::kNoRecord;
  TimeNs gap = 0;       // sample time of `current` minus the record's [ns]
  std::int64_t dl = 0;  // counts of each wheel during the gap (wrap rule)
  std::int64_t dr = 0;
  // The most counts each wheel could make in the gap (set from the plausibility check on;
  // with dl/dr they say which wheel jumped and how far on kCounterJump) [counts].
  double max_dl = 0.0;
  double max_dr = 0.0;
  Pose2 pose;  // on kResumed: the pose the loop starts from (the record's plus the gap's step)
  // The record's gyro calibration belongs to this loop's gyro (same nonzero id, same boot and
  // clock, within max_age): set whether or not the pose resumes (the bias is the chip's, not
  // the encoders').
  bool gyro_matches = false;
  bool gyro_restored = false;  // the loop restored it and its bias is valid
  GyroCalibration gyro;        // on gyro_restored: the fusion's calibration after the restore
  bool resumed() const noexcept { return reason == ResumeReason::kResumed; }
};

// decide_resume: whether `rec` may be continued from, given the loop's context and the first
// reading `current` after the restart. Checks in order: boot, clock, age, backend, continuity,
// kinematics, calibration, reading health, counter plausibility (each wheel's travel during the
// gap at most max_wheel_speed * gap plus one count, and that bound below half the counter range).
// Also, for any reason after the age check, whether the record's gyro calibration is this
// gyro's (gyro_matches).
ResumeDecision decide_resume(const StateRecord& rec, const ResumeContext& ctx,
                             const EncoderSample& current) noexcept;

}  // namespace odo::loop
