// FieldRange: a value outside its allowed range, as data (field, value, limits, unit), and the
// one function that words it. Validators return it; callers that present the field under
// another name (a command-line option, a config key) rename the field instead of editing text.
#pragma once

#include <cstdint>
#include <sstream>
#include <string>

namespace odo {

struct FieldRange {
  std::string field;  // e.g. "k_left", "loop.rate_hz", "--runs"
  double value = 0.0;
  double lo = 0.0;
  double hi = 0.0;
  std::string unit;           // "" when dimensionless
  bool unit_on_value = true;  // "x = 3 m is outside ... m"; false: the unit follows the range only
  bool integer = false;       // value and limits are whole numbers (printed without exponent)
};

// range_text: "= <value>[ unit] is outside the allowed range [<lo>, <hi>][ unit]".
inline std::string range_text(const FieldRange& r) {
  std::ostringstream m;
  auto num = [&](double v) {
    if (r.integer)
      m << static_cast<long long>(v);
    else
      m << v;
  };
  const std::string u = r.unit.empty() ? std::string() : " " + r.unit;
  m << "= ";
  num(r.value);
  if (r.unit_on_value) m << u;
  m << " is outside the allowed range [";
  num(r.lo);
  m << ", ";
  num(r.hi);
  m << "]" << u;
  return m.str();
}

// range_message: "<field> " + range_text(r).
inline std::string range_message(const FieldRange& r) {
  return r.field + " " + range_text(r);
}

}  // namespace odo
