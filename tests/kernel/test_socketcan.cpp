// Kernel tier: SocketCanBus on vcan interfaces in the VM harness. Kernel filters, link down and
// up, an interface that vanishes and comes back, and a full transmit queue: send never blocks,
// every drop is counted by reason.
#include <gtest/gtest.h>

#include <chrono>
#include <string>
#include <thread>

#include "can_env.hpp"
#include "kernel_env.hpp"
#include "odo/drivers/socketcan_bus.hpp"

namespace odo::test {
namespace {

using namespace std::chrono_literals;
using drivers::CanFilter;
using drivers::SocketCanBus;
using drivers::SocketCanOptions;

CanFrame frame(std::uint32_t id, std::uint8_t fill, bool ext = false) {
  CanFrame f;
  f.id = id;
  f.extended = ext;
  f.len = 8;
  for (std::size_t i = 0; i < 8; ++i) f.data[i] = static_cast<std::uint8_t>(fill + i);
  return f;
}

// receive_within: polls the non-blocking receive until a frame arrives or `limit` passes.
bool receive_within(SocketCanBus& bus, CanFrame& out, std::chrono::milliseconds limit) {
  const auto end = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < end) {
    if (bus.receive(out)) return true;
    std::this_thread::sleep_for(1ms);
  }
  return false;
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

TEST(SocketCan, SendReceiveThroughKernelFilters) {
  ODO_REQUIRE_VM();
  Vcan v("vcsc0");
  ASSERT_TRUE(v.ok);
  SocketCanOptions rxo;
  rxo.interface = v.name;
  rxo.filters = {CanFilter{0x120, 0x7F0, false}, CanFilter{0x18FF0010, 0x1FFFFFFF, true}};
  auto rx = SocketCanBus::open(rxo);
  ASSERT_TRUE(rx.ok()) << rx.error().message;
  SocketCanOptions txo;
  txo.interface = v.name;  // no filters: a transmit-only socket that receives nothing
  auto tx = SocketCanBus::open(txo);
  ASSERT_TRUE(tx.ok()) << tx.error().message;

  // Filtered out: another id, the right id as an extended frame, a near miss of the extended.
  ASSERT_EQ((*tx)->send(frame(0x130, 1)), CanTx::kSent);
  ASSERT_EQ((*tx)->send(frame(0x123, 2, true)), CanTx::kSent);
  ASSERT_EQ((*tx)->send(frame(0x18FF0011, 3, true)), CanTx::kSent);
  // Accepted: inside the standard range and the exact extended id.
  ASSERT_EQ((*tx)->send(frame(0x12A, 4)), CanTx::kSent);
  ASSERT_EQ((*tx)->send(frame(0x18FF0010, 5, true)), CanTx::kSent);

  CanFrame got;
  ASSERT_TRUE(receive_within(**rx, got, 1000ms));
  EXPECT_EQ(got.id, 0x12Au);
  EXPECT_FALSE(got.extended);
  EXPECT_EQ(got.len, 8);
  EXPECT_EQ(got.data[0], 4);
  EXPECT_EQ(got.data[7], 11);
  EXPECT_GT(got.stamp, 0);
  ASSERT_TRUE(receive_within(**rx, got, 1000ms));
  EXPECT_EQ(got.id, 0x18FF0010u);
  EXPECT_TRUE(got.extended);
  EXPECT_EQ(got.data[0], 5);
  // Nothing else arrives: the three filtered frames never reached user space.
  EXPECT_FALSE(receive_within(**rx, got, 200ms)) << "unexpected id 0x" << std::hex << got.id;
  EXPECT_FALSE(receive_within(**tx, got, 50ms));  // the transmit-only socket receives nothing
  EXPECT_EQ((*rx)->counters().received, 2u);
  EXPECT_EQ((*tx)->counters().sent, 5u);
}

TEST(SocketCan, LinkDownDropsCountsNeverBlocksAndResumes) {
  ODO_REQUIRE_VM();
  Vcan v("vcsc1");
  ASSERT_TRUE(v.ok);
  SocketCanOptions o;
  o.interface = v.name;
  o.filters = {CanFilter{0x100, 0x700, false}};
  auto rx = SocketCanBus::open(o);
  ASSERT_TRUE(rx.ok()) << rx.error().message;
  o.filters.clear();
  auto tx = SocketCanBus::open(o);
  ASSERT_TRUE(tx.ok()) << tx.error().message;

  ASSERT_EQ(run("ip link set " + v.name + " down"), 0);
  double worst = 0.0;
  for (int i = 0; i < 200; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    EXPECT_EQ((*tx)->send(frame(0x101, static_cast<std::uint8_t>(i))), CanTx::kLinkDown);
    worst = std::max(worst, seconds_since(t0));
  }
  EXPECT_EQ((*tx)->counters().tx_link_down, 200u);
  EXPECT_EQ((*tx)->counters().sent, 0u);
  EXPECT_LT(worst, 0.02) << "a send while the link was down took " << worst << " s";
  EXPECT_TRUE((*tx)->is_open());  // a downed link keeps the socket

  ASSERT_EQ(run("ip link set " + v.name + " up"), 0);
  CanFrame got;
  while ((*rx)->receive(got)) {
  }  // a stale ENETDOWN report is consumed here
  EXPECT_EQ((*tx)->send(frame(0x102, 9)), CanTx::kSent);
  ASSERT_TRUE(receive_within(**rx, got, 1000ms));
  EXPECT_EQ(got.id, 0x102u);
  EXPECT_EQ((*tx)->counters().sent, 1u);
  std::printf("link down: 200 drops counted, worst send %.1f us; resumed after up\n", worst * 1e6);
}

TEST(SocketCan, VanishedInterfaceIsReopenedByName) {
  ODO_REQUIRE_VM();
  auto v = std::make_unique<Vcan>("vcsc2");
  ASSERT_TRUE(v->ok);
  SocketCanOptions o;
  o.interface = "vcsc2";
  o.reopen_period = 0.05;
  auto tx = SocketCanBus::open(o);
  ASSERT_TRUE(tx.ok()) << tx.error().message;
  ASSERT_EQ((*tx)->send(frame(0x200, 1)), CanTx::kSent);

  v.reset();  // ip link del
  EXPECT_EQ((*tx)->send(frame(0x200, 2)), CanTx::kLinkDown);
  EXPECT_FALSE((*tx)->is_open());
  // While gone: every send is a counted link-down drop; re-open attempts fail quietly.
  for (int i = 0; i < 20; ++i) {
    EXPECT_EQ((*tx)->send(frame(0x200, 3)), CanTx::kLinkDown);
    std::this_thread::sleep_for(5ms);
  }
  v = std::make_unique<Vcan>("vcsc2");  // back, with a new interface index
  ASSERT_TRUE(v->ok);
  SocketCanOptions ro;
  ro.interface = "vcsc2";
  ro.filters = {CanFilter{0x200, 0x7FF, false}};
  auto rx = SocketCanBus::open(ro);
  ASSERT_TRUE(rx.ok()) << rx.error().message;
  std::this_thread::sleep_for(60ms);  // one re-open period
  EXPECT_EQ((*tx)->send(frame(0x200, 4)), CanTx::kSent);
  EXPECT_TRUE((*tx)->is_open());
  EXPECT_EQ((*tx)->counters().reopens, 1u);
  EXPECT_EQ((*tx)->counters().tx_link_down, 21u);
  CanFrame got;
  ASSERT_TRUE(receive_within(**rx, got, 1000ms));
  EXPECT_EQ(got.data[0], 4);
}

TEST(SocketCan, FullTransmitQueueDropsAndCountsWithoutBlocking) {
  ODO_REQUIRE_VM();
  Vcan v("vcsc3");
  ASSERT_TRUE(v.ok);
  // vcan transmits synchronously, so its queue never fills by itself. A token-bucket qdisc of
  // 1 kbit/s holding one packet stands in for a slow controller: the kernel refuses the rest
  // with ENOBUFS (qdisc drop) or EAGAIN (socket send buffer), exactly as a busy can0 does.
  run("modprobe sch_tbf 2>/dev/null");  // qdisc modules are not auto-loaded in the VM
  ASSERT_EQ(run("tc qdisc replace dev " + v.name + " root tbf rate 1kbit burst 64 limit 64"), 0);
  SocketCanOptions o;
  o.interface = v.name;
  o.tx_buffer_bytes = 4096;
  auto tx = SocketCanBus::open(o);
  ASSERT_TRUE(tx.ok()) << tx.error().message;
  constexpr int kFrames = 2000;
  double worst = 0.0;
  int full = 0, sent = 0;
  for (int i = 0; i < kFrames; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    const CanTx r = (*tx)->send(frame(0x300, static_cast<std::uint8_t>(i)));
    worst = std::max(worst, seconds_since(t0));
    full += r == CanTx::kQueueFull ? 1 : 0;
    sent += r == CanTx::kSent ? 1 : 0;
  }
  const auto& c = (*tx)->counters();
  EXPECT_GT(full, kFrames / 2) << "the queue should have refused most frames";
  EXPECT_EQ(c.tx_queue_full, static_cast<std::uint64_t>(full));
  EXPECT_EQ(c.sent, static_cast<std::uint64_t>(sent));
  EXPECT_EQ(c.sent + c.tx_queue_full, static_cast<std::uint64_t>(kFrames));
  EXPECT_EQ(c.tx_errors, 0u);
  EXPECT_LT(worst, 0.02) << "a send into the full queue took " << worst << " s";
  std::printf("queue full: %d sent, %d dropped (counted), worst send %.1f us\n", sent, full,
              worst * 1e6);
}

}  // namespace
}  // namespace odo::test
