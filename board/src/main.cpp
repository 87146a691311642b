// The microcontroller firmware (issue 36): the same fixed-rate odometry loop as odometryd, on
// TIM2's update interrupt, pose on CAN framed as SLCAN on USART1. ODO_BOARD_SIM: the encoders are
// sim_hal's simulated robot driving odometryd's default square (QEMU); otherwise TIM3/TIM4 in
// encoder mode (a real board). Options (QEMU, through semihosting's command line):
//   --duration S  run S seconds of loop time (default: the scenario plus 1 s, as odometryd
//                 --virtual-time; 0 = forever)   --fault  end in a bus fault after start-up
//   --serial-hz H the serial counts stream's rate on USART2 [Hz], loop rate / whole number, 0 off
//   --rate-hz H   the loop rate [Hz] (default 100; the CAN and serial rates must divide it)
//   --covariance-ticks N  error_model.covariance_ticks (loop ticks merged into one covariance step)
#include <array>
#include <atomic>
#include <cstdlib>
#include <cstring>
#include <optional>

#include "odo/board/board_config.hpp"
#include "odo/board/bxcan.hpp"
#include "odo/board/mmio_bus.hpp"
#include "odo/board/pins.hpp"
#include "odo/board/serial_stream.hpp"
#include "odo/board/slcan_link.hpp"
#include "odo/board/stm32_encoder_timers.hpp"
#include "odo/board/stm32_flash.hpp"
#include "odo/board/stm32f4.hpp"
#include "odo/board/system.hpp"
#include "odo/board/text.hpp"
#include "odo/board/timer_clock.hpp"
#include "odo/board/uart.hpp"
#include "odo/calibration/record.hpp"
#include "odo/calibration/store.hpp"
#include "odo/loop/loop.hpp"
#if ODO_BOARD_SIM
#include "odo/sim/robot.hpp"
#include "odo/sim/side_wheels_sim.hpp"
#include "odo/sim/sim_encoder.hpp"
#endif

