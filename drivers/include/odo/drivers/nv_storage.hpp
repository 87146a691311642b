// Non-volatile storage backends on Linux: a regular file, an EEPROM exposed as an nvmem file
// (e.g. /sys/bus/nvmem/devices/0-00500/nvmem of the at24 driver) and a raw flash partition
// through the MTD character device (/dev/mtdN).
#pragma once

#include <memory>
#include <string>
#include <string_view>

#include "odo/hal/nv_storage.hpp"
#include "odo/hal/result.hpp"

namespace odo::drivers {

// nv_backend_name: "auto", "file", "nvmem", "mtd" (hal's kNvBackends).
inline std::string_view nv_backend_name(NvBackend b) noexcept {
  return choice_name(kNvBackends, b);
}
// detect_nv_backend: /dev/mtd* -> mtd, a file named "nvmem" or under /sys/ -> nvmem, else file.
NvBackend detect_nv_backend(std::string_view path) noexcept;

// FileNvStorage: a regular file of nominal `size` bytes. A missing file or bytes past its end
// read as erased (0xFF); write() creates the file (and fsyncs its directory), pwrite()s and
// fdatasync()s before returning.
class FileNvStorage final : public NvStorage {
 public:
  static constexpr std::size_t kDefaultSize = 1024;
  explicit FileNvStorage(std::string path, std::size_t size = kDefaultSize)
      : path_(std::move(path)), size_(size) {}
  NvGeometry geometry() const noexcept override { return NvGeometry{size_, 0, 1}; }
  Status read(std::size_t off, std::span<std::uint8_t> out) override;
  Status write(std::size_t off, std::span<const std::uint8_t> data) override;
  Status erase(std::size_t off, std::size_t len) override;

 private:
  std::string path_;
  std::size_t size_;
};

// NvmemStorage: a byte-addressable EEPROM as a fixed-size file (the nvmem sysfs attribute).
// The file must exist; its size is the medium's size. Writes are followed by fsync().
class NvmemStorage final : public NvStorage {
 public:
  static Result<std::unique_ptr<NvmemStorage>> open(const std::string& path);
  ~NvmemStorage() override;
  NvGeometry geometry() const noexcept override { return NvGeometry{size_, 0, 1}; }
  Status read(std::size_t off, std::span<std::uint8_t> out) override;
  Status write(std::size_t off, std::span<const std::uint8_t> data) override;
  Status erase(std::size_t off, std::size_t len) override;

 private:
  NvmemStorage(std::string path, int fd, std::size_t size)
      : path_(std::move(path)), fd_(fd), size_(size) {}
  std::string path_;
  int fd_;
  std::size_t size_;
};

// MtdStorage: a raw flash partition, /dev/mtdN. Geometry from MEMGETINFO; erase with MEMERASE
// (whole erase blocks; bad blocks on NAND are refused); uncorrectable ECC reads are
// Errc::kCorrupt.
class MtdStorage final : public NvStorage {
 public:
  static Result<std::unique_ptr<MtdStorage>> open(const std::string& path);
  ~MtdStorage() override;
  NvGeometry geometry() const noexcept override { return geom_; }
  Status read(std::size_t off, std::span<std::uint8_t> out) override;
  Status write(std::size_t off, std::span<const std::uint8_t> data) override;
  Status erase(std::size_t off, std::size_t len) override;

 private:
  MtdStorage(std::string path, int fd, NvGeometry g) : path_(std::move(path)), fd_(fd), geom_(g) {}
  std::string path_;
  int fd_;
  NvGeometry geom_;
};

// open_nv_storage: the backend `kind` (kAuto: detect_nv_backend) on `path`.
Result<std::unique_ptr<NvStorage>> open_nv_storage(const std::string& path, NvBackend kind);

}  // namespace odo::drivers
