#include "odo/drivers/nv_storage.hpp"

#include <fcntl.h>
#include <mtd/mtd-user.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <vector>

namespace odo::drivers {
namespace {

Error sys_error(const std::string& path, const char* what, int err) {
  return make_error(Errc::kIo, path + ": " + what + ": " + std::strerror(err));
}

Status check_range(const std::string& path, std::size_t off, std::size_t len, std::size_t size) {
  if (off > size || len > size - off)
    return make_error(Errc::kInvalidArgument, path + ": range " + std::to_string(off) + "+" +
                                                  std::to_string(len) + " beyond the " +
                                                  std::to_string(size) + "-byte medium");
  return Ok{};
}

// pread_all: reads until `out` is full or end of file; returns the number of bytes read.
Result<std::size_t> pread_all(int fd, const std::string& path, std::size_t off,
                              std::span<std::uint8_t> out) {
  std::size_t done = 0;
  while (done < out.size()) {
    const ssize_t n =
        ::pread(fd, out.data() + done, out.size() - done, static_cast<off_t>(off + done));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      // EBADMSG: the flash ECC could not correct the data (EUCLEAN, corrected, is not an error
      // for pread()).
      if (errno == EBADMSG) return make_error(Errc::kCorrupt, path + ": uncorrectable ECC error");
      return sys_error(path, "read", errno);
    }
    if (n == 0) break;
    done += static_cast<std::size_t>(n);
  }
  return done;
}

Status pwrite_all(int fd, const std::string& path, std::size_t off,
                  std::span<const std::uint8_t> data) {
  std::size_t done = 0;
  while (done < data.size()) {
    const ssize_t n =
        ::pwrite(fd, data.data() + done, data.size() - done, static_cast<off_t>(off + done));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return sys_error(path, "write", n < 0 ? errno : EIO);
    done += static_cast<std::size_t>(n);
  }
  return Ok{};
}

// fsync_dir: makes a file's creation durable (its directory entry lives in the directory).
Status fsync_dir(const std::string& file) {
  std::filesystem::path dir = std::filesystem::path(file).parent_path();
  if (dir.empty()) dir = ".";
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return sys_error(dir.string(), "open directory", errno);
  const int rc = ::fsync(fd);
  const int err = errno;
  ::close(fd);
  if (rc != 0) return sys_error(dir.string(), "fsync directory", err);
  return Ok{};
}

}  // namespace

NvBackend detect_nv_backend(std::string_view path) noexcept {
  if (path.starts_with("/dev/mtd")) return NvBackend::kMtd;
  if (path.starts_with("/sys/") || path.ends_with("/nvmem") || path == "nvmem")
    return NvBackend::kNvmem;
  return NvBackend::kFile;
}

// ---- regular file ---------------------------------------------------------------------------

Status FileNvStorage::read(std::size_t off, std::span<std::uint8_t> out) {
  if (auto s = check_range(path_, off, out.size(), size_); !s) return s;
  std::fill(out.begin(), out.end(), std::uint8_t{0xFF});
  const int fd = ::open(path_.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    if (errno == ENOENT) return Ok{};  // never written: reads as erased
    return sys_error(path_, "open", errno);
  }
  auto n = pread_all(fd, path_, off, out);
  ::close(fd);
  if (!n) return std::move(n).error();
  // Bytes past the end of the file were never written: they stay 0xFF.
  return Ok{};
}

Status FileNvStorage::write(std::size_t off, std::span<const std::uint8_t> data) {
  if (auto s = check_range(path_, off, data.size(), size_); !s) return s;
  const int fd = ::open(path_.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  int wfd = fd;
  const bool created = fd >= 0;
  if (!created) {
    if (errno != EEXIST) return sys_error(path_, "create", errno);
    wfd = ::open(path_.c_str(), O_RDWR | O_CLOEXEC);
    if (wfd < 0) return sys_error(path_, "open for writing", errno);
  }
  Status s = pwrite_all(wfd, path_, off, data);
  if (s && ::fdatasync(wfd) != 0) s = sys_error(path_, "fdatasync", errno);
  ::close(wfd);
  if (s && created) s = fsync_dir(path_);
  return s;
}

Status FileNvStorage::erase(std::size_t off, std::size_t len) {
  const std::vector<std::uint8_t> ff(len, 0xFF);
  return write(off, ff);
}

// ---- nvmem (EEPROM) -------------------------------------------------------------------------

Result<std::unique_ptr<NvmemStorage>> NvmemStorage::open(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDWR | O_CLOEXEC);
  if (fd < 0) return sys_error(path, "open nvmem device", errno);
  struct stat st {};
  if (::fstat(fd, &st) != 0 || st.st_size <= 0) {
    ::close(fd);
    return make_error(Errc::kUnsupported, path + ": nvmem file reports no size");
  }
  return std::unique_ptr<NvmemStorage>(
      new NvmemStorage(path, fd, static_cast<std::size_t>(st.st_size)));
}

NvmemStorage::~NvmemStorage() {
  ::close(fd_);
}

