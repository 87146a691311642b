// CAN pose broadcast (issue 10): a loop::TickObserver that encodes the protocol's frames at their
// configured rates and sends them through a CanBus without ever blocking, takes set-pose
// commands addressed to this node, and (optionally) hands every frame sent to a candump-format
// log written by a thread of its own. README "CAN protocol" documents the frames.
#pragma once

#include <atomic>
#include <cstdint>
#include <cstdio>
#include <iosfwd>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "odo/firmware/config.hpp"
#include "odo/hal/can_bus.hpp"
#include "odo/hal/result.hpp"
#include "odo/loop/command.hpp"
#include "odo/loop/loop.hpp"
#include "odo/loop/recording_encoder.hpp"
#include "odo/loop/spsc_ring.hpp"
#include "odo/protocol/can_protocol.hpp"
#include "odo/protocol/candump_log.hpp"

namespace odo::sim {
class SimCanPort;
}

namespace odo::fw {

// CanFrameRing: the loop thread's frames to the log thread, allocated once; a full ring drops
// the frame and counts it.
using CanFrameRing = loop::SpscRing<CanFrame>;
inline constexpr std::size_t kCanLogRingFrames = 4096;  // 24 s of the default broadcast

// CanLogWriter: drains a CanFrameRing into a candump -L file from its own thread (every 20 ms),
// so the loop never does file I/O. Frame stamps are loop time [ns]; the wall-clock time of loop
// time zero is added.
class CanLogWriter {
 public:
  ~CanLogWriter();
  static Result<std::unique_ptr<CanLogWriter>> open(const std::string& path, std::string iface);
  CanFrameRing& ring() noexcept { return ring_; }
  // start: the thread; epoch_ns = CLOCK_REALTIME at loop time zero [ns].
  void start(std::int64_t epoch_ns);
  // stop: joins the thread after writing everything queued; closes the file.
  void stop();
  // written: lines written so far; safe to read from any thread while the writer runs.
  std::uint64_t written() const noexcept { return written_.load(std::memory_order_relaxed); }

 private:
  CanLogWriter(std::FILE* f, std::string iface) : file_(f), iface_(std::move(iface)) {}
  void drain() noexcept;
  std::FILE* file_;
  std::vector<char> buffer_;  // stdio buffer, allocated at open: fwrite never allocates
  std::string iface_;
  CanFrameRing ring_{kCanLogRingFrames};
  std::int64_t epoch_ns_ = 0;
  std::atomic<bool> stop_{false};
  std::thread thread_;
  // Atomic: the writer thread counts, the status side may read while it runs (a plain
  // counter was only safe to read after stop(); ThreadSanitizer found the mid-run read).
  std::atomic<std::uint64_t> written_{0};
};

// Transmit and command counters; written by the loop thread, read after the run (or for the
// status frame on the loop thread).
struct CanBroadcastCounters {
  std::uint64_t sent = 0;
  std::uint64_t dropped_queue_full = 0;
  std::uint64_t dropped_link_down = 0;
  std::uint64_t dropped_error = 0;
  std::uint64_t set_pose_applied = 0;   // commands posted to the loop
  std::uint64_t set_pose_rejected = 0;  // for this node but malformed (length, theta range)
  std::uint64_t fixes_forwarded = 0;    // FixPose + FixSigma pairs handed to the estimator
  std::uint64_t fixes_refused = 0;      // fix frames malformed, unpaired or not taken (ring full)
  std::uint64_t dropped() const noexcept {
    return dropped_queue_full + dropped_link_down + dropped_error;
  }
};

// Per-message rates as divisors of the loop rate (send on ticks where tick % div == 0; 0 = off).
struct CanDivisors {
  std::uint32_t pose = 0, velocity = 0, uncertainty = 0, status = 0, timing = 0;
};

struct CanBroadcastOptions {
  std::uint32_t base_id = protocol::kDefaultBaseId;
  int node_id = protocol::kDefaultNodeId;
  CanDivisors div;
  bool set_pose = true;             // accept set-pose commands
  std::size_t max_rx_per_tick = 8;  // receive() calls per tick at most (a flood cannot stall us)
  bool lossless_log = false;        // virtual time: wait for the log writer instead of dropping
};

class CanBroadcaster final : public loop::TickObserver {
 public:
  // bus: where frames go; commands: the loop's queue for set-pose commands (may be null:
  // commands ignored); log: optional ring that gets every frame the bus accepted.
  CanBroadcaster(const CanBroadcastOptions& o, CanBus& bus, loop::CommandQueue* commands,
                 CanFrameRing* log) noexcept;

  void on_tick(const loop::LoopSnapshot& snap) noexcept override;
  // send_final: the final pose group, velocity, uncertainty, timing and a status frame with the
  // stopping flag (clean stop); call on the loop thread after run() returned.
  void send_final(const loop::LoopSnapshot& snap) noexcept;

