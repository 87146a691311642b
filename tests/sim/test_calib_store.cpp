// The A/B calibration store on the simulated medium: statuses, alternation, and power cuts,
// torn pages and bit flips (exhaustive and seeded random).
#include <gtest/gtest.h>

#include <cstdio>
#include <functional>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "odo/board/stm32_flash.hpp"
#include "odo/calibration/store.hpp"
#include "odo/sim/sim_nv_storage.hpp"
#include "odo/sim/stm32_flash_model.hpp"

namespace odo::calib {
namespace {

using sim::SimMedium;
using sim::SimNvStorage;

CalibrationRecord make_record(int i) {
  CalibrationRecord r;
  r.c_l = 1.0 - 0.001 * i;
  r.c_r = 1.0 + 0.001 * i;
  r.wheelbase = 0.34 - 0.0005 * i;
  if (i % 2 == 1) r.wheel_diameter = 0.15 + 0.0001 * i;
  r.e_s = 1.0 - 0.0002 * i;
  r.time = 1795000000 + i;
  r.method = "umbmark";
  r.e_max_before = 0.2 + 0.01 * i;
  r.e_max_after = 0.01 * (i + 1);
  r.runs = static_cast<std::uint32_t>(10 + i);
  return r;
}

// same_payload: equal apart from the sequence number the store assigns.
bool same_payload(CalibrationRecord a, CalibrationRecord b) {
  a.sequence = b.sequence = 0;
  return a == b;
}

struct MediumSpec {
  const char* name;
  SimMedium kind;
  std::size_t size, erase_block, page;
};
// A 1 KiB EEPROM with 16-byte pages (24C08-like) and a NOR flash with 4 KiB erase blocks.
const MediumSpec kMedia[] = {{"eeprom", SimMedium::kEeprom, 1024, 0, 16},
                             {"flash", SimMedium::kFlash, 16384, 4096, 256}};

SimNvStorage make_medium(const MediumSpec& m) {
  return SimNvStorage(m.kind, m.size, m.erase_block, m.page);
}

TEST(CalibStore, BlankStoreIsUncalibrated) {
  for (const auto& spec : kMedia) {
    auto medium = make_medium(spec);
    auto store = CalibrationStore::create(medium);
    ASSERT_TRUE(store);
    auto l = store->load();
    ASSERT_TRUE(l);
    EXPECT_EQ(l->status, StoreStatus::kUncalibrated) << spec.name;
    EXPECT_FALSE(l->record.has_value());
    EXPECT_TRUE(l->slots[0].blank && l->slots[1].blank);
  }
  // An EEPROM delivered zeroed reads as never written too.
  SimNvStorage zeroed(SimMedium::kEeprom, 256, 0, 8);
  std::fill(zeroed.raw().begin(), zeroed.raw().end(), 0);
  auto l = CalibrationStore::create(zeroed)->load();
  ASSERT_TRUE(l);
  EXPECT_EQ(l->status, StoreStatus::kUncalibrated);
}

TEST(CalibStore, LayoutFollowsTheMedium) {
  auto l = plan_layout(NvGeometry{256, 0, 1});  // 24C02: two 128-byte slots
  ASSERT_TRUE(l);
  EXPECT_EQ(l->slot_size, 128U);
  EXPECT_EQ(l->slot_offset[1], 128U);
  l = plan_layout(NvGeometry{4096, 0, 1});
  ASSERT_TRUE(l);
  EXPECT_EQ(l->slot_size, 512U);
  l = plan_layout(NvGeometry{262144, 16384, 1});  // mtdram 256 KiB, 16 KiB blocks
  ASSERT_TRUE(l);
  EXPECT_EQ(l->slot_size, 16384U);
  EXPECT_EQ(l->slot_offset[1], 16384U);
  auto small = plan_layout(NvGeometry{128, 0, 1});
  ASSERT_FALSE(small);
  EXPECT_NE(small.error().message.find("too small"), std::string::npos);
  EXPECT_FALSE(plan_layout(NvGeometry{16384, 16384, 1}));  // one erase block is not enough
}

TEST(CalibStore, SavesAlternateAndNewerWins) {
  for (const auto& spec : kMedia) {
    auto medium = make_medium(spec);
    auto store = CalibrationStore::create(medium);
    ASSERT_TRUE(store);
    // First save: both slots get sequence 1.
    auto s1 = store->save(make_record(1));
    ASSERT_TRUE(s1) << s1.error().message;
    EXPECT_EQ(*s1, 1U);
    auto l = store->load();
    ASSERT_TRUE(l);
    EXPECT_EQ(l->status, StoreStatus::kOk);
    EXPECT_TRUE(l->slots[0].valid && l->slots[1].valid);
    EXPECT_TRUE(same_payload(*l->record, make_record(1)));
    // Then B, A, B, ...
    for (int i = 2; i <= 5; ++i) {
      auto s = store->save(make_record(i));
      ASSERT_TRUE(s);
      EXPECT_EQ(*s, static_cast<std::uint64_t>(i));
      l = store->load();
      ASSERT_TRUE(l);
      EXPECT_EQ(l->slot, i % 2 == 0 ? 1 : 0) << spec.name << " save " << i;
      EXPECT_EQ(l->record->sequence, static_cast<std::uint64_t>(i));
      EXPECT_TRUE(same_payload(*l->record, make_record(i)));
      // The other slot still holds the previous record.
      EXPECT_EQ(l->slots[static_cast<std::size_t>(1 - l->slot)].sequence,
                static_cast<std::uint64_t>(i - 1));
    }
  }
}

TEST(CalibStore, ClearLeavesAResetMarker) {
  auto medium = make_medium(kMedia[0]);
  auto store = CalibrationStore::create(medium);
  ASSERT_TRUE(store->save(make_record(1)));
  ASSERT_TRUE(store->save(make_record(2)));
  auto c = store->clear();
  ASSERT_TRUE(c);
  EXPECT_EQ(*c, 3U);
  auto l = store->load();
  ASSERT_TRUE(l);
  EXPECT_EQ(l->status, StoreStatus::kUncalibrated);
  ASSERT_TRUE(l->record.has_value());
  EXPECT_TRUE(l->record->cleared);
  auto s = store->save(make_record(4));
  ASSERT_TRUE(s);
  EXPECT_EQ(*s, 4U);
  EXPECT_EQ(store->load()->status, StoreStatus::kOk);
}

TEST(CalibStore, BothSlotsDamagedIsCorruptNeverDefaults) {
  for (const auto& spec : kMedia) {
    auto medium = make_medium(spec);
    auto store = CalibrationStore::create(medium);
    ASSERT_TRUE(store->save(make_record(1)));
    ASSERT_TRUE(store->save(make_record(2)));
    medium.flip_bit(store->layout().slot_offset[0] + 40, 3);
    auto l = store->load();
    ASSERT_TRUE(l);
    EXPECT_EQ(l->status, StoreStatus::kOk);  // B survives
    EXPECT_TRUE(same_payload(*l->record, make_record(2)));
    medium.flip_bit(store->layout().slot_offset[1] + 60, 0);
    l = store->load();
    ASSERT_TRUE(l);
    EXPECT_EQ(l->status, StoreStatus::kCorrupt) << spec.name;
    EXPECT_FALSE(l->record.has_value());
    EXPECT_NE(l->describe().find("CRC mismatch"), std::string::npos) << l->describe();
    // A rejected record leaves the medium byte-for-byte untouched.
    const auto before = medium.raw();
    auto bad = make_record(3);
    bad.c_l = 1.5;
    auto s = store->save(bad);
    ASSERT_FALSE(s);
    EXPECT_NE(s.error().message.find("c_l"), std::string::npos);
    EXPECT_EQ(medium.raw(), before);
    // A new save repairs the store (both slots rewritten).
    ASSERT_TRUE(store->save(make_record(3)));
    l = store->load();
    EXPECT_EQ(l->status, StoreStatus::kOk);
    EXPECT_TRUE(l->slots[0].valid && l->slots[1].valid);
  }
}

// ---- power cuts -----------------------------------------------------------------------------

// Outcome of a load after a fault, checked against the records that were really written.
enum class Outcome { kOld, kNew, kUncalibratedOld, kCorrupt, kWrong };

Outcome classify(const LoadResult& l, const std::optional<CalibrationRecord>& old_rec,
                 const CalibrationRecord& new_rec, std::uint64_t new_seq) {
  if (l.status == StoreStatus::kCorrupt) return Outcome::kCorrupt;
  if (l.status == StoreStatus::kUncalibrated && !l.record)
    return old_rec ? Outcome::kWrong : Outcome::kUncalibratedOld;
  if (!l.record) return Outcome::kWrong;
  if (old_rec && *l.record == *old_rec) return Outcome::kOld;
  if (l.record->sequence == new_seq && same_payload(*l.record, new_rec) &&
      l.record->cleared == new_rec.cleared)
    return Outcome::kNew;
  return Outcome::kWrong;
}

// Prepares a medium holding `prior` saves (0 = blank); returns the newest record, if any.
template <class M>
std::optional<CalibrationRecord> prepare(M& m, int prior) {
  auto store = CalibrationStore::create(m);
  for (int i = 1; i <= prior; ++i) EXPECT_TRUE(store->save(make_record(i)));
  if (prior == 0) return std::nullopt;
  return store->load()->record;
}

// MediumCase: a medium of the fault tests: its name, a fresh one, and the steps one save of a
// record takes on it (erase and program; a medium's steps are its fault model's).
template <class M>
struct MediumCase {
  const char* name;
  std::function<M()> make;
  std::function<std::uint64_t(const StoreLayout&)> save_steps;
};

std::vector<MediumCase<SimNvStorage>> sim_media() {
  std::vector<MediumCase<SimNvStorage>> v;
  for (const auto& spec : kMedia) {
    v.push_back({spec.name, [spec] { return make_medium(spec); },
                 [spec](const StoreLayout& lay) -> std::uint64_t {
                   return (spec.erase_block ? lay.slot_size : 0) + kRecordV1Bytes;
                 }});
  }
  return v;
}

template <class M>
void power_cut_sweep(const std::vector<MediumCase<M>>& media) {
  // For each medium, with and without tearing the page in flight, for a first save (both
  // slots), a save into slot B, a save into slot A and a reset marker: cut the power after
  // every single step (erase and program) of the save. The next load must give the
  // previous record or the new one (for a first save: uncalibrated or the new one).
  std::uint64_t cuts = 0;
  for (const auto& spec : media) {
    for (bool tear : {false, true}) {
      for (int prior : {0, 1, 2}) {
        for (bool clear : {false, true}) {
          if (clear && prior == 0) continue;
          auto base = spec.make();
          const auto old_rec = prepare(base, prior);
          CalibrationRecord new_rec = clear ? CalibrationRecord{} : make_record(prior + 1);
          if (clear) {
            new_rec.cleared = true;
            new_rec.method = "reset";
          }
          const std::uint64_t new_seq = old_rec ? old_rec->sequence + 1 : 1;
          // Length of the whole save in byte steps.
          auto probe = base;
          const auto s0 = probe.steps();
          auto ps = CalibrationStore::create(probe);
          ASSERT_TRUE(clear ? ps->clear() : ps->save(new_rec));
          const std::uint64_t total = probe.steps() - s0;
          ASSERT_GE(total, spec.save_steps(ps->layout()));
          for (std::uint64_t cut = 0; cut <= total; ++cut) {
            auto m = base;
            m.set_tear(tear, cut * 7919 + prior);
            m.cut_power_after(cut);
            auto store = CalibrationStore::create(m);
            auto r = clear ? store->clear() : store->save(new_rec);
            EXPECT_EQ(r.ok(), cut == total);
            m.power_on();
            auto l = store->load();
            ASSERT_TRUE(l);
            const Outcome o = classify(*l, old_rec, new_rec, new_seq);
            ASSERT_TRUE(o == Outcome::kOld || o == Outcome::kNew || o == Outcome::kUncalibratedOld)
                << spec.name << " tear=" << tear << " prior=" << prior << " clear=" << clear
                << " cut after " << cut << " of " << total << ": " << l->describe();
            if (cut == total) {
              EXPECT_EQ(o, Outcome::kNew);
            }
            if (cut == 0) {
              EXPECT_NE(o, Outcome::kNew);
            }
            // The store recovers: the next save succeeds and is what loads.
            if (cut % 97 == 0) {
              ASSERT_TRUE(store->save(make_record(9)));
              EXPECT_TRUE(same_payload(*store->load()->record, make_record(9)));
            }
            ++cuts;
          }
        }
      }
    }
  }
  std::printf("power cuts simulated: %llu\n", static_cast<unsigned long long>(cuts));
}

TEST(CalibStoreFaults, PowerCutAfterEveryByteOfEverySave) {
  power_cut_sweep(sim_media());
}

template <class M>
void random_faults(const std::vector<MediumCase<M>>& media, int n_trials) {
  // n_trials seeded trials (about 3 in 4 of them single-fault; 16,000 on the simulated media).
  // Single-fault trials (a torn save, or bit flips confined to one slot, or both in the slot being
  // written) must load the previous or the new record. Two-slot trials (bit flips in both slots)
  // may be reported corrupt, but must never load anything that was not written.
  std::mt19937_64 rng(20261122);
  int wrong = 0, corrupt_single = 0, corrupt_double = 0, trials = 0, single = 0;
  int n_old = 0, n_new = 0;
  for (int t = 0; t < n_trials; ++t) {
    const auto& spec = media[rng() % media.size()];
    auto m = spec.make();
    const int prior = static_cast<int>(rng() % 4);
    const auto old_rec = prepare(m, prior);
    const CalibrationRecord new_rec = make_record(prior + 1);
    const std::uint64_t new_seq = old_rec ? old_rec->sequence + 1 : 1;
    auto store = CalibrationStore::create(m);
    const StoreLayout lay = store->layout();
    const int kind = static_cast<int>(rng() % 4);  // 0 torn, 1 flips one slot, 2 torn+flips, 3 both
    int target = -1;                               // the slot the save writes
    if (old_rec) target = 1 - store->load()->slot;
    if (kind == 0 || kind == 2) {
      m.set_tear(true, rng());
      const std::uint64_t span = spec.save_steps(lay);
      const std::uint64_t cut = rng() % (old_rec ? span : 2 * span);
      m.cut_power_after(cut);
      (void)store->save(new_rec);
      m.power_on();
      // A first save writes A then B: the cut tore the slot it was writing.
      if (!old_rec) target = cut < span ? 0 : 1;
    } else {
      EXPECT_TRUE(store->save(new_rec));
    }
    const int flips = 1 + static_cast<int>(rng() % 8);
    auto flip_in = [&](int slot) {
      for (int f = 0; f < flips; ++f)
        m.flip_bit(lay.slot_offset[static_cast<std::size_t>(slot)] + rng() % kRecordV1Bytes,
                   static_cast<int>(rng() % 8));
    };
    if (kind == 1) flip_in(static_cast<int>(rng() % 2));
    if (kind == 2) flip_in(target);
    if (kind == 3) {
      flip_in(0);
      flip_in(1);
    }
    auto l = store->load();
    ASSERT_TRUE(l);
    const Outcome o = classify(*l, old_rec, new_rec, new_seq);
    if (o == Outcome::kWrong) ++wrong;
    if (o == Outcome::kOld) ++n_old;
    if (o == Outcome::kNew) ++n_new;
    if (o == Outcome::kCorrupt) (kind == 3 ? corrupt_double : corrupt_single)++;
    EXPECT_TRUE(o != Outcome::kCorrupt || kind == 3)
        << "trial " << t << " kind " << kind << " prior " << prior << ": " << l->describe();
    ++trials;
    if (kind != 3) ++single;
  }
  std::printf(
      "random trials: %d (single-fault %d), loaded old %d, new %d, wrong %d, corrupt (one slot "
      "hit) %d, "
      "detected corrupt (both slots hit) %d\n",
      trials, single, n_old, n_new, wrong, corrupt_single, corrupt_double);
  EXPECT_EQ(wrong, 0);
  EXPECT_EQ(corrupt_single, 0);
  EXPECT_GE(single, n_trials / 8 * 5);  // three in four trials are single-fault
}

TEST(CalibStoreFaults, SeededRandomBitFlipsAndTornWrites) {
  random_faults(sim_media(), 16000);
}

// ---- the same faults on the STM32F4's flash (issue 36) ---------------------------------------

// F4FlashMedium: the store on the microcontroller's stack: board::FlashNvStorage over the
// register-level flash driver over sim_hal's flash-controller model, sectors 2 and 3 (16 KB each,
// the F405's smallest; the store's slots are their first 512 bytes). Its steps are the model's: a
// sector erase, a programmed word. Copyable as SimNvStorage is (a copy's driver talks to the copy's
// model).
class F4FlashMedium final : public NvStorage {
 public:
  F4FlashMedium() : model_(0x08008000, 16384, 2, 2), flash_(model_), nv_(flash_, 2, 2) {}
  F4FlashMedium(const F4FlashMedium& o) : model_(o.model_), flash_(model_), nv_(flash_, 2, 2) {}
  F4FlashMedium& operator=(const F4FlashMedium&) = delete;
  NvGeometry geometry() const noexcept override { return nv_.geometry(); }
  Status read(std::size_t off, std::span<std::uint8_t> out) override { return nv_.read(off, out); }
  Status write(std::size_t off, std::span<const std::uint8_t> d) override {
    return nv_.write(off, d);
  }
  Status erase(std::size_t off, std::size_t len) override { return nv_.erase(off, len); }
  void cut_power_after(std::uint64_t n) noexcept { model_.cut_power_after(n); }
  void set_tear(bool on, std::uint64_t seed) noexcept { model_.set_tear(on, seed); }
  void power_on() noexcept { model_.power_on(); }
  // flip_bit: bit `bit` of the medium's byte `byte` (block i is the start of sector 2 + i).
  void flip_bit(std::size_t byte, int bit) noexcept {
    const std::size_t w = board::FlashNvStorage::kWindow;
    model_.flip_bit(byte / w * 16384 + byte % w, bit);
  }
  std::uint64_t steps() const noexcept { return model_.steps(); }

