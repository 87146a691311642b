// Choice: one spelling of an enum value, for the tables that are the only place a choice is
// written as text (config keys, command-line options). Code compares enum values; the text is
// read once, where it enters, and printed from the same table.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "odo/hal/result.hpp"

namespace odo {

template <class E>
struct Choice {
  E value;
  std::string_view name;  // as the user writes it
};

// choice_name: the spelling of v in `table` (an array or span of Choice<E>); "?" if absent.
template <class Table, class E>
constexpr std::string_view choice_name(const Table& table, E v) {
  for (const auto& c : table)
    if (c.value == v) return c.name;
  return "?";
}

// choice_value: the value spelt `name` in `table`; nullopt when it is none of them.
template <class E, class Table>
constexpr std::optional<E> choice_value(const Table& table, std::string_view name) {
  for (const auto& c : table)
    if (c.name == name) return c.value;
  return std::nullopt;
}

// choice_join: the spellings in table order, separated by `sep` (", " or " or "), for messages.
template <class Table>
std::string choice_join(const Table& table, std::string_view sep) {
  std::string s;
  for (const auto& c : table) {
    if (!s.empty()) s += sep;
    s += c.name;
  }
  return s;
}

// parse_choice_of: the value spelt `text` in `table`; otherwise an error naming the field (a
// config key or a command-line option) and the spellings: "--gyro = 'x' must be a or b".
template <class E, class Table>
Result<E> parse_choice_of(const Table& table, std::string_view field, std::string_view text) {
  if (auto v = choice_value<E>(table, text)) return *v;
  return make_error(Errc::kInvalidArgument, std::string(field) + " = '" + std::string(text) +
                                                "' must be " + choice_join(table, " or "));
}

}  // namespace odo
