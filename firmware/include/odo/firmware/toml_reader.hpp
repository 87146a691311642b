// TableReader: typed, range-checked access to one TOML table, remembering which keys were used
// so that unknown (mistyped) keys are reported with their line.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include <toml++/toml.h>

#include "odo/firmware/config.hpp"
#include "odo/hal/field_range.hpp"

namespace odo::fw {

class TableReader {
 public:
  // table may be null (section absent: every getter returns its default).
  TableReader(const toml::table* table, std::string path, std::string_view source,
              std::string* error);

  // number: a float or integer in [lo, hi]; `unit` is printed in messages.
  double number(std::string_view key, double def, double lo, double hi, std::string_view unit);
  // number: the value of row.key, checked against the row's range (a range table's row).
  double number(double def, const RangeRow& row);
  // integer: an integer in [lo, hi].
  std::int64_t integer(std::string_view key, std::int64_t def, std::int64_t lo, std::int64_t hi);
  // integer: the whole number at row.key, within the row's (whole) limits.
  std::int64_t integer(std::int64_t def, const RangeRow& row) {
    return integer(row.key, def, static_cast<std::int64_t>(row.lo),
                   static_cast<std::int64_t>(row.hi));
  }
  // integers: an integer (read as a list of one) or an array of 1..max_count integers, each in
  // [lo, hi]; errors name the element (key[i]) and its line. Absent: `def`.
  std::vector<std::int64_t> integers(std::string_view key, std::vector<std::int64_t> def,
                                     std::int64_t lo, std::int64_t hi, std::size_t max_count);
  bool boolean(std::string_view key, bool def);
  std::string string(std::string_view key, std::string def);
  // strings: an array of strings (may be empty).
  std::vector<std::string> strings(std::string_view key, std::vector<std::string> def);
  // choice: a string that must spell one of E's choices (config.hpp).
  template <class E>
  E choice(std::string_view key, E def) {
    const std::string v = string(key, std::string(name_of(def)));
    if (auto e = parse_choice<E>(v)) return *e;
    reject_choice(key, v, choice_list<E>());
    return def;
  }
  // reject: reports a problem found across settings at the line of `key` (or of the table).
  void reject(std::string_view key, const std::string& what);
  // location: "file:line: path.key" of `key` (the table's line when the key is absent), for
  // errors found later, when the value is used (a serial device that is not there).
  std::string location(std::string_view key) const;
  // written: the file gives `key` in this table (otherwise a getter returns its default).
  bool written(std::string_view key) const { return table_ != nullptr && table_->contains(key); }
  // sub: a nested table (may be absent).
  TableReader sub(std::string_view key);
  // finish: reports the first key of this table that no getter asked for.
  void finish();
  // ok: no error so far (the first error is kept, later ones dropped).
  bool ok() const { return error_->empty(); }

 private:
  const toml::node* get(std::string_view key);
  void fail(const toml::node* n, std::string_view key, const std::string& what);
  void reject_choice(std::string_view key, const std::string& v, const std::string& list);
  std::string where(const toml::node* n) const;

  const toml::table* table_;
  std::string path_;
  std::string source_;
  std::string* error_;
  std::set<std::string, std::less<>> used_;
};

}  // namespace odo::fw
