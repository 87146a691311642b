// The resume state file's Linux side (issue 33: firmware/ does no raw Linux I/O): a file of a
// fixed size written in place by the state writer thread, read whole at start, and whether a
// directory is a tmpfs (emptied by every reboot).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "odo/hal/result.hpp"

namespace odo::drivers {

// StateFile: a file of at least `bytes` bytes, open for writing in place.
class StateFile {
 public:
  // open: opens or creates `path` (mode 0644), making its directory when that one level is
  // missing (mode 0755 whatever the umask, as systemd's RuntimeDirectory=), and sizes it to
  // `bytes` when shorter. Errors: "PATH: cannot open the state file (reason)", "PATH: cannot
  // size the state file (reason)".
  static Result<std::unique_ptr<StateFile>> open(const std::string& path, std::size_t bytes);
  ~StateFile();
  StateFile(const StateFile&) = delete;
  StateFile& operator=(const StateFile&) = delete;

  // write_at: `data` at byte `offset` in one pwrite, no allocation; false when it was not all
  // written.
  bool write_at(std::size_t offset, std::span<const std::uint8_t> data) noexcept;

 private:
  explicit StateFile(int fd) : fd_(fd) {}
  int fd_;
};

// read_file_head: up to out.size() bytes from the start of `path`; the count read. kNotFound
// (message "PATH: no such file") when it does not exist, kIo naming the path and the reason
// otherwise.
Result<std::size_t> read_file_head(const std::string& path, std::span<std::uint8_t> out);

// on_tmpfs: whether the directory of `path` (the path up to its last '/', "." without one) is
// on a tmpfs.
bool on_tmpfs(const std::string& path);

}  // namespace odo::drivers
