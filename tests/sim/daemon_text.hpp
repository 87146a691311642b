// What tests read of odometryd's text while run_daemon runs in another thread: a sink for its
// stream (LockedText) and a count of its status thread's lines. Tests wait on the daemon's own
// lines instead of guessing how long a start takes.
#pragma once

#include <cstddef>
#include <mutex>
#include <streambuf>
#include <string>

namespace odo::test {

// LockedText: an ostream sink that keeps what is written to it, readable from another thread
// while the daemon writes (an ostringstream would be a data race there).
class LockedText final : public std::streambuf {
 public:
  // text: a copy of everything written so far.
  std::string text() const {
    std::lock_guard<std::mutex> l(m_);
    return text_;
  }

 protected:
  int overflow(int c) override {
    if (c == traits_type::eof()) return traits_type::not_eof(c);
    std::lock_guard<std::mutex> l(m_);
    text_.push_back(static_cast<char>(c));
    return c;
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    std::lock_guard<std::mutex> l(m_);
    text_.append(s, static_cast<std::size_t>(n));
    return n;
  }

 private:
  mutable std::mutex m_;
  std::string text_;
};

// status_lines: how many of the status thread's lines (each has "  rate=") `e` holds.
inline std::size_t status_lines(const std::string& e) {
  std::size_t lines = 0;
  for (auto p = e.find("  rate="); p != std::string::npos; p = e.find("  rate=", p + 1)) ++lines;
  return lines;
}

}  // namespace odo::test
