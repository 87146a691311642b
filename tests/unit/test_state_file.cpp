// drivers/state_file: the resume state file's Linux side (issue 33: moved out of firmware/).
#include "odo/drivers/state_file.hpp"

#include <gtest/gtest.h>
#include <sched.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <cstdlib>
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

// on_tmpfs of a tmpfs this test mounts itself: in a child with a mount namespace of its own
// (the machine untouched, and no dependence on which tmpfs it happens to have). Exit status of
// the child: 0 on_tmpfs true, 1 false, 2 the namespace or the mount could not be made.
int on_tmpfs_in_own_mount(const std::string& dir) {
  const pid_t pid = ::fork();
  if (pid == 0) {
    if (::unshare(CLONE_NEWNS) != 0 ||
        ::mount(nullptr, "/", nullptr, MS_REC | MS_PRIVATE, nullptr) != 0 ||
        ::mount("odo-test", dir.c_str(), "tmpfs", 0, "size=64k") != 0)
      ::_exit(2);
    ::_exit(on_tmpfs(dir + "/state.bin") ? 0 : 1);
  }
  int status = 0;
  ::waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 3;
}

TEST(StateFile, OnTmpfsOfAMountedTmpfsNotOfOtherFileSystems) {
  const std::string dir = fresh_dir("state_file_tmpfs");
  ASSERT_EQ(::mkdir(dir.c_str(), 0755), 0);
  EXPECT_FALSE(on_tmpfs("/proc/state.bin"));  // proc
  const int r = on_tmpfs_in_own_mount(dir);
  if (r == 2) GTEST_SKIP() << "cannot make a mount namespace and a tmpfs (needs root)";
  EXPECT_EQ(r, 0) << "on_tmpfs did not see the tmpfs mounted on " << dir;
}

}  // namespace
}  // namespace odo::drivers
