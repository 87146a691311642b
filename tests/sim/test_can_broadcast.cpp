// CAN broadcast on the simulated bus (sim tier, virtual time). Fault matrix rows "CAN link down"
// and "full CAN transmit queue": frames are dropped and counted, the loop keeps ticking on time,
// broadcasting resumes by itself. Row "CAN flood on the receive side": the set-pose receive
// work per tick is bounded and commands still apply. Also: set-pose commands, the stopping
// status, sequence counters.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "odo/firmware/can_broadcast.hpp"
#include "odo/firmware/config.hpp"
#include "odo/firmware/rig.hpp"
#include "odo/loop/loop.hpp"
#include "odo/protocol/can_protocol.hpp"
#include "odo/sim/sim_can_bus.hpp"

namespace odo::test {
namespace {

using protocol::Msg;

// Bench: the daemon's simulated rig and loop at 100 Hz with a broadcaster on a SimCanPort.
struct Bench {
  explicit Bench(const std::string& scenario = "square-ccw", std::size_t tx_cap = 64,
                 bool drain = true)
      : cfg(make_cfg(scenario)),
        kin(*Kinematics::create(cfg.robot)),
        rig(std::move(fw::Rig::create(cfg, kin, true).value())),
        loop(loop::OdometryLoop::create(loop::LoopConfig{100.0}, kin, rig.encoder(), rig.clock())
                 .value()),
        port(tx_cap, 16),
        bc(opts(), port, &loop->commands(), &ring) {
    if (drain) port.connect_wire();
    loop->add_observer(&bc);
    loop->start();
  }
  static fw::Config make_cfg(const std::string& scenario) {
    fw::Config c = fw::default_config();
    c.sim.scenario = *fw::parse_choice<fw::SimScenario>(scenario);
    c.sim.robot = fw::SimRobotKind::kNominal;
    return c;
  }
  static fw::CanBroadcastOptions opts() {
    fw::CanBroadcastOptions o;
    o.div = fw::CanDivisors{2, 2, 10, 10, 100};  // the default rates at 100 Hz
    return o;
  }
  // ticks: runs n ticks; returns the frames the wire took (through the log ring).
  std::vector<CanFrame> ticks(int n) {
    for (int i = 0; i < n; ++i) loop->tick();
    return wire_frames();
  }
  std::vector<CanFrame> wire_frames() {
    std::vector<CanFrame> out;
    CanFrame f;
    while (ring.pop(f)) out.push_back(f);
    return out;
  }
  fw::Config cfg;
  Kinematics kin;
  fw::Rig rig;
  std::unique_ptr<loop::OdometryLoop> loop;
  sim::SimCanPort port;
  fw::CanFrameRing ring{1 << 14};
  fw::CanBroadcaster bc;
};

std::uint32_t id(Msg m) {
  return protocol::frame_id(0x400, 1, m);
}

std::vector<std::uint8_t> pose_seqs(const std::vector<CanFrame>& fs) {
  std::vector<std::uint8_t> s;
  for (const auto& f : fs)
    if (f.id == id(Msg::kPoseX)) s.push_back(f.data[7]);
  return s;
}

TEST(CanBroadcast, FramesAtTheirRatesAndPoseGroupsShareTheirSequence) {
  Bench b;
  const auto fs = b.ticks(100);
  std::size_t n[16] = {};
  for (const auto& f : fs) ++n[f.id - 0x410];
  // 100 ticks (1..100): every 2nd -> 50, every 10th -> 10, every 100th -> 1.
  EXPECT_EQ(n[0], 50u);
  EXPECT_EQ(n[1], 50u);
  EXPECT_EQ(n[2], 50u);
  EXPECT_EQ(n[3], 10u);
  EXPECT_EQ(n[4], 10u);
  EXPECT_EQ(n[5], 1u);
  EXPECT_EQ(n[6], 10u);  // EncoderFaults, with each Status
  // PoseX is immediately followed by PoseYTheta with the same seq; seq steps by one.
  for (std::size_t i = 0; i + 1 < fs.size(); ++i) {
    if (fs[i].id != id(Msg::kPoseX)) continue;
    EXPECT_EQ(fs[i + 1].id, id(Msg::kPoseYTheta));
    EXPECT_EQ(fs[i + 1].data[7], fs[i].data[7]);
  }
  const auto seqs = pose_seqs(fs);
  for (std::size_t i = 1; i < seqs.size(); ++i)
    EXPECT_EQ(static_cast<std::uint8_t>(seqs[i - 1] + 1), seqs[i]);
  EXPECT_EQ(b.bc.counters().sent, fs.size());
  EXPECT_EQ(b.bc.counters().dropped(), 0u);
}

TEST(CanBroadcast, RatesFollowTheTickNumberWhenItRepeatsJumpsOrGoesBack) {
  // A message is sent on the ticks that are a multiple of its divisor. The broadcaster skips the
  // checks on ticks it knows to be quiet; fed tick numbers that repeat, jump ahead and go back,
  // it must still send exactly what the modulo rule says, call by call.
  sim::SimCanPort port(64, 16);
  fw::CanFrameRing ring{1 << 10};
  fw::CanBroadcastOptions o;
  o.div = fw::CanDivisors{3, 4, 10, 0, 7};  // status off
  port.connect_wire();
  fw::CanBroadcaster bc(o, port, nullptr, &ring);
  std::vector<std::uint64_t> ticks;
  for (std::uint64_t t = 0; t <= 50; ++t) ticks.push_back(t);
  for (std::uint64_t t : {50, 50, 21, 22, 23, 24, 1000, 1001, 1004, 1008, 5, 6, 0, 0, 70, 69})
    ticks.push_back(t);
  std::size_t frames = 0;
  for (const std::uint64_t t : ticks) {
    loop::LoopSnapshot s;
    s.tick = t;
    bc.on_tick(s);
    std::vector<std::uint32_t> want;
    if (t % 3 == 0) {
      // Two push_backs: GCC 12's -Wstringop-overflow misreads insert() of a list into an empty
      // vector under -O2 (tsan build).
      want.push_back(id(Msg::kPoseX));
      want.push_back(id(Msg::kPoseYTheta));
    }
    if (t % 4 == 0) want.push_back(id(Msg::kVelocity));
    if (t % 10 == 0) want.push_back(id(Msg::kUncertainty));
    if (t % 7 == 0) want.push_back(id(Msg::kTiming));
    std::vector<std::uint32_t> got;
    CanFrame f;
    while (ring.pop(f)) got.push_back(f.id);
    EXPECT_EQ(got, want) << "tick " << t;
    frames += got.size();
  }
  EXPECT_EQ(bc.counters().sent, frames);
  EXPECT_GT(frames, 60u);
}

// StatusBench: a broadcaster that sends Status (and EncoderFaults with it) on every tick and
// nothing else, fed snapshots by hand.
struct StatusBench {
  StatusBench() { port.connect_wire(); }
  static fw::CanBroadcastOptions opts() {
    fw::CanBroadcastOptions o;
    o.div = fw::CanDivisors{0, 0, 0, 1, 0};
    return o;
  }
  sim::SimCanPort port{64, 16};
  fw::CanFrameRing ring{1 << 10};
  fw::CanBroadcaster bc{opts(), port, nullptr, &ring};
};

// gyro_state in the Status frame (protocol/odometry.dbc: 0 none, 1 fusing, 2 learning the bias or
// waiting for the first sample, 3 fault), one snapshot per case on a status-every-tick bus.
TEST(CanBroadcast, GyroStateFollowsTheGyroAndTheFusion) {
  StatusBench b;
  fw::CanFrameRing& ring = b.ring;
  fw::CanBroadcaster& bc = b.bc;
  struct Case {
    bool enabled;
    std::uint32_t gyro_flags, fusion_flags;
    bool bias_valid;
    int want;
  };
  const Case cases[] = {
      {false, kGyroOk, 0, false, 0},                                       // no gyro wired
      {true, kGyroOk, kFusionNoBias, false, 2},                            // learning the bias
      {true, kGyroOk, 0, true, 1},                                         // fusing
      {true, kGyroStarting, kFusionGyroFault | kFusionNoBias, false, 2},   // no sample yet
      {true, kGyroStale, kFusionGyroFault, true, 3},                       // went stale
      {true, kGyroStarting | kGyroReadError, kFusionGyroFault, false, 3},  // starting, read fails
      {true, kGyroOk, kFusionGyroFault, true, 3},  // NaN rate (the fusion's flag)
  };
  std::uint64_t tick = 0;
  for (const Case& c : cases) {
    loop::LoopSnapshot s;
    s.tick = tick++;
    s.gyro.enabled = c.enabled;
    s.gyro.gyro_flags = c.gyro_flags;
    s.gyro.fusion_flags = c.fusion_flags;
    s.gyro.bias_valid = c.bias_valid;
    bc.on_tick(s);
    CanFrame f;
    protocol::StatusMsg st;
    ASSERT_TRUE(ring.pop(f));
    ASSERT_EQ(f.id, id(Msg::kEncoderFaults));  // the counters go just before each Status
    ASSERT_TRUE(ring.pop(f));
    ASSERT_EQ(f.id, id(Msg::kStatus));
    ASSERT_TRUE(protocol::decode_status(f, st));
    EXPECT_EQ(st.gyro_state, c.want) << "case " << s.tick;
    EXPECT_FALSE(ring.pop(f));
  }
}

// EncoderFaults (issue 37): the backend's counters of the snapshot, one byte each, saturating at
// 255, sent just before each Status frame; they follow the counters as these grow.
TEST(CanBroadcast, EncoderFaultsCarryTheBackendsCountersJustBeforeStatus) {
  StatusBench b;
  fw::CanFrameRing& ring = b.ring;
  fw::CanBroadcaster& bc = b.bc;
  loop::LoopSnapshot s;
  s.encoder_counters = {1, 2, 3, 4, 5, 6, 7, 8};
  for (std::uint64_t grow : {0u, 250u}) {
    EncoderCounters& c = s.encoder_counters;
    c.link_errors += grow;        // 5 -> 255: the last value that is exact
    c.sequence_gaps += 2 * grow;  // 6 -> 506: saturates at 255
    ++s.tick;
    bc.on_tick(s);
    CanFrame f;
    ASSERT_TRUE(ring.pop(f));
    ASSERT_EQ(f.id, id(Msg::kEncoderFaults));
    EncoderCounters got;
    ASSERT_TRUE(protocol::decode_encoder_faults(f, got));
    EXPECT_EQ(got.invalid_transitions, 1u);
    EXPECT_EQ(got.implausible_jumps, 2u);
    EXPECT_EQ(got.stale_events, 3u);
    EXPECT_EQ(got.read_errors, 4u);
    EXPECT_EQ(got.link_errors, grow == 0 ? 5u : 255u);
    EXPECT_EQ(got.sequence_gaps, grow == 0 ? 6u : 255u);
    EXPECT_EQ(got.controller_resets, 7u);
    EXPECT_EQ(got.reconnects, 8u);
    ASSERT_TRUE(ring.pop(f));
    EXPECT_EQ(f.id, id(Msg::kStatus));
  }
}

// SideWheels (issue 38): with several wheels per side, the side flags (encoder flag bits 8-10,
// beyond Status's byte) and their counters go between EncoderFaults and Status, at the Status
// rate and in the final group; with one wheel per side the frame is never sent (the bus as
// before).
TEST(CanBroadcast, SideWheelsGoWithStatusOnlyWithSeveralWheelsPerSide) {
  for (const int wheels : {1, 3}) {
    sim::SimCanPort port{64, 16};
    port.connect_wire();
    fw::CanFrameRing ring{1 << 10};
    fw::CanBroadcastOptions o = StatusBench::opts();
    o.wheels_per_side = wheels;
    fw::CanBroadcaster bc{o, port, nullptr, &ring};
    loop::LoopSnapshot s;
    s.tick = 1;
    s.encoder_flags = kEncoderSlipLeft | kEncoderStaleRight;
    s.encoder_counters.slip_events = 4;
    s.encoder_counters.wheel_drops = 1;
    bc.on_tick(s);
    bc.send_final(s);
    std::vector<std::uint32_t> ids;
    CanFrame f;
    while (ring.pop(f)) {
      ids.push_back(f.id);
      if (f.id != id(Msg::kSideWheels)) continue;
      protocol::SideWheelsMsg m;
      ASSERT_TRUE(protocol::decode_side_wheels(f, m));
      EXPECT_EQ(m.encoder_flags, std::uint32_t{kEncoderSlipLeft});
      EXPECT_EQ(m.wheels_per_side, wheels);
      EXPECT_EQ(m.counters.slip_events, 4u);
      EXPECT_EQ(m.counters.wheel_drops, 1u);
    }
    const auto n_side = std::count(ids.begin(), ids.end(), id(Msg::kSideWheels));
    EXPECT_EQ(n_side, wheels > 1 ? 2 : 0) << wheels;  // the tick's and the final group's
    for (std::size_t i = 0; i < ids.size(); ++i) {
      if (ids[i] != id(Msg::kSideWheels)) continue;
      ASSERT_GT(i, 0u);
      ASSERT_LT(i + 1, ids.size());
      EXPECT_EQ(ids[i - 1], id(Msg::kEncoderFaults));
      EXPECT_EQ(ids[i + 1], id(Msg::kStatus));
    }
  }
}

TEST(CanBroadcast, LinkDownDropsCountsKeepsTheLoopAndResumes) {
  Bench b;
  const auto before = b.ticks(50);
  const std::uint8_t last_seq = pose_seqs(before).back();
  b.port.set_link_up(false);
  const auto during = b.ticks(200);
  EXPECT_TRUE(during.empty());
  const auto& c = b.bc.counters();
  EXPECT_GT(c.dropped_link_down, 0u);
  EXPECT_EQ(c.dropped_link_down, b.port.counters().tx_down);  // every refusal counted once
  EXPECT_EQ(c.dropped_queue_full + c.dropped_error, 0u);
  // The loop kept its rate: every tick ran, none missed.
  EXPECT_EQ(b.loop->stats().ticks, 250u);
  EXPECT_EQ(b.loop->stats().missed_deadlines, 0u);
  b.port.set_link_up(true);
  const auto after = b.ticks(50);
  ASSERT_FALSE(after.empty());
  // The sequence counter ran on while the link was down: a receiver sees the gap (100 groups
  // lost in 200 ticks) and knows frames were lost.
  const auto seqs = pose_seqs(after);
  EXPECT_EQ(static_cast<std::uint8_t>(seqs.front() - last_seq), 101);
  // The Timing frame reports the drops (every 100th tick; tick 300 is in `after`).
  bool timing_seen = false;
  for (const auto& f : after) {
    if (f.id != id(Msg::kTiming)) continue;
    protocol::TimingMsg t;
    ASSERT_TRUE(protocol::decode_timing(f, t));
    EXPECT_EQ(t.tx_dropped, c.dropped_link_down);
    timing_seen = true;
  }
  EXPECT_TRUE(timing_seen);
}

TEST(CanBroadcast, FullTransmitQueueDropsCountsAndNeverBlocks) {
  Bench b("square-ccw", /*tx_cap=*/8, /*drain=*/false);  // nobody takes frames off the bus
  b.ticks(100);
  const auto& c = b.bc.counters();
  EXPECT_EQ(c.sent, 8u);
  EXPECT_GT(c.dropped_queue_full, 100u);
  EXPECT_EQ(c.dropped_queue_full, b.port.counters().tx_full);
  EXPECT_EQ(b.loop->stats().ticks, 100u);
  EXPECT_EQ(b.loop->stats().missed_deadlines, 0u);
  // The bus frees up: sending resumes at the next tick.
  CanFrame f;
  while (b.port.drain_tx(f)) {
  }
  const std::uint64_t sent_before = c.sent;
  b.ticks(2);
  EXPECT_GT(c.sent, sent_before);
}

CanFrame set_pose_frame(int node, double x, double y, double th, bool reset = false) {
  CanFrame f;
  const std::uint32_t id = protocol::frame_id(0x400, node, Msg::kSetPose);
  if (reset)
    protocol::encode_set_pose_reset(id, f);
  else
    protocol::encode_set_pose(id, SetPose{{x, y, th}}, f);
  return f;
}

std::uint8_t last_ack(const std::vector<CanFrame>& fs) {
  std::uint8_t ack = 0;
  for (const auto& f : fs) {
    protocol::StatusMsg s;
    if (f.id == id(Msg::kStatus) && protocol::decode_status(f, s)) ack = s.set_pose_ack;
  }
  return ack;
}

TEST(CanBroadcast, SetPoseAppliesAtTheNextTickAndIsAcknowledged) {
  Bench b("idle");
  b.ticks(9);
  ASSERT_TRUE(b.port.inject(set_pose_frame(2, 9, 9, 0)));          // another node: ignored
  ASSERT_TRUE(b.port.inject(set_pose_frame(1, 1.5, -2.25, 0.5)));  // ours
  b.loop->tick();                                                  // tick 10: command read
  EXPECT_EQ(b.loop->snapshot().pose.x, 0.0);                       // not yet
  auto fs = b.wire_frames();
  EXPECT_EQ(last_ack(fs), 0);  // the status at tick 10 does not claim it yet
  fs = b.ticks(10);            // ticks 11..20
  EXPECT_NEAR(b.loop->snapshot().pose.x, 1.5, 1e-12);
  EXPECT_NEAR(b.loop->snapshot().pose.y, -2.25, 1e-12);
  EXPECT_NEAR(b.loop->snapshot().pose.theta, 0.5, 1e-12);
  EXPECT_EQ(last_ack(fs), 1);
  // The broadcast pose follows.
  double x = 0;
  std::uint8_t seq = 0;
  ASSERT_TRUE(protocol::decode_pose_x(fs[0], x, seq));
  EXPECT_NEAR(x, 1.5, protocol::kPosScale / 2);
  // Reset (DLC 0), then a malformed command (DLC 3): rejected and counted.
  ASSERT_TRUE(b.port.inject(set_pose_frame(1, 0, 0, 0, true)));
  CanFrame bad = set_pose_frame(1, 1, 1, 1);
  bad.len = 3;
  ASSERT_TRUE(b.port.inject(bad));
  fs = b.ticks(10);
  EXPECT_EQ(b.loop->snapshot().pose.x, 0.0);
  EXPECT_EQ(b.loop->snapshot().pose.y, 0.0);
  EXPECT_EQ(last_ack(fs), 2);
  EXPECT_EQ(b.bc.counters().set_pose_applied, 2u);
  EXPECT_EQ(b.bc.counters().set_pose_rejected, 1u);
}

// CountingBus: a SimCanPort seen through the CanBus interface, counting receive() calls.
class CountingBus final : public CanBus {
 public:
  explicit CountingBus(sim::SimCanPort& p) : port_(p) {}
  CanTx send(const CanFrame& f) noexcept override { return port_.send(f); }
  bool receive(CanFrame& out) noexcept override {
    ++receives_;
    return port_.receive(out);
  }
  std::uint64_t receives() const noexcept { return receives_; }

