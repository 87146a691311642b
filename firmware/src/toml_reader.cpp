#include "odo/firmware/toml_reader.hpp"

#include "odo/hal/field_range.hpp"

#include <cmath>
#include <sstream>

namespace odo::fw {

TableReader::TableReader(const toml::table* table, std::string path, std::string_view source,
                         std::string* error)
    : table_(table), path_(std::move(path)), source_(source), error_(error) {}

std::string TableReader::where(const toml::node* n) const {
  std::ostringstream o;
  o << source_;
  if (n != nullptr && n->source().begin.line > 0) o << ":" << n->source().begin.line;
  return o.str();
}

void TableReader::fail(const toml::node* n, std::string_view key, const std::string& what) {
  if (!error_->empty()) return;
  std::ostringstream o;
  o << where(n != nullptr ? n : table_) << ": " << path_ << (path_.empty() ? "" : ".") << key << " "
    << what;
  *error_ = o.str();
}

std::string TableReader::location(std::string_view key) const {
  const toml::node* n = table_ != nullptr ? table_->get(key) : nullptr;
  return where(n != nullptr ? n : table_) + ": " + path_ + (path_.empty() ? "" : ".") +
         std::string(key);
}

void TableReader::reject(std::string_view key, const std::string& what) {
  fail(table_ != nullptr ? table_->get(key) : nullptr, key, what);
}

const toml::node* TableReader::get(std::string_view key) {
  used_.emplace(key);
  if (table_ == nullptr) return nullptr;
  return table_->get(key);
}

double TableReader::number(std::string_view key, double def, double lo, double hi,
                           std::string_view unit) {
  const std::string k(key), u(unit);
  return number(def, RangeRow{k.c_str(), lo, hi, u.c_str()});
}

double TableReader::number(double def, const RangeRow& row) {
  const toml::node* n = get(row.key);
  if (n == nullptr) return def;
  double v = 0;
  if (auto f = n->value_exact<double>()) {
    v = *f;
  } else if (auto i = n->value_exact<std::int64_t>()) {
    v = static_cast<double>(*i);
  } else {
    fail(n, row.key, "must be a number");
    return def;
  }
  if (!row.contains(v)) {
    FieldRange r = row.range(row.key, v);
    r.unit_on_value = false;  // "x = 3 is outside the allowed range [0, 1] m"
    fail(n, row.key, range_text(r));
    return def;
  }
  return v;
}

std::int64_t TableReader::integer(std::string_view key, std::int64_t def, std::int64_t lo,
                                  std::int64_t hi) {
  const toml::node* n = get(key);
  if (n == nullptr) return def;
  auto i = n->value_exact<std::int64_t>();
  if (!i) {
    fail(n, key, "must be an integer");
    return def;
  }
  if (*i < lo || *i > hi) {
    fail(n, key, range_text(integer_range(std::string(key), *i, lo, hi)));
    return def;
  }
  return *i;
}

std::vector<std::int64_t> TableReader::integers(std::string_view key, std::vector<std::int64_t> def,
                                                std::int64_t lo, std::int64_t hi,
                                                std::size_t max_count) {
  const toml::node* n = get(key);
  if (n == nullptr) return def;
  if (!n->is_array()) return {integer(key, def.empty() ? lo : def.front(), lo, hi)};
  const toml::array& a = *n->as_array();
  if (a.empty() || a.size() > max_count) {
    fail(n, key,
         "has " + std::to_string(a.size()) + " entries: give 1.." + std::to_string(max_count));
    return def;
  }
  std::vector<std::int64_t> v;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const std::string elem = std::string(key) + "[" + std::to_string(i) + "]";
    auto x = a.get(i)->value_exact<std::int64_t>();
    if (!x) {
      fail(a.get(i), elem, "must be an integer");
      return def;
    }
    if (*x < lo || *x > hi) {
      fail(a.get(i), elem, range_text(integer_range(elem, *x, lo, hi)));
      return def;
    }
    v.push_back(*x);
  }
  return v;
}

bool TableReader::boolean(std::string_view key, bool def) {
  const toml::node* n = get(key);
  if (n == nullptr) return def;
  auto b = n->value_exact<bool>();
  if (!b) {
    fail(n, key, "must be true or false");
    return def;
  }
  return *b;
}

std::string TableReader::string(std::string_view key, std::string def) {
  const toml::node* n = get(key);
  if (n == nullptr) return def;
  auto s = n->value_exact<std::string>();
  if (!s) {
    fail(n, key, "must be a string");
    return def;
  }
  return *s;
}

std::vector<std::string> TableReader::strings(std::string_view key, std::vector<std::string> def) {
  const toml::node* n = get(key);
  if (n == nullptr) return def;
  const toml::array* a = n->as_array();
  std::vector<std::string> v;
  for (std::size_t i = 0; a != nullptr && i < a->size(); ++i) {
    auto s = a->get(i)->value_exact<std::string>();
    if (!s) break;
    v.push_back(*s);
  }
  if (a == nullptr || v.size() != a->size()) {
    fail(n, key, "must be an array of strings, e.g. [\"eth0\"]");
    return def;
  }
  return v;
}

void TableReader::reject_choice(std::string_view key, const std::string& v,
                                const std::string& list) {
  const toml::node* n = table_ != nullptr ? table_->get(key) : nullptr;
  fail(n, key, "= \"" + v + "\" is not one of: " + list);
}

TableReader TableReader::sub(std::string_view key) {
  const toml::node* n = get(key);
  const toml::table* t = n != nullptr ? n->as_table() : nullptr;
  if (n != nullptr && t == nullptr) fail(n, key, "must be a table");
  return TableReader(t, path_.empty() ? std::string(key) : path_ + "." + std::string(key), source_,
                     error_);
}

void TableReader::finish() {
  if (table_ == nullptr) return;
  for (const auto& [k, node] : *table_) {
    if (used_.find(k.str()) == used_.end()) {
      fail(&node, k.str(), "is not a known setting (misspelt?)");
      return;
    }
  }
}

}  // namespace odo::fw
