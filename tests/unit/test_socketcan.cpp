// SocketCanBus parts that need no kernel CAN: the errno -> drop reason mapping, the Linux can_id
// conversion, and the error message when the interface cannot be opened.
#include <gtest/gtest.h>
#include <linux/can.h>

#include <cerrno>

#include "odo/drivers/socketcan_bus.hpp"

namespace odo::drivers {
namespace {

TEST(SocketCanErrno, EveryDocumentedErrnoHasItsReason) {
  EXPECT_EQ(tx_result_for_errno(ENOBUFS), CanTx::kQueueFull);
  EXPECT_EQ(tx_result_for_errno(EAGAIN), CanTx::kQueueFull);
  EXPECT_EQ(tx_result_for_errno(ENETDOWN), CanTx::kLinkDown);
  EXPECT_EQ(tx_result_for_errno(ENXIO), CanTx::kLinkDown);
  EXPECT_EQ(tx_result_for_errno(ENODEV), CanTx::kLinkDown);
  for (int e : {EINVAL, EIO, EPERM, EMSGSIZE, EBADF})
    EXPECT_EQ(tx_result_for_errno(e), CanTx::kError);
  EXPECT_TRUE(errno_means_vanished(ENODEV));
  EXPECT_TRUE(errno_means_vanished(ENXIO));
  EXPECT_FALSE(errno_means_vanished(ENETDOWN));  // link down: the socket stays bound
  EXPECT_FALSE(errno_means_vanished(ENOBUFS));
}

TEST(SocketCanId, StandardAndExtendedRoundTrip) {
  CanFrame f;
  f.id = 0x7FF;
  EXPECT_EQ(to_socketcan_id(f), 0x7FFu);
  f.id = 0xFFF;  // bits above 11 are not part of a standard id
  EXPECT_EQ(to_socketcan_id(f), 0x7FFu);
  f.id = 0x1ABCDEF0;
  f.extended = true;
  EXPECT_EQ(to_socketcan_id(f), 0x1ABCDEF0u | CAN_EFF_FLAG);

  CanFrame g;
  ASSERT_TRUE(from_socketcan_id(0x1ABCDEF0u | CAN_EFF_FLAG, g));
  EXPECT_TRUE(g.extended);
  EXPECT_EQ(g.id, 0x1ABCDEF0u);
  ASSERT_TRUE(from_socketcan_id(0x123, g));
  EXPECT_FALSE(g.extended);
  EXPECT_EQ(g.id, 0x123u);
  EXPECT_FALSE(from_socketcan_id(0x123 | CAN_RTR_FLAG, g));  // remote frames are not used
  EXPECT_FALSE(from_socketcan_id(CAN_ERR_FLAG | 0x4, g));    // error frames neither
}

// Issue 39: the kernel's receive stamp (CLOCK_REALTIME) moved onto CLOCK_MONOTONIC by its age.
TEST(SocketCanStamp, KernelStampMovesToMonotonicByItsAge) {
  // Realtime now 1000.5 s, monotonic now 20 s; the frame arrived at 1000.49 s realtime, 10 ms
  // ago: 20 s - 10 ms = 19.99 s.
  EXPECT_EQ(kernel_stamp_to_monotonic(1'000'490'000'000, 1'000'500'000'000, 20'000'000'000),
            19'990'000'000);
  // The realtime clock stepped back between the frame and now (age < 0): the read time.
  EXPECT_EQ(kernel_stamp_to_monotonic(1'000'600'000'000, 1'000'500'000'000, 20'000'000'000),
            20'000'000'000);
  // Stepped forward by a minute (age 60 s > 10 s): the read time too. Exactly 10 s is kept.
  EXPECT_EQ(kernel_stamp_to_monotonic(940'500'000'000, 1'000'500'000'000, 20'000'000'000),
            20'000'000'000);
  EXPECT_EQ(kernel_stamp_to_monotonic(990'500'000'000, 1'000'500'000'000, 20'000'000'000),
            10'000'000'000);
}

TEST(SocketCanOpen, MissingInterfaceNamesItAndTheCall) {
  SocketCanOptions o;
  o.interface = "nocan7";
  auto bus = SocketCanBus::open(o);
  ASSERT_FALSE(bus.ok());
  // Here (no CONFIG_CAN) socket() fails; in the VM the interface lookup does. Either way the
  // message says which interface and which call.
  EXPECT_NE(bus.error().message.find("socketcan nocan7:"), std::string::npos)
      << bus.error().message;
  EXPECT_NE(bus.error().message.find("failed"), std::string::npos);
}

TEST(SocketCanOpen, RejectsBadNameAndPeriod) {
  SocketCanOptions o;
  o.reopen_period = 0.0;
  EXPECT_FALSE(SocketCanBus::open(o).ok());
  o.reopen_period = 1.0;
  o.interface = "a_name_longer_than_15";
  auto bus = SocketCanBus::open(o);
  EXPECT_FALSE(bus.ok());
}

}  // namespace
}  // namespace odo::drivers
