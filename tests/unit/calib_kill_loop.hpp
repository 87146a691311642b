// Shared by the SIGKILL tests (unit tier on files, kernel tier on MTD and an at24 EEPROM): a
// writer process saving records as fast as it can is killed at random moments; after every
// kill the store must load a valid, self-consistent record and the sequence never goes back.
#pragma once

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <random>
#include <string>
#include <thread>

#include "odo/calibration/store.hpp"

namespace odo::calib {

// Payload derived from the sequence number, so a load can tell whether the record is whole.
inline CalibrationRecord record_for(std::uint64_t seq) {
  CalibrationRecord r;
  r.c_l = 1.0 - 1e-4 * static_cast<double>(seq % 997);
  r.c_r = 1.0 + 1e-4 * static_cast<double>(seq % 991);
  r.wheelbase = 0.3 + 1e-5 * static_cast<double>(seq % 983);
  r.time = static_cast<std::int64_t>(seq);
  r.runs = static_cast<std::uint32_t>(seq % 1000000);
  r.method = "killtest";
  return r;
}

inline bool consistent(const CalibrationRecord& r) {
  CalibrationRecord want = record_for(r.sequence);
  want.sequence = r.sequence;
  return r == want;
}

using Opener = std::unique_ptr<NvStorage> (*)(const std::string&);

[[noreturn]] inline void writer(Opener open, const std::string& path) {
  auto medium = open(path);
  auto store = CalibrationStore::create(*medium);
  for (;;) {
    auto l = store->load();
    if (!l || !l->record) _exit(3);
    if (!store->save(record_for(l->record->sequence + 1))) _exit(4);
  }
}

// kill_loop: seeds the store, then `rounds` times: fork a writer, let it run 0.2 ms to the kill
// window (max_sleep_us, or 100 of this machine's saves if that is longer), SIGKILL it, load and
// check.
inline void kill_loop(Opener open, const std::string& path, int rounds, std::uint64_t seed,
                      int max_sleep_us = 20000) {
  std::uint64_t last_seq = 1;
  {
    auto medium = open(path);
    auto store = CalibrationStore::create(*medium);
    ASSERT_TRUE(store);
    auto cur = store->load();
    ASSERT_TRUE(cur);
    const std::uint64_t first = cur->record ? cur->record->sequence + 1 : 1;
    ASSERT_TRUE(store->save(record_for(first)));
    last_seq = first;
  }
  // The kill window scales with what one writer round (open, load, save) costs here: under
  // emulation (qemu-user in the cross builds) that is many times the native cost, and a fixed
  // window would kill most writers before their first save, which tests nothing.
  constexpr int kTimedSaves = 4;
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < kTimedSaves; ++i) {
    auto medium = open(path);
    auto store = CalibrationStore::create(*medium);
    ASSERT_TRUE(store->save(record_for(++last_seq)));
  }
  const double save_us =
      std::chrono::duration<double, std::micro>(std::chrono::steady_clock::now() - t0).count() /
      kTimedSaves;
  const int window_us = std::max(max_sleep_us, static_cast<int>(100.0 * save_us));
  std::mt19937_64 rng(seed);
  int advanced = 0, one_slot_bad = 0;
  for (int i = 0; i < rounds; ++i) {
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) writer(open, path);
    // 0.2 ms .. the window: from the middle of start-up to hundreds of saves.
    std::this_thread::sleep_for(
        std::chrono::microseconds(200 + rng() % static_cast<std::uint64_t>(window_us - 199)));
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
      "%d kills (window %d us, one save %.0f us): store advanced in %d rounds to sequence "
      "%llu; %d loads found one slot invalid\n",
      rounds, window_us, save_us, advanced, static_cast<unsigned long long>(last_seq),
      one_slot_bad);
  // The writer must really have been writing when it was killed.
  EXPECT_GT(advanced, rounds / 2);
}

}  // namespace odo::calib
