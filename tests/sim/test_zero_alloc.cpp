// The loop allocates nothing after start-up: this binary replaces every global operator new and
// delete (and, without sanitizers, the malloc family) with counting versions, then runs the
// firmware's loop on the simulated robot for 200,000 ticks.
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <memory>
#include <new>
#include <thread>

#include <fcntl.h>
#include <unistd.h>

#include "odo/drivers/serial_port.hpp"
#include "odo/firmware/can_link.hpp"
#include "odo/firmware/config.hpp"
#include "odo/firmware/rig.hpp"
#include "odo/firmware/state_persist.hpp"
#include "odo/loop/loop.hpp"
#include "odo/protocol/can_protocol.hpp"
#include "odo/protocol/serial_counts_source.hpp"
#include "odo/sim/sim_can_bus.hpp"
#include "odo/sim/sim_run.hpp"
#include "odo/sim/truth.hpp"

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define ODO_COUNT_MALLOC 0
#else
#define ODO_COUNT_MALLOC 1
#endif

#if ODO_COUNT_MALLOC
extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void __libc_free(void*);
void* __libc_memalign(std::size_t, std::size_t);
void* __libc_valloc(std::size_t);
void* __libc_pvalloc(std::size_t);
}
#endif

namespace {

// The allocator underneath operator new: glibc's own when malloc itself is replaced (so one
// allocation is counted once), the sanitizer's malloc otherwise.
#if ODO_COUNT_MALLOC
void* raw_malloc(std::size_t n) noexcept {
  return __libc_malloc(n);
}
void* raw_memalign(std::size_t a, std::size_t n) noexcept {
  return __libc_memalign(a, n);
}
void raw_free(void* p) noexcept {
  __libc_free(p);
}
#else
void* raw_malloc(std::size_t n) noexcept {
  return std::malloc(n);
}
void* raw_memalign(std::size_t a, std::size_t n) noexcept {
  return std::aligned_alloc(a, n);
}
// GCC 12 reports this free() as freeing operator new's memory once the replaced operators
// below are inlined at -O2 (-Wmismatched-new-delete): it does not see that they allocate with
// raw_malloc. A false positive of replacing the global allocator.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void raw_free(void* p) noexcept {
  std::free(p);
}
#pragma GCC diagnostic pop
#endif

std::atomic<bool> g_armed{false};
std::atomic<std::uint64_t> g_allocs{0};  // allocations while armed
std::atomic<std::uint64_t> g_frees{0};   // deallocations while armed

inline void note_alloc() noexcept {
  if (g_armed.load(std::memory_order_relaxed)) g_allocs.fetch_add(1, std::memory_order_relaxed);
}
inline void note_free(void* p) noexcept {
  if (p != nullptr && g_armed.load(std::memory_order_relaxed))
    g_frees.fetch_add(1, std::memory_order_relaxed);
}

void* checked(void* p) {
  if (p == nullptr) throw std::bad_alloc();
  return p;
}
void* aligned(std::size_t n, std::align_val_t a) noexcept {
  const auto al = static_cast<std::size_t>(a);
  return raw_memalign(al, (n + al - 1) / al * al);
}

}  // namespace

#if ODO_COUNT_MALLOC
// The malloc family, forwarded to glibc's own implementation. (Under AddressSanitizer or
// ThreadSanitizer their interceptors own malloc, and replacing it under them crashes the
// runtime at start-up; then only operator new/delete are counted.)
extern "C" {
void* malloc(std::size_t n) {
  note_alloc();
  return __libc_malloc(n);
}
void* calloc(std::size_t n, std::size_t m) {
  note_alloc();
  return __libc_calloc(n, m);
}
void* realloc(void* p, std::size_t n) {
  note_alloc();
  return __libc_realloc(p, n);
}
void* reallocarray(void* p, std::size_t n, std::size_t m) {
  note_alloc();
  if (m != 0 && n > SIZE_MAX / m) return nullptr;
  return __libc_realloc(p, n * m);
}
void free(void* p) {
  note_free(p);
  __libc_free(p);
}
void* aligned_alloc(std::size_t a, std::size_t n) {
  note_alloc();
  return __libc_memalign(a, n);
}
void* memalign(std::size_t a, std::size_t n) {
  note_alloc();
  return __libc_memalign(a, n);
}
int posix_memalign(void** out, std::size_t a, std::size_t n) {
  note_alloc();
  void* p = __libc_memalign(a, n);
  if (p == nullptr) return ENOMEM;
  *out = p;
  return 0;
}
void* valloc(std::size_t n) {
  note_alloc();
  return __libc_valloc(n);
}
void* pvalloc(std::size_t n) {
  note_alloc();
  return __libc_pvalloc(n);
}
}
#endif

