#include "odo/calibration/record.hpp"

#include <ctime>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <string>

#include "odo/hal/bytes.hpp"
#include "odo/hal/crc.hpp"
#include "odo/hal/format.hpp"
#include "odo/odometry/kinematics.hpp"

namespace odo::calib {
namespace {

// Flag bits: which optional fields are present.
constexpr std::uint32_t kFlagCleared = 1U << 0;
constexpr std::uint32_t kFlagWheelbase = 1U << 1;
constexpr std::uint32_t kFlagDiameter = 1U << 2;
constexpr std::uint32_t kFlagScaling = 1U << 3;
constexpr std::uint32_t kFlagEmaxBefore = 1U << 4;
constexpr std::uint32_t kFlagEmaxAfter = 1U << 5;
constexpr std::uint32_t kFlagFit = 1U << 6;  // version 2: the fit fields at 104 .. 143
constexpr std::uint32_t kFlagIcr = 1U << 7;  // version 3: x_icr, sigma_x_icr at 144 .. 159

template <class T>
void put(std::vector<std::uint8_t>& b, std::size_t off, T v) {
  put_le(std::span<std::uint8_t>(b), off, v);
}

template <class T>
T get(std::span<const std::uint8_t> b, std::size_t off) {
  return get_le<T>(b, off);
}

Error corrupt(const std::string& why) {
  return make_error(Errc::kCorrupt, why);
}

Status check_range(const char* field, double v, double lo, double hi, const char* unit) {
  if (std::isfinite(v) && v >= lo && v <= hi) return Ok{};
  return range_error({field, v, lo, hi, unit, false});
}

Status check_count(const char* field, std::uint32_t v) {
  if (v <= RecordLimits::kRunsMax) return Ok{};
  return range_error(integer_range(field, v, 0, RecordLimits::kRunsMax));
}

Status validate_fit(const FixFitProvenance& f) {
  using L = RecordLimits;
  for (auto [field, v] : {std::pair{"fit residual", f.residual},
                          {"sigma_c_l", f.sigma_c_l},
                          {"sigma_c_r", f.sigma_c_r}})
    if (auto s = check_range(field, v, 0.0, 1e9, ""); !s) return s;
  if (auto s = check_range("sigma_wheelbase", f.sigma_wheelbase, 0.0, L::kWheelbaseMax, "m"); !s)
    return s;
  if (auto s = check_count("fixes_used", f.fixes_used); !s) return s;
  return check_count("fixes_rejected", f.fixes_rejected);
}

}  // namespace

Result<std::vector<std::uint8_t>> encode_record(const CalibrationRecord& r) {
  if (r.method.size() >= kMethodBytes)
    return make_error(Errc::kInvalidArgument, "method \"" + r.method + "\" is longer than " +
                                                  std::to_string(kMethodBytes - 1) + " bytes");
  const double values[] = {r.c_l,
                           r.c_r,
                           r.wheelbase.value_or(0.0),
                           r.wheel_diameter.value_or(0.0),
                           r.e_s.value_or(0.0),
                           r.e_max_before.value_or(0.0),
                           r.e_max_after.value_or(0.0)};
  for (double v : values)
    if (!std::isfinite(v)) return make_error(Errc::kInvalidArgument, "a value is not finite");
  std::uint32_t flags = 0;
  if (r.cleared) flags |= kFlagCleared;
  if (r.wheelbase) flags |= kFlagWheelbase;
  if (r.wheel_diameter) flags |= kFlagDiameter;
  if (r.e_s) flags |= kFlagScaling;
  if (r.e_max_before) flags |= kFlagEmaxBefore;
  if (r.e_max_after) flags |= kFlagEmaxAfter;
  if (r.fit) flags |= kFlagFit;
  if (r.x_icr) flags |= kFlagIcr;

  // The oldest version that holds the record's fields: older readers keep reading it.
  const std::uint16_t version = r.x_icr ? kRecordVersionIcr
                                : r.fit ? kRecordVersionFit
                                        : kRecordVersion;
  const std::size_t len = r.x_icr ? kRecordV3Bytes : r.fit ? kRecordV2Bytes : kRecordV1Bytes;
  std::vector<std::uint8_t> b(len, 0);
  put<std::uint32_t>(b, 0, kRecordMagic);
  put<std::uint16_t>(b, 4, version);
  put<std::uint16_t>(b, 6, static_cast<std::uint16_t>(len));
  put<std::uint64_t>(b, 8, r.sequence);
  put<std::uint32_t>(b, 16, flags);
  put<std::uint32_t>(b, 20, r.runs);
  put<std::int64_t>(b, 24, r.time);
  for (std::size_t i = 0; i < 7; ++i) put<double>(b, 32 + 8 * i, values[i]);
  std::memcpy(b.data() + 88, r.method.data(), r.method.size());
  if (r.fit) {
    const FixFitProvenance& f = *r.fit;
    const double fv[] = {f.residual, f.sigma_c_l, f.sigma_c_r, f.sigma_wheelbase};
    for (double v : fv)
      if (!std::isfinite(v)) return make_error(Errc::kInvalidArgument, "a fit value is not finite");
    put<std::uint32_t>(b, 104, f.fixes_used);
    put<std::uint32_t>(b, 108, f.fixes_rejected);
    for (std::size_t i = 0; i < 4; ++i) put<double>(b, 112 + 8 * i, fv[i]);
  }
  if (r.x_icr) {
    const double sx = r.sigma_x_icr;
    if (!std::isfinite(*r.x_icr) || !std::isfinite(sx))
      return make_error(Errc::kInvalidArgument, "x_icr is not finite");
    put<double>(b, 144, *r.x_icr);
    put<double>(b, 152, sx);
  }
  put<std::uint32_t>(b, len - 4, crc32(std::span<const std::uint8_t>(b.data(), len - 4)));
  return b;
}

namespace {

// too_old: a flag whose fields need version >= need_v and length >= need_len set in a record
// of `version` and `length`: corrupt, named (shared by the fit and the x_icr fields).
Error too_old(const char* what, std::uint16_t version, std::uint16_t length, int need_v,
              std::size_t need_len) {
  return corrupt(std::string(what) + " flagged in a record of version " + std::to_string(version) +
                 " and length " + std::to_string(length) + " (needs >= " + std::to_string(need_v) +
                 " and >= " + std::to_string(need_len) + ")");
}

// decode_fit: the fit provenance of a record whose flags say it has one (version >= 2).
Result<FixFitProvenance> decode_fit(std::span<const std::uint8_t> bytes, std::uint16_t version,
                                    std::uint16_t length) {
  if (version < kRecordVersionFit || length < kRecordV2Bytes)
    return too_old("fit fields", version, length, kRecordVersionFit, kRecordV2Bytes);
  FixFitProvenance f;
  f.fixes_used = get<std::uint32_t>(bytes, 104);
  f.fixes_rejected = get<std::uint32_t>(bytes, 108);
  double* fv[] = {&f.residual, &f.sigma_c_l, &f.sigma_c_r, &f.sigma_wheelbase};
  for (std::size_t i = 0; i < 4; ++i) {
    *fv[i] = get<double>(bytes, 112 + 8 * i);
    if (!std::isfinite(*fv[i])) return corrupt("a stored fit value is not finite");
  }
  return f;
}

// decode_icr: x_icr and its sigma of a record whose flags say it has them (version >= 3).
Status decode_icr(std::span<const std::uint8_t> bytes, std::uint16_t version, std::uint16_t length,
                  CalibrationRecord& r) {
  if (version < kRecordVersionIcr || length < kRecordV3Bytes)
    return too_old("x_icr", version, length, kRecordVersionIcr, kRecordV3Bytes);
  const double x = get<double>(bytes, 144), sx = get<double>(bytes, 152);
  if (!std::isfinite(x) || !std::isfinite(sx)) return corrupt("a stored x_icr is not finite");
  r.x_icr = x;
  r.sigma_x_icr = sx;
  return Ok{};
}

}  // namespace

Result<CalibrationRecord> decode_record(std::span<const std::uint8_t> bytes) {
  if (bytes.size() < kRecordV1Bytes) return corrupt("shorter than a version-1 record");
  const auto magic = get<std::uint32_t>(bytes, 0);
  if (magic != kRecordMagic) {
    return corrupt("no record magic (found 0x" + hex_text(magic) + ")");
  }
  const auto version = get<std::uint16_t>(bytes, 4);
  const auto length = get<std::uint16_t>(bytes, 6);
  if (version < 1) return corrupt("format version 0 is not valid");
  if (length < kRecordV1Bytes || length > bytes.size()) {
    Error e = range_error(
        integer_range("length", length, kRecordV1Bytes, static_cast<std::int64_t>(bytes.size())));
    e.code = Errc::kCorrupt;  // a stored length: the record is damaged, not the caller's input
    return e;
  }
  const auto stored = get<std::uint32_t>(bytes, length - 4U);
  const auto computed = crc32(bytes.first(length - 4U));
  if (stored != computed) {
    return corrupt("CRC mismatch (stored 0x" + hex_text(stored) + ", computed 0x" +
                   hex_text(computed) + ")");
  }
  CalibrationRecord r;
  r.sequence = get<std::uint64_t>(bytes, 8);
  const auto flags = get<std::uint32_t>(bytes, 16);
  r.runs = get<std::uint32_t>(bytes, 20);
  r.time = get<std::int64_t>(bytes, 24);
  double v[7];
  for (std::size_t i = 0; i < 7; ++i) {
    v[i] = get<double>(bytes, 32 + 8 * i);
    if (!std::isfinite(v[i])) return corrupt("a stored value is not finite");
  }
  r.cleared = (flags & kFlagCleared) != 0;
  r.c_l = v[0];
  r.c_r = v[1];
  if (flags & kFlagWheelbase) r.wheelbase = v[2];
  if (flags & kFlagDiameter) r.wheel_diameter = v[3];
  if (flags & kFlagScaling) r.e_s = v[4];
  if (flags & kFlagEmaxBefore) r.e_max_before = v[5];
  if (flags & kFlagEmaxAfter) r.e_max_after = v[6];
  const auto* m = reinterpret_cast<const char*>(bytes.data() + 88);
  // std::find, not POSIX strnlen (not declared by a bare-metal C library in strict C++20).
  r.method.assign(m, std::find(m, m + (kMethodBytes - 1), '\0'));
  if (flags & kFlagFit) {
    auto f = decode_fit(bytes, version, length);
    if (!f) return std::move(f).error();
    r.fit = *f;
  }
  if (flags & kFlagIcr)
    if (auto s = decode_icr(bytes, version, length, r); !s) return std::move(s).error();
  return r;
}

Result<KinematicParams> apply_record(const KinematicParams& nominal, const CalibrationRecord& r) {
  if (auto range = validate_record(r); !range) return std::move(range).error();
  KinematicParams p = nominal;
  p.c_l = r.c_l;
  p.c_r = r.c_r;
  if (r.wheelbase) p.wheelbase = *r.wheelbase;
  if (r.wheel_diameter) p.wheel_diameter = *r.wheel_diameter;
  if (r.x_icr) p.x_icr = *r.x_icr;
  if (auto ok = Kinematics::create(p); !ok) return std::move(ok).error();
  return p;
}

Status validate_record(const CalibrationRecord& r) {
  using L = RecordLimits;
  if (auto s = check_range("c_l", r.c_l, L::kFactorMin, L::kFactorMax, ""); !s) return s;
  if (auto s = check_range("c_r", r.c_r, L::kFactorMin, L::kFactorMax, ""); !s) return s;
  if (r.wheelbase)
    if (auto s = check_range("wheelbase", *r.wheelbase, L::kWheelbaseMin, L::kWheelbaseMax, "m");
        !s)
      return s;
  if (r.wheel_diameter)
    if (auto s =
            check_range("wheel_diameter", *r.wheel_diameter, L::kDiameterMin, L::kDiameterMax, "m");
        !s)
      return s;
  if (r.e_s)
    if (auto s = check_range("e_s", *r.e_s, L::kScalingMin, L::kScalingMax, ""); !s) return s;
  if (r.e_max_before)
    if (auto s = check_range("e_max_syst_before", *r.e_max_before, L::kEmaxMin, L::kEmaxMax, "m");
        !s)
      return s;
  if (r.e_max_after)
    if (auto s = check_range("e_max_syst_after", *r.e_max_after, L::kEmaxMin, L::kEmaxMax, "m"); !s)
      return s;
  constexpr Limit kX = KinematicLimits::kXIcr;
  if (r.x_icr)
    if (auto s = check_range("x_icr", *r.x_icr, kX.lo, kX.hi, "m"); !s) return s;
  if (auto s = check_range("sigma_x_icr", r.sigma_x_icr, 0.0, kX.hi, "m"); !s) return s;
  if (!r.x_icr && r.sigma_x_icr != 0.0)
    return make_error(Errc::kInvalidArgument, "sigma_x_icr is given without x_icr");
  if (auto s = check_count("runs", r.runs); !s) return s;
  if (r.time < 0)
    return make_error(Errc::kInvalidArgument,
                      "time = " + std::to_string(r.time) + " is before 1970 (allowed: >= 0 s)");
  if (r.method.size() >= kMethodBytes)
    return make_error(Errc::kInvalidArgument, "method \"" + r.method + "\" is longer than " +
                                                  std::to_string(kMethodBytes - 1) + " bytes");
  if (r.fit) return validate_fit(*r.fit);
  return Ok{};
}

std::string utc_text(std::int64_t t) {
  const std::time_t tt = static_cast<std::time_t>(t);
  std::tm tm{};
  gmtime_r(&tt, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

}  // namespace odo::calib