 private:
  sim::SimCanPort& port_;
  std::uint64_t receives_ = 0;
};

// foreign_frame: a frame the broadcaster must ignore: a standard id below the protocol's base,
// another node's set-pose, or an extended id whose low bits equal our set-pose id.
CanFrame foreign_frame(std::mt19937& rng) {
  CanFrame f;
  switch (rng() % 3) {
    case 0:
      f.id = rng() % 0x400;
      f.len = 8;
      break;
    case 1:
      f = set_pose_frame(2 + static_cast<int>(rng() % 5), 7, 7, 0);
      break;
    default:
      f = set_pose_frame(1, 7, 7, 0);
      f.extended = true;
      break;
  }
  return f;
}

TEST(CanBroadcast, ReceiveFloodIsReadAtMostMaxRxPerTickAndSetPoseStillApplies) {
  // Every tick for 5 s a burst of 100 frames arrives: foreign ones and, at a random place in
  // the burst, one set-pose command for us whose x is its serial number (1 mm each). The
  // receive queue (256 frames, like a socket buffer) saturates and drops the newest frames.
  Bench b("idle");
  sim::SimCanPort port(64, 256);
  CountingBus bus(port);
  fw::CanBroadcastOptions o = Bench::opts();
  const std::size_t cap = o.max_rx_per_tick;
  ASSERT_GT(cap, 0u);
  port.connect_wire();
  fw::CanBroadcaster bc(o, bus, &b.loop->commands(), nullptr);
  b.loop->add_observer(&bc);
  constexpr int kTicks = 500, kBurst = 100;
  constexpr double kStep = 1e-3;  // x of command k: k mm, exact at the protocol's resolution
  std::mt19937 rng(20261122);
  std::vector<int> accepted;  // serials of our commands the receive queue took, in order
  int serial = 0;
  auto serial_of_pose = [&] {
    return static_cast<int>(std::lround(b.loop->snapshot().pose.x / kStep));
  };
  int last_pose = 0;
  for (int t = 0; t < kTicks; ++t) {
    const int ours_at = static_cast<int>(rng() % kBurst);
    for (int i = 0; i < kBurst; ++i) {
      if (i == ours_at) {
        ++serial;
        if (port.inject(set_pose_frame(1, serial * kStep, 0, 0))) accepted.push_back(serial);
      } else {
        port.inject(foreign_frame(rng));
      }
    }
    const std::uint64_t before = bus.receives();
    const std::uint64_t applied_before = bc.counters().set_pose_applied;
    b.loop->tick();
    // Bounded work: never more than the cap of receive() calls, and the cap exactly while
    // frames are waiting (the queue never runs dry during this flood).
    EXPECT_EQ(bus.receives() - before, cap) << "tick " << t;
    EXPECT_LE(bc.counters().set_pose_applied - applied_before, cap);
    // The pose is the newest command taken so far (applied one tick after it was read), and
    // commands apply in the order they arrived.
    const int p = serial_of_pose();
    EXPECT_GE(p, last_pose) << "tick " << t;
    if (p != 0) {
      EXPECT_TRUE(std::find(accepted.begin(), accepted.end(), p) != accepted.end());
    }
    last_pose = p;
  }
  // The loop kept its period: every tick ran, none missed.
  EXPECT_EQ(b.loop->stats().ticks, static_cast<std::uint64_t>(kTicks));
  EXPECT_EQ(b.loop->stats().missed_deadlines, 0u);
  // The queue overflowed (the flood is 100 frames per tick against a read of `cap`), commands
  // got through during the flood, and some of ours were lost with the foreign frames.
  EXPECT_GT(port.counters().rx_dropped, 0u);
  EXPECT_GT(bc.counters().set_pose_applied, 0u);
  EXPECT_LT(accepted.size(), static_cast<std::size_t>(serial));
  // The flood stops: the backlog drains at `cap` frames per tick; then every command the
  // queue took has been applied exactly once, in order, and the pose is the last one.
  const int drain_ticks = static_cast<int>((256 + cap - 1) / cap) + 2;
  for (int t = 0; t < drain_ticks; ++t) b.loop->tick();
  EXPECT_EQ(bc.counters().set_pose_applied, accepted.size());
  EXPECT_EQ(bc.counters().set_pose_rejected, 0u);
  ASSERT_FALSE(accepted.empty());
  EXPECT_EQ(serial_of_pose(), accepted.back());
  EXPECT_EQ(b.loop->stats().missed_deadlines, 0u);
}

TEST(CanBroadcast, CleanStopSendsFinalPoseThenStoppingStatus) {
  Bench b;
  b.ticks(137);
  b.wire_frames();
  b.bc.send_final(b.loop->snapshot());
  const auto fs = b.wire_frames();
  ASSERT_EQ(fs.size(), 7u);
  EXPECT_EQ(fs.front().id, id(Msg::kPoseX));
  EXPECT_EQ(fs[5].id, id(Msg::kEncoderFaults));
  EXPECT_EQ(fs.back().id, id(Msg::kStatus));
  protocol::StatusMsg st;
  ASSERT_TRUE(protocol::decode_status(fs.back(), st));
  EXPECT_TRUE(st.stopping);
  EXPECT_DOUBLE_EQ(st.uptime, 1.0);  // 1.37 s of loop time, whole seconds
  double x = 0, y = 0, th = 0;
  std::uint8_t s1 = 0, s2 = 0;
  ASSERT_TRUE(protocol::decode_pose_x(fs[0], x, s1));
  ASSERT_TRUE(protocol::decode_pose_y_theta(fs[1], y, th, s2));
  EXPECT_EQ(s1, s2);
  EXPECT_NEAR(x, b.loop->snapshot().pose.x, protocol::kPosScale / 2 + 1e-12);
  EXPECT_NEAR(y, b.loop->snapshot().pose.y, protocol::kPosScale / 2 + 1e-12);
  // The uncertainty frame carries the error model's standard deviations.
  protocol::UncertaintyMsg u;
  ASSERT_TRUE(protocol::decode_uncertainty(fs[3], u));
  ASSERT_TRUE(b.loop->snapshot().has_cov);
  EXPECT_NEAR(u.sigma_x, std::sqrt(b.loop->snapshot().cov[0]), protocol::kSigmaPosScale / 2);
  EXPECT_NEAR(u.sigma_theta, std::sqrt(b.loop->snapshot().cov[8]), protocol::kSigmaThetaScale / 2);
}

}  // namespace
}  // namespace odo::test