namespace odo::board {
namespace {

struct Options {
  double duration = -1.0;  // [s]; < 0: the scenario's own
  bool fault = false;
  double serial_hz = -1.0;         // [Hz] serial counts stream on USART2; < 0: BoardConfig's
  double rate_hz = -1.0;           // [Hz] loop rate; < 0: BoardConfig's
  double covariance_ticks = -1.0;  // error_model.covariance_ticks; < 0: BoardConfig's
};

// parse_options: the semihosting command line's words after the program name.
Options parse_options() noexcept {
  Options o;
  static char cmd[128];
  if (!semihost_cmdline(cmd, sizeof cmd)) return o;
  for (char* w = std::strtok(cmd, " "); w != nullptr; w = std::strtok(nullptr, " ")) {
    if (std::strcmp(w, "--fault") == 0) o.fault = true;
    if (std::strcmp(w, "--duration") == 0) {
      if (char* v = std::strtok(nullptr, " ")) o.duration = std::strtod(v, nullptr);
    }
    if (std::strcmp(w, "--serial-hz") == 0) {
      if (char* v = std::strtok(nullptr, " ")) o.serial_hz = std::strtod(v, nullptr);
    }
    if (std::strcmp(w, "--rate-hz") == 0) {
      if (char* v = std::strtok(nullptr, " ")) o.rate_hz = std::strtod(v, nullptr);
    }
    if (std::strcmp(w, "--covariance-ticks") == 0) {
      if (char* v = std::strtok(nullptr, " ")) o.covariance_ticks = std::strtod(v, nullptr);
    }
  }
  return o;
}

void say(Line& l) noexcept {
  l.add("\r");
  uart1().write(l.c_str(), l.size());
}

[[noreturn]] void fail(const char* what) noexcept {
  Line l;
  say(l.add("# error: ").add(what));
  uart1().flush();
  std::exit(2);
}

// EncoderWiring: the board's encoder source, the scenario's length [s] (0: none) and, with
// several wheels per side, the source's per-wheel readings of its last read.
struct EncoderWiring {
  EncoderSource* source = nullptr;
  double scenario = 0.0;
  const std::array<SideReadings, 2>* wheels = nullptr;
};

// side_config: [encoder]'s side keys of cfg with the combiner's slip window counted in this
// loop's ticks (the combiner reads once a tick).
SideWheelsConfig side_config(const BoardConfig& cfg) noexcept {
  SideWheelsConfig w = cfg.wheels;
  w.read_period = 1.0 / cfg.rate_hz;
  return w;
}

#if ODO_BOARD_SIM
// sim_wheels: several wheels per side on the simulated robot, as odometryd's sim backend with
// encoder.wheels_per_side > 1 (SimSideWheelsSource, the wheel model's documented defaults).
EncoderWiring sim_wheels(const BoardConfig& cfg, sim::SimRobot& robot) noexcept {
  static std::optional<sim::SimSideWheelsSource> enc;
  sim::SideWheelsSimParams p;
  p.wheels_per_side = cfg.wheels.wheels_per_side;
  auto model = sim::SideWheelsSim::create(p, robot.geometry());
  if (!model) fail("simulated wheels");
  auto src = sim::SimSideWheelsSource::create(robot, std::move(model).value(), side_config(cfg),
                                              cfg.counter_bits);
  if (!src) fail(src.error().message.c_str());
  enc.emplace(std::move(src).value());
  return {&*enc, sim::scenario_duration(robot.scenario()), &enc->readings()};
}
#endif

EncoderWiring make_encoders(const BoardConfig& cfg, const Kinematics& k) noexcept {
#if ODO_BOARD_SIM
  // odometryd's simulated robot (firmware/src/rig.cpp composes it the same way).
  static std::optional<sim::SimRobot> robot;
  static std::optional<sim::SimEncoderSource> enc;
  sim::SquareOptions so;
  so.side = cfg.side;
  so.speed = cfg.speed;
  so.turn_rate = cfg.turn_rate;
  so.pause = cfg.pause;
  auto r = sim::SimRobot::create(sim::simulated_geometry(cfg.sim_labmate, k.params()),
                                 sim::squares_scenario(k, so, sim::SquareSet::kCcw));
  if (!r) fail("simulated robot");
  robot.emplace(std::move(r).value());
  if (kBoardWheelsPerSide > 1) return sim_wheels(cfg, *robot);
  enc.emplace(*robot, cfg.counter_bits);
  return {&*enc, sim::scenario_duration(robot->scenario())};
#else
  // Wired for two wheels per side at most (the chip's six encoder timers would allow three:
  // README "On a real STM32F405 board").
  static_assert(kBoardWheelsPerSide <= 2, "a real board counts at most 2 wheels per side");
  (void)k;
  static MmioBus mmio;
  if constexpr (kBoardWheelsPerSide == 2) {
    static std::optional<Stm32SideTimers> side;
    auto t = Stm32SideTimers::create(mmio, side_config(cfg));
    if (!t)
      fail("encoder: wheels_per_side, slip_window, slip_counts or slip_fraction out of range");
    side.emplace(std::move(*t));
    side->init();
    return {&*side, 0.0, &side->readings()};
  }
  static Stm32EncoderTimers enc(mmio);
  enc.init();
  return {&enc, 0.0};
#endif
}

// StoredCalibration: the kinematics the loop runs on and the store's status.
struct StoredCalibration {
  KinematicParams params;
  calib::StoreStatus status = calib::StoreStatus::kUncalibrated;
};

// load_calibration: the A/B store in flash sectors 10 and 11 (read-only at start-up: reads are
// plain memory reads, so this works in QEMU, whose flash is the image plus -device loader
// data); the record applied to `nominal` as odometryd applies it, nominal values otherwise.
StoredCalibration load_calibration(const KinematicParams& nominal) noexcept {
  static MmioBus mmio;
  static Stm32Flash flash(mmio);
  static FlashNvStorage nv(flash, 10, 2);
  StoredCalibration c{nominal, calib::StoreStatus::kUncalibrated};
  Line l;
  l.add("# calibration (flash sectors 10-11): ");
  auto store = calib::CalibrationStore::create(nv);
  auto loaded = store ? store->load() : Result<calib::LoadResult>(std::move(store).error());
  if (!loaded || loaded->status == calib::StoreStatus::kCorrupt) {
    c.status = calib::StoreStatus::kCorrupt;
    say(l.add("ERROR: store unreadable or corrupt; running on NOMINAL values"));
    return c;
  }
  if (loaded->status != calib::StoreStatus::kOk || !loaded->record) {
    say(l.add("uncalibrated; running on nominal values"));
    return c;
  }
  auto p = calib::apply_record(nominal, *loaded->record);
  if (!p) {
    c.status = calib::StoreStatus::kCorrupt;
    say(l.add("ERROR: stored values rejected; running on NOMINAL values"));
    return c;
  }
  c.params = *p;
  c.status = calib::StoreStatus::kOk;
  say(l.add("ok, sequence ").num(static_cast<std::int64_t>(loaded->record->sequence)));
  return c;
}

// report_end: the run's figures as a '#'-line (tests and benchmarks read it).
void report_end(const loop::OdometryLoop& lp, const PoseBroadcaster& bc,
                const SerialStream& st) noexcept {
  const loop::LoopStats& s = lp.stats();
  Line l;
  l.add("# end ticks=").num(static_cast<std::int64_t>(s.ticks));
  l.add(" missed=").num(static_cast<std::int64_t>(s.missed_deadlines));
  l.add(" compute_mean_ns=").num(s.compute_time.mean).add(" compute_max_ns=").num(s.compute_max);
  l.add(" wakeup_max_ns=").num(s.wakeup_latency_max);
  l.add(" frames=").num(bc.sent()).add(" dropped=").num(bc.dropped());
  l.add(" set_pose=").num(bc.set_pose_applied());
  l.add(" serial_records=").num(st.sent());
  l.add(" allocations=").num(heap_allocations());
  say(l);
}

// say_banner: the start-up line: clocks and loop rate.
void say_banner(const ClockInfo& ci, const BoardConfig& cfg) {
  Line banner;
  say(banner.add("# diffodom mcu: sysclk ")
          .num(ci.sysclk_hz)
          .add(" Hz")
          .add(ci.pll ? "" : " (HSI)")
          .add(", SysTick ")
          .num(ci.tim_hz)
          .add(" Hz, loop ")
          .num(static_cast<int>(cfg.rate_hz))
          .add(" Hz"));
}

// broadcast_options: the CAN ids and the pose and Status rates (as loop-tick divisors) of cfg.
BroadcastOptions broadcast_options(const BoardConfig& cfg) {
  const std::int64_t pose_div = protocol::divisor_for(cfg.rate_hz, cfg.pose_hz);
  const std::int64_t status_div = protocol::divisor_for(cfg.rate_hz, cfg.status_hz);
  if (pose_div < 0 || status_div < 0) fail("--rate-hz: the pose and Status rates must divide it");
  BroadcastOptions bo;
  bo.base_id = cfg.base_id;
  bo.node_id = cfg.node_id;
  bo.pose_div = static_cast<std::uint32_t>(pose_div);
  bo.status_div = static_cast<std::uint32_t>(status_div);
  bo.wheels_per_side = cfg.wheels.wheels_per_side;
  return bo;
}

// pose_bus: where the protocol's frames go. QEMU models no bxCAN: there USART1 carries them as
// SLCAN. A board: CAN1 at 500 kbit/s (PB8 RX, PB9 TX), its filter passing only this node's
// set-pose frames into FIFO 0; USART1 keeps the '#' reports.
CanBus& pose_bus(const BoardConfig& cfg) noexcept {
#if ODO_BOARD_SIM
  (void)cfg;
  static SlcanBus bus(uart1());
  return bus;
#else
  reg(rcc::kApb1Enr) |= 1u << 25;  // CAN1EN: the controller's clock before its registers
  static MmioBus mmio;
  static BxCan can(mmio);
  const std::uint32_t set_pose =
      protocol::frame_id(cfg.base_id, cfg.node_id, protocol::Msg::kSetPose);
  if (auto s = can.init(BxCan::kBtr500k, set_pose, 0x7FFu); !s) fail(s.error().message.c_str());
  return can;
#endif
}

// with_options: the built-in configuration with the command line's loop rate and covariance
// grouping (the loop's own checks refuse values out of range).
BoardConfig with_options(const Options& opt) noexcept {
  BoardConfig cfg;
  if (opt.rate_hz > 0.0) cfg.rate_hz = opt.rate_hz;
  // strtod, already linked for the rates, instead of strtol (1 KB more); a fraction or a value
  // out of range becomes 0 and the loop's own check refuses it.
  if (opt.covariance_ticks >= 0.0) {
    const double n = opt.covariance_ticks;
    // The bound first: converting a double beyond uint32_t's range is undefined.
    const bool whole = n <= 1e6 && n == static_cast<double>(static_cast<std::uint32_t>(n));
    cfg.error_model.covariance_ticks = whole ? static_cast<std::uint32_t>(n) : 0u;
  }
  return cfg;
}

}  // namespace
}  // namespace odo::board

