#include "odo/drivers/state_file.hpp"

#include <fcntl.h>
#include <linux/magic.h>
#include <sys/stat.h>
#include <sys/statfs.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

namespace odo::drivers {
namespace {

// io_error: "PATH: WHAT (reason of err)".
Error io_error(const std::string& what, const std::string& path, int err) {
  return make_error(Errc::kIo, path + ": " + what + " (" + std::strerror(err) + ")");
}

// make_directory: creates the file's directory when it is missing (one level: run by hand there
// is no systemd to make /run/odometryd), 0755 whatever the umask; true if it was made.
bool make_directory(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  if (slash == std::string::npos || slash == 0) return false;
  const std::string dir = path.substr(0, slash);
  if (::mkdir(dir.c_str(), 0755) != 0) return false;
  return ::chmod(dir.c_str(), 0755) == 0;
}

}  // namespace

Result<std::unique_ptr<StateFile>> StateFile::open(const std::string& path, std::size_t bytes) {
  int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0 && errno == ENOENT && make_directory(path))
    fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd < 0) return io_error("cannot open the state file", path, errno);
  // Sized once here: every later write is in place, within the file (no growth, no allocation
  // in the file system on the writer's path).
  struct stat st {};
  if (::fstat(fd, &st) != 0 ||
      (st.st_size < static_cast<off_t>(bytes) && ::ftruncate(fd, static_cast<off_t>(bytes)) != 0)) {
    auto e = io_error("cannot size the state file", path, errno);
    ::close(fd);
    return e;
  }
  return std::unique_ptr<StateFile>(new StateFile(fd));
}

StateFile::~StateFile() {
  ::close(fd_);
}

bool StateFile::write_at(std::size_t offset, std::span<const std::uint8_t> data) noexcept {
  return ::pwrite(fd_, data.data(), data.size(), static_cast<off_t>(offset)) ==
         static_cast<ssize_t>(data.size());
}

Result<std::size_t> read_file_head(const std::string& path, std::span<std::uint8_t> out) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    if (errno == ENOENT) return make_error(Errc::kNotFound, path + ": no such file");
    return io_error("cannot open", path, errno);
  }
  const ssize_t n = ::pread(fd, out.data(), out.size(), 0);
  const int err = errno;  // pread's, before close can change it
  ::close(fd);
  if (n < 0) return io_error("cannot read", path, err);
  return static_cast<std::size_t>(n);
}

bool on_tmpfs(const std::string& path) {
  const std::size_t slash = path.rfind('/');
  const std::string dir = slash == std::string::npos ? "." : path.substr(0, slash + 1);
  struct statfs f {};
  return ::statfs(dir.c_str(), &f) == 0 && f.f_type == TMPFS_MAGIC;
}

}  // namespace odo::drivers