 private:
  sim::Stm32FlashModel model_;
  board::Stm32Flash flash_;
  board::FlashNvStorage nv_;
};

std::vector<MediumCase<F4FlashMedium>> f4_media() {
  // One save: the slot's sector erase, then the record's words.
  return {{"stm32f4-flash", [] { return F4FlashMedium(); },
           [](const StoreLayout&) -> std::uint64_t { return 1 + (kRecordV1Bytes + 3) / 4; }}};
}

TEST(CalibStoreFaults, Stm32F4FlashPowerCutAfterEveryWord) {
  power_cut_sweep(f4_media());
}

TEST(CalibStoreFaults, Stm32F4FlashSeededRandomBitFlipsAndTornWrites) {
  // 4000: each trial erases 16 KB sectors through the register model (16000 took 25 s).
  random_faults(f4_media(), 4000);
}

TEST(CalibStoreF4Flash, DriverProgramsErasesAndReportsErrors) {
  sim::Stm32FlashModel model(0x08008000, 16384, 2, 2);
  board::Stm32Flash flash(model);
  // Words only clear bits: 0xFFFF00FF then 0x0F0F0F0F leaves 0x0F0F000F.
  const std::uint32_t w[] = {0xFFFF00FFu, 0x12345678u};
  ASSERT_TRUE(flash.program(0x08008000, w));
  const std::uint32_t w2[] = {0x0F0F0F0Fu};
  ASSERT_TRUE(flash.program(0x08008000, w2));
  EXPECT_EQ(flash.read_word(0x08008000), 0x0F0F000Fu);
  EXPECT_EQ(flash.read_word(0x08008004), 0x12345678u);
  EXPECT_EQ(model.read(sim::Stm32FlashModel::kCr) >> 31, 1u);  // locked again after each operation
  ASSERT_TRUE(flash.erase_sector(2));
  EXPECT_EQ(flash.read_word(0x08008000), 0xFFFFFFFFu);
  // Sector 4 is not in the model (as if write-protected): WRPERR is an error naming the flag.
  auto e = flash.erase_sector(4);
  ASSERT_FALSE(e);
  EXPECT_NE(e.error().message.find("WRPERR"), std::string::npos) << e.error().message;
  EXPECT_FALSE(flash.program(0x08008002, w2));  // unaligned: refused before the controller
  EXPECT_EQ(board::Stm32Flash::sector_base(10), 0x080C0000u);  // RM0090 table 5
  EXPECT_EQ(board::Stm32Flash::sector_size(4), 65536u);
}

}  // namespace
}  // namespace odo::calib
