// The calibration record: what the robot learned about itself (UMBmark factors, effective
// wheelbase, corrected wheel diameter, scaling error) and where it came from, plus its
// byte-exact, CRC-protected, extensible on-medium encoding. Pure code, no I/O.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "odo/hal/result.hpp"

namespace odo {
struct KinematicParams;  // odometry/kinematics.hpp (apply_record's callers include it)
}

namespace odo::calib {

// Provenance of a record fitted from absolute fixes (self-calibration, issue 18): format
// version 2. Records without it are written as version 1, byte for byte as before.
struct FixFitProvenance {
  std::uint32_t fixes_used = 0;      // fixes the fit used
  std::uint32_t fixes_rejected = 0;  // outlier fixes it rejected
  double residual = 0.0;             // held-out mean chi2 per degree of freedom of the values
  double sigma_c_l = 0.0;            // standard deviations of the values
  double sigma_c_r = 0.0;
  double sigma_wheelbase = 0.0;  // [m]

  bool operator==(const FixFitProvenance&) const = default;
};

struct CalibrationRecord {
  std::uint64_t sequence = 0;       // assigned by the store: newer records have larger numbers
  bool cleared = false;             // a reset marker: "no calibration" (written by `calib reset`)
  double c_l = 1.0;                 // UMBmark correction factor, left wheel (Eq. 6.33)
  double c_r = 1.0;                 // UMBmark correction factor, right wheel (Eq. 6.34)
  std::optional<double> wheelbase;  // effective wheelbase b_new [m] (Eq. 6.28)
  std::optional<double> wheel_diameter;  // corrected nominal wheel diameter Dn* [m] (App. B)
  std::optional<double> e_s;             // scaling error E_s = L_calc / L_actual (Eq. B.1)
  std::optional<double> x_icr;  // skid steer: ICR offset [m] (Kinematics::x_icr), version 3
  double sigma_x_icr = 0.0;     // [m] its standard deviation when fitted (0: not fitted)
  // Provenance.
  std::int64_t time = 0;                // when the values were obtained [s since 1970, UTC]
  std::string method;                   // how: "umbmark", "set", "import", ... (<= 15 bytes)
  std::optional<double> e_max_before;   // E_max,syst before the calibration [m] (Eq. 3.4)
  std::optional<double> e_max_after;    // E_max,syst after (measured or predicted) [m]
  std::uint32_t runs = 0;               // number of UMBmark runs (cw + ccw) behind the values
  std::optional<FixFitProvenance> fit;  // self-calibration provenance (method "online", ...)

  bool operator==(const CalibrationRecord&) const = default;
};

// Encoding, version 1 (all little-endian; offsets in bytes):
//   0 magic "ODCL"  4 version u16  6 length u16 (whole record incl. CRC)  8 sequence u64
//  16 flags u32  20 runs u32  24 time i64  32 c_l  40 c_r  48 wheelbase  56 wheel_diameter
//  64 e_s  72 e_max_before  80 e_max_after (f64 IEEE-754)  88 method char[16]
//  length-4: CRC-32 (IEEE 802.3) of bytes [0, length-4).
// Extension rule: a later version appends its fields after byte 104 and raises version and
// length; every reader decodes the version-1 fields of any record with version >= 1 and
// length >= 108 and skips (but CRC-checks) the rest, so no record is ever lost to an upgrade.
//
// Version 2 (records with `fit`, flag bit 6): the version-1 fields, then 104 fixes_used u32
// 108 fixes_rejected u32  112 residual  120 sigma_c_l  128 sigma_c_r  136 sigma_wheelbase (f64),
// CRC at 144, length 148. A record without `fit` is still written as version 1, so media and
// readers of version 1 see no change; a version-1 reader reads a version-2 record's version-1
// fields by the rule above. Flag bit 6 in a record of version < 2 or length < 148 is corrupt.
//
// Version 3 (records with `x_icr`, flag bit 7; issue 38): the version-2 layout (its fit fields
// zero and flag bit 6 clear when the record has no `fit`), then 144 x_icr  152 sigma_x_icr (f64),
// CRC at 160, length 164. Records without x_icr are written as version 1 or 2 as before; a
// reader of version 1 or 2 reads a version-3 record's older fields (and runs without x_icr). Flag
// bit 7 in a record of version < 3 or length < 164 is corrupt.
inline constexpr std::uint32_t kRecordMagic = 0x4C43444FU;  // bytes 'O' 'D' 'C' 'L'
inline constexpr std::uint16_t kRecordVersion = 1;
inline constexpr std::uint16_t kRecordVersionFit = 2;
inline constexpr std::uint16_t kRecordVersionIcr = 3;
inline constexpr std::size_t kRecordV1Bytes = 108;
inline constexpr std::size_t kRecordV2Bytes = 148;
inline constexpr std::size_t kRecordV3Bytes = 164;
inline constexpr std::size_t kMethodBytes = 16;

// encode_record: the bytes of `r`: version 1 (kRecordV1Bytes) without `fit` and `x_icr`,
// version 2 (kRecordV2Bytes) with `fit` only, version 3 (kRecordV3Bytes) with `x_icr`. Fails when
// the method text is longer than 15 bytes or a value is not finite.
Result<std::vector<std::uint8_t>> encode_record(const CalibrationRecord& r);

// decode_record: parses a record at the start of `bytes` (a slot). Errc::kCorrupt with the
// reason (magic, version, length, CRC, non-finite value) when it is not a valid record.
Result<CalibrationRecord> decode_record(std::span<const std::uint8_t> bytes);

// Allowed ranges of the stored values (checked by every writer and by the daemon).
struct RecordLimits {
  static constexpr double kFactorMin = 0.9, kFactorMax = 1.1;          // c_l, c_r
  static constexpr double kWheelbaseMin = 0.01, kWheelbaseMax = 20.0;  // [m]
  static constexpr double kDiameterMin = 0.005, kDiameterMax = 5.0;    // [m]
  static constexpr double kScalingMin = 0.8, kScalingMax = 1.25;       // E_s
  static constexpr double kEmaxMin = 0.0, kEmaxMax = 100.0;            // [m]
  static constexpr std::uint32_t kRunsMax = 1000000;
  // x_icr and sigma_x_icr: KinematicLimits::kXIcr, the kinematics' own range.
};

// validate_record: every value finite and inside RecordLimits; the error names the field and
// the allowed range.
Status validate_record(const CalibrationRecord& r);

// apply_record: the kinematics `nominal` corrected by the record (c_L, c_R, and the wheelbase,
// wheel diameter and x_icr when it holds them). Errors: the record's values out of range, or the
// corrected kinematics invalid (odometryd and the microcontroller firmware both run on nominal
// values then).
Result<KinematicParams> apply_record(const KinematicParams& nominal, const CalibrationRecord& r);

// utc_text: a record time [s since the Unix epoch] as "YYYY-MM-DDTHH:MM:SSZ".
std::string utc_text(std::int64_t t);

}  // namespace odo::calib
