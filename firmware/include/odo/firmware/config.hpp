// The daemon's configuration: a TOML file, validated field by field. Every error names the file,
// the line, the field and the allowed range.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "odo/hal/result.hpp"
#include "odo/odometry/kinematics.hpp"

namespace odo::fw {

struct LoopSection {
  double rate_hz = 100.0;      // [Hz] 50..2000
  double status_period = 1.0;  // [s] between status lines, 0 = none
};

struct SimSection {
  std::string robot = "labmate";        // labmate | nominal (true geometry = believed)
  std::string scenario = "square-ccw";  // square-ccw | square-cw | squares | idle
  double side = 4.0;                    // [m]
  double speed = 0.2;                   // [m/s]
  double turn_rate = 0.5;               // [rad/s]
  double pause = 0.5;                   // [s]
  int counter_bits = 32;                // simulated counter width, 16..64
};

struct EncoderSection {
  std::string backend = "sim";  // sim | hctl1100 | gpio | can
};

// [realtime]: how the loop thread is made real-time at start (each part reported at start).
struct RealtimeSection {
  int priority = 80;            // SCHED_FIFO priority 1..99 of the loop thread; 0 = SCHED_OTHER
  bool lock_memory = true;      // mlockall(MCL_CURRENT | MCL_FUTURE)
  int cpu = -1;                 // pin the loop thread to this CPU; -1 = no pinning
  int prefault_stack = 262144;  // bytes of loop stack touched before the first tick, 0..4 MiB
  bool required = false;        // true: refuse to start when a requested part cannot be applied
};

// Where the calibration record lives ([calibration]); see calibration_io.hpp.
struct CalibrationSection {
  std::string store = "/var/lib/odometryd/calibration.bin";  // "" = no store: nominal values
  std::string backend = "auto";                              // auto | file | nvmem | mtd
};

struct Config {
  std::string source = "<built-in>";  // file the config came from
  LoopSection loop;
  KinematicParams robot;  // nominal robot; c_l, c_r, wheelbase may be replaced by calibration
  EncoderSection encoder;
  SimSection sim;
  RealtimeSection realtime;
  CalibrationSection calibration;
};

// default_config: the embedded default: the simulated LabMate of the UMBmark report.
Config default_config();

// parse_config: parses TOML text; `source` names it in messages. Unknown keys are errors.
Result<Config> parse_config(std::string_view text, std::string_view source);

// load_config: reads and parses a file.
Result<Config> load_config(const std::string& path);

}  // namespace odo::fw