int main() {
  using namespace odo;
  using namespace odo::board;
  const ClockInfo ci = clock_init();
  pins_init();
  const Options opt = parse_options();
  static const BoardConfig cfg = with_options(opt);
  uart1().init(ci.apb2_hz, cfg.baud, kIrqUsart1);
  say_banner(ci, cfg);
  auto k = Kinematics::create(cfg.robot);
  if (!k) fail("kinematics");
  // The robot follows the nominal kinematics (as odometryd's rig); the loop runs on the store's.
  const EncoderWiring enc = make_encoders(cfg, *k);
  const StoredCalibration cal = load_calibration(cfg.robot);
  auto kc = Kinematics::create(cal.params);
  if (!kc) fail("calibrated kinematics");
  static LatchedEncoder latched(*enc.source, enc.wheels);
  loop::LoopConfig lc;
  lc.rate_hz = cfg.rate_hz;
  lc.error_model = cfg.error_model;
  lc.calibration = cal.status;
  TimerClock& clock = timer_clock();
  auto created = loop::OdometryLoop::create(lc, *kc, latched, clock);
  if (!created) fail(created.error().message.c_str());  // names the setting and its range
  static std::unique_ptr<loop::OdometryLoop> lp = std::move(created).value();
  CanBus& bus = pose_bus(cfg);
  static PoseBroadcaster bc(broadcast_options(cfg), bus, lp->commands());
  lp->add_observer(&bc);
  uart2().init(ci.apb1_hz, cfg.baud, kIrqUsart2);
  const double serial_hz = opt.serial_hz >= 0.0 ? opt.serial_hz : cfg.serial_hz;
  const std::int64_t serial_div = protocol::divisor_for(cfg.rate_hz, serial_hz);
  if (serial_div < 0) fail("--serial-hz: not the loop rate divided by a whole number");
  static SerialStream stream(*lp, uart2(), static_cast<std::uint32_t>(serial_div),
                             enc.wheels ? &latched.wheels() : nullptr, cfg.wheels.wheels_per_side);
  lp->add_observer(&stream);
  clock.configure(lp->period(), ci.tim_hz);
  latched.latch(0);  // the reference reading: time 0, where the clock stands until the first sleep
  clock.set_latch(&latched);
  if (opt.fault) {  // an unmapped address: a bus fault (tests the fault reporter)
    const std::uint32_t v = reg(0x5FFFFFF0u);
    asm volatile("" : : "r"(v));
  }
  const double duration = opt.duration >= 0.0 ? opt.duration : enc.scenario + 1.0;
  lock_heap();
  watchdog_start(cfg.iwdg_timeout_ms);
  const std::atomic<bool> stop{false};
  lp->run(from_seconds(duration), stop);
  bc.send_final(lp->snapshot());
  report_end(*lp, bc, stream);
  uart1().flush();
  semihost_exit(0);
}
