// Real processes on a real file: a writer saving records as fast as it can is killed with
// SIGKILL at random moments; after every kill the store must load a valid, self-consistent
// record (never a mix of two), and the sequence never goes backwards.
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "calib_kill_loop.hpp"
#include "odo/drivers/nv_storage.hpp"

namespace odo::calib {
namespace {

std::string temp_store(const char* name) {
  const char* base = std::getenv("TMPDIR");
  std::filesystem::path dir =
      std::filesystem::path(base ? base : "/tmp") / ("odo_killtest_" + std::to_string(getpid()));
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

TEST(CalibKill, FileBackendSurvivesSigkill) {
  const std::string path = temp_store("calibration.bin");
  std::filesystem::remove(path);
  kill_loop(
      [](const std::string& p) -> std::unique_ptr<NvStorage> {
        return std::make_unique<drivers::FileNvStorage>(p);
      },
      path, 250, 42);
  std::filesystem::remove_all(std::filesystem::path(path).parent_path());
}

TEST(CalibKill, NvmemStyleFileSurvivesSigkill) {
  // A fixed-size file standing in for an EEPROM's nvmem attribute (256 bytes: a 24C02).
  const std::string path = temp_store("nvmem");
  {
    std::ofstream f(path, std::ios::binary | std::ios::trunc);
    const std::string ff(256, '\xFF');
    f << ff;
  }
  kill_loop(
      [](const std::string& p) -> std::unique_ptr<NvStorage> {
        auto m = drivers::NvmemStorage::open(p);
        if (!m) _exit(5);
        return std::move(m).value();
      },
      path, 250, 43);
  EXPECT_EQ(std::filesystem::file_size(path), 256U);  // a fixed-size medium never grows
  std::filesystem::remove_all(std::filesystem::path(path).parent_path());
}

}  // namespace
}  // namespace odo::calib
