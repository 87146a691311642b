#include "odo/firmware/state_persist.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <iomanip>
#include <span>
#include <sstream>
#include <utility>

#include "odo/calibration/record.hpp"
#include "odo/drivers/state_file.hpp"
#include "odo/hal/crc.hpp"

namespace odo::fw {
namespace {

// hex_value: 0..15 of a hex digit, -1 for anything else.
int hex_value(char c) {
  int v = -1;
  std::from_chars(&c, &c + 1, v, 16);
  return v;
}

Error io_error(const std::string& what, const std::string& path) {
  return make_error(Errc::kIo, path + ": " + what + " (" + std::strerror(errno) + ")");
}

// Backend ids as stored in a record: the EncoderKind plus the bus, so that the simulated and
// the real variant of a backend never continue each other's counts.
std::uint8_t backend_id(const Config& cfg) {
  // The kind in the high nibble (the shift is done in unsigned; the ids fit a byte).
  auto id = static_cast<std::uint8_t>(static_cast<unsigned>(cfg.encoder.backend) << 4);
  if (cfg.encoder.backend == EncoderKind::kHctl1100)
    id |= static_cast<std::uint8_t>(cfg.hctl1100.bus);
  if (cfg.encoder.backend == EncoderKind::kCan)
    id |= static_cast<std::uint8_t>(cfg.can_encoder.bus);
  if (cfg.encoder.backend == EncoderKind::kSerial) id |= static_cast<std::uint8_t>(cfg.serial.link);
  return id;
}

// gyro_resume_text: the resume line's end into out[0, n): with `tell`, what became of the
// record's gyro calibration ("; gyro ..."), then the newline. Returns the characters written.
int gyro_resume_text(const loop::ResumeDecision& d, bool tell, char* out, std::size_t n) {
  int k = 0;
  if (!tell)
    k = std::snprintf(out, n, "\n");
  else if (d.gyro_restored)
    k = std::snprintf(out, n, "; gyro bias %.6e rad/s (%.1f s of standstill)%s restored\n",
                      d.gyro.bias, d.gyro.bias_time, d.gyro.scale_valid ? " and scale" : "");
  else
    k = std::snprintf(
        out, n, "; gyro: %s, detection waits for the next standstill\n",
        d.gyro_matches ? "its bias was not learnt yet" : "the record is another gyro's (or none)");
  return std::clamp(k, 0, static_cast<int>(n) - 1);
}

}  // namespace

Result<loop::BootId> parse_boot_id(std::string_view text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.remove_suffix(1);
  loop::BootId id{};
  std::size_t n = 0;
  int high = -1;
  for (const char c : text) {
    if (c == '-') continue;
    const int v = hex_value(c);
    if (v < 0 || n >= id.size()) return make_error(Errc::kParse, "boot id: not a UUID");
    if (high < 0) {
      high = v;
    } else {
      id[n++] = static_cast<std::uint8_t>(high << 4 | v);
      high = -1;
    }
  }
  if (n != id.size() || high >= 0) return make_error(Errc::kParse, "boot id: not a UUID");
  return id;
}

Result<loop::BootId> read_boot_id(const std::string& path) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) return io_error("cannot open", path);
  char buf[64] = {};
  const std::size_t n = std::fread(buf, 1, sizeof buf - 1, f);
  std::fclose(f);
  auto id = parse_boot_id(std::string_view(buf, n));
  if (!id) return make_error(Errc::kParse, path + ": " + id.error().message);
  return id;
}

Result<loop::BootId> current_boot_id(const std::string& state_path, const char* env,
                                     const std::string& path) {
  auto id = read_boot_id(path);
  if (id) return id;
  if (env != nullptr) {
    auto e = parse_boot_id(env);
    if (!e)
      return make_error(Errc::kParse,
                        std::string(kBootIdEnv) + "=\"" + env + "\": " + e.error().message);
    return e;
  }
  // A record on a tmpfs (emptied by every reboot) is from this boot by construction: the
  // all-zero id stands for "this boot" in both the record and the check.
  if (drivers::on_tmpfs(state_path)) return loop::BootId{};
  return id;
}

