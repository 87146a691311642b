// Text for the board's '#'-lines (banner, final report) without printf: a fixed buffer.
#pragma once

#include <cstddef>
#include <cstdint>

namespace odo::board {

class Line {
 public:
  // add: text; num: a decimal number (negative with '-'); the line stops growing when full.
  Line& add(const char* s) noexcept;
  Line& num(std::int64_t v) noexcept;
  const char* c_str() noexcept {
    buf_[n_] = '\0';
    return buf_;
  }
  std::size_t size() const noexcept { return n_; }

 private:
  void put(char c) noexcept {
    if (n_ + 1 < sizeof buf_) buf_[n_++] = c;
  }
  char buf_[160] = {};
  std::size_t n_ = 0;
};

}  // namespace odo::board
