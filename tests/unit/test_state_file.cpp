// drivers/state_file: the resume state file's Linux side (issue 33: moved out of firmware/).
#include "odo/drivers/state_file.hpp"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

namespace odo::drivers {
namespace {

std::string fresh_dir(const std::string& name) {
  const std::string dir = ::testing::TempDir() + name;
  std::system(("rm -rf '" + dir + "'").c_str());
  return dir;
}

TEST(StateFile, OpenMakesOneMissingDirectorySizesTheFileAndWritesInPlace) {
  const std::string dir = fresh_dir("state_file_dir"), path = dir + "/state.bin";
  const mode_t old_mask = ::umask(077);  // the directory's mode must not follow the umask
  auto f = StateFile::open(path, 256);
  ::umask(old_mask);
  ASSERT_TRUE(f) << f.error().message;
  struct stat st {};
  ASSERT_EQ(::stat(dir.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0755u);
  ASSERT_EQ(::stat(path.c_str(), &st), 0);
  EXPECT_EQ(st.st_size, 256);
  const std::array<std::uint8_t, 3> data{0x11, 0x22, 0x33};
  EXPECT_TRUE((*f)->write_at(128, data));
  std::array<std::uint8_t, 512> back{};
  auto n = read_file_head(path, back);
  ASSERT_TRUE(n) << n.error().message;
  EXPECT_EQ(*n, 256u);  // the file's size, not the buffer's
  EXPECT_EQ(back[127], 0u);
  EXPECT_EQ(back[128], 0x11);
  EXPECT_EQ(back[130], 0x33);
  EXPECT_EQ(back[131], 0u);
  // A file already longer is left as it is.
  f->reset();
  auto again = StateFile::open(path, 64);
  ASSERT_TRUE(again);
  ASSERT_EQ(::stat(path.c_str(), &st), 0);
  EXPECT_EQ(st.st_size, 256);
}

TEST(StateFile, ReasonsNameThePath) {
  // Two missing levels: only one is made (a typo in a parent is not papered over).
  const std::string deep = fresh_dir("state_file_deep") + "/a/state.bin";
  auto f = StateFile::open(deep, 16);
  ASSERT_FALSE(f);
  EXPECT_EQ(f.error().message.rfind(deep + ": cannot open the state file (", 0), 0u)
      << f.error().message;
  std::array<std::uint8_t, 8> b{};
  auto missing = read_file_head(deep, b);
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().code, Errc::kNotFound);
  // A directory opens but cannot be read: the reason is the read's (EISDIR), not open's.
  const std::string dir = ::testing::TempDir();
  auto d = read_file_head(dir, b);
  ASSERT_FALSE(d);
  EXPECT_EQ(d.error().code, Errc::kIo);
  EXPECT_NE(d.error().message.find(": cannot read (Is a directory)"), std::string::npos)
      << d.error().message;
}

// on_tmpfs against the kernel's own list of mounts.
TEST(StateFile, OnTmpfsAsProcMountsSays) {
  std::ifstream mounts("/proc/mounts");
  std::string line, tmpfs_dir;
  while (std::getline(mounts, line)) {
    std::istringstream l(line);
    std::string dev, dir, type;
    l >> dev >> dir >> type;
    if (type == "tmpfs" && tmpfs_dir.empty() && ::access(dir.c_str(), R_OK) == 0) tmpfs_dir = dir;
  }
  EXPECT_FALSE(on_tmpfs("/proc/state.bin"));  // proc, not tmpfs
  if (tmpfs_dir.empty()) GTEST_SKIP() << "no readable tmpfs in /proc/mounts";
  EXPECT_TRUE(on_tmpfs(tmpfs_dir + "/state.bin")) << tmpfs_dir;
}

}  // namespace
}  // namespace odo::drivers
