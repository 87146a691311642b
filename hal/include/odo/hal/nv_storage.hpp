// NvStorage: a small non-volatile medium (a file, an EEPROM, a raw flash partition) addressed
// by byte offset. The calibration store (calibration/) works on this interface only.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "odo/hal/choice.hpp"
#include "odo/hal/result.hpp"

namespace odo {

// NvBackend: the kind of medium behind a storage path (drivers/ opens each; the config's
// calibration.backend names them through kNvBackends). kAuto: detected from the path.
enum class NvBackend : std::uint8_t { kAuto, kFile, kNvmem, kMtd };
inline constexpr Choice<NvBackend> kNvBackends[] = {{NvBackend::kAuto, "auto"},
                                                    {NvBackend::kFile, "file"},
                                                    {NvBackend::kNvmem, "nvmem"},
                                                    {NvBackend::kMtd, "mtd"}};

// Shape of a medium. Offsets and sizes in bytes.
struct NvGeometry {
  std::size_t size = 0;         // usable bytes, addresses [0, size)
  std::size_t erase_block = 0;  // erase granularity; 0: byte-writable, erase() not needed
  std::size_t write_unit = 1;   // writes must start and end on multiples of this (flash pages)
};

class NvStorage {
 public:
  virtual ~NvStorage() = default;
  // geometry: size and erase/write granularity of the medium.
  virtual NvGeometry geometry() const noexcept = 0;
  // read: fills `out` from offset `off`; bytes never written read as 0xFF (erased).
  virtual Status read(std::size_t off, std::span<std::uint8_t> out) = 0;
  // write: stores `data` at `off` and returns only once it is durable (synced to the medium).
  // On flash the range must have been erased. A failure may leave the range partly written.
  virtual Status write(std::size_t off, std::span<const std::uint8_t> data) = 0;
  // erase: sets [off, off+len) to 0xFF; on flash both must be multiples of erase_block. Durable
  // on return, like write().
  virtual Status erase(std::size_t off, std::size_t len) = 0;
};

}  // namespace odo