// Every replaceable global allocation and deallocation function (C++17/20).
void* operator new(std::size_t n) {
  note_alloc();
  return checked(raw_malloc(n == 0 ? 1 : n));
}
void* operator new[](std::size_t n) {
  note_alloc();
  return checked(raw_malloc(n == 0 ? 1 : n));
}
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  note_alloc();
  return raw_malloc(n == 0 ? 1 : n);
}
void* operator new[](std::size_t n, const std::nothrow_t&) noexcept {
  note_alloc();
  return raw_malloc(n == 0 ? 1 : n);
}
void* operator new(std::size_t n, std::align_val_t a) {
  note_alloc();
  return checked(aligned(n, a));
}
void* operator new[](std::size_t n, std::align_val_t a) {
  note_alloc();
  return checked(aligned(n, a));
}
void* operator new(std::size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
  note_alloc();
  return aligned(n, a);
}
void* operator new[](std::size_t n, std::align_val_t a, const std::nothrow_t&) noexcept {
  note_alloc();
  return aligned(n, a);
}
void operator delete(void* p) noexcept {
  note_free(p);
  raw_free(p);
}
void operator delete[](void* p) noexcept {
  note_free(p);
  raw_free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  note_free(p);
  raw_free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  note_free(p);
  raw_free(p);
}
void operator delete(void* p, const std::nothrow_t&) noexcept {
  note_free(p);
  raw_free(p);
}
void operator delete[](void* p, const std::nothrow_t&) noexcept {
  note_free(p);
  raw_free(p);
}
void operator delete(void* p, std::align_val_t) noexcept {
  note_free(p);
  raw_free(p);
}
void operator delete[](void* p, std::align_val_t) noexcept {
  note_free(p);
  raw_free(p);
}
void operator delete(void* p, std::size_t, std::align_val_t) noexcept {
  note_free(p);
  raw_free(p);
}
void operator delete[](void* p, std::size_t, std::align_val_t) noexcept {
  note_free(p);
  raw_free(p);
}
void operator delete(void* p, std::align_val_t, const std::nothrow_t&) noexcept {
  note_free(p);
  raw_free(p);
}
void operator delete[](void* p, std::align_val_t, const std::nothrow_t&) noexcept {
  note_free(p);
  raw_free(p);
}

