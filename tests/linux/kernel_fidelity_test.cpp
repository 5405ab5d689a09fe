// What the kernel does with a spidev node, done by the emulated one in process and through the
// daemon alike: access modes (EBADF), paths past a node (ENOTDIR), every spelling of a node's
// path, and the controller's slowest clock (EINVAL, no bus time taken).
#include <gtest/gtest.h>

#include <map>
#include <string>

#include "run_program.hpp"

namespace l6470emu::test {
namespace {

constexpr const char* kChain = "bus=0 cs=0 chips=L6470";

class KernelFidelity : public ::testing::TestWithParam<bool> {
 protected:
  void SetUp() override {
    const std::string why = missing_prerequisites();
    if (!why.empty()) GTEST_SKIP() << why;
  }
};

TEST_P(KernelFidelity, AccessModesPathsAndTheSlowestClockAreTheKernels) {
  const bool daemon = GetParam();
  std::unique_ptr<ServeDaemon> d;
  Env env = {{"LD_PRELOAD", preload_library()}, {"L6470EMU_CHAIN", kChain}, {"L6470EMU_LOG", "off"}};
  if (daemon) {
    d = std::make_unique<ServeDaemon>(kChain, std::vector<std::string>{"--log", "off"});
    ASSERT_TRUE(d->ready());
    env = d->env();
  }
  const RunResult r = run_program({system_python(), script("spidev_fidelity.py")}, env);
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const std::map<std::string, std::string> got = key_values(r.out);
  const std::map<std::string, std::string> want = {
      {"read_on_wronly", "EBADF"}, {"write_on_wronly", "ok"}, {"wronly_accmode", "True"},
      {"read_on_dup_of_wronly", "EBADF"}, {"write_on_rdonly", "EBADF"}, {"read_on_rdonly", "ok"},
      {"rdonly_accmode", "True"},
      {"open_trailing_slash", "ENOTDIR"}, {"stat_trailing_slash", "ENOTDIR"},
      {"open_trailing_dot", "ENOTDIR"}, {"stat_trailing_dot", "ENOTDIR"},
      {"open_below", "ENOTDIR"}, {"stat_below", "ENOTDIR"},
      {"open_dotdot_after", "ENOTDIR"}, {"stat_dotdot_after", "ENOTDIR"},
      {"open_double_slash", "ok"}, {"stat_double_slash", "ok"}, {"open_dot", "ok"}, {"stat_dot", "ok"},
      {"open_dotdot", "ok"}, {"stat_dotdot", "ok"}, {"open_mixed", "ok"}, {"stat_mixed", "ok"},
      {"open_relative", "ok"}, {"open_relative_dot", "ok"}, {"open_dir_fd", "ok"},
      {"set_speed_1hz", "ok"}, {"xfer_at_1hz", "EINVAL"}, {"read_at_1hz", "EINVAL"},
      {"xfer_at_3814hz", "EINVAL"}, {"xfer_at_3815hz", "ok"}, {"xfer_at_5mhz", "ok"}};
  for (const auto& [key, value] : want) {
    const auto it = got.find(key);
    EXPECT_TRUE(it != got.end() && it->second == value)
        << key << ": " << (it == got.end() ? std::string("missing") : it->second) << ", the kernel's is " << value;
  }
}

INSTANTIATE_TEST_SUITE_P(InProcessAndThroughTheDaemon, KernelFidelity, ::testing::Bool(),
                         [](const auto& info) { return info.param ? "Daemon" : "InProcess"; });

TEST(KernelFidelityTime, ATransferTooSlowForTheControllerTakesNoBusTime) {
  if (const std::string why = missing_prerequisites(); !why.empty()) GTEST_SKIP() << why;
  ServeDaemon d(kChain, {"--virtual-time", "--log", "off"});
  ASSERT_TRUE(d.ready());
  // 4 bytes at 1 Hz would be 32 s of the bus; the controller cannot clock that slowly.
  const RunResult r = run_program(
      {system_python(), "-c",
       "import spidev\ns = spidev.SpiDev(); s.open(0, 0); s.mode = 3\n"
       "try:\n  s.xfer2([0, 0, 0, 0], 1)\nexcept OSError as e:\n  print('errno', e.errno)\n"},
      d.env());
  EXPECT_EQ(r.out, "errno 22\n") << r.err;
  const RunResult t = d.ctl({"time"});
  EXPECT_NE(t.out.find(": 0 ticks = 0.000000 s"), std::string::npos) << t.out;
}

}  // namespace
}  // namespace l6470emu::test
