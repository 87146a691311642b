// The daemon's configuration: a TOML file, validated field by field. Every error names the file,
// the line, the field and the allowed range.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include "odo/calibration/icr_fit.hpp"
#include "odo/hal/angle.hpp"
#include "odo/hal/choice.hpp"
#include "odo/hal/field_range.hpp"
#include "odo/hal/nv_storage.hpp"
#include "odo/hal/result.hpp"
#include "odo/hal/side_wheels.hpp"
#include "odo/odometry/error_model.hpp"
#include "odo/odometry/gyrodometry.hpp"
#include "odo/odometry/kinematics.hpp"

namespace odo::ros2 {
struct Config;  // [ros2]: odo/ros2/config.hpp (its fields and checks are the ros2 library's)
}

namespace odo::fw {

// Choices of the config file: each an enum, spelt once in its table below; code compares
// enum values, so a misspelt choice does not compile.
template <class E>
using Choice = odo::Choice<E>;  // hal/choice.hpp; the name as written in the file

enum class EncoderKind : std::uint8_t { kSim, kHctl1100, kGpio, kCan, kSerial };
// [serial] protocol (the backend maps it onto protocol::SerialProtocol, same order).
enum class SerialProtocol : std::uint8_t { kDiffodom, kArduinoBridge };
enum class SerialLink : std::uint8_t { kTty, kSim };
enum class SimRobotKind : std::uint8_t { kLabmate, kNominal };
enum class SimScenario : std::uint8_t { kSquareCcw, kSquareCw, kSquares, kIdle };
enum class HctlBus : std::uint8_t { kGpio, kSim };
enum class HctlLatch : std::uint8_t { kNone, kLsb };
enum class CanEncoderBus : std::uint8_t { kSocketCan, kSim };
enum class CanEncoderProtocol : std::uint8_t { kOdrive, kGeneric };
enum class ByteOrder : std::uint8_t { kLittle, kBig };
enum class CanBusKind : std::uint8_t { kSim, kSocketCan, kNone };
enum class GyroBackend : std::uint8_t { kNone, kSim, kIio, kCan };
enum class GyroAxis : std::uint8_t { kX, kY, kZ };
enum class GyroMode : std::uint8_t { kBuffered, kPolled };
enum class GyroModelKind : std::uint8_t { kConsumer, kIndustrial };

inline constexpr Choice<EncoderKind> kEncoderKinds[] = {{EncoderKind::kSim, "sim"},
                                                        {EncoderKind::kHctl1100, "hctl1100"},
                                                        {EncoderKind::kGpio, "gpio"},
                                                        {EncoderKind::kCan, "can"},
                                                        {EncoderKind::kSerial, "serial"}};
inline constexpr Choice<SimRobotKind> kSimRobotKinds[] = {{SimRobotKind::kLabmate, "labmate"},
                                                          {SimRobotKind::kNominal, "nominal"}};
inline constexpr Choice<SimScenario> kSimScenarios[] = {{SimScenario::kSquareCcw, "square-ccw"},
                                                        {SimScenario::kSquareCw, "square-cw"},
                                                        {SimScenario::kSquares, "squares"},
                                                        {SimScenario::kIdle, "idle"}};
inline constexpr Choice<HctlBus> kHctlBuses[] = {{HctlBus::kGpio, "gpio"}, {HctlBus::kSim, "sim"}};
inline constexpr Choice<HctlLatch> kHctlLatches[] = {{HctlLatch::kNone, "none"},
                                                     {HctlLatch::kLsb, "lsb"}};
inline constexpr Choice<CanEncoderBus> kCanEncoderBuses[] = {
    {CanEncoderBus::kSocketCan, "socketcan"}, {CanEncoderBus::kSim, "sim"}};
inline constexpr Choice<CanEncoderProtocol> kCanEncoderProtocols[] = {
    {CanEncoderProtocol::kOdrive, "odrive"}, {CanEncoderProtocol::kGeneric, "generic"}};
inline constexpr Choice<SerialProtocol> kSerialProtocols[] = {
    {SerialProtocol::kDiffodom, "diffodom"}, {SerialProtocol::kArduinoBridge, "arduino-bridge"}};
inline constexpr Choice<SerialLink> kSerialLinks[] = {{SerialLink::kTty, "tty"},
                                                      {SerialLink::kSim, "sim"}};
inline constexpr Choice<ByteOrder> kByteOrders[] = {{ByteOrder::kLittle, "little"},
                                                    {ByteOrder::kBig, "big"}};
inline constexpr Choice<CanBusKind> kCanBusKinds[] = {
    {CanBusKind::kSim, "sim"}, {CanBusKind::kSocketCan, "socketcan"}, {CanBusKind::kNone, "none"}};
inline constexpr Choice<GyroBackend> kGyroBackends[] = {{GyroBackend::kNone, "none"},
                                                        {GyroBackend::kSim, "sim"},
                                                        {GyroBackend::kIio, "iio"},
                                                        {GyroBackend::kCan, "can"}};
inline constexpr Choice<GyroAxis> kGyroAxes[] = {
    {GyroAxis::kX, "x"}, {GyroAxis::kY, "y"}, {GyroAxis::kZ, "z"}};
inline constexpr Choice<GyroMode> kGyroModes[] = {{GyroMode::kBuffered, "buffered"},
                                                  {GyroMode::kPolled, "polled"}};
inline constexpr Choice<GyroModelKind> kGyroModelKinds[] = {
    {GyroModelKind::kConsumer, "consumer"}, {GyroModelKind::kIndustrial, "industrial"}};

// kChoiceTables: every choice table, found by its enum type (choices<E>()).
inline constexpr std::tuple kChoiceTables{
    std::span<const Choice<EncoderKind>>(kEncoderKinds),
    std::span<const Choice<SimRobotKind>>(kSimRobotKinds),
    std::span<const Choice<SimScenario>>(kSimScenarios),
    std::span<const Choice<HctlBus>>(kHctlBuses),
    std::span<const Choice<HctlLatch>>(kHctlLatches),
    std::span<const Choice<CanEncoderBus>>(kCanEncoderBuses),
    std::span<const Choice<CanEncoderProtocol>>(kCanEncoderProtocols),
    std::span<const Choice<SerialProtocol>>(kSerialProtocols),
    std::span<const Choice<SerialLink>>(kSerialLinks),
    std::span<const Choice<ByteOrder>>(kByteOrders),
    std::span<const Choice<NvBackend>>(kNvBackends),
    std::span<const Choice<CanBusKind>>(kCanBusKinds),
    std::span<const Choice<GyroBackend>>(kGyroBackends),
    std::span<const Choice<GyroAxis>>(kGyroAxes),
    std::span<const Choice<GyroMode>>(kGyroModes),
    std::span<const Choice<GyroModelKind>>(kGyroModelKinds),
    std::span<const Choice<SideCombine>>(kSideCombineNames),
    std::span<const Choice<calib::IcrFit>>(calib::kIcrFitNames)};

// choices: the table of enum E's choices.
template <class E>
constexpr std::span<const Choice<E>> choices() {
  return std::get<std::span<const Choice<E>>>(kChoiceTables);
}

// name_of: how the config file spells choice v.
template <class E>
constexpr std::string_view name_of(E v) {
  return choice_name(choices<E>(), v);
}

// parse_choice: the choice spelt `name`; nullopt when it is none of them.
template <class E>
constexpr std::optional<E> parse_choice(std::string_view name) {
  return choice_value<E>(choices<E>(), name);
}

// choice_names: the spellings of E's choices, in table order.
template <class E>
std::vector<std::string> choice_names() {
  std::vector<std::string> v;
  for (const Choice<E>& c : choices<E>()) v.emplace_back(c.name);
  return v;
}

// choice_list: "a, b, c": the spellings of E's choices, for messages.
template <class E>
std::string choice_list() {
  return choice_join(choices<E>(), ", ");
}

struct LoopSection {
  double rate_hz = 100.0;      // [Hz] 50..2000
  double status_period = 1.0;  // [s] between status lines, 0 = none
};

struct SimSection {
  SimRobotKind robot = SimRobotKind::kLabmate;  // nominal: true geometry = believed
  SimScenario scenario = SimScenario::kSquareCcw;
  double side = 4.0;         // [m]
  double speed = 0.2;        // [m/s]
  double turn_rate = 0.5;    // [rad/s]
  double pause = 0.5;        // [s]
  double start_delay = 0.0;  // [s] standstill before the scenario (time to read a start pose)
  int counter_bits = 32;     // simulated counter width, 16..64
};

// [hctl1100]: two HCTL-1100 counter chips on one 8-bit multiplexed bus (AD0..AD7, ALE, /OE,
// R/W, one /CS per chip). bus = "gpio": the lines on a GPIO chip via libgpiod; bus = "sim": the
// register model following the simulated robot (same driver, same bus interface).
struct Hctl1100Section {
  HctlBus bus = HctlBus::kGpio;
  std::string chip = "gpiochip0";
  int ad[8] = {0, 1, 2, 3, 4, 5, 6, 7};  // line offsets of AD0..AD7
  int ale = 8;
  int oe = 9;
  int rw = 10;
  int cs_left = 11;
  int cs_right = 12;
  bool control_active_low = true;  // /CS and /OE are active-low pins
  double settle = 0.0;             // [s] extra wait after each bus strobe, 0..0.1
  double max_speed = 3.0;          // [m/s] physical maximum wheel surface speed (jump check)
  int agree_window = 16;           // [counts] 0..64
  int max_attempts = 4;            // 2..16
  bool reverse_left = false;
  bool reverse_right = false;
  HctlLatch latch = HctlLatch::kNone;  // bus = "sim" only: byte-latch model
  double bus_cycle = 1e-6;             // bus = "sim" only: [s] duration of one simulated bus cycle
};

// [gpio]: A/B (and optional index) lines of both wheels, decoded in software.
struct GpioSection {
  std::string chip = "gpiochip0";
  int left_a = 0;
  int left_b = 1;
  int left_index = -1;  // -1 = none
  int right_a = 2;
  int right_b = 3;
  int right_index = -1;
  bool active_low = false;
  bool reverse_left = false;
  bool reverse_right = false;
  int batch = 64;                // events per read, 1..1024
  double reorder_window = 0.02;  // [s] 0..0.1
  double idle_check = 0.05;      // [s] 0.01..10
  // Several wheels per side (issue 38): left_a = [17, 5] etc. give one A/B pair per wheel; the
  // fields above are wheel 1 of each side (the index lines too), more_*[k - 2] wheel k.
  int wheels_per_side = 1;  // the lists' length
  std::array<int, kMaxWheelsPerSide - 1> more_left_a{};
  std::array<int, kMaxWheelsPerSide - 1> more_left_b{};
  std::array<int, kMaxWheelsPerSide - 1> more_right_a{};
  std::array<int, kMaxWheelsPerSide - 1> more_right_b{};
};

// [can_encoder]: wheel encoder counts that motor controllers publish on CAN. bus = "socketcan":
// a SocketCAN interface; bus = "sim": a simulated ODrive pair following the simulated robot
// (same driver on a simulated bus port).
struct CanEncoderSection {
  CanEncoderBus bus = CanEncoderBus::kSocketCan;
  std::string interface = "can0";                             // SocketCAN interface
  CanEncoderProtocol protocol = CanEncoderProtocol::kOdrive;  // odrive: CAN Simple counts
  int node_left = 0;                                          // odrive: axis node ids 0..63
  int node_right = 1;
  bool reverse_left = false;
  bool reverse_right = false;
  double timeout = 0.1;          // [s] a wheel without a frame for this long is stale
  double max_speed = 3.0;        // [m/s] physical maximum wheel surface speed (jump check)
  double request_rate = 0.0;     // [Hz] remote requests per wheel, 0 = off (cyclic senders)
  int max_frames_per_read = 64;  // frames taken per loop tick, 1..4096
  // generic layout (protocol = "generic"); both wheels share width, order, signedness.
  std::int64_t left_id = 0x100;  // arbitration id, 0..0x7FF (0..0x1FFFFFFF extended)
  std::int64_t right_id = 0x101;
  bool extended = false;  // 29-bit ids
  int left_offset = 0;    // [bytes] 0..7
  int right_offset = 0;
  int width = 32;         // [bits] 16, 24, ..., 64
  bool is_signed = true;  // key "signed"
  ByteOrder byte_order = ByteOrder::kLittle;
  // Several wheels per side (issue 38): node_left = [0, 2] (odrive) or left_id = [0x100, 0x102]
  // (generic, with left_offset one offset for all or a list as long) gives the side's wheels;
  // the fields above are wheel 1 of each side, more_*[k - 2] wheel k. Both sides alike.
  int wheels_per_side = 1;  // the lists' length, 1..kMaxWheelsPerSide
  std::array<int, kMaxWheelsPerSide - 1> more_node_left{};
  std::array<int, kMaxWheelsPerSide - 1> more_node_right{};
  std::array<std::int64_t, kMaxWheelsPerSide - 1> more_left_id{};
  std::array<std::int64_t, kMaxWheelsPerSide - 1> more_right_id{};
  std::array<int, kMaxWheelsPerSide - 1> more_left_offset{};
  std::array<int, kMaxWheelsPerSide - 1> more_right_offset{};
  // bus = "sim" only
  double sim_period = 0.01;           // [s] cyclic message period of the simulated controllers
  double sim_stop_left_after = -1.0;  // [s] the left axis stops sending after this; < 0 never
  double sim_stop_right_after = -1.0;
};

// [serial]: counts from a microcontroller on a serial line (README "Serial counts"; issue 37).
// link = "tty": the device; link = "sim": the simulated robot behind a simulated peer speaking
// the protocol (in-process bytes, through the same source).
struct SerialSection {
  SerialLink link = SerialLink::kTty;
  std::string device = "/dev/ttyACM0";  // a tty; /dev/serial/by-id/... links are followed
  std::string device_where;             // "file:line: serial.device", for errors at open
  int baud = 115200;                    // one of drivers::kSerialBaudRates
  SerialProtocol protocol = SerialProtocol::kDiffodom;
  int bits_left = 32;  // [bits] 8..32: the controller's counter width per wheel
  int bits_right = 32;
  bool reverse_left = false;  // negate the wheel's count
  bool reverse_right = false;
  double timeout = 0.1;        // [s] no valid sample for this long: stale
  double reopen_period = 0.5;  // [s] between attempts to reopen a vanished device
  double poll_rate = 100.0;    // [Hz] arduino-bridge: "e" requests per second
  double max_speed = 3.0;      // [m/s] physical maximum wheel surface speed (jump check)
  double clock_window = 1.0;   // [s] diffodom: window of the clock mapping's minimum
  double start_wait = 2.5;     // [s] the first sample may take this long (an Arduino reboots)
  // link = "sim" only
  double sim_period = 0.01;  // [s] sample period of the simulated controller
};

// SectionNumber: one number key of a section: its range row (key, limits, unit) and the field it
// sets. A section's table of these is the only place its ranges are written: the reader and the
// config error tests take them from there.
template <class S>
struct SectionNumber {
  RangeRow row;
  double S::*member;
};

// [serial]'s numbers.
inline constexpr SectionNumber<SerialSection> kSerialNumbers[] = {
    {{"timeout", 0.005, 10.0, "s"}, &SerialSection::timeout},
    {{"reopen_period", 0.01, 60.0, "s"}, &SerialSection::reopen_period},
    {{"poll_rate", 1.0, 1000.0, "Hz"}, &SerialSection::poll_rate},
    {{"max_speed", 0.01, 100.0, "m/s"}, &SerialSection::max_speed},
    {{"clock_window", 0.05, 60.0, "s"}, &SerialSection::clock_window},
    {{"start_wait", 0.0, 30.0, "s"}, &SerialSection::start_wait},
    {{"sim_period", 0.001, 1.0, "s"}, &SerialSection::sim_period}};

struct EncoderSection {
  EncoderKind backend = EncoderKind::kSim;
  // Several encoders per side (hal/side_wheels.hpp): wheels_per_side, combine and the slip
  // threshold from the [encoder] keys; read_period is the loop's tick, counter_bits the
  // backend's. wheels_per_side = 1: the backend reads one counter per side as before.
  SideWheelsConfig side;
};

// backend_carries_side_wheels: whether encoder backend `be` reads several counters per side
// (encoder.wheels_per_side > 1 is refused for the others).
constexpr bool backend_carries_side_wheels(EncoderKind be) {
  return be == EncoderKind::kSim || be == EncoderKind::kCan || be == EncoderKind::kSerial ||
         be == EncoderKind::kGpio;
}

// [realtime]: how the loop thread is made real-time at start (each part reported at start).
struct RealtimeSection {
  int priority = 80;            // SCHED_FIFO priority 1..99 of the loop thread; 0 = SCHED_OTHER
  bool lock_memory = true;      // mlockall(MCL_CURRENT | MCL_FUTURE)
  int cpu = -1;                 // pin the loop thread to this CPU; -1 = no pinning
  int prefault_stack = 262144;  // bytes of loop stack touched before the first tick, 0..4 MiB
  int cpu_latency_us = -1;      // [us] PM QoS CPU wake-up latency held while running; -1 = off
  bool required = false;        // true: refuse to start when a requested part cannot be applied
};

// Where the calibration record lives ([calibration]); see calibration_io.hpp.
struct CalibrationSection {
  std::string store = "/var/lib/odometryd/calibration.bin";  // "" = no store: nominal values
  NvBackend backend = NvBackend::kAuto;
};

// [can]: the CAN pose broadcast (README "CAN protocol"). Rates must divide the loop rate.
struct CanSection {
  CanBusKind bus = CanBusKind::kSim;
  std::string interface = "can0";  // bus = "socketcan": the SocketCAN interface
  int node_id = 1;                 // 0..63: frame ids = base_id + 16 * node_id + message
  int base_id = 0x400;             // 0..1024, multiple of 16, base_id + 16 * node_id <= 0x7F0
  double pose_hz = 50.0;           // [Hz] PoseX + PoseYTheta; 0 = off
  double velocity_hz = 50.0;       // [Hz]
  double uncertainty_hz = 10.0;    // [Hz]
  double status_hz = 10.0;         // [Hz]
  double timing_hz = 1.0;          // [Hz]
  bool set_pose = true;            // accept set-pose commands addressed to node_id
  double reopen_period = 1.0;      // [s] 0.01..60: retry period when the interface vanished
};

// [resume]: the pose that survives restarts (issue 17; README "Restarts").
struct ResumeSection {
  bool enabled = true;                            // read the record at start and keep writing it
  std::string path = "/run/odometryd/state.bin";  // two-slot state record (tmpfs)
  double rate_hz = 50.0;                          // [Hz] records written per second, 1..loop rate
  double max_age = 5.0;                           // [s] 0.01..3600: oldest record resumed from
};

// [selfcal]: self-calibration from absolute fixes (issue 18; README "Self-calibration").
struct SelfCalSection {
  bool enabled = false;
  int min_fixes = 9;                    // fixes in the window before the first fit
  int max_fixes = 41;                   // window: the oldest fix (and its counts) go beyond this
  int fit_every = 4;                    // a fit after every this many new fixes
  int hold_out_every = 4;               // every n-th excursion held out for the acceptance test
  double max_sigma_factor = 2e-4;       // acceptance bound on sigma(c_L), sigma(c_R)
  double max_sigma_wheelbase = 2e-4;    // [m] acceptance bound on sigma(b)
  double min_improvement = 0.1;         // held-out score below (1 - this) x the one in use
  double prior_sigma_factor = 0.01;     // prior around the calibration in use
  double prior_sigma_wheelbase = 0.02;  // [m]
  // x_icr = "fit": the skid-steer ICR offset is a 4th parameter (issue 38), applied only when
  // its standard deviation is below max_sigma_x_icr; "fixed": held at the value in use.
  calib::IcrFit x_icr = calib::IcrFit::kFixed;
  double prior_sigma_x_icr = 0.1;  // [m]
  double max_sigma_x_icr = 0.002;  // [m]
};

// SelfCalRange: one [selfcal] number, its range and unit: the only place they are written
// (the reader, its messages and README's table come from here).
template <class T>
struct SelfCalRange {
  const char* key;
  T SelfCalSection::*member;
  T lo, hi;
  const char* unit;
};
inline constexpr SelfCalRange<int> kSelfCalIntegers[] = {
    {"min_fixes", &SelfCalSection::min_fixes, 3, 1000, ""},
    {"max_fixes", &SelfCalSection::max_fixes, 3, 1000, ""},
    {"fit_every", &SelfCalSection::fit_every, 1, 1000, ""},
    {"hold_out_every", &SelfCalSection::hold_out_every, 2, 1000, ""}};
inline constexpr SelfCalRange<double> kSelfCalNumbers[] = {
    {"max_sigma_factor", &SelfCalSection::max_sigma_factor, 1e-6, 0.1, ""},
    {"max_sigma_wheelbase", &SelfCalSection::max_sigma_wheelbase, 1e-6, 0.1, "m"},
    {"min_improvement", &SelfCalSection::min_improvement, 0.0, 0.9, ""},
    {"prior_sigma_factor", &SelfCalSection::prior_sigma_factor, 1e-4, 0.5, ""},
    {"prior_sigma_wheelbase", &SelfCalSection::prior_sigma_wheelbase, 1e-4, 1.0, "m"},
    {"prior_sigma_x_icr", &SelfCalSection::prior_sigma_x_icr, 1e-4, 1.0, "m"},
    {"max_sigma_x_icr", &SelfCalSection::max_sigma_x_icr, 1e-5, 0.1, "m"}};

// [gyro]: a yaw-rate gyro and the gyrodometry fusion (README "Gyro"). backend = "iio": a MEMS
// gyro through Linux IIO; "can": a rate sent on CAN ([can_gyro]); "sim": a simulated gyro on the
// simulated robot (model's error terms). Numbers default to kNotSet where "not set" means "the
// model's value" (see gyrodometry_params).
struct GyroSection {
  GyroBackend backend = GyroBackend::kNone;
  std::string device;            // iio: device name, sysfs directory or /dev/iio:deviceN
  GyroAxis axis = GyroAxis::kZ;  // iio: the chip axis along the robot's z
  int sign = 1;                  // +1: that axis points up; -1: chip upside down
  GyroMode mode = GyroMode::kBuffered;
  double rate = 0.0;            // iio: sampling frequency to set [Hz]; 0 = leave it
  std::string trigger;          // iio buffered: trigger to attach; "" = leave it
  int buffer_length = 256;      // iio buffered: scans in the kernel buffer
  double stale_timeout = 0.05;  // [s] no sample for this long: the gyro is stale
  GyroModelKind model = GyroModelKind::kConsumer;  // sim: parameter set
  std::int64_t seed = 1;                           // sim: noise seed
  double noise_density = kNotSet;     // [rad/s/sqrt(Hz)] fusion noise model (sim: the model's)
  double bias_instability = kNotSet;  // [rad/s]
  double scale_tolerance = kNotSet;   // residual scale-factor error (fraction)
  double delay = kNotSet;             // [s] lag of the gyro's samples behind the motion
  double delay_tolerance = 0.0005;    // [s] how far `delay` may be off
  double window = 0.1;                // [s] comparison window
  double k_sigma = 5.0;
  double max_wheel_speed = 2.0;   // [m/s]
  double max_wheel_accel = 10.0;  // [m/s^2]
  double still_time = 0.5;        // [s]
  double bias_tau = 60.0;         // [s]
  bool scale_estimation = true;   // estimate the scale factor on turns once calibrated
  static constexpr double kNotSet = -1.0;
};

// [gyro]'s numbers that belong to the gyro source (the fusion's own are its table,
// gyrodometry_range).
inline constexpr SectionNumber<GyroSection> kGyroSourceNumbers[] = {
    {{"rate", 0.0, 100000.0, "Hz"}, &GyroSection::rate},
    {{"stale_timeout", 0.001, 10.0, "s"}, &GyroSection::stale_timeout},
};

// [can_gyro]: the yaw rate of a CAN IMU ([gyro] backend = "can"; drivers/can_gyro.hpp).
struct CanGyroSection {
  CanEncoderBus bus = CanEncoderBus::kSocketCan;  // socketcan | sim (a simulated CAN IMU)
  std::string interface = "can0";                 // SocketCAN interface
  std::int64_t id = 0x120;  // arbitration id, 0..0x7FF (0..0x1FFFFFFF extended)
  bool extended = false;    // 29-bit id
  int offset = 0;           // [bytes] first byte of the rate field, 0..7
  int width = 16;           // [bits] 16, 24 or 32
  bool is_signed = true;    // key "signed"
  ByteOrder byte_order = ByteOrder::kLittle;
  // [rad/s per LSB]: default 2000 deg/s full scale of a 16-bit word, the usual MEMS range (and
  // the simulated consumer gyro's)
  double scale = 2000.0 * kRadPerDeg / 32768.0;
  double rate_offset = 0.0;      // [rad/s] added after scaling (unsigned fields)
  int max_frames_per_read = 64;  // frames taken per loop tick, 1..4096
  double sim_stop_after = -1.0;  // bus = "sim": [s] the IMU stops sending after this; < 0 never
};

struct Config {
  std::string source = "<built-in>";  // file the config came from
  LoopSection loop;
  KinematicParams robot;  // nominal robot; c_l, c_r, wheelbase may be replaced by calibration
  EncoderSection encoder;
  SimSection sim;
  RealtimeSection realtime;
  CalibrationSection calibration;
  Hctl1100Section hctl1100;
  GpioSection gpio;
  CanEncoderSection can_encoder;
  SerialSection serial;
  ErrorModelParams error_model;  // [error_model]: Chong-Kleeman k_L, k_R [m^(1/2)]
  CanSection can;
  // [ros2]: the ROS 2 output over DDS (README "ROS 2"), off unless enabled = true; null when
  // the config was not read from text (default_config: off).
  std::shared_ptr<const ros2::Config> ros2;
  ResumeSection resume;
  SelfCalSection selfcal;
  GyroSection gyro;
  CanGyroSection can_gyro;
};

// default_config: the embedded default: the simulated LabMate of the UMBmark report.
Config default_config();

// parse_config: parses TOML text; `source` names it in messages. Unknown keys are errors.
Result<Config> parse_config(std::string_view text, std::string_view source);

// gyrodometry_params: the fusion's parameters from [gyro]; keys left unset take the simulated
// model's figures (simulated_gyro) or the consumer-class defaults (GyroNoiseModel).
GyrodometryParams gyrodometry_params(const Config& cfg);

// load_config: reads and parses a file.
Result<Config> load_config(const std::string& path);

// simulated_robot: the encoders are the simulated robot's (backend "sim", or hctl1100 /
// can_encoder on their simulated bus).
bool simulated_robot(const Config& cfg);

// simulated_gyro: the gyro is the simulated model (backend "sim", or "can" with [can_gyro] bus
// "sim"): it needs the simulated robot, and its model's figures are the fusion's defaults.
bool simulated_gyro(const Config& cfg);

}  // namespace odo::fw
