#include "odo/firmware/config.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <sstream>

#include "odo/drivers/can_encoder.hpp"
#include "odo/drivers/gpio_quadrature.hpp"
#include "odo/drivers/hctl1100_encoder.hpp"
#include "odo/drivers/serial_port.hpp"
#include "odo/firmware/toml_reader.hpp"
#include "odo/hal/side_sample.hpp"
#include "odo/loop/loop.hpp"
#include "odo/odometry/count_delta.hpp"
#include "odo/odometry/gyrodometry.hpp"
#include "odo/protocol/can_protocol.hpp"
#include "odo/ros2/config.hpp"

namespace odo::fw {

Config default_config() {
  Config c;
  c.robot.wheel_diameter = 0.15;
  c.robot.counts_per_rev = 2048;
  c.robot.gear_ratio = 16;
  c.robot.wheelbase_nominal = 0.34;
  c.robot.wheelbase = 0.34;
  return c;
}

namespace {

void read_loop(TableReader t, LoopSection& s) {
  s.rate_hz =
      t.number("rate_hz", s.rate_hz, loop::kLoopRateLimit.lo, loop::kLoopRateLimit.hi, "Hz");
  s.status_period = t.number("status_period", s.status_period, 0.0, 3600.0, "s");
  t.finish();
}

void read_robot(TableReader t, KinematicParams& p) {
  using L = KinematicLimits;  // the limits Kinematics::create checks
  auto num = [&](std::string_view key, double v, Limit l, std::string_view unit) {
    return t.number(key, v, l.lo, l.hi, unit);
  };
  p.wheel_diameter = num("wheel_diameter", p.wheel_diameter, L::kWheelDiameter, "m");
  p.counts_per_rev = num("counts_per_rev", p.counts_per_rev, L::kCountsPerRev, "counts");
  p.gear_ratio = num("gear_ratio", p.gear_ratio, L::kGearRatio, "");
  p.wheelbase_nominal = num("wheelbase", p.wheelbase_nominal, L::kWheelbase, "m");
  // Until a calibration is loaded the effective wheelbase is the nominal one.
  p.wheelbase = p.wheelbase_nominal;
  p.c_l = num("c_l", p.c_l, L::kFactor, "");
  p.c_r = num("c_r", p.c_r, L::kFactor, "");
  p.x_icr = num("x_icr", p.x_icr, L::kXIcr, "m");
  t.finish();
}

// The [encoder] keys of several encoders per side, from the combiner's own table
// (side_wheels_range at this loop's tick): the whole wheels_per_side, then the numbers.
constexpr double SideWheelsConfig::*kSideNumbers[kSideConfigParams] = {
    nullptr, &SideWheelsConfig::slip_window, &SideWheelsConfig::slip_counts,
    &SideWheelsConfig::slip_fraction};

void read_encoder(TableReader t, EncoderSection& s, double loop_hz) {
  s.backend = t.choice("backend", s.backend);
  SideWheelsConfig& w = s.side;
  w.read_period = 1.0 / loop_hz;
  w.wheels_per_side = static_cast<int>(
      t.integer(w.wheels_per_side, side_wheels_range(SideParam::kWheelsPerSide, w.read_period)));
  w.combine = t.choice("combine", w.combine);
  for (std::size_t i = 1; i < kSideConfigParams; ++i)
    w.*kSideNumbers[i] =
        t.number(w.*kSideNumbers[i], side_wheels_range(static_cast<SideParam>(i), w.read_period));
  if (w.wheels_per_side > 1 && !backend_carries_side_wheels(s.backend))
    t.reject("wheels_per_side", "= " + std::to_string(w.wheels_per_side) + " needs a backend " +
                                    "that reads several counters per side; backend \"" +
                                    std::string(name_of(s.backend)) + "\" reads one");
  t.finish();
}

void read_sim(TableReader t, SimSection& s) {
  s.robot = t.choice("robot", s.robot);
  s.scenario = t.choice("scenario", s.scenario);
  s.side = t.number("side", s.side, 0.1, 100.0, "m");
  s.speed = t.number("speed", s.speed, 0.01, 5.0, "m/s");
  s.turn_rate = t.number("turn_rate", s.turn_rate, 0.05, 10.0, "rad/s");
  s.pause = t.number("pause", s.pause, 0.0, 60.0, "s");
  s.start_delay = t.number("start_delay", s.start_delay, 0.0, 600.0, "s");
  s.counter_bits =
      static_cast<int>(t.integer("counter_bits", s.counter_bits, kCounterBitsMin, kCounterBitsMax));
  t.finish();
}

void read_realtime(TableReader t, RealtimeSection& s) {
  s.priority = static_cast<int>(t.integer("priority", s.priority, 0, 99));
  s.lock_memory = t.boolean("lock_memory", s.lock_memory);
  s.cpu = static_cast<int>(t.integer("cpu", s.cpu, -1, 1023));
  s.prefault_stack = static_cast<int>(t.integer("prefault_stack", s.prefault_stack, 0, 4194304));
  s.cpu_latency_us = static_cast<int>(t.integer("cpu_latency_us", s.cpu_latency_us, -1, 1000000));
  s.required = t.boolean("required", s.required);
  t.finish();
}

void read_calibration(TableReader t, CalibrationSection& s) {
  s.store = t.string("store", s.store);
  s.backend = t.choice("backend", s.backend);
  t.finish();
}

void read_hctl1100(TableReader t, Hctl1100Section& s) {
  s.bus = t.choice("bus", s.bus);
  s.chip = t.string("chip", s.chip);
  for (int i = 0; i < 8; ++i) {
    const std::string key = "ad" + std::to_string(i);
    s.ad[i] = static_cast<int>(t.integer(key, s.ad[i], 0, 1023));
  }
  s.ale = static_cast<int>(t.integer("ale", s.ale, 0, 1023));
  s.oe = static_cast<int>(t.integer("oe", s.oe, 0, 1023));
  s.rw = static_cast<int>(t.integer("rw", s.rw, 0, 1023));
  s.cs_left = static_cast<int>(t.integer("cs_left", s.cs_left, 0, 1023));
  s.cs_right = static_cast<int>(t.integer("cs_right", s.cs_right, 0, 1023));
  s.control_active_low = t.boolean("control_active_low", s.control_active_low);
  s.settle = t.number("settle", s.settle, 0.0, 0.1, "s");
  s.max_speed = t.number("max_speed", s.max_speed, 0.01, 100.0, "m/s");
  s.agree_window = static_cast<int>(t.integer(s.agree_window, drivers::kHctlAgreeWindow));
  s.max_attempts = static_cast<int>(t.integer(s.max_attempts, drivers::kHctlMaxAttempts));
  s.reverse_left = t.boolean("reverse_left", s.reverse_left);
  s.reverse_right = t.boolean("reverse_right", s.reverse_right);
  s.latch = t.choice("latch", s.latch);
  s.bus_cycle = t.number("bus_cycle", s.bus_cycle, 0.0, 1e-3, "s");
  t.finish();
}

// read_side_list: the side's key `key`, an integer (one wheel) or a list of 1..kMaxWheelsPerSide
// in [lo, hi]; wheel 1 into `first`, wheels 2.. into `more`; returns the number of wheels.
template <class T, class U>
int read_side_list(TableReader& t, std::string_view key, T& first,
                   std::array<U, kMaxWheelsPerSide - 1>& more, std::int64_t lo, std::int64_t hi) {
  const std::vector<std::int64_t> v =
      t.integers(key, {static_cast<std::int64_t>(first)}, lo, hi, kMaxWheelsPerSide);
  first = static_cast<T>(v.front());
  for (std::size_t k = 1; k < v.size(); ++k) more[k - 1] = static_cast<U>(v[k]);
  return static_cast<int>(v.size());
}

// same_count: `key` lists as many wheels as `ref_key` (else reported at `key`, with `why`);
// returns the reference count.
int same_count(TableReader& t, std::string_view ref_key, int ref, std::string_view key, int n,
               std::string_view why) {
  if (n != ref)
    t.reject(key, "lists " + std::to_string(n) + " wheel(s) but " + std::string(ref_key) +
                      " lists " + std::to_string(ref) + ": " + std::string(why));
  return ref;
}
constexpr std::string_view kBothSides = "both sides need the same number of wheels";

// read_can_odrive_nodes: node_left / node_right, one node id per wheel, all different.
void read_can_odrive_nodes(TableReader& t, CanEncoderSection& s, bool used) {
  const int nl = read_side_list(t, "node_left", s.node_left, s.more_node_left, 0, 63);
  const int nr = read_side_list(t, "node_right", s.node_right, s.more_node_right, 0, 63);
  if (!used) return;
  s.wheels_per_side = same_count(t, "node_left", nl, "node_right", nr, kBothSides);
  if (s.wheels_per_side == 1 && s.node_left == s.node_right) {
    t.reject("node_right", "= " + std::to_string(s.node_right) +
                               " is the left wheel's node id too (they must differ)");
    return;
  }
  for (int i = 1; i < 2 * s.wheels_per_side; ++i) {
    const int id = wheel_of_side(i, s.node_left, s.node_right, s.more_node_left, s.more_node_right);
    for (int j = 0; j < i; ++j) {
      if (wheel_of_side(j, s.node_left, s.node_right, s.more_node_left, s.more_node_right) == id) {
        t.reject(i % 2 == 1 ? "node_right" : "node_left",
                 "gives node id " + std::to_string(id) +
                     " to two wheels (each wheel needs its own axis)");
        return;
      }
    }
  }
}

// read_can_generic_ids: left_id / right_id (a list: one frame per wheel) and the offsets (one
// for the side's wheels, or a list as long); no two wheels on the same bytes of one frame.
void read_can_generic_ids(TableReader& t, CanEncoderSection& s, bool used) {
  const std::int64_t max_id = s.extended ? 0x1FFFFFFF : 0x7FF;
  const int il = read_side_list(t, "left_id", s.left_id, s.more_left_id, 0, max_id);
  const int ir = read_side_list(t, "right_id", s.right_id, s.more_right_id, 0, max_id);
  const int max_offset = 8 - s.width / 8;
  const int ol = read_side_list(t, "left_offset", s.left_offset, s.more_left_offset, 0, max_offset);
  const int orr =
      read_side_list(t, "right_offset", s.right_offset, s.more_right_offset, 0, max_offset);
  if (!used) return;
  s.wheels_per_side = same_count(t, "left_id", il, "right_id", ir, kBothSides);
  const int n = s.wheels_per_side;
  // One offset: every wheel of the side uses it.
  if (ol == 1) s.more_left_offset.fill(s.left_offset);
  if (orr == 1) s.more_right_offset.fill(s.right_offset);
  constexpr std::string_view kOffsets = "give one offset for all, or one per wheel";
  if (ol != 1) same_count(t, "left_id", n, "left_offset", ol, kOffsets);
  if (orr != 1) same_count(t, "right_id", n, "right_offset", orr, kOffsets);
  for (int i = 1; i < 2 * n; ++i) {
    const bool right = i % 2 == 1;
    const auto at = [&](int w) {
      return std::pair{
          wheel_of_side(w, s.left_id, s.right_id, s.more_left_id, s.more_right_id),
          wheel_of_side(w, s.left_offset, s.right_offset, s.more_left_offset, s.more_right_offset)};
    };
    for (int j = 0; j < i; ++j) {
      if (at(i) != at(j)) continue;
      if (n == 1)
        t.reject("right_offset", "= " + std::to_string(s.right_offset) +
                                     ": both wheels would read the same bytes of frame " +
                                     std::to_string(s.left_id));
      else
        t.reject(right ? "right_id" : "left_id",
                 "puts two wheels on the same bytes (frame " + std::to_string(at(i).first) +
                     ", offset " + std::to_string(at(i).second) +
                     "): give each wheel its own frame id or offset");
      return;
    }
  }
}

// read_gpio: [gpio]; `wheels`: encoder.wheels_per_side when GPIO is the encoder, 0 otherwise.
void read_gpio(TableReader t, GpioSection& s, int wheels) {
  s.chip = t.string("chip", s.chip);
  const std::array<int, 4> n{read_side_list(t, "left_a", s.left_a, s.more_left_a, 0, 1023),
                             read_side_list(t, "left_b", s.left_b, s.more_left_b, 0, 1023),
                             read_side_list(t, "right_a", s.right_a, s.more_right_a, 0, 1023),
                             read_side_list(t, "right_b", s.right_b, s.more_right_b, 0, 1023)};
  constexpr std::array<const char*, 4> kKeys{"left_a", "left_b", "right_a", "right_b"};
  s.wheels_per_side = n[0];
  for (std::size_t i = 1; i < n.size(); ++i)
    same_count(t, kKeys[0], n[0], kKeys[i], n[i], "one A/B pair per wheel, both sides alike");
  if (wheels > 0 && n[0] != wheels)
    t.reject("left_a", "lists " + std::to_string(n[0]) +
                           " wheel(s) but encoder.wheels_per_side = " + std::to_string(wheels) +
                           ": give one line per wheel of the side");
  s.left_index = static_cast<int>(t.integer("left_index", s.left_index, -1, 1023));
  s.right_index = static_cast<int>(t.integer("right_index", s.right_index, -1, 1023));
  s.active_low = t.boolean("active_low", s.active_low);
  s.reverse_left = t.boolean("reverse_left", s.reverse_left);
  s.reverse_right = t.boolean("reverse_right", s.reverse_right);
  s.batch = static_cast<int>(t.integer(s.batch, drivers::kGpioBatch));
  s.reorder_window = t.number("reorder_window", s.reorder_window, 0.0, 0.1, "s");
  s.idle_check = t.number("idle_check", s.idle_check, 0.01, 10.0, "s");
  t.finish();
}

// read_can_encoder: [can_encoder]; `wheels`: encoder.wheels_per_side when the CAN backend is
// the encoder (its lists must be that long), 0 otherwise.
void read_can_encoder(TableReader t, CanEncoderSection& s, int wheels) {
  s.bus = t.choice("bus", s.bus);
  s.interface = t.string("interface", s.interface);
  s.protocol = t.choice("protocol", s.protocol);
  read_can_odrive_nodes(t, s, s.protocol == CanEncoderProtocol::kOdrive);
  s.reverse_left = t.boolean("reverse_left", s.reverse_left);
  s.reverse_right = t.boolean("reverse_right", s.reverse_right);
  s.timeout = t.number("timeout", s.timeout, 0.005, 10.0, "s");
  s.max_speed = t.number("max_speed", s.max_speed, 0.01, 100.0, "m/s");
  s.request_rate = t.number("request_rate", s.request_rate, 0.0, 1000.0, "Hz");
  s.max_frames_per_read =
      static_cast<int>(t.integer(s.max_frames_per_read, drivers::kCanMaxFramesPerRead));
  s.extended = t.boolean("extended", s.extended);
  s.width = static_cast<int>(t.integer("width", s.width, 16, 64));
  if (s.width % 8 != 0)
    t.reject("width",
             "= " + std::to_string(s.width) + " must be a whole number of bytes (16, 24, ..., 64)");
  read_can_generic_ids(t, s, s.protocol == CanEncoderProtocol::kGeneric);
  s.is_signed = t.boolean("signed", s.is_signed);
  s.byte_order = t.choice("byte_order", s.byte_order);
  s.sim_period = t.number("sim_period", s.sim_period, 0.001, 1.0, "s");
  s.sim_stop_left_after = t.number("sim_stop_left_after", s.sim_stop_left_after, -1.0, 1e6, "s");
  s.sim_stop_right_after = t.number("sim_stop_right_after", s.sim_stop_right_after, -1.0, 1e6, "s");
  if (wheels > 0 && s.wheels_per_side != wheels)
    t.reject(s.protocol == CanEncoderProtocol::kOdrive ? "node_left" : "left_id",
             "lists " + std::to_string(s.wheels_per_side) +
                 " wheel(s) but encoder.wheels_per_side = " + std::to_string(wheels) +
                 ": give one per wheel of the side");
  if (s.bus == CanEncoderBus::kSim && s.wheels_per_side > 1)
    t.reject("bus",
             "= \"sim\" simulates one ODrive axis per side: " + std::to_string(s.wheels_per_side) +
                 " wheels per side need bus = \"socketcan\"");
  t.finish();
}

// read_serial: [serial]; `wheels`: encoder.wheels_per_side when the serial backend is the
// encoder, 0 otherwise.
void read_serial(TableReader t, SerialSection& s, int wheels) {
  s.link = t.choice("link", s.link);
  s.device = t.string("device", s.device);
  s.device_where = t.location("device");
  s.protocol = t.choice("protocol", s.protocol);
  s.baud = static_cast<int>(t.integer("baud", s.baud, 1, 4000000));
  if (!drivers::supported_baud(s.baud))
    t.reject("baud", "= " + std::to_string(s.baud) + " is not a supported baud rate (" +
                         drivers::baud_list() + ")");
  s.bits_left = static_cast<int>(t.integer("bits_left", s.bits_left, 8, 32));
  s.bits_right = static_cast<int>(t.integer("bits_right", s.bits_right, 8, 32));
  s.reverse_left = t.boolean("reverse_left", s.reverse_left);
  s.reverse_right = t.boolean("reverse_right", s.reverse_right);
  for (const auto& n : kSerialNumbers) s.*n.member = t.number(s.*n.member, n.row);
  if (wheels > 1 && s.protocol == SerialProtocol::kArduinoBridge)
    t.reject("protocol",
             "= \"arduino-bridge\" carries one count per side: encoder.wheels_per_side = " +
                 std::to_string(wheels) + " needs protocol = \"diffodom\" (version 2 records)");
  t.finish();
}

void read_error_model(TableReader t, ErrorModelParams& k) {
  k.k_left = t.number("k_left", k.k_left, 0.0, kErrorModelKMax, "m^(1/2)");
  k.k_right = t.number("k_right", k.k_right, 0.0, kErrorModelKMax, "m^(1/2)");
  k.covariance_ticks = static_cast<std::uint32_t>(
      t.integer("covariance_ticks", k.covariance_ticks, 1, kCovarianceTicksMax));
  t.finish();
}

// read_interface: the key "interface", a network interface name (the kernel's IFNAMSIZ - 1).
std::string read_interface(TableReader& t, std::string def) {
  std::string name = t.string("interface", std::move(def));
  if (name.empty() || name.size() > 15)
    t.reject("interface", "= \"" + name + "\" must be 1..15 characters (a network interface)");
  return name;
}

// ---- [can] (CAN pose broadcast) ----
void read_can(TableReader t, CanSection& s, TableReader loop, double loop_hz) {
  s.bus = t.choice("bus", s.bus);
  s.interface = read_interface(t, s.interface);
  s.node_id = static_cast<int>(t.integer("node_id", s.node_id, 0, protocol::kMaxNodeId));
  s.base_id = static_cast<int>(t.integer("base_id", s.base_id, 0, 1024));
  if (s.base_id % 16 != 0)
    t.reject("base_id", "= " + std::to_string(s.base_id) + " must be a multiple of 16");
  // The ranges keep every node's block of 16 ids inside 11 bits.
  static_assert(protocol::frame_id(1024, protocol::kMaxNodeId, protocol::Msg::kSetPose) + 7 <=
                0x7FF);
  for (auto [key, rate] :
       {std::pair{"pose_hz", &s.pose_hz}, std::pair{"velocity_hz", &s.velocity_hz},
        std::pair{"uncertainty_hz", &s.uncertainty_hz}, std::pair{"status_hz", &s.status_hz},
        std::pair{"timing_hz", &s.timing_hz}}) {
    *rate = t.number(key, *rate, 0.0, 2000.0, "Hz");
    if (t.ok() && protocol::divisor_for(loop_hz, *rate) < 0) {
      std::ostringstream o;
      if (t.written(key)) {
        o << "= " << *rate
          << " Hz must be 0 or loop.rate_hz / n for a whole n >= 1 (loop.rate_hz = " << loop_hz
          << ")";
        t.reject(key, o.str());
      } else {  // the rate is can's default: the loop rate the user wrote is what does not fit
        o << "= " << loop_hz << " Hz is not a whole multiple of can." << key << " = " << *rate
          << " Hz (its default): use a loop rate that is (e.g. 100 or 200), or set can." << key
          << " to loop.rate_hz / n, or 0 (off)";
        loop.reject("rate_hz", o.str());
      }
    }
  }
  s.set_pose = t.boolean("set_pose", s.set_pose);
  s.reopen_period = t.number("reopen_period", s.reopen_period, 0.01, 60.0, "s");
  t.finish();
}

// ---- [ros2] (ROS 2 output; ranges and name rules are the ros2 library's) ----
void read_ros2(TableReader t, ros2::Config& c, double loop_hz, int loop_priority) {
  c.enabled = t.boolean("enabled", c.enabled);
  c.domain_id =
      static_cast<std::uint32_t>(t.integer("domain_id", c.domain_id, 0, ros2::kDomainIdMax));
  c.ns = t.string("namespace", c.ns);
  c.odom_frame = t.string("odom_frame", c.odom_frame);
  c.base_frame = t.string("base_frame", c.base_frame);
  c.rate_hz = t.number("rate_hz", c.rate_hz, ros2::kRateMinHz, loop_hz, "Hz");
  c.publish_tf = t.boolean("publish_tf", c.publish_tf);
  c.interfaces = t.strings("interfaces", c.interfaces);
  c.peers = t.strings("peers", c.peers);
  c.multicast = t.boolean("multicast", c.multicast);
  c.priority = static_cast<int>(t.integer("priority", c.priority, 0, ros2::kPriorityMax));
  c.spin_us = static_cast<int>(t.integer("spin_us", c.spin_us, 0, ros2::kSpinMaxUs));
  if (!t.ok()) return;
  if (auto p = ros2::check(c, loop_hz)) t.reject(p->key, p->what);
  if (c.priority > 0 && loop_priority > 0 && c.priority >= loop_priority)
    t.reject("priority", "= " + std::to_string(c.priority) + " must be below realtime.priority (" +
                             std::to_string(loop_priority) +
                             "): the publish thread must never preempt the loop");
  if (c.enabled && !ros2::kBuiltWithDds)
    t.reject("enabled",
             "= true, but this odometryd was built without the ROS 2 output (-DODO_ROS2=OFF, no "
             "Cyclone DDS): set enabled = false or use a build with -DODO_ROS2=ON");
  t.finish();
}

// ---- [resume] (pose that survives restarts) ----
void read_resume(TableReader t, ResumeSection& s, double loop_hz) {
  s.enabled = t.boolean("enabled", s.enabled);
  s.path = t.string("path", s.path);
  if (s.path.empty()) t.reject("path", "= \"\" must name the state file");
  s.rate_hz = t.number("rate_hz", s.rate_hz, 1.0, loop_hz, "Hz");
  s.max_age = t.number("max_age", s.max_age, 0.01, 3600.0, "s");
  t.finish();
}

// ---- [selfcal] (self-calibration from absolute fixes) ----
void read_selfcal(TableReader t, SelfCalSection& s) {
  s.enabled = t.boolean("enabled", s.enabled);
  for (const auto& r : kSelfCalIntegers)
    s.*r.member = static_cast<int>(t.integer(r.key, s.*r.member, r.lo, r.hi));
  for (const auto& r : kSelfCalNumbers)
    s.*r.member = t.number(r.key, s.*r.member, r.lo, r.hi, r.unit);
  s.x_icr = t.choice("x_icr", s.x_icr);
  if (t.ok() && s.max_fixes < s.min_fixes)
    t.reject("max_fixes", "= " + std::to_string(s.max_fixes) + " must be >= min_fixes (" +
                              std::to_string(s.min_fixes) + ")");
  t.finish();
}

// ---- [gyro] ----
// The section's field of each of the fusion's user-set parameters, in GyroParam order.
constexpr double GyroSection::*kGyroFusionMembers[kGyroConfigParams] = {
    &GyroSection::noise_density, &GyroSection::bias_instability, &GyroSection::scale_tolerance,
    &GyroSection::delay,         &GyroSection::delay_tolerance,  &GyroSection::window,
    &GyroSection::k_sigma,       &GyroSection::max_wheel_speed,  &GyroSection::max_wheel_accel,
    &GyroSection::still_time,    &GyroSection::bias_tau};

// read_gyro_numbers: the source's numbers, then the fusion's against its own limits at this
// loop's tick (bias_tau after still_time: its lower limit is the still_time just read).
void read_gyro_numbers(TableReader& t, GyroSection& s, double loop_hz) {
  for (const auto& n : kGyroSourceNumbers) s.*n.member = t.number(s.*n.member, n.row);
  for (std::size_t i = 0; i < kGyroConfigParams; ++i) {
    const RangeRow r = gyrodometry_range(static_cast<GyroParam>(i), 1.0 / loop_hz, s.still_time);
    s.*kGyroFusionMembers[i] = t.number(s.*kGyroFusionMembers[i], r);
  }
}

void read_gyro(TableReader t, GyroSection& s, double loop_hz) {
  s.backend = t.choice("backend", s.backend);
  s.device = t.string("device", s.device);
  s.axis = t.choice("axis", s.axis);
  s.sign = static_cast<int>(t.integer("sign", s.sign, -1, 1));
  if (s.sign == 0)
    t.reject("sign",
             "= 0 must be +1 (the chip axis points up, along the robot's z) or -1 "
             "(mounted upside down)");
  s.mode = t.choice("mode", s.mode);
  s.trigger = t.string("trigger", s.trigger);
  s.buffer_length = static_cast<int>(t.integer("buffer_length", s.buffer_length, 2, 65536));
  s.model = t.choice("model", s.model);
  s.seed = t.integer("seed", s.seed, 0, INT64_MAX);
  read_gyro_numbers(t, s, loop_hz);
  s.scale_estimation = t.boolean("scale_estimation", s.scale_estimation);
  if (s.backend == GyroBackend::kIio && s.device.empty())
    t.reject("device",
             "must name the IIO gyro (its name, sysfs directory or /dev/iio:deviceN) "
             "when backend = \"iio\"");
  t.finish();
}

// ---- [can_gyro] ----
void read_can_gyro(TableReader t, CanGyroSection& s) {
  s.bus = t.choice("bus", s.bus);
  s.interface = read_interface(t, s.interface);
  s.extended = t.boolean("extended", s.extended);
  s.id = t.integer("id", s.id, 0, s.extended ? 0x1FFFFFFF : 0x7FF);
  s.width = static_cast<int>(t.integer("width", s.width, 16, 32));
  if (s.width % 8 != 0)
    t.reject("width", "= " + std::to_string(s.width) + " must be 16, 24 or 32 (whole bytes)");
  s.offset = static_cast<int>(t.integer("offset", s.offset, 0, 8 - s.width / 8));
  s.is_signed = t.boolean("signed", s.is_signed);
  s.byte_order = t.choice("byte_order", s.byte_order);
  s.scale = t.number("scale", s.scale, 1e-9, 1.0, "rad/s per LSB");
  s.rate_offset = t.number("rate_offset", s.rate_offset, -1000.0, 1000.0, "rad/s");
  s.max_frames_per_read =
      static_cast<int>(t.integer(s.max_frames_per_read, drivers::kCanMaxFramesPerRead));
  s.sim_stop_after = t.number("sim_stop_after", s.sim_stop_after, -1.0, 1e6, "s");
  t.finish();
}

// check_gyro_robot: a simulated gyro measures the simulated robot's motion, so it needs the
// simulated robot's encoders; caught here, with the line, before any hardware is opened.
void check_gyro_robot(TableReader& root, const Config& c) {
  if (!simulated_gyro(c) || simulated_robot(c)) return;
  const std::string why =
      " is a simulated gyro, which needs the simulated robot, but encoder.backend "
      "= \"" +
      std::string(name_of(c.encoder.backend)) +
      "\" reads real hardware (use the real gyro: gyro.backend = \"iio\", or "
      "\"can\" with can_gyro.bus = \"socketcan\")";
  if (c.gyro.backend == GyroBackend::kSim)
    root.sub("gyro").reject("backend", "= \"sim\"" + why);
  else
    root.sub("can_gyro").reject("bus", "= \"sim\" with gyro.backend = \"can\"" + why);
}

// first_non_ascii: the first byte >= 0x80 as "line N, column C (byte 0xXX)", or "" if none.
// The config is plain ASCII: toml++ 3.3 (Debian 12) reaches __builtin_unreachable() on some
// non-ASCII characters (upstream issues #190 and #295; found here by fuzz_config), so such a
// file never reaches the TOML parser.
std::string first_non_ascii(std::string_view text) {
  int line = 1, column = 1;
  for (const char ch : text) {
    const auto byte = static_cast<unsigned char>(ch);
    if (byte >= 0x80) {
      char where[80];
      std::snprintf(where, sizeof where, "%d: column %d: byte 0x%02X", line, column, byte);
      return where;
    }
    if (ch == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
  }
  return {};
}

}  // namespace

Result<Config> parse_config(std::string_view text, std::string_view source) {
  Config c = default_config();
  c.source = std::string(source);
  if (const std::string bad = first_non_ascii(text); !bad.empty()) {
    return make_error(Errc::kParse, std::string(source) + ":" + bad +
                                        " is not ASCII (the config file must be plain ASCII)");
  }
  toml::table parsed;
  try {
    // toml++ reports syntax errors by exception; this is configure time, not the loop path.
    parsed = toml::parse(text, source);
  } catch (const toml::parse_error& e) {
    std::ostringstream m;
    m << source << ":" << e.source().begin.line << ": TOML syntax error: " << e.description();
    return make_error(Errc::kParse, m.str());
  }
  std::string error;
  TableReader root(&parsed, "", source, &error);
  read_loop(root.sub("loop"), c.loop);
  read_robot(root.sub("robot"), c.robot);
  read_encoder(root.sub("encoder"), c.encoder, c.loop.rate_hz);
  read_sim(root.sub("sim"), c.sim);
  read_realtime(root.sub("realtime"), c.realtime);
  read_calibration(root.sub("calibration"), c.calibration);
  read_hctl1100(root.sub("hctl1100"), c.hctl1100);
  read_gpio(root.sub("gpio"), c.gpio,
            c.encoder.backend == EncoderKind::kGpio ? c.encoder.side.wheels_per_side : 0);
  read_can_encoder(root.sub("can_encoder"), c.can_encoder,
                   c.encoder.backend == EncoderKind::kCan ? c.encoder.side.wheels_per_side : 0);
  read_serial(root.sub("serial"), c.serial,
              c.encoder.backend == EncoderKind::kSerial ? c.encoder.side.wheels_per_side : 0);
  read_error_model(root.sub("error_model"), c.error_model);
  read_can(root.sub("can"), c.can, root.sub("loop"), c.loop.rate_hz);
  ros2::Config ros2_cfg;
  read_ros2(root.sub("ros2"), ros2_cfg, c.loop.rate_hz, c.realtime.priority);
  c.ros2 = std::make_shared<const ros2::Config>(std::move(ros2_cfg));
  read_resume(root.sub("resume"), c.resume, c.loop.rate_hz);
  read_selfcal(root.sub("selfcal"), c.selfcal);
  read_gyro(root.sub("gyro"), c.gyro, c.loop.rate_hz);
  read_can_gyro(root.sub("can_gyro"), c.can_gyro);
  check_gyro_robot(root, c);
  root.finish();
  if (!error.empty()) return make_error(Errc::kInvalidArgument, error);
  return c;
}

bool simulated_robot(const Config& cfg) {
  const EncoderKind be = cfg.encoder.backend;
  return be == EncoderKind::kSim ||
         (be == EncoderKind::kHctl1100 && cfg.hctl1100.bus == HctlBus::kSim) ||
         (be == EncoderKind::kCan && cfg.can_encoder.bus == CanEncoderBus::kSim) ||
         (be == EncoderKind::kSerial && cfg.serial.link == SerialLink::kSim);
}

bool simulated_gyro(const Config& cfg) {
  return cfg.gyro.backend == GyroBackend::kSim ||
         (cfg.gyro.backend == GyroBackend::kCan && cfg.can_gyro.bus == CanEncoderBus::kSim);
}

Result<Config> load_config(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) {
    return make_error(Errc::kNotFound,
                      path + ": cannot open config file (" + std::strerror(errno) + ")");
  }
  std::string text;
  char buf[4096];
  std::size_t n = 0;
  while ((n = std::fread(buf, 1, sizeof buf, f)) > 0) text.append(buf, n);
  // A read error (e.g. the path is a directory: EISDIR) must not pass for an empty file, which
  // would silently mean "all defaults".
  const bool failed = std::ferror(f) != 0;
  const int err = errno;
  std::fclose(f);
  if (failed) {
    return make_error(Errc::kIo, path + ": cannot read config file (" + std::strerror(err) + ")");
  }
  return parse_config(text, path);
}

}  // namespace odo::fw
