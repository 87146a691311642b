// The pose that survives restarts (issue 17), the daemon's side: the boot id, the state file
// (two slots of loop/state_record.hpp), the per-tick observer that hands the loop's state to a
// writer thread, and the wiring that offers the stored record to the loop at start.
#pragma once

#include <semaphore.h>

#include <atomic>
#include <memory>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <thread>

#include "odo/firmware/config.hpp"
#include "odo/hal/result.hpp"
#include "odo/loop/loop.hpp"
#include "odo/loop/state_record.hpp"
#include "odo/loop/triple_buffer.hpp"

namespace odo::drivers {
class StateFile;  // drivers/state_file.hpp: the file's Linux side
}  // namespace odo::drivers

namespace odo::fw {

inline constexpr const char* kBootIdPath = "/proc/sys/kernel/random/boot_id";

// parse_boot_id: "xxxxxxxx-xxxx-xxxx-xxxx-xxxxxxxxxxxx" (a trailing newline allowed) as bytes.
Result<loop::BootId> parse_boot_id(std::string_view text);
// read_boot_id: the running kernel's boot id from `path`.
Result<loop::BootId> read_boot_id(const std::string& path = kBootIdPath);

// kBootIdEnv: the boot id given by the service manager where /proc/sys is hidden (the unit's
// ProcSubset=pid): Environment=ODOMETRYD_BOOT_ID=%b.
inline constexpr const char* kBootIdEnv = "ODOMETRYD_BOOT_ID";
// current_boot_id: the boot id from `path`; when that cannot be read, from `env` (the value of
// kBootIdEnv, nullptr when unset; a value that is no UUID is an error naming the variable);
// without either, the all-zero id when `state_path` is on a tmpfs (a record there is from this
// boot), else the error.
Result<loop::BootId> current_boot_id(const std::string& state_path, const char* env,
                                     const std::string& path = kBootIdPath);

// read_state_file: the newest valid record of the state file at `path`; Errc::kNotFound when
// there is none, Errc::kCorrupt when neither slot holds a valid record.
Result<loop::StateRecord> read_state_file(const std::string& path);

// counters_survive_restart: whether the configured backend's counters keep counting while
// odometryd is down: the HCTL-1100 chips on their bus (bus = "gpio") and the motor controllers'
// counters on SocketCAN (the driver reports them as the controllers hold them). GPIO quadrature
// (decoded by this process) and the simulated backends (they restart with the process) do not.
bool counters_survive_restart(const Config& cfg);

// gyro_id: which gyro [gyro] and [can_gyro] configure, as far as the meaning of its rate goes
// (backend, device, axis, sign, model and seed, the CAN field and its scaling): the state record
// carries it, and a learnt bias and scale are restored only to the same id. 0: no gyro.
std::uint32_t gyro_id(const Config& cfg);

// StatePersister: a TickObserver that, every n-th tick (and at once on the tick a command such
// as set-pose took effect), copies the loop's state into a triple buffer and wakes a writer
// thread; the thread writes the record into the state file's next slot. The loop thread never
// blocks, allocates or does I/O here.
class StatePersister final : public loop::TickObserver {
 public:
  // create: opens (creates) the state file; `identity` carries the fields that do not change
  // (boot id, clock epoch, backend, calibration sequence) and the last sequence used.
  static Result<std::unique_ptr<StatePersister>> create(const std::string& path, double rate_hz,
                                                        double loop_hz,
                                                        const loop::OdometryLoop& loop,
                                                        const loop::StateRecord& identity);
  ~StatePersister() override;
  StatePersister(const StatePersister&) = delete;
  StatePersister& operator=(const StatePersister&) = delete;

  void on_tick(const loop::LoopSnapshot& snap) noexcept override;
  // start: the writer thread; once the loop's start() decided it logs the decision on `log`
  // (`fixed`: the reason when no record was offered, `note`: details appended).
  void start(std::ostream& log, std::optional<loop::ResumeReason> fixed, std::string note);
  // stop: ends and joins the thread, then writes the loop's final state (call once the loop
  // stopped ticking; idempotent).
  void stop();
  std::uint64_t written() const noexcept { return written_.load(std::memory_order_relaxed); }
  std::uint64_t write_errors() const noexcept {
    return write_errors_.load(std::memory_order_relaxed);
  }

 private:
  StatePersister(std::unique_ptr<drivers::StateFile> file, std::uint64_t every,
                 const loop::OdometryLoop& loop, const loop::StateRecord& identity);
  void run(std::ostream& log, std::optional<loop::ResumeReason> fixed, const std::string& note);
  void write_newest() noexcept;

  std::unique_ptr<drivers::StateFile> file_;
  std::uint64_t every_;  // ticks per record
  const loop::OdometryLoop& loop_;
  loop::StateRecord identity_;
  // loop thread
  std::uint64_t countdown_ = 1;
  std::uint64_t seen_commands_ = 0;
  std::uint64_t sequence_;
  loop::TripleBuffer<loop::StateRecord> records_;
  // writer thread
  loop::StateRecord newest_;
  std::uint64_t last_written_ = 0;
  sem_t wake_{};
  std::atomic<bool> done_{false};
  std::atomic<std::uint64_t> written_{0};
  std::atomic<std::uint64_t> write_errors_{0};
  std::thread thread_;
};

// ResumeWiring: what prepare_resume set up for the daemon.
struct ResumeWiring {
  bool active = false;   // persistence and the resume decision in use (not in virtual time)
  bool offered = false;  // a record was handed to the loop (its decision is the loop's)
  loop::ResumeReason reason = loop::ResumeReason::kDisabled;  // when not offered
  std::string note;  // details of a missing or corrupt record
  std::unique_ptr<StatePersister> persister;
};

// prepare_resume: reads the state file and, when there is a valid record, offers it to `loop`
// (resume_from); creates the persister (a state file that cannot be opened is reported on
// `log` and the daemon runs without persistence). Configure time.
ResumeWiring prepare_resume(const Config& cfg, loop::OdometryLoop& loop,
                            std::uint64_t calibration_sequence, std::ostream& log);

// resume_reason: the final reason (the loop's decision when a record was offered).
loop::ResumeReason resume_reason(const ResumeWiring& w, const loop::OdometryLoop& loop);

}  // namespace odo::fw
