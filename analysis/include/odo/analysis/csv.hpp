// Small strict CSV reading for the command-line tools: a fixed header, numeric fields, and an
// error that names the line and the field.
#pragma once

#include <cstdint>
#include <istream>
#include <string>
#include <string_view>
#include <vector>

#include "odo/hal/result.hpp"

namespace odo::analysis {

// kMaxReturnError: a return error beyond 1000 m or 1000 rad is a unit mistake, not odometry.
inline constexpr double kMaxReturnError = 1000.0;

// return_error_range: the range of a run's return error field `field` ("ex", ...) in `unit`.
inline FieldRange return_error_range(const std::string& field, double v, const char* unit) {
  return {"field '" + field + "'", v, -kMaxReturnError, kMaxReturnError, unit, false};
}

// CsvReader: reads rows of comma-separated fields; blank lines and lines starting with '#' are
// skipped. Field text is trimmed of spaces and a trailing CR.
class CsvReader {
 public:
  CsvReader(std::istream& in, std::string source) : in_(in), source_(std::move(source)) {}
  // header: reads the first row; every name in `required` must be present, names in `optional`
  // may be; anything else is an error. Returns the column index of each name (or -1).
  Result<std::vector<int>> header(const std::vector<std::string_view>& required,
                                  const std::vector<std::string_view>& optional = {});
  // next: reads the next data row into `fields`; false at end of input.
  bool next(std::vector<std::string>& fields);
  int line() const { return line_; }
  std::size_t columns() const { return n_columns_; }  // columns named in the header
  // error: an Error of kind kParse prefixed with "source:line: ".
  Error error(const std::string& what) const;
  // range_error: error(range_message(r)) carrying r (kind kParse: the file is at fault).
  Error range_error(FieldRange r) const;

  // parse_double / parse_int64: strict parsing of one field (whole field, finite).
  Result<double> parse_double(const std::string& text, std::string_view field) const;
  Result<std::int64_t> parse_int64(const std::string& text, std::string_view field) const;

 private:
  std::istream& in_;
  std::string source_;
  int line_ = 0;
  std::size_t n_columns_ = 0;
};

}  // namespace odo::analysis
