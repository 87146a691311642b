// The storage backends on real kernel devices, inside the VM harness: a RAM-backed MTD flash
// partition (mtdram, /dev/mtdN: MEMGETINFO, MEMERASE) and a real at24 EEPROM exposed by the
// nvmem subsystem (a 24C02 on the i2c-stub SMBus adapter), plus an nvmem-style plain file.
#include <fcntl.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include <nlohmann/json.hpp>

#include "../unit/calib_kill_loop.hpp"
#include "kernel_env.hpp"
#include "odo/calibration/store.hpp"
#include "odo/drivers/nv_storage.hpp"

namespace odo::test {
namespace {

using calib::CalibrationRecord;
using calib::CalibrationStore;
using calib::StoreStatus;

// mtd_device: loads mtdram (256 KiB, 16 KiB erase blocks) and returns its /dev/mtdN.
std::string mtd_device() {
  if (run("grep -q 'mtdram test device' /proc/mtd || modprobe mtdram total_size=256 "
          "erase_size=16") != 0)
    return "";
  std::ifstream in("/proc/mtd");
  std::string line;
  while (std::getline(in, line))
    if (line.find("mtdram test device") != std::string::npos)
      return "/dev/" + line.substr(0, line.find(':'));
  return "";
}

// at24_nvmem: a 24C02 EEPROM (256 bytes) bound by the at24 driver on the i2c-stub adapter;
// returns its nvmem attribute.
std::string at24_nvmem() {
  const std::string bus = i2c_stub_bus();
  if (bus.empty()) return "";
  const std::string setup =
      "sh -c 'set -e; modprobe at24;"
      "ls -d /sys/bus/nvmem/devices/*-0050*/nvmem >/dev/null 2>&1 && exit 0;"
      "echo 24c02 0x50 > /sys/bus/i2c/devices/" +
      bus + "/new_device; sleep 0.3'";
  if (run(setup) != 0) return "";
  for (const auto& e : std::filesystem::directory_iterator("/sys/bus/nvmem/devices"))
    if (e.path().filename().string().find("-0050") != std::string::npos)
      return (e.path() / "nvmem").string();
  return "";
}

std::vector<std::uint8_t> device_bytes(const std::string& path, std::size_t n) {
  std::vector<std::uint8_t> b(n);
  const int fd = open(path.c_str(), O_RDONLY);
  EXPECT_GE(fd, 0);
  EXPECT_EQ(pread(fd, b.data(), n, 0), static_cast<ssize_t>(n));
  close(fd);
  return b;
}

std::string capture(const std::string& cmd, int& rc) {
  std::string out;
  FILE* p = popen(cmd.c_str(), "r");
  char buf[512];
  while (p && fgets(buf, sizeof buf, p)) out += buf;
  const int st = p ? pclose(p) : -1;
  rc = WIFEXITED(st) ? WEXITSTATUS(st) : 128;
  return out;
}

std::unique_ptr<NvStorage> open_mtd(const std::string& p) {
  auto m = drivers::MtdStorage::open(p);
  if (!m) _exit(5);
  return std::move(m).value();
}
std::unique_ptr<NvStorage> open_nvmem(const std::string& p) {
  auto m = drivers::NvmemStorage::open(p);
  if (!m) _exit(5);
  return std::move(m).value();
}

// Every truncated write of a record into the slot being replaced (what a power cut while
// programming leaves) loads the previous record; only the complete write loads the new one.
void truncated_writes_load_old(NvStorage& medium) {
  auto store = CalibrationStore::create(medium);
  ASSERT_TRUE(store);
  const auto lay = store->layout();
  const auto g = medium.geometry();
  for (int round = 0; round < 2; ++round) {
    auto old = store->load();
    ASSERT_TRUE(old && old->status == StoreStatus::kOk);
    const int target = 1 - old->slot;
    CalibrationRecord next = calib::record_for(old->record->sequence + 1);
    next.sequence = old->record->sequence + 1;
    auto bytes = calib::encode_record(next);
    ASSERT_TRUE(bytes);
    for (std::size_t k = 0; k <= bytes->size(); ++k) {
      const std::size_t off = lay.slot_offset[static_cast<std::size_t>(target)];
      if (g.erase_block > 0) {
        ASSERT_TRUE(medium.erase(off, lay.slot_size));
      } else {
        // An EEPROM slot still holds the record before last; overwrite its first k bytes only.
      }
      ASSERT_TRUE(medium.write(off, std::span<const std::uint8_t>(bytes->data(), k)));
      auto l = store->load();
      ASSERT_TRUE(l);
      ASSERT_EQ(l->status, StoreStatus::kOk) << "k=" << k << ": " << l->describe();
      // A prefix that already completes the record (the old bytes after it happen to match,
      // e.g. the last CRC byte on an EEPROM) is the new record: old or new, nothing else.
      if (k == 0) {
        ASSERT_EQ(*l->record, *old->record);
      }
      if (k == bytes->size()) {
        ASSERT_EQ(*l->record, next);
      }
      ASSERT_TRUE(*l->record == *old->record || *l->record == next) << "k=" << k;
    }
  }
}

TEST(CalibMtd, GeometryFromMemgetinfo) {
  ODO_REQUIRE_VM();
  const std::string dev = mtd_device();
  ASSERT_FALSE(dev.empty()) << "mtdram did not load";
  auto m = drivers::MtdStorage::open(dev);
  ASSERT_TRUE(m) << m.error().message;
  const NvGeometry g = (*m)->geometry();
  EXPECT_EQ(g.size, 256U * 1024U);
  EXPECT_EQ(g.erase_block, 16U * 1024U);
  EXPECT_EQ(g.write_unit, 1U);
  auto bad = drivers::MtdStorage::open("/dev/null");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message.find("MEMGETINFO"), std::string::npos);
}

TEST(CalibMtd, EraseSaveAlternateCorrupt) {
  ODO_REQUIRE_VM();
  const std::string dev = mtd_device();
  ASSERT_FALSE(dev.empty());
  auto m = drivers::MtdStorage::open(dev);
  ASSERT_TRUE(m);
  NvStorage& medium = **m;
  ASSERT_TRUE(medium.erase(0, medium.geometry().size));  // MEMERASE of all 16 blocks
  EXPECT_EQ(device_bytes(dev, 64), std::vector<std::uint8_t>(64, 0xFF));
  EXPECT_FALSE(medium.erase(100, 16384));  // unaligned erase refused
  auto store = CalibrationStore::create(medium);
  ASSERT_TRUE(store);
  EXPECT_EQ(store->layout().slot_size, 16384U);
  EXPECT_EQ(store->load()->status, StoreStatus::kUncalibrated);
  for (std::uint64_t i = 1; i <= 5; ++i) {
    auto s = store->save(calib::record_for(i));
    ASSERT_TRUE(s) << s.error().message;
    auto l = store->load();
    ASSERT_EQ(l->status, StoreStatus::kOk);
    EXPECT_EQ(l->record->sequence, i);
    EXPECT_TRUE(calib::consistent(*l->record) || i == 1);
  }
  // The device really holds both slots: magic at 0 and at 16384.
  const auto raw = device_bytes(dev, 16384 + 4);
  EXPECT_EQ(std::string(raw.begin(), raw.begin() + 4), "ODCL");
  EXPECT_EQ(std::string(raw.begin() + 16384, raw.end()), "ODCL");
  // Programming zeros over a slot (flash can clear bits without an erase) damages it: the
  // other slot wins; both damaged is "corrupt".
  const std::uint8_t zeros[8] = {};
  ASSERT_TRUE(medium.write(40, zeros));
  auto l = store->load();
  EXPECT_EQ(l->status, StoreStatus::kOk);
  EXPECT_EQ(l->slot, 1);
  ASSERT_TRUE(medium.write(16384 + 40, zeros));
  l = store->load();
  EXPECT_EQ(l->status, StoreStatus::kCorrupt) << l->describe();
  ASSERT_TRUE(store->save(calib::record_for(7)));  // repairs by rewriting both slots
  EXPECT_EQ(store->load()->status, StoreStatus::kOk);
  truncated_writes_load_old(medium);
}

TEST(CalibMtd, SigkilledWriterOnTheDevice) {
  ODO_REQUIRE_VM();
  const std::string dev = mtd_device();
  ASSERT_FALSE(dev.empty());
  {
    auto m = drivers::MtdStorage::open(dev);
    ASSERT_TRUE(m);
    ASSERT_TRUE((*m)->erase(0, 2 * 16384));
  }
  // Under TCG a 16 KiB erase takes milliseconds: give the writer up to 100 ms per round.
  calib::kill_loop(open_mtd, dev, 200, 7, 100000);
}

TEST(CalibMtd, OdomctlOnTheDevice) {
  ODO_REQUIRE_VM();
  const std::string dev = mtd_device();
  ASSERT_FALSE(dev.empty());
  const std::string ctl = std::string(ODOMCTL_PATH) + " calib ";
  int rc = 0;
  EXPECT_EQ(run(ctl + "reset --store " + dev + " >/dev/null"), 0);
  capture(ctl + "set --store " + dev + " --cl 0.998 --cr 1.002 --wheelbase 0.337", rc);
  ASSERT_EQ(rc, 0);
  auto j = nlohmann::json::parse(capture(ctl + "show --json --store " + dev, rc));
  EXPECT_EQ(rc, 0);
  EXPECT_EQ(j["status"], "ok");
  EXPECT_EQ(j["c_l"], 0.998);
  EXPECT_EQ(j["wheelbase"], 0.337);
  // A rejected value leaves the flash byte-for-byte untouched.
  const auto before = device_bytes(dev, 2 * 16384);
  const std::string msg = capture(ctl + "set --store " + dev + " --wheelbase 30 2>&1", rc);
  EXPECT_EQ(rc, 2);
  EXPECT_NE(msg.find("wheelbase"), std::string::npos) << msg;
  EXPECT_NE(msg.find("[0.01, 20]"), std::string::npos) << msg;
  EXPECT_EQ(device_bytes(dev, 2 * 16384), before);
}

TEST(CalibAt24, RealEepromThroughNvmem) {
  ODO_REQUIRE_VM();
  const std::string path = at24_nvmem();
  ASSERT_FALSE(path.empty()) << "i2c-stub / at24 did not give an nvmem device";
  auto m = drivers::NvmemStorage::open(path);
  ASSERT_TRUE(m) << m.error().message;
  NvStorage& medium = **m;
  EXPECT_EQ(medium.geometry().size, 256U);
  EXPECT_EQ(medium.geometry().erase_block, 0U);
  ASSERT_TRUE(medium.erase(0, 256));  // 0xFF everywhere, written byte by byte by at24
  auto store = CalibrationStore::create(medium);
  ASSERT_TRUE(store);
  EXPECT_EQ(store->layout().slot_size, 128U);
  EXPECT_EQ(store->load()->status, StoreStatus::kUncalibrated);
  for (std::uint64_t i = 1; i <= 4; ++i) ASSERT_TRUE(store->save(calib::record_for(i)));
  auto l = store->load();
  ASSERT_EQ(l->status, StoreStatus::kOk);
  EXPECT_EQ(l->record->sequence, 4U);
  EXPECT_EQ(l->slot, 1);
  truncated_writes_load_old(medium);
}

TEST(CalibAt24, SigkilledWriterOnTheEeprom) {
  ODO_REQUIRE_VM();
  const std::string path = at24_nvmem();
  ASSERT_FALSE(path.empty());
  calib::kill_loop(open_nvmem, path, 200, 11, 100000);
}

TEST(CalibNvmemFile, OdomctlOnAFixedSizeFile) {
  ODO_REQUIRE_VM();
  const std::string path = "/tmp/odo_nvmem_file";
  ASSERT_EQ(run("head -c 256 /dev/zero > " + path), 0);
  const std::string ctl = std::string(ODOMCTL_PATH) + " calib ";
  const std::string store = " --backend nvmem --store " + path;
  int rc = 0;
  auto j = nlohmann::json::parse(capture(ctl + "show --json" + store, rc));
  EXPECT_EQ(rc, 0);
  EXPECT_EQ(j["status"], "uncalibrated");  // a zeroed EEPROM was never written
  capture(ctl + "set --cl 0.999 --wheel-diameter 0.1502" + store, rc);
  ASSERT_EQ(rc, 0);
  j = nlohmann::json::parse(capture(ctl + "show --json" + store, rc));
  EXPECT_EQ(j["status"], "ok");
  EXPECT_EQ(j["wheel_diameter"], 0.1502);
  EXPECT_EQ(std::filesystem::file_size(path), 256U);
  const auto before = device_bytes(path, 256);
  const std::string msg = capture(ctl + "set --cr 0.5" + store + " 2>&1", rc);
  EXPECT_EQ(rc, 2);
  EXPECT_NE(msg.find("c_r"), std::string::npos);
  EXPECT_EQ(device_bytes(path, 256), before);
  // A missing nvmem device is an error naming it, not an empty store.
  capture(ctl + "show --backend nvmem --store /tmp/does-not-exist 2>&1", rc);
  EXPECT_EQ(rc, 1);
}

}  // namespace
}  // namespace odo::test
