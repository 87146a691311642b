// Result<T>: a value or an Error, for code that must not throw (the loop path) and for
// configure-time validation that wants a readable message.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <variant>

#include "odo/hal/field_range.hpp"

namespace odo {

enum class Errc : std::uint8_t {
  kInvalidArgument,  // a parameter outside its allowed range
  kParse,            // malformed input text
  kIo,               // the operating system refused an operation
  kNotFound,         // a file, device or record does not exist
  kCorrupt,          // stored data failed its integrity check
  kUnsupported,      // the build or the hardware lacks the feature
  kBusy,             // try again later (e.g. a full transmit queue)
  kTimeout,          // a deadline passed before the operation completed
};

// Error: a code plus a human-readable message naming the field and the allowed range; a range
// error also carries that range as data (range_error), so that no caller parses the text.
struct Error {
  Errc code = Errc::kInvalidArgument;
  std::string message;
  std::optional<FieldRange> range;  // set by range_error
};

// Result<T>: holds either a T or an Error; never throws on access through the checked API.
template <class T>
class [[nodiscard]] Result {
 public:
  Result(T value) : v_(std::move(value)) {}      // NOLINT(google-explicit-constructor)
  Result(Error error) : v_(std::move(error)) {}  // NOLINT(google-explicit-constructor)

  bool ok() const noexcept { return v_.index() == 0; }
  explicit operator bool() const noexcept { return ok(); }
  T& value() & { return std::get<0>(v_); }
  const T& value() const& { return std::get<0>(v_); }
  T&& value() && { return std::get<0>(std::move(v_)); }
  T* operator->() { return &std::get<0>(v_); }
  const T* operator->() const { return &std::get<0>(v_); }
  T& operator*() & { return std::get<0>(v_); }
  const T& operator*() const& { return std::get<0>(v_); }
  const Error& error() const& { return std::get<1>(v_); }
  Error&& error() && { return std::get<1>(std::move(v_)); }

 private:
  std::variant<T, Error> v_;
};

// Status: a Result without a value.
struct Ok {};
using Status = Result<Ok>;

// make_error: shorthand for building an Error result.
inline Error make_error(Errc code, std::string message) {
  return Error{code, std::move(message), std::nullopt};
}

// range_error: kInvalidArgument worded by range_message(r), carrying r.
inline Error range_error(FieldRange r) {
  std::string m = range_message(r);
  return Error{Errc::kInvalidArgument, std::move(m), std::move(r)};
}

// check_row: Ok when `row` contains v; otherwise its range error under the field name
// prefix + key, e.g. "hctl1100: agree_window" (a driver checking the value the config reader
// checked against the same row).
inline Status check_row(const RangeRow& row, std::string_view prefix, double v) {
  if (row.contains(v)) return Ok{};
  return range_error(row.range(std::string(prefix) + row.key, v));
}

}  // namespace odo