  const CanBroadcastCounters& counters() const noexcept { return c_; }
  std::uint8_t seq() const noexcept { return seq_; }
  // set_fix_ring: configure time; FixPose + FixSigma addressed to this node go there (null:
  // fix frames are ignored).
  void set_fix_ring(loop::FixRing* r) noexcept { fixes_ = r; }

 private:
  // take_commands: handles the received frame `f`, then receives and handles more, up to
  // max_rx_per_tick frames in all (`f` is scratch space).
  void take_commands(CanFrame& f) noexcept;
  // take_fix: one FixPose or FixSigma frame; a FixSigma completing the FixPose of the same seq
  // becomes a PoseFix at rx_stamp_ - age.
  void take_fix(const CanFrame& f, protocol::Msg m) noexcept;
  void send(const CanFrame& f, std::int64_t loop_time) noexcept;
  void send_pose_group(const loop::LoopSnapshot& s) noexcept;
  void send_velocity(const loop::LoopSnapshot& s) noexcept;
  void send_uncertainty(const loop::LoopSnapshot& s) noexcept;
  void send_status(const loop::LoopSnapshot& s, bool stopping) noexcept;
  void send_timing(const loop::LoopSnapshot& s) noexcept;
  void log_frame(const CanFrame& f) noexcept {
    if (o_.lossless_log)
      log_->push_wait(f, [] { std::this_thread::yield(); });
    else
      log_->push(f);
  }
  std::uint32_t id(protocol::Msg m) const noexcept {
    return protocol::frame_id(o_.base_id, o_.node_id, m);
  }

  CanBroadcastOptions o_;
  CanBus* bus_;
  loop::CommandQueue* commands_;
  CanFrameRing* log_;
  CanBroadcastCounters c_;
  std::uint8_t seq_ = 0;  // pose group counter (first group: 0)
  bool sent_any_pose_ = false;
  std::uint8_t ack_ = 0;           // set-pose commands applied (mod 256), in the status frame
  std::uint32_t pending_ack_ = 0;  // requested this tick, applied at the next one
  loop::FixRing* fixes_ = nullptr;
  protocol::FixMsg fix_half_;  // the last FixPose received
  bool have_fix_half_ = false;
  TimeNs rx_stamp_ = 0;  // sample time of the tick that receives [ns]
  // Ticks strictly between quiet_after_ and quiet_after_ + quiet_span_ + 1 are a multiple of no
  // divisor: on them the rate checks are skipped (the span is 0 until the first check).
  std::uint64_t quiet_after_ = 0;
  std::uint64_t quiet_span_ = 0;

  // send_due: sends what is due on tick t (t % divisor == 0) and notes the next such tick.
  void send_due(const loop::LoopSnapshot& s) noexcept;
};

// CanLink: the [can] section wired up: the bus (simulated port or SocketCAN), the broadcaster
// registered on the loop, the optional candump log. Built at configure time.
class CanLink {
 public:
  ~CanLink();
  // create: null (and ok) for bus = "none" with no log; errors name the interface.
  // virtual_time: the log waits for its writer rather than dropping (no deadlines to keep).
  static Result<std::unique_ptr<CanLink>> create(const CanSection& s, double loop_hz,
                                                 loop::OdometryLoop& loop,
                                                 const std::string& can_log,
                                                 bool virtual_time = false);
  // start: the log thread (call just before the loop runs).
  void start(std::int64_t epoch_ns);
  // send_final: final frames with the stopping status (loop thread, after run()).
  void send_final(const loop::LoopSnapshot& snap) noexcept { bc_->send_final(snap); }
  // close_log: writes what is queued and closes the log (joins its thread).
  void close_log();
  // finish: send_final, then close_log.
  void finish(const loop::LoopSnapshot& snap);
  const CanBroadcastCounters& counters() const noexcept { return bc_->counters(); }
  // set_fix_ring: absolute fixes received on this link go to `r` (configure time).
  void set_fix_ring(loop::FixRing* r) noexcept { bc_->set_fix_ring(r); }
  std::uint64_t log_written() const noexcept { return log_ ? log_->written() : 0; }
  std::uint64_t log_dropped() const noexcept { return log_ ? log_->ring().dropped() : 0; }
  const std::string& describe() const noexcept { return describe_; }
  // sim_port: the simulated bus port (bus = "sim"), for tests that inject commands; else null.
  sim::SimCanPort* sim_port() noexcept { return sim_port_; }

 private:
  CanLink() = default;
  sim::SimCanPort* sim_port_ = nullptr;
  std::unique_ptr<CanBus> bus_;
  std::unique_ptr<CanLogWriter> log_;
  std::unique_ptr<CanBroadcaster> bc_;
  std::string describe_;
};

}  // namespace odo::fw
