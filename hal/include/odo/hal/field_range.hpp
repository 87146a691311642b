// FieldRange: a value outside its allowed range, as data (field, value, limits, unit), and the
// one function that words it. Validators return it (Error::range carries it, range_error makes
// that Error); callers that present the field under another name (a command-line option, a
// config key) rename the field instead of editing text. Limit: a range written once in the
// module that owns the value and checked against by every reader of it.
#pragma once

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>
#include <utility>

namespace odo {

// Limit: the closed range [lo, hi] of one value (finite limits).
struct Limit {
  double lo = 0.0;
  double hi = 0.0;
  // contains: lo <= v <= hi (false for NaN and, the limits being finite, for +-inf).
  constexpr bool contains(double v) const noexcept { return v >= lo && v <= hi; }
};

struct FieldRange {
  FieldRange() = default;
  // The common case: a real value outside [lo, hi]; the rest of the fields keep their defaults.
  FieldRange(std::string f, double v, double l, double h, std::string u = {}, bool u_on_v = true)
      : field(std::move(f)), value(v), lo(l), hi(h), unit(std::move(u)), unit_on_value(u_on_v) {}

  std::string field;  // e.g. "k_left", "loop.rate_hz", "--runs"
  double value = 0.0;
  double lo = 0.0;
  double hi = 0.0;
  std::string unit;           // "" when dimensionless
  bool unit_on_value = true;  // "x = 3 m is outside ... m"; false: the unit follows the range only
  bool integer = false;       // whole numbers: ivalue, ilo, ihi are printed (exact beyond 2^53)
  bool lo_open = false;       // "(lo, ...": lo itself is outside too
  bool hi_open = false;       // "..., hi)"
  std::string note;           // after the range, e.g. "(check the units: metres)"
  std::int64_t ivalue = 0, ilo = 0, ihi = 0;
};

// integer_range: a whole-number field outside [lo, hi] (no unit).
inline FieldRange integer_range(std::string field, std::int64_t v, std::int64_t lo,
                                std::int64_t hi) {
  FieldRange r{std::move(field), static_cast<double>(v), static_cast<double>(lo),
               static_cast<double>(hi)};
  r.integer = true;
  r.ivalue = v;
  r.ilo = lo;
  r.ihi = hi;
  return r;
}

// positive_range: a value that must be positive and finite, "(0, inf) unit".
inline FieldRange positive_range(std::string field, double v, std::string unit) {
  FieldRange r{std::move(field), v,    0.0, std::numeric_limits<double>::infinity(),
               std::move(unit),  false};
  r.lo_open = r.hi_open = true;
  return r;
}

// RangeRow: one number's key, allowed range and unit: the one shape of a row of a range table
// (written once beside the code that owns the value; readers and checkers derive from it).
struct RangeRow {
  const char* key = "";   // the user-facing name, e.g. "window" (a config key under its section)
  double lo = 0.0;        // lower limit
  double hi = 0.0;        // upper limit
  const char* unit = "";  // "" when dimensionless
  bool lo_open = false;   // lo itself is outside ("(lo, hi]")
  // contains: v finite and within the range (NaN and +-inf are outside).
  constexpr bool contains(double v) const noexcept {
    return (lo_open ? v > lo : v >= lo) && v <= hi && v - v == 0.0;
  }
  // range: the FieldRange that says `v` is outside this row, under the field name `field`.
  FieldRange range(std::string field, double v) const {
    FieldRange r{std::move(field), v, lo, hi, unit};
    r.lo_open = lo_open;
    return r;
  }
};

// range_text: "= <value>[ unit] is outside the allowed range [<lo>, <hi>][ unit][ note]"
// (numbers as %g prints them, with the digits needed to give the value back).
inline std::string range_text(const FieldRange& r) {
  auto num = [&](double v, std::int64_t i) {
    char b[32];
    if (r.integer) {
      std::snprintf(b, sizeof b, "%lld", static_cast<long long>(i));
    } else {
      // %g, with more digits where 6 would not give the value back: 10.00001 must not read as
      // the limit 10 it lies beyond.
      for (int p = 6; p <= 17; ++p) {
        std::snprintf(b, sizeof b, "%.*g", p, v);
        if (std::strtod(b, nullptr) == v || !(v == v)) break;
      }
    }
    return std::string(b);
  };
  const std::string u = r.unit.empty() ? std::string() : " " + r.unit;
  std::string m = "= " + num(r.value, r.ivalue);
  if (r.unit_on_value) m += u;
  m += " is outside the allowed range ";
  m += r.lo_open ? "(" : "[";
  m += num(r.lo, r.ilo) + ", " + num(r.hi, r.ihi);
  m += r.hi_open ? ")" : "]";
  m += u;
  if (!r.note.empty()) m += " " + r.note;
  return m;
}

// range_message: "<field> " + range_text(r).
inline std::string range_message(const FieldRange& r) {
  return r.field + " " + range_text(r);
}

}  // namespace odo