Status NvmemStorage::read(std::size_t off, std::span<std::uint8_t> out) {
  if (auto s = check_range(path_, off, out.size(), size_); !s) return s;
  auto n = pread_all(fd_, path_, off, out);
  if (!n) return std::move(n).error();
  if (*n != out.size()) return make_error(Errc::kIo, path_ + ": short read");
  return Ok{};
}

Status NvmemStorage::write(std::size_t off, std::span<const std::uint8_t> data) {
  if (auto s = check_range(path_, off, data.size(), size_); !s) return s;
  if (auto s = pwrite_all(fd_, path_, off, data); !s) return s;
  // at24 writes synchronously (it polls the chip until the page is programmed); fsync makes a
  // file standing in for the EEPROM durable too. sysfs files do not support it: EINVAL is fine.
  if (::fsync(fd_) != 0 && errno != EINVAL && errno != EROFS)
    return sys_error(path_, "fsync", errno);
  return Ok{};
}

Status NvmemStorage::erase(std::size_t off, std::size_t len) {
  const std::vector<std::uint8_t> ff(len, 0xFF);
  return write(off, ff);
}

// ---- MTD (raw flash) ------------------------------------------------------------------------

Result<std::unique_ptr<MtdStorage>> MtdStorage::open(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDWR | O_CLOEXEC);
  if (fd < 0) return sys_error(path, "open MTD device", errno);
  mtd_info_user info{};
  if (::ioctl(fd, MEMGETINFO, &info) != 0) {
    const int err = errno;
    ::close(fd);
    return sys_error(path, "MEMGETINFO (not an MTD character device?)", err);
  }
  if ((info.flags & MTD_WRITEABLE) == 0) {
    ::close(fd);
    return make_error(Errc::kUnsupported, path + ": MTD partition is read-only");
  }
  NvGeometry g;
  g.size = info.size;
  // Flash discipline (erase, then program) wherever the device offers erase blocks, even on
  // MTD_NO_ERASE devices such as mtdram, which implement MEMERASE as well.
  g.erase_block = info.erasesize;
  g.write_unit = info.writesize > 0 ? info.writesize : 1;
  return std::unique_ptr<MtdStorage>(new MtdStorage(path, fd, g));
}

MtdStorage::~MtdStorage() {
  ::close(fd_);
}

Status MtdStorage::read(std::size_t off, std::span<std::uint8_t> out) {
  if (auto s = check_range(path_, off, out.size(), geom_.size); !s) return s;
  auto n = pread_all(fd_, path_, off, out);
  if (!n) return std::move(n).error();
  if (*n != out.size()) return make_error(Errc::kIo, path_ + ": short read");
  return Ok{};
}

Status MtdStorage::write(std::size_t off, std::span<const std::uint8_t> data) {
  if (auto s = check_range(path_, off, data.size(), geom_.size); !s) return s;
  if (off % geom_.write_unit != 0 || data.size() % geom_.write_unit != 0)
    return make_error(Errc::kInvalidArgument, path_ + ": write not aligned to the " +
                                                  std::to_string(geom_.write_unit) +
                                                  "-byte write unit");
  // mtdchar writes go straight to the chip driver (no page cache): durable on return.
  return pwrite_all(fd_, path_, off, data);
}

Status MtdStorage::erase(std::size_t off, std::size_t len) {
  if (auto s = check_range(path_, off, len, geom_.size); !s) return s;
  if (geom_.erase_block == 0) {
    const std::vector<std::uint8_t> ff(len, 0xFF);
    return write(off, ff);
  }
  if (off % geom_.erase_block != 0 || len % geom_.erase_block != 0)
    return make_error(Errc::kInvalidArgument, path_ + ": erase not aligned to the " +
                                                  std::to_string(geom_.erase_block) +
                                                  "-byte erase block");
  for (std::size_t b = off; b < off + len; b += geom_.erase_block) {
    loff_t pos = static_cast<loff_t>(b);
    const int bad = ::ioctl(fd_, MEMGETBADBLOCK, &pos);
    if (bad > 0)
      return make_error(Errc::kIo, path_ + ": erase block at " + std::to_string(b) + " is bad");
    erase_info_user ei{};
    ei.start = static_cast<std::uint32_t>(b);
    ei.length = static_cast<std::uint32_t>(geom_.erase_block);
    if (::ioctl(fd_, MEMERASE, &ei) != 0) return sys_error(path_, "MEMERASE", errno);
  }
  return Ok{};
}

Result<std::unique_ptr<NvStorage>> open_nv_storage(const std::string& path, NvBackend kind) {
  if (kind == NvBackend::kAuto) kind = detect_nv_backend(path);
  switch (kind) {
    case NvBackend::kMtd: {
      auto m = MtdStorage::open(path);
      if (!m) return std::move(m).error();
      return std::unique_ptr<NvStorage>(std::move(m).value());
    }
    case NvBackend::kNvmem: {
      auto m = NvmemStorage::open(path);
      if (!m) return std::move(m).error();
      return std::unique_ptr<NvStorage>(std::move(m).value());
    }
    default:
      return std::unique_ptr<NvStorage>(std::make_unique<FileNvStorage>(path));
  }
}

}  // namespace odo::drivers