namespace odo::test {
namespace {

// Counting window: armed from construction to disarm(); counts are read after disarming, so
// the test framework's own allocations (messages, results) are never counted.
struct AllocWindow {
  AllocWindow() {
    g_allocs = 0;
    g_frees = 0;
    g_armed = true;
  }
  void disarm() { g_armed = false; }
  ~AllocWindow() { g_armed = false; }
};

void escape(void* p) {
  asm volatile("" : : "g"(p) : "memory");
}

TEST(ZeroAlloc, CountersSeeEveryKindOfAllocation) {
  // The counters must see what they are meant to see, or a zero below would prove nothing.
  AllocWindow w;
  auto a = std::make_unique<int>(1);
  escape(a.get());
  auto b = std::make_unique<double[]>(3);
  escape(b.get());
  struct alignas(64) Wide {
    double v[8];
  };
  auto c = std::make_unique<Wide>();
  escape(c.get());
  a.reset();
  b.reset();
  c.reset();
#if ODO_COUNT_MALLOC
  void* (*volatile m)(std::size_t) = &std::malloc;  // through a pointer: not elided
  void* p = m(40);
  escape(p);
  std::free(p);
#endif
  w.disarm();
  EXPECT_EQ(g_allocs.load(), 3u + ODO_COUNT_MALLOC);
  EXPECT_EQ(g_frees.load(), 3u + ODO_COUNT_MALLOC);
}

// An observer that breaks the rule: allocates on every tick.
struct AllocatingObserver final : loop::TickObserver {
  void on_tick(const loop::LoopSnapshot& s) noexcept override {
    auto* p = new std::uint64_t(s.tick);
    escape(p);
    delete p;
  }
};

TEST(ZeroAlloc, AnAllocationInsideATickIsCaught) {
  // The same counting window around ticks sees an allocation made on the loop path.
  fw::Config cfg = fw::default_config();
  auto kin = Kinematics::create(cfg.robot);
  auto rig = fw::Rig::create(cfg, *kin, true);
  ASSERT_TRUE(rig.ok());
  auto loop =
      loop::OdometryLoop::create(loop::LoopConfig{}, *kin, rig->encoder(), rig->clock()).value();
  AllocatingObserver bad;
  loop->add_observer(&bad);
  loop->start();
  AllocWindow w;
  for (int i = 0; i < 10; ++i) loop->tick();
  w.disarm();
  EXPECT_EQ(g_allocs.load(), 10u);
  EXPECT_EQ(g_frees.load(), 10u);
}

TEST(ZeroAlloc, CovarianceMergedOverTicksAllocatesNothing) {
  // error_model.covariance_ticks = 10 at 1 kHz (the microcontroller's setting): the groups of
  // ticks, their early closes at the corners' reversing wheels and a set pose's drop of the
  // pending ticks, over both squares.
  fw::Config cfg = fw::default_config();
  cfg.sim.scenario = fw::SimScenario::kSquares;
  auto kin = Kinematics::create(cfg.robot);
  auto rig = fw::Rig::create(cfg, *kin, true);
  ASSERT_TRUE(rig.ok()) << rig.error().message;
  loop::LoopConfig lc;
  lc.rate_hz = 1000.0;
  lc.error_model.covariance_ticks = 10;
  auto loop = loop::OdometryLoop::create(lc, *kin, rig->encoder(), rig->clock()).value();
  loop->start();
  AllocWindow w;
  for (int i = 0; i < 200'000; ++i) {
    loop->tick();
    if (i == 150'005) {
      ASSERT_TRUE(loop->post(loop::SetPose{{0.0, 0.0, 0.0}}));
    }
  }
  w.disarm();
  EXPECT_EQ(g_allocs.load(), 0u);
  EXPECT_GT(loop->odometry().covariance()[8], 0.0);  // the groups were propagated
}

TEST(ZeroAlloc, SlipIntervalsWithAndWithoutAGyroAllocateNothing) {
  // Two wheels per side (issue 38): the combiner on every read, and the slip path (extra travel
  // variance; with a gyro, the forced gyro heading) on the ticks of 20 injected lifted wheels, a
  // counter fault among them, at 1 kHz.
  const sim::RobotGeometry geo;
  const Kinematics k = Kinematics::create(sim::nominal_params(0.15, geo.wheelbase, geo)).value();
  const sim::GyroModel model = sim::consumer_gyro();
  const sim::SideWheelsSimParams wheels;
  for (const bool gyro : {false, true}) {
    sim::SimRunOptions o;
    o.loop.rate_hz = 1000.0;
    o.gyro = gyro ? &model : nullptr;
    o.side_wheels = &wheels;
    const double w = 0.3 / 0.075;
    auto run = sim::SimRun::create(geo, k, sim::Scenario{{45.0, w, 0.9 * w}}, o).value();
    sim::SideWheelsSim& m = run->side_wheels()->model();
    loop::OdometryLoop& loop = run->loop();
    loop.start();
    AllocWindow win;
    for (int t = 0; t < 44'000; ++t) {
      // Fault i over [2 + 2i, 2.5 + 2i) s, injected (one per wheel at a time) just before.
      if (t % 2000 == 1900 && t / 2000 < 20) {
        const int i = t / 2000;
        const TimeNs at = from_seconds(2.0 + 2.0 * i);
        m.inject(i % 2, i % 4 < 2 ? 0 : 1,
                 i == 7 ? sim::WheelFault::kCounter : sim::WheelFault::kUnloaded, at,
                 at + from_seconds(0.5));
      }
      loop.tick();
    }
    win.disarm();
    EXPECT_EQ(g_allocs.load(), 0u) << (gyro ? "with the gyro" : "odometry alone");
    EXPECT_EQ(g_frees.load(), 0u);
    const EncoderCounters& c = loop.snapshot().encoder_counters;
    EXPECT_EQ(c.slip_events, 19u) << (gyro ? "with the gyro" : "odometry alone");  // the path ran
    EXPECT_EQ(c.wheel_drops, 1u);
    // With the gyro the flagged ticks took the fused slip path (the gyro's own disagreement
    // usually opens the interval first, so it counts the event).
    if (gyro) {
      EXPECT_GT(loop.fusion()->counters().gyro_used_ticks, 0u);
    }
  }
}

TEST(ZeroAlloc, LoopRunsTwoHundredThousandTicksWithoutAllocating) {
  // The daemon's own wiring: default config (simulated LabMate driving two squares), 1 kHz on
  // the virtual clock, ground-truth observer attached. Start-up may allocate; ticks may not.
  fw::Config cfg = fw::default_config();
  cfg.loop.rate_hz = 1000.0;
  cfg.sim.scenario = fw::SimScenario::kSquares;
  auto kin = Kinematics::create(cfg.robot);
  ASSERT_TRUE(kin.ok());
  auto rig = fw::Rig::create(cfg, *kin, /*virtual_time=*/true);
  ASSERT_TRUE(rig.ok()) << rig.error().message;
  loop::LoopConfig lc;
  lc.rate_hz = cfg.loop.rate_hz;
  auto loop = loop::OdometryLoop::create(lc, *kin, rig->encoder(), rig->clock()).value();
  ASSERT_NE(rig->truth(), nullptr);
  loop->add_observer(rig->truth());
  // The CAN broadcast at the default rates on the simulated bus, with the candump log (its
  // writer thread formats and writes frames while the window is open) and set-pose commands.
  const std::string can_log = ::testing::TempDir() + "zero_alloc_can.log";
  auto can = fw::CanLink::create(cfg, *loop, can_log);
  ASSERT_TRUE(can.ok()) << can.error().message;
  ASSERT_NE((*can)->sim_port(), nullptr);
  (*can)->start(0);
  // Persistence on (issue 17): the observer hands the state to the writer thread at 50 Hz and
  // at once on set-pose; the thread writes the state file while the window is open.
  const std::string state_path = ::testing::TempDir() + "zero_alloc_state.bin";
  std::remove(state_path.c_str());
  std::ofstream state_log("/dev/null");
  // The writer thread logs the resume decision once, maybe inside the window: the stream's
  // buffer is allocated here, by a first write, so that line allocates nothing.
  state_log << "resume log\n" << std::flush;
  auto persister =
      fw::StatePersister::create(state_path, 50.0, cfg.loop.rate_hz, *loop, loop::StateRecord{});
  ASSERT_TRUE(persister.ok()) << persister.error().message;
  loop->add_observer(persister->get());
  (*persister)->start(state_log, loop::ResumeReason::kNoRecord, "");
  loop->start();

  constexpr std::uint64_t kTicks = 200'000;  // 200 s at 1 kHz: both squares, then standstill
  loop::LoopSnapshot reader;
  std::uint64_t published = 0;
  {
    AllocWindow w;
    for (std::uint64_t i = 0; i < kTicks; ++i) {
      loop->tick();
      // The status thread's side of the hand-over too, now and then.
      if ((i & 1023) == 0 && loop->snapshots().latest(reader)) ++published;
      if (i == 100'000) {  // new calibration from the reloader thread: the other producer
        ASSERT_TRUE(loop->post(loop::SetKinematics{*kin, calib::StoreStatus::kOk}));
      }
      if (i == 120'000) {
        // Let the log's writer thread catch up once while the window is open, so that "it
        // wrote while the loop ran" below does not depend on the scheduler: on a loaded
        // machine the writer could otherwise get no CPU during these ~0.1 s of ticks and only
        // drain the ring at close (4096 frames, as seen on a fresh CI machine under load).
        // Sleeping does not allocate; the ring still overflows before and after this point.
        const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(20);
        while ((*can)->log_written() + (*can)->log_dropped() < (*can)->counters().sent &&
               std::chrono::steady_clock::now() < until)
          std::this_thread::sleep_for(std::chrono::milliseconds(1));
      }
      if (i == 150'000) {  // a set-pose command (reset to zero) arrives on the bus
        CanFrame cmd;
        protocol::encode_set_pose_reset(
            protocol::frame_id(protocol::kDefaultBaseId, cfg.can.node_id, protocol::Msg::kSetPose),
            cmd);
        (*can)->sim_port()->inject(cmd);
      }
    }
    (*can)->send_final(loop->snapshot());  // the clean-stop frames: no allocation either
    w.disarm();
    // Joins the state writer after its last write: shutdown, off the loop path (the exiting
    // thread frees its own start-up state, as the log writer's does in close_log below).
    (*persister)->stop();
    (*can)->close_log();  // joins the writer thread and closes the file: frees, off the loop path
    EXPECT_EQ(g_allocs.load(), 0u) << "heap allocations during " << kTicks << " ticks";
    EXPECT_EQ(g_frees.load(), 0u) << "heap deallocations during " << kTicks << " ticks";
  }
  // It really ran: every tick counted, motion integrated, statistics kept, frames sent.
  EXPECT_EQ(loop->stats().ticks, kTicks);
  // 50 + 50 + 50 + 10 + 10 (Status) + 10 (EncoderFaults) + 1 frames per second of loop time,
  // plus the seven final frames.
  EXPECT_EQ((*can)->counters().sent, 181u * (kTicks / 1000) + 7u);
  EXPECT_EQ((*can)->counters().dropped(), 0u);
  EXPECT_EQ((*can)->counters().set_pose_applied, 1u);
  EXPECT_EQ(loop->commands_applied(), 2u);  // the calibration and the set-pose command
  // Records: every 20th tick of 200,000 (1 kHz / 50 Hz) is 10,000; each command's tick adds
  // one and restarts the count of 20 (which loses at most the partial period before it), and
  // stop() adds the final state: 10,001 .. 10,003. The file holds the last, the final pose.
  EXPECT_EQ((*persister)->write_errors(), 0u);
  EXPECT_GT((*persister)->written(), 0u);
  auto saved = fw::read_state_file(state_path);
  ASSERT_TRUE(saved.ok()) << saved.error().message;
  EXPECT_GE(saved->sequence, 10'001u);
  EXPECT_LE(saved->sequence, 10'003u);
  EXPECT_EQ(saved->pose.x, loop->snapshot().pose.x);
  EXPECT_EQ(saved->pose.theta, loop->snapshot().pose.theta);
  EXPECT_EQ(loop->snapshot().calibration_state, calib::StoreStatus::kOk);
  // The writer runs on wall time and the loop here is faster than real time: what the ring
  // could not hold is counted, never waited for.
  EXPECT_EQ((*can)->log_written() + (*can)->log_dropped(), (*can)->counters().sent);
  EXPECT_GT((*can)->log_written(), 4096u);
  EXPECT_GT(published, 100u);
  ASSERT_LT(rig->scenario_duration(), 199.0);
  EXPECT_NEAR(loop->odometry().distance(), 32.0, 0.2);  // two 4 m squares: 32 m of legs
  EXPECT_EQ(loop->wakeup_histogram().count(), kTicks);
  EXPECT_EQ(loop->stats().wakeup_latency.count,
            kTicks - kTicks % loop::OdometryLoop::kSummaryTicks);
}

TEST(ZeroAlloc, CanReceiveFloodWithoutAllocating) {
  // Fault matrix row "CAN flood on the receive side": the daemon's CAN link on the simulated
  // bus with set-pose on; every tick 100 frames arrive (foreign ids and, every 10th tick, a
  // set-pose command for this node), far more than the broadcaster reads per tick.
  fw::Config cfg = fw::default_config();
  cfg.loop.rate_hz = 1000.0;
  cfg.sim.scenario = fw::SimScenario::kIdle;
  ASSERT_TRUE(cfg.can.set_pose);
  auto kin = Kinematics::create(cfg.robot);
  ASSERT_TRUE(kin.ok());
  auto rig = fw::Rig::create(cfg, *kin, /*virtual_time=*/true);
  ASSERT_TRUE(rig.ok()) << rig.error().message;
  loop::LoopConfig lc;
  lc.rate_hz = cfg.loop.rate_hz;
  auto loop = loop::OdometryLoop::create(lc, *kin, rig->encoder(), rig->clock()).value();
  auto can = fw::CanLink::create(cfg, *loop, "");
  ASSERT_TRUE(can.ok()) << can.error().message;
  sim::SimCanPort* port = (*can)->sim_port();
  ASSERT_NE(port, nullptr);
  loop->start();
  CanFrame ours;
  protocol::encode_set_pose(
      protocol::frame_id(protocol::kDefaultBaseId, cfg.can.node_id, protocol::Msg::kSetPose),
      SetPose{{1.0, 2.0, 0.5}}, ours);
  CanFrame foreign;
  foreign.len = 8;
  constexpr std::uint64_t kTicks = 20'000;
  std::uint64_t ours_taken = 0;
  {
    AllocWindow w;
    for (std::uint64_t i = 0; i < kTicks; ++i) {
      for (std::uint32_t k = 0; k < 100; ++k) {
        if (k == 0 && i % 10 == 0) {
          if (port->inject(ours)) ++ours_taken;
        } else {
          foreign.id = (k * 37 + static_cast<std::uint32_t>(i)) % 0x400;  // below the base id
          port->inject(foreign);
        }
      }
      loop->tick();
    }
    w.disarm();
    EXPECT_EQ(g_allocs.load(), 0u) << "heap allocations during " << kTicks << " flooded ticks";
    EXPECT_EQ(g_frees.load(), 0u) << "heap deallocations during " << kTicks << " flooded ticks";
  }
  EXPECT_EQ(loop->stats().ticks, kTicks);
  EXPECT_EQ(loop->stats().missed_deadlines, 0u);
  EXPECT_GT(port->counters().rx_dropped, 0u);  // it really was a flood
  EXPECT_GT(ours_taken, 0u);
  // Commands still apply: the ones read so far (the backlog holds the rest).
  EXPECT_GT((*can)->counters().set_pose_applied, 0u);
  EXPECT_LE((*can)->counters().set_pose_applied, ours_taken);
  EXPECT_NEAR(loop->snapshot().pose.x, 1.0, 1e-9);
  EXPECT_NEAR(loop->snapshot().pose.y, 2.0, 1e-9);
}

// rig_ticks_without_allocating: the daemon's rig for cfg (virtual time) under the loop for 40 s at
// 1 kHz, no allocation or deallocation in any tick; `snap` is the last snapshot.
void rig_ticks_without_allocating(const fw::Config& cfg, loop::LoopSnapshot& snap) {
  auto kin = Kinematics::create(cfg.robot);
  ASSERT_TRUE(kin.ok());
  auto rig = fw::Rig::create(cfg, *kin, /*virtual_time=*/true);
  ASSERT_TRUE(rig.ok()) << rig.error().message;
  loop::LoopConfig lc;
  lc.rate_hz = cfg.loop.rate_hz;
  auto loop = loop::OdometryLoop::create(lc, *kin, rig->encoder(), rig->clock()).value();
  loop->start();
  constexpr std::uint64_t kTicks = 40'000;  // 40 s at 1 kHz
  {
    AllocWindow w;
    for (std::uint64_t i = 0; i < kTicks; ++i) loop->tick();
    w.disarm();
    EXPECT_EQ(g_allocs.load(), 0u) << "heap allocations during " << kTicks << " ticks";
    EXPECT_EQ(g_frees.load(), 0u) << "heap deallocations during " << kTicks << " ticks";
  }
  ASSERT_TRUE(loop->snapshots().latest(snap));
}

TEST(ZeroAlloc, CanEncoderBackendTicksWithoutAllocating) {
  // [encoder] backend = "can" on the simulated ODrive pair: frames packed, queued on the
  // simulated port, drained and decoded every tick, and the stale path once the left axis stops
  // sending at 20 s; none of it may allocate.
  fw::Config cfg = fw::default_config();
  cfg.loop.rate_hz = 1000.0;
  cfg.encoder.backend = fw::EncoderKind::kCan;
  cfg.can_encoder.bus = fw::CanEncoderBus::kSim;
  cfg.can_encoder.sim_stop_left_after = 20.0;
  loop::LoopSnapshot snap;
  ASSERT_NO_FATAL_FAILURE(rig_ticks_without_allocating(cfg, snap));
  EXPECT_EQ(snap.encoder_flags, static_cast<std::uint32_t>(kEncoderStaleLeft));
  EXPECT_EQ(snap.encoder_counters.stale_events, 1u);
}

// serial_backend_without_allocating: [encoder] backend = "serial" with link = "sim": the
// simulated controller's bytes (diffodom records, or arduino-bridge answers to the polls) go
// through the real SerialCountsSource every tick; none of it may allocate.
void serial_backend_without_allocating(fw::SerialProtocol p) {
  fw::Config cfg = fw::default_config();
  cfg.loop.rate_hz = 1000.0;
  cfg.encoder.backend = fw::EncoderKind::kSerial;
  cfg.serial.link = fw::SerialLink::kSim;
  cfg.serial.protocol = p;
  cfg.serial.poll_rate = 200.0;
  loop::LoopSnapshot snap;
  ASSERT_NO_FATAL_FAILURE(rig_ticks_without_allocating(cfg, snap));
  EXPECT_EQ(snap.encoder_flags, 0u);
  EXPECT_GT(snap.distance, 1.0);  // the robot moved: samples went through
}

TEST(ZeroAlloc, SerialDiffodomBackendTicksWithoutAllocating) {
  serial_backend_without_allocating(fw::SerialProtocol::kDiffodom);
}
TEST(ZeroAlloc, SerialArduinoBridgeBackendTicksWithoutAllocating) {
  serial_backend_without_allocating(fw::SerialProtocol::kArduinoBridge);
}

// Issue 38: the diffodom link with two wheels per side (version 2 records from the simulated
// board, each wheel unwrapped and combined by SideCombiner every tick) allocates nothing either.
TEST(ZeroAlloc, SerialTwoWheelsPerSideTicksWithoutAllocating) {
  fw::Config cfg = fw::default_config();
  cfg.loop.rate_hz = 1000.0;
  cfg.encoder.backend = fw::EncoderKind::kSerial;
  cfg.encoder.side.wheels_per_side = 2;
  cfg.encoder.side.read_period = 1e-3;
  cfg.serial.link = fw::SerialLink::kSim;
  loop::LoopSnapshot snap;
  ASSERT_NO_FATAL_FAILURE(rig_ticks_without_allocating(cfg, snap));
  EXPECT_EQ(snap.encoder_flags, 0u);
  EXPECT_GT(snap.distance, 1.0);
}

TEST(ZeroAlloc, SerialPortOnAPtyReadsWithoutAllocating) {
  // The tty path itself: SerialPort (termios, its reader thread's ring drained by the loop) on a
  // kernel pseudo-terminal, diffodom records written into the master between reads.
  const int m = posix_openpt(O_RDWR | O_NOCTTY | O_NONBLOCK);
  ASSERT_GE(m, 0);
  ASSERT_EQ(grantpt(m), 0);
  ASSERT_EQ(unlockpt(m), 0);
  auto port = drivers::SerialPort::open(ptsname(m), 115200);
  ASSERT_TRUE(port.ok()) << port.error().message;
  protocol::SerialCountsSource src(**port, protocol::SerialSourceConfig{});
  std::uint64_t allocs = 0;
  EncoderSample s;
  TimeNs now = 0;
  // Lock step: frame i (counts i + 1: the first record primes the count, and 0 is what the
  // sample holds before) is written, then the loop reads (1 ms of its time a read) until the
  // sample shows it. The reader thread still runs beside the reads; one frame at a time keeps
  // its ring far from full however slow the machine (CI's qemu-armhf and ASan runs filled it
  // when the frames were written regardless, and a dropped last chunk left nothing to see).
  for (int i = 0; i < 2000; ++i) {
    std::array<std::uint8_t, protocol::kSerialCountsFrameMax> f{};
    const protocol::SerialCounts c{.seq = static_cast<std::uint16_t>(i),
                                   .time_us = static_cast<std::uint32_t>(i) * 1000u,
                                   .left = i + 1,
                                   .right = -i - 1};
    const std::size_t len = protocol::encode_serial_counts(c, f);
    ASSERT_EQ(::write(m, f.data(), len), static_cast<ssize_t>(len));
    for (int tries = 0; tries < 5000; ++tries) {
      now += 1'000'000;
      AllocWindow w;
      s = src.read(now);
      w.disarm();
      allocs += g_allocs.load() + g_frees.load();
      if (s.left == i + 1) break;
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    ASSERT_EQ(s.left, i + 1) << "frame " << i << " not read within 5000 reads";
  }
  EXPECT_EQ(allocs, 0u);
  // Nothing was lost on the way: no chunk dropped, no broken frame, no gap in the sequence.
  EXPECT_EQ((*port)->dropped(), 0u);
  EXPECT_EQ(s.counters.link_errors, 0u);
  EXPECT_EQ(s.counters.sequence_gaps, 0u);
  ::close(m);
}

// gyro_fusion_without_allocating: the fused loop on [gyro] `backend` ticks without the heap.
void gyro_fusion_without_allocating(fw::GyroBackend backend) {
  // The consumer gyro model fused in the loop, both squares at 1 kHz. The wheel
  // acceleration limit is set below what the squares' ramps need, so every start and stop of a
  // leg opens a flagged interval and the gyro path (window correction, gyro heading, its
  // covariance) runs inside the window, not just the comparison; a set-pose resets the fusion.
  fw::Config cfg = fw::default_config();
  cfg.loop.rate_hz = 1000.0;
  cfg.sim.scenario = fw::SimScenario::kSquares;
  cfg.gyro.backend = backend;
  cfg.can_gyro.bus = fw::CanEncoderBus::kSim;  // backend = "can": the simulated CAN IMU
  cfg.gyro.max_wheel_accel = 0.05;
  auto kin = Kinematics::create(cfg.robot);
  ASSERT_TRUE(kin.ok());
  auto rig = fw::Rig::create(cfg, *kin, /*virtual_time=*/true);
  ASSERT_TRUE(rig.ok()) << rig.error().message;
  ASSERT_NE(rig->gyro(), nullptr);
  loop::LoopConfig lc;
  lc.rate_hz = cfg.loop.rate_hz;
  lc.gyrodometry = rig->gyrodometry();
  lc.calibration = calib::StoreStatus::kOk;  // scale estimation on as well
  auto made = loop::OdometryLoop::create(lc, *kin, rig->encoder(), rig->clock(), rig->gyro());
  ASSERT_TRUE(made.ok()) << made.error().message;
  auto loop = std::move(made).value();
  loop->start();
  constexpr std::uint64_t kTicks = 120'000;
  {
    AllocWindow w;
    for (std::uint64_t i = 0; i < kTicks; ++i) {
      loop->tick();
      if (i == 60'000) {
        ASSERT_TRUE(loop->post(loop::SetPose{Pose2{}}));
      }
    }
    w.disarm();
    EXPECT_EQ(g_allocs.load(), 0u) << "heap allocations during " << kTicks << " gyro ticks";
    EXPECT_EQ(g_frees.load(), 0u) << "heap deallocations during " << kTicks << " gyro ticks";
  }
  const loop::LoopGyroStatus& g = loop->snapshot().gyro;
  EXPECT_TRUE(g.enabled);
  EXPECT_TRUE(g.bias_valid);
  EXPECT_GT(g.gyro.samples, kTicks - 10);  // a 1 kHz gyro read at 1 kHz
  EXPECT_GT(g.fusion.accel_events, 0u);
  EXPECT_GT(g.fusion.gyro_used_ticks, 0u);
  EXPECT_EQ(loop->commands_applied(), 1u);
}

TEST(ZeroAlloc, GyroFusionTicksWithoutAllocating) {
  gyro_fusion_without_allocating(fw::GyroBackend::kSim);
}

TEST(ZeroAlloc, CanGyroFusionTicksWithoutAllocating) {
  // The same through the simulated CAN IMU and the firmware's CAN decoder (drivers/can_gyro).
  gyro_fusion_without_allocating(fw::GyroBackend::kCan);
}

}  // namespace
}  // namespace odo::test
