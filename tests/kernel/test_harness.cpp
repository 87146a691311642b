// The VM harness itself: the facilities the kernel tier relies on are really there.
#include <linux/can.h>
#include <sys/socket.h>
#include <unistd.h>

#include <filesystem>

#include "kernel_env.hpp"

namespace odo::test {
namespace {

TEST(KernelHarness, VcanInterfaceAndCanSocket) {
  ODO_REQUIRE_VM();
  ASSERT_EQ(run("ip link add dev odoh0 type vcan && ip link set odoh0 up"), 0);
  const int s = socket(PF_CAN, SOCK_RAW, CAN_RAW);
  ASSERT_GE(s, 0);
  close(s);
  EXPECT_EQ(run("ip link del odoh0"), 0);
}

TEST(KernelHarness, GpioSimConfigfs) {
  ODO_REQUIRE_VM();
  EXPECT_TRUE(std::filesystem::is_directory("/sys/kernel/config/gpio-sim"));
}

TEST(KernelHarness, MtdramModuleLoads) {
  ODO_REQUIRE_VM();
  // 256 KiB of RAM-backed flash with 16 KiB erase blocks.
  ASSERT_EQ(run("modprobe mtdram total_size=256 erase_size=16"), 0);
  EXPECT_TRUE(std::filesystem::exists("/dev/mtd0"));
}

}  // namespace
}  // namespace odo::test