Result<loop::StateRecord> read_state_file(const std::string& path) {
  std::array<std::uint8_t, loop::kStateFileBytes> b{};
  auto n = drivers::read_file_head(path, b);
  if (!n) {
    if (n.error().code == Errc::kNotFound)
      return make_error(Errc::kNotFound,
                        "no state file yet at " + path + " (odometryd writes it while it runs)");
    return std::move(n).error();
  }
  auto r = loop::decode_state_file(std::span<const std::uint8_t>(b.data(), *n));
  if (!r) return make_error(r.error().code, path + ": " + r.error().message);
  return r;
}

std::uint32_t gyro_id(const Config& cfg) {
  const GyroSection& g = cfg.gyro;
  if (g.backend == GyroBackend::kNone) return 0;
  std::ostringstream t;
  t << std::setprecision(17);  // every bit of the scaling: another LSB is another gyro
  t << name_of(g.backend) << '|' << g.device << '|' << name_of(g.axis) << '|' << g.sign;
  if (simulated_gyro(cfg)) t << '|' << name_of(g.model) << '|' << g.seed;  // another chip
  if (g.backend == GyroBackend::kCan) {
    const CanGyroSection& c = cfg.can_gyro;
    t << '|' << name_of(c.bus) << '|' << c.interface << '|' << c.id << '|' << c.extended << '|'
      << c.offset << '|' << c.width << '|' << c.is_signed << '|' << name_of(c.byte_order) << '|'
      << c.scale << '|' << c.rate_offset;
  }
  // The records' own CRC-32 of that text: any change of it is another gyro.
  const std::string text = t.str();
  const std::uint32_t h = odo::crc32(std::span<const std::uint8_t>(
      reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
  return h != 0 ? h : 1;  // 0 means "no gyro"
}

bool counters_survive_restart(const Config& cfg) {
  // Several encoders per side: the sides' counts are this process's combination of the wheels'
  // deltas (hal/side_wheels.hpp), from 0 at its start, not a counter that kept counting.
  if (cfg.encoder.side.wheels_per_side > 1) return false;
  switch (cfg.encoder.backend) {
    case EncoderKind::kHctl1100:
      return cfg.hctl1100.bus == HctlBus::kGpio;
    case EncoderKind::kCan:
      // The driver reports the controllers' own counters (drivers/can_encoder.hpp).
      return cfg.can_encoder.bus == CanEncoderBus::kSocketCan;
    case EncoderKind::kSerial:
      // The microcontroller's own counters (protocol/serial_counts_source.hpp).
      return cfg.serial.link == SerialLink::kTty;
    case EncoderKind::kGpio:  // decoded by this process: edges are lost while it is down
    case EncoderKind::kSim:   // restarts with the process
      return false;
  }
  return false;
}

// ---- StatePersister ----

Result<std::unique_ptr<StatePersister>> StatePersister::create(const std::string& path,
                                                               double rate_hz, double loop_hz,
                                                               const loop::OdometryLoop& loop,
                                                               const loop::StateRecord& identity) {
  // Both slots exist from the start; the older record in them stays readable until replaced.
  auto file = drivers::StateFile::open(path, loop::kStateFileBytes);
  if (!file) return std::move(file).error();
  const auto every = static_cast<std::uint64_t>(std::max(1.0, std::round(loop_hz / rate_hz)));
  return std::unique_ptr<StatePersister>(
      new StatePersister(std::move(file).value(), every, loop, identity));
}

StatePersister::StatePersister(std::unique_ptr<drivers::StateFile> file, std::uint64_t every,
                               const loop::OdometryLoop& loop, const loop::StateRecord& identity)
    : file_(std::move(file)),
      every_(every),
      loop_(loop),
      identity_(identity),
      sequence_(identity.sequence) {
  sem_init(&wake_, 0, 0);
}

StatePersister::~StatePersister() {
  stop();
  sem_destroy(&wake_);
}

void StatePersister::on_tick(const loop::LoopSnapshot&) noexcept {
  // Every n-th tick, and at once on a tick whose commands (a set pose) changed the state.
  const std::uint64_t applied = loop_.commands_applied();
  if (--countdown_ != 0 && applied == seen_commands_) return;
  countdown_ = every_;
  seen_commands_ = applied;
  loop::StateRecord& r = records_.back();
  loop::fill_state_record(loop_, r);
  r.sequence = ++sequence_;
  records_.publish();
  sem_post(&wake_);  // never blocks; a futex wake only when the writer waits
}

void StatePersister::start(std::ostream& log, std::optional<loop::ResumeReason> fixed,
                           std::string note) {
  thread_ = std::thread([this, &log, fixed, n = std::move(note)] { run(log, fixed, n); });
}

void StatePersister::stop() {
  if (!thread_.joinable()) return;
  done_.store(true, std::memory_order_release);
  sem_post(&wake_);
  thread_.join();
  // The loop has stopped (stop() is called after run() returned): the state of its very last
  // tick, which need not have been a due tick, is written too.
  loop::StateRecord& r = records_.back();
  loop::fill_state_record(loop_, r);
  r.sequence = ++sequence_;
  records_.publish();
  write_newest();
}

void StatePersister::write_newest() noexcept {
  if (!records_.latest(newest_) || newest_.sequence == last_written_) return;
  loop::StateRecord r = newest_;
  r.boot_id = identity_.boot_id;
  r.clock_epoch = identity_.clock_epoch;
  r.backend = identity_.backend;
  r.calibration_sequence = identity_.calibration_sequence;
  r.gyro_id = identity_.gyro_id;
  loop::StateBytes b{};
  loop::encode_state(r, b);
  if (file_->write_at((r.sequence % 2) * loop::kStateSlotBytes, b)) {
    last_written_ = r.sequence;
    written_.fetch_add(1, std::memory_order_relaxed);
  } else {
    write_errors_.fetch_add(1, std::memory_order_relaxed);
  }
}

namespace {

// counter_jump_text: appends to the `n` bytes in `line` which wheel jumped and how far, against
// the most it could move in the gap (issue 39); returns the new length.
int counter_jump_text(const loop::ResumeDecision& d, char* line, std::size_t size, int n) {
  const std::array<std::pair<const char*, std::int64_t>, 2> wheels{
      {{"left", d.dl}, {"right", d.dr}}};
  const std::array<double, 2> bound{d.max_dl, d.max_dr};
  for (std::size_t i = 0; i < 2; ++i) {
    if (std::fabs(static_cast<double>(wheels[i].second)) <= bound[i]) continue;
    n = std::clamp(n, 0, static_cast<int>(size) - 1);
    n += std::snprintf(line + n, size - static_cast<std::size_t>(n),
                       ": %s wheel %+lld counts in the %.3f s gap, at most %.0f at max_speed",
                       wheels[i].first, static_cast<long long>(wheels[i].second), to_seconds(d.gap),
                       std::floor(bound[i]));
  }
  return n;
}

}  // namespace

void StatePersister::run(std::ostream& log, std::optional<loop::ResumeReason> fixed,
                         const std::string& note) {
  bool told = false;
  while (!done_.load(std::memory_order_acquire)) {
    timespec until{};
    clock_gettime(CLOCK_REALTIME, &until);
    until.tv_nsec += 100'000'000;  // wake at least every 0.1 s to notice stop and the decision
    if (until.tv_nsec >= 1'000'000'000) {
      until.tv_sec += 1;
      until.tv_nsec -= 1'000'000'000;
    }
    sem_timedwait(&wake_, &until);
    if (!told && loop_.resume_decided()) {
      // The decision is made in the loop's start(); it is told here, off the loop thread.
      const loop::ResumeDecision& d = loop_.resume_decision();
      const loop::ResumeReason why = fixed ? *fixed : d.reason;
      // A stack buffer and one write: the thread allocates nothing while the loop runs.
      char line[400];
      int n = 0;
      bool tell_gyro = false;
      if (why == loop::ResumeReason::kResumed) {
        // The gap's counts, integrated as one step, and the pose that gave: what a check of
        // the resume (against the counts the controllers sent) needs.
        n = std::snprintf(line, sizeof line,
                          "odometryd: resume: resumed after a gap of %.3f s (left %+lld, right "
                          "%+lld counts) at x %.10f m, y %.10f m, theta %.12f rad",
                          to_seconds(d.gap), static_cast<long long>(d.dl),
                          static_cast<long long>(d.dr), d.pose.x, d.pose.y, d.pose.theta);
        tell_gyro = loop_.fusion() != nullptr;
      } else {
        const std::string_view name = loop::resume_reason_name(why);
        n = std::snprintf(line, sizeof line, "odometryd: resume: fresh start (%.*s)%s",
                          static_cast<int>(name.size()), name.data(), note.c_str());
        if (why == loop::ResumeReason::kCounterJump) n = counter_jump_text(d, line, sizeof line, n);
        // A fresh pose may still come with the gyro's calibration (same chip, same boot): told
        // when it does; why the pose did not resume is the reason already.
        tell_gyro = !fixed && d.gyro_restored;
      }
      n = std::clamp(n, 0, static_cast<int>(sizeof line) - 1);  // a long note is cut
      n += gyro_resume_text(d, tell_gyro, line + n, sizeof line - static_cast<std::size_t>(n));
      log.write(line, std::min<int>(n, sizeof line - 1)).flush();
      told = true;
    }
    write_newest();
  }
}

// ---- wiring ----

ResumeWiring prepare_resume(const Config& cfg, loop::OdometryLoop& loop,
                            std::uint64_t calibration_sequence, std::ostream& log) {
  ResumeWiring w;
  w.active = true;
  if (!cfg.resume.enabled) {
    log << "odometryd: resume: off ([resume] enabled = false)\n";
    return w;
  }
  loop::StateRecord identity;
  auto boot = current_boot_id(cfg.resume.path, std::getenv(kBootIdEnv));
  if (boot) identity.boot_id = *boot;
  identity.backend = backend_id(cfg);
  identity.calibration_sequence = calibration_sequence;
  identity.gyro_id = gyro_id(cfg);
  auto rec = read_state_file(cfg.resume.path);
  if (rec && boot) {
    identity.sequence = rec->sequence;  // ours follow it: the newest slot is always ours
    const Kinematics& k = loop.odometry().kinematics();
    loop::ResumeContext c;
    c.boot_id = identity.boot_id;
    c.max_age = from_seconds(cfg.resume.max_age);
    c.backend = identity.backend;
    c.backend_continuous = counters_survive_restart(cfg);
    c.counter_bits = loop.counter_bits();
    c.calibration_sequence = calibration_sequence;
    c.metres_per_count_left = k.metres_per_count_left();
    c.metres_per_count_right = k.metres_per_count_right();
    c.wheelbase = k.wheelbase();
    c.gyro_id = identity.gyro_id;
    c.max_wheel_speed = cfg.encoder.backend == EncoderKind::kCan      ? cfg.can_encoder.max_speed
                        : cfg.encoder.backend == EncoderKind::kSerial ? cfg.serial.max_speed
                                                                      : cfg.hctl1100.max_speed;
    loop.resume_from(*rec, c);
    w.offered = true;
  } else if (!rec) {
    w.reason = rec.error().code == Errc::kNotFound ? loop::ResumeReason::kNoRecord
                                                   : loop::ResumeReason::kCorrupt;
    w.note = ": " + rec.error().message;
  } else {
    // Without the boot id a reboot cannot be told from a restart: never resume.
    w.reason = loop::ResumeReason::kOtherBoot;
    w.note = ": " + boot.error().message;
  }
  auto p =
      StatePersister::create(cfg.resume.path, cfg.resume.rate_hz, cfg.loop.rate_hz, loop, identity);
  if (!p) {
    log << "odometryd: resume: " << p.error().message << ": the pose will not survive a restart\n";
  } else {
    w.persister = std::move(p).value();
    loop.add_observer(w.persister.get());
  }
  return w;
}

loop::ResumeReason resume_reason(const ResumeWiring& w, const loop::OdometryLoop& loop) {
  return w.offered ? loop.resume_decision().reason : w.reason;
}

}  // namespace odo::fw
