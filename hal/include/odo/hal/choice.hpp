// Choice: one spelling of an enum value, for the tables that are the only place a choice is
// written as text (config keys, command-line options). Code compares enum values; the text is
// read once, where it enters, and printed from the same table.
#pragma once

#include <optional>
#include <string>
#include <string_view>

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

}  // namespace odo
