#include "odo/analysis/csv.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>

namespace odo::analysis {
namespace {

std::string trim(std::string_view s) {
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string_view::npos) return {};
  const auto e = s.find_last_not_of(" \t\r");
  return std::string(s.substr(b, e - b + 1));
}

void split(const std::string& line, std::vector<std::string>& out) {
  out.clear();
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = line.find(',', start);
    out.push_back(trim(std::string_view(line).substr(start, comma - start)));
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
}

}  // namespace

Error CsvReader::error(const std::string& what) const {
  return make_error(Errc::kParse, source_ + ":" + std::to_string(line_) + ": " + what);
}

Error CsvReader::range_error(FieldRange r) const {
  Error e = error(range_message(r));
  e.range = std::move(r);
  return e;
}

Result<std::vector<int>> CsvReader::header(const std::vector<std::string_view>& required,
                                           const std::vector<std::string_view>& optional) {
  std::vector<std::string> names;
  if (!next(names)) {
    line_ = std::max(line_, 1);
    return error("empty file: expected a header line");
  }
  std::vector<int> idx(required.size() + optional.size(), -1);
  for (std::size_t c = 0; c < names.size(); ++c) {
    bool known = false;
    for (std::size_t k = 0; k < required.size() + optional.size(); ++k) {
      const std::string_view want =
          k < required.size() ? required[k] : optional[k - required.size()];
      if (names[c] == want) {
        if (idx[k] >= 0) return error("column '" + names[c] + "' appears twice in the header");
        idx[k] = static_cast<int>(c);
        known = true;
      }
    }
    if (!known) return error("unknown column '" + names[c] + "' in the header");
  }
  for (std::size_t k = 0; k < required.size(); ++k) {
    if (idx[k] < 0) {
      std::string all;
      for (auto r : required) all += (all.empty() ? "" : ",") + std::string(r);
      return error("missing column '" + std::string(required[k]) + "' (header must name " + all +
                   ")");
    }
  }
  n_columns_ = names.size();
  return idx;
}

bool CsvReader::next(std::vector<std::string>& fields) {
  std::string line;
  while (std::getline(in_, line)) {
    ++line_;
    const std::string t = trim(line);
    if (t.empty() || t[0] == '#') continue;
    split(t, fields);
    return true;
  }
  return false;
}

Result<double> CsvReader::parse_double(const std::string& text, std::string_view field) const {
  double v = 0;
  const char* b = text.data();
  const char* e = b + text.size();
  auto [p, ec] = std::from_chars(b, e, v);
  if (text.empty() || ec != std::errc() || p != e || !std::isfinite(v)) {
    return error("field '" + std::string(field) + "' = '" + text + "' is not a finite number");
  }
  return v;
}

Result<std::int64_t> CsvReader::parse_int64(const std::string& text, std::string_view field) const {
  std::int64_t v = 0;
  const char* b = text.data();
  const char* e = b + text.size();
  if (b != e && *b == '+') ++b;
  auto [p, ec] = std::from_chars(b, e, v);
  if (text.empty() || ec != std::errc() || p != e) {
    return error("field '" + std::string(field) + "' = '" + text +
                 "' is not an integer in the signed 64-bit range");
  }
  return v;
}

}  // namespace odo::analysis
