// Hctl1100Model: register-level model of the position-monitoring part of an HCTL-1100 motion
// control chip: the 4x quadrature decoder and the 24-bit two's-complement actual position
// counter read through the 8-bit registers R12H (MSB), R13H and R14H (LSB).
//
// Byte latching: we could not confirm from a data sheet how the chip keeps the three bytes of
// one reading together, so the model offers both behaviours: kNone (every register read returns
// the live byte, so a multi-byte read can tear while the wheel moves) and kLsbLatch (reading
// R14H latches R12H and R13H until R12H has been read). The driver's read protocol
// (drivers/hctl1100_encoder) is correct against both.
#pragma once

#include <array>
#include <cstdint>

#include "odo/hal/parallel_bus.hpp"
#include "odo/hal/quadrature.hpp"

namespace odo::sim {

class Hctl1100Model {
 public:
  static constexpr std::uint8_t kRegPosMsb = 0x12;  // R12H: bits 23..16
  static constexpr std::uint8_t kRegPosMid = 0x13;  // R13H: bits 15..8
  static constexpr std::uint8_t kRegPosLsb = 0x14;  // R14H: bits 7..0
  static constexpr int kBits = 24;

  enum class Latch { kNone, kLsbLatch };

  explicit Hctl1100Model(Latch latch = Latch::kNone) : latch_(latch) {}

  // follow: the encoder disc moved to cumulative position `counts` (4x counts of the simulated
  // wheel); every intermediate A/B state is presented to the decoder, as the chip's input
  // sampling does when the edge rate is within its limit.
  void follow(std::int64_t counts) noexcept;
  // sample: presents one raw A/B state to the decoder (fault injection: a state two steps away
  // is an illegal transition, which the chip cannot count).
  void sample(QuadState s) noexcept;
  // read_register: one bus read of `reg`; unknown registers read as 0.
  std::uint8_t read_register(std::uint8_t reg) noexcept;

  // position: the 24-bit counter, sign-extended.
  std::int32_t position() const noexcept;
  // preset: sets the counter (e.g. close to the wrap) without moving the disc.
  void preset(std::int32_t value) noexcept { counter_ = static_cast<std::uint32_t>(value) & kMask; }
  // inject_jump: adds `delta` counts to the counter at once (electrical noise, a chip reset).
  void inject_jump(std::int32_t delta) noexcept { preset(position() + delta); }
  // illegal_transitions: transitions the decoder saw with both channels changed.
  std::uint64_t illegal_transitions() const noexcept { return illegal_; }
  std::int64_t disc_position() const noexcept { return disc_; }

 private:
  static constexpr std::uint32_t kMask = 0xFFFFFFu;
  Latch latch_;
  std::uint32_t counter_ = 0;  // low 24 bits used
  QuadState state_ = quad_state_at(0);
  std::int64_t disc_ = 0;  // where the disc is, in counts
  bool latched_ = false;
  std::uint32_t latch_value_ = 0;
  std::uint64_t illegal_ = 0;
};

// BusCycleHook: lets a simulation move the world on between bus cycles, so that a multi-byte
// read sees the counter change underneath it as real hardware does.
class BusCycleHook {
 public:
  virtual ~BusCycleHook() = default;
  virtual void on_bus_cycle() noexcept = 0;
};

// SimHctlBus: the parallel bus with one Hctl1100Model per chip select; can fail reads.
class SimHctlBus final : public ParallelBus {
 public:
  static constexpr int kMaxUnits = 4;
  // units: the models on this bus (not owned), unit i on chip select i.
  SimHctlBus(Hctl1100Model* unit0, Hctl1100Model* unit1 = nullptr);

  BusRead read_register(int unit, std::uint8_t reg) noexcept override;
  int units() const noexcept override { return n_; }

  // set_hook: called before every bus cycle (null: none).
  void set_hook(BusCycleHook* hook) noexcept { hook_ = hook; }
  // fail_next: the next `n` read cycles fail (a bus fault: the lines cannot be driven).
  void fail_next(int n) noexcept { fail_ = n; }
  std::uint64_t cycles() const noexcept { return cycles_; }

 private:
  std::array<Hctl1100Model*, kMaxUnits> units_{};
  int n_ = 0;
  BusCycleHook* hook_ = nullptr;
  int fail_ = 0;
  std::uint64_t cycles_ = 0;
};

}  // namespace odo::sim
