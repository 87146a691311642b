// Real processes on a real file: a writer saving records as fast as it can is killed with
// SIGKILL at random moments; after every kill the store must load a valid, self-consistent
// record (never a mix of two), and the sequence never goes backwards.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <thread>

#include "odo/calibration/store.hpp"
#include "odo/drivers/nv_storage.hpp"

namespace odo::calib {
namespace {

// Payload derived from the sequence number, so a load can tell whether the record is whole.
CalibrationRecord record_for(std::uint64_t seq) {
  CalibrationRecord r;
  r.c_l = 1.0 - 1e-4 * static_cast<double>(seq % 997);
  r.c_r = 1.0 + 1e-4 * static_cast<double>(seq % 991);
  r.wheelbase = 0.3 + 1e-5 * static_cast<double>(seq % 983);
  r.time = static_cast<std::int64_t>(seq);
  r.runs = static_cast<std::uint32_t>(seq % 1000000);
  r.method = "killtest";
  return r;
}

bool consistent(const CalibrationRecord& r) {
  CalibrationRecord want = record_for(r.sequence);
  want.sequence = r.sequence;
  return r == want;
}

using Opener = std::unique_ptr<NvStorage> (*)(const std::string&);

[[noreturn]] void writer(Opener open, const std::string& path) {
  auto medium = open(path);
  auto store = CalibrationStore::create(*medium);
  for (;;) {
    auto l = store->load();
    if (!l || !l->record) _exit(3);
    if (!store->save(record_for(l->record->sequence + 1))) _exit(4);
  }
}

void kill_loop(Opener open, const std::string& path, int rounds, std::uint64_t seed) {
  {
    auto medium = open(path);
    auto store = CalibrationStore::create(*medium);
    ASSERT_TRUE(store);
    ASSERT_TRUE(store->save(record_for(1)));
  }
  std::mt19937_64 rng(seed);
  std::uint64_t last_seq = 1;
  int advanced = 0, one_slot_bad = 0;
  for (int i = 0; i < rounds; ++i) {
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) writer(open, path);
    // 0.2 .. 20 ms: from the middle of start-up to hundreds of saves.
    std::this_thread::sleep_for(std::chrono::microseconds(200 + rng() % 19800));
    ASSERT_EQ(kill(pid, SIGKILL), 0);
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    ASSERT_TRUE(WIFSIGNALED(status)) << "writer exited by itself with " << WEXITSTATUS(status);
    auto medium = open(path);
    auto store = CalibrationStore::create(*medium);
    auto l = store->load();
    ASSERT_TRUE(l) << l.error().message;
    ASSERT_EQ(l->status, StoreStatus::kOk) << "round " << i << ": " << l->describe();
    ASSERT_TRUE(consistent(*l->record))
        << "round " << i << ": a mixed record, sequence " << l->record->sequence;
    ASSERT_GE(l->record->sequence, last_seq);
    if (l->record->sequence > last_seq) ++advanced;
    if (!l->slots[0].valid || !l->slots[1].valid) ++one_slot_bad;
    last_seq = l->record->sequence;
  }
  std::printf(
      "%d kills: store advanced in %d rounds to sequence %llu; %d loads found one slot "
      "invalid\n",
      rounds, advanced, static_cast<unsigned long long>(last_seq), one_slot_bad);
  // The writer must really have been writing when it was killed.
  EXPECT_GT(advanced, rounds / 2);
}

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
        return std::make_unique<drv::FileNvStorage>(p);
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
        auto m = drv::NvmemStorage::open(p);
        if (!m) _exit(5);
        return std::move(m).value();
      },
      path, 250, 43);
  EXPECT_EQ(std::filesystem::file_size(path), 256U);  // a fixed-size medium never grows
  std::filesystem::remove_all(std::filesystem::path(path).parent_path());
}

}  // namespace
}  // namespace odo::calib
