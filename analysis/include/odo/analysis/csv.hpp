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
