// path= takes a node over in host programs, so it may name only what does not exist yet or a
// spidev node: another driver's node (/dev/kvm, /dev/loop0, /dev/hwrng, ...), a file or a
// directory there is refused with one line, by the Linux front's check (linux/device_paths.hpp)
// and so by serve and the preload.
#include <fcntl.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <algorithm>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "board/board_config.hpp"
#include "linux/device_paths.hpp"
#include "run_program.hpp"

namespace l6470emu {
namespace {

std::string error_for_path(const std::string& path) {
  const ParseResult r = parse_board_config("chips=L6470 path=" + path, "T");
  if (!r.config) return r.error.message;
  const std::string e = check_device_paths(*r.config, "T");
  return e.empty() ? "(accepted)" : e;
}

bool exists(const std::string& path) {
  struct stat st{};
  return stat(path.c_str(), &st) == 0;
}

TEST(ConfigPath, ExistingNodesOfOtherDriversAreRefused) {
  int tried = 0;
  for (const char* node : {"/dev/kvm", "/dev/loop0", "/dev/hwrng", "/dev/loop-control", "/dev/autofs", "/dev/vda"}) {
    if (!exists(node)) continue;
    ++tried;
    const std::string e = error_for_path(node);
    EXPECT_EQ(e.rfind(std::string("l6470emu: config T: chain 1 (bus=0 cs=0): path '") + node + "' is an existing ", 0), 0u) << e;
    EXPECT_NE(e.find("not a spidev node: the emulator would take it over in host programs"), std::string::npos) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
  if (tried == 0) GTEST_SKIP() << "none of /dev/kvm, /dev/loop0, /dev/hwrng, /dev/loop-control, /dev/autofs here";
}

/// A directory under /dev holding a node of another driver (1:3, /dev/null's), a block device, a
/// spidev node (153:7), a regular file and a directory. Needs root (mknod); removed afterwards.
class DevScratch : public ::testing::Test {
 protected:
  void SetUp() override {
    if (geteuid() != 0) GTEST_SKIP() << "needs root to make device nodes under /dev";
    dir_ = "/dev/l6470emu-test-" + std::to_string(getpid());
    if (mkdir(dir_.c_str(), 0755) != 0) GTEST_SKIP() << "cannot make " << dir_;
    if (mknod((dir_ + "/other").c_str(), S_IFCHR | 0600, makedev(1, 3)) != 0 ||
        mknod((dir_ + "/block").c_str(), S_IFBLK | 0600, makedev(7, 200)) != 0 ||
        mknod((dir_ + "/spidev9.7").c_str(), S_IFCHR | 0600, makedev(153, 7)) != 0)
      GTEST_SKIP() << "cannot make device nodes in " << dir_;
    std::ofstream(dir_ + "/file") << "x";
    mkdir((dir_ + "/sub").c_str(), 0755);
  }
  void TearDown() override {
    if (dir_.empty()) return;
    for (const char* n : {"/other", "/block", "/spidev9.7", "/file"}) unlink((dir_ + n).c_str());
    rmdir((dir_ + "/sub").c_str());
    rmdir(dir_.c_str());
  }
  std::string dir_;
};

TEST_F(DevScratch, OnlyASpidevNodeOrNothingIsAcceptedAtPath) {
  const std::string tail = ", not a spidev node: the emulator would take it over in host programs (write a path "
                           "that does not exist, e.g. path=/dev/spidev9.0, or leave path= out)";
  // The kernel's name of the device ('null') comes from /sys/dev/char, when /sys is there.
  const std::string other = error_for_path(dir_ + "/other");
  EXPECT_EQ(other.rfind("l6470emu: config T: chain 1 (bus=0 cs=0): path '" + dir_ + "/other' is an existing character device (1:3", 0),
            0u) << other;
  EXPECT_NE(other.find(") of another driver" + tail), std::string::npos) << other;
  EXPECT_EQ(error_for_path(dir_ + "/block"),
            "l6470emu: config T: chain 1 (bus=0 cs=0): path '" + dir_ + "/block' is an existing block device (7:200)" + tail);
  EXPECT_EQ(error_for_path(dir_ + "/file"),
            "l6470emu: config T: chain 1 (bus=0 cs=0): path '" + dir_ + "/file' is an existing regular file" + tail);
  EXPECT_EQ(error_for_path(dir_ + "/sub"),
            "l6470emu: config T: chain 1 (bus=0 cs=0): path '" + dir_ + "/sub' is an existing directory" + tail);
  EXPECT_NE(error_for_path(dir_ + "/file/x").find("is a path that cannot be looked at (Not a directory)"),
            std::string::npos);
  EXPECT_EQ(error_for_path(dir_ + "/spidev9.7"), "(accepted)");    // the kernel's spidev: the emulator stands in
  EXPECT_EQ(error_for_path(dir_ + "/spidev9.8"), "(accepted)");    // nothing there yet
  EXPECT_EQ(error_for_path(dir_ + "/sub/motor"), "(accepted)");
}

TEST_F(DevScratch, ServeAndThePreloadRefuseAnotherDriversNodeWithOneLine) {
  if (const std::string why = test::missing_prerequisites(); !why.empty()) GTEST_SKIP() << why;
  const std::string chain = "bus=0 cs=0 chips=L6470 path=" + dir_ + "/other";
  const test::RunResult serve = test::run_program(
      {test::l6470emu_program(), "serve", "--chain", chain, "--socket", test::temp_socket_path("path")}, {}, 10);
  EXPECT_EQ(serve.status, 2);
  EXPECT_EQ(std::count(serve.err.begin(), serve.err.end(), '\n'), 1) << serve.err;
  EXPECT_NE(serve.err.find("is an existing character device (1:3"), std::string::npos) << serve.err;
  const test::RunResult program = test::run_program({test::system_python(), "-c", "print('ran')"},
                                                    {{"LD_PRELOAD", test::preload_library()}, {"L6470EMU_CHAIN", chain}});
  EXPECT_EQ(program.status, 2);
  EXPECT_EQ(program.out, "");
  EXPECT_NE(program.err.find("is an existing character device (1:3"), std::string::npos) << program.err;
}

}  // namespace
}  // namespace l6470emu
