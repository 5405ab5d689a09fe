// No silent typos at the preload's edges: an L6470EMU_* variable nobody reads is named with the
// right one; opening a spidev or gpiochip node the board does not have says which it has; virtual
// host time with a daemon, and a bad L6470EMU_CHECK, stop the program with one line.
#include <gtest/gtest.h>

#include <string>

#include "board/environment_names.hpp"
#include "board/run_report.hpp"
#include "linux/fork_plan.hpp"
#include "run_program.hpp"

namespace l6470emu::test {
namespace {

class Typos : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string why = missing_prerequisites();
    if (!why.empty()) GTEST_SKIP() << why;
  }
};

std::size_t count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST_F(Typos, AMistypedVariableIsNamedWithTheOneMeantEvenWhenItLeavesNothingConfigured) {
  const RunResult r = run_program({"/bin/true"}, {{"LD_PRELOAD", preload_library()}, {"L6470EMU_CHIAN", "chips=L6470"}});
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.err.find("l6470emu: unknown environment variable L6470EMU_CHIAN: nothing reads it (did you mean "
                       "L6470EMU_CHAIN?)"),
            std::string::npos)
      << r.err;
  const RunResult s = run_program({"/bin/true"}, {{"LD_PRELOAD", preload_library()},
                                                  {"L6470EMU_CHAIN", "chips=L6470"},
                                                  {"L6470EMU_CHECKS", "error"}});
  EXPECT_NE(s.err.find("L6470EMU_CHECKS: nothing reads it (did you mean L6470EMU_CHECK?)"), std::string::npos) << s.err;
  const RunResult t = run_program({"/bin/true"}, {{"LD_PRELOAD", preload_library()}, {"L6470EMU_CHAIN", "chips=L6470"},
                                                  {"L6470EMU_LOG", "stderr"}, {"L6470EMU_SHM", "off"}});
  EXPECT_EQ(t.err.find("unknown environment variable"), std::string::npos) << t.err;
}

TEST_F(Typos, TheVariablesRunAndCampaignSetForTheirProgramsAreKnown) {
  for (const char* name : {kRunProgressEnv, kRunReportEnv, kRunScenarioEnv, kRunTimeoutEnv, kForkPlanEnv}) {
    bool known = false;
    for (const char* const* k = known_environment_variables(); *k; ++k) known = known || std::string(*k) == name;
    EXPECT_TRUE(known) << name << " is set by run or campaign but the preload would call it unknown";
  }
}

TEST_F(Typos, OpeningANodeTheBoardLacksSaysWhichNodesItHasOncePerPath) {
  const RunResult r = run_program(
      {system_python(), "-c",
       "import spidev\n"
       "for _ in range(3):\n"
       "  try:\n    spidev.SpiDev().open(0, 1)\n  except OSError as e:\n    print('errno', e.errno)\n"
       "try:\n  open('/dev/gpiochip7', 'rb')\nexcept OSError as e:\n  print('errno', e.errno)\n"},
      {{"LD_PRELOAD", preload_library()}, {"L6470EMU_CHAIN", "bus=0 cs=0 chips=L6470"}});
  EXPECT_EQ(r.status, 0) << r.err;
  const std::string said = "open /dev/spidev0.1: the emulated board has no such node (it has /dev/spidev0.0, "
                           "/dev/gpiochip0); the call goes to the system";
  EXPECT_EQ(count(r.err, said), 1u) << r.err;
  EXPECT_NE(r.err.find("open /dev/gpiochip7: the emulated board has no such node"), std::string::npos) << r.err;
}

TEST_F(Typos, VirtualTimeWithADaemonIsAnErrorNotIgnored) {
  const RunResult r = run_program({"/bin/true"}, {{"LD_PRELOAD", preload_library()},
                                                  {"L6470EMU_CHAIN", "chips=L6470 time=virtual"},
                                                  {"L6470EMU_SOCKET", "/tmp/l6470emu-nowhere.sock"}});
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("l6470emu: time=virtual runs the board inside the program, but L6470EMU_SOCKET sends it to "
                       "the daemon at /tmp/l6470emu-nowhere.sock"),
            std::string::npos)
      << r.err;
  const RunResult s = run_program({"/bin/true"}, {{"LD_PRELOAD", preload_library()},
                                                  {"L6470EMU_CHAIN", "time=virtual socket=/tmp/l6470emu-nowhere.sock"}});
  EXPECT_EQ(s.status, 2);
  EXPECT_NE(s.err.find("but socket= sends it to the daemon"), std::string::npos) << s.err;
}

TEST_F(Typos, ABadCheckSettingStopsTheProgramWithOneLine) {
  const RunResult r = run_program({"/bin/true"}, {{"LD_PRELOAD", preload_library()},
                                                  {"L6470EMU_CHAIN", "chips=L6470"},
                                                  {"L6470EMU_CHECK", "strict"}});
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err, "l6470emu: L6470EMU_CHECK must be off, warn or error, not 'strict'\n");
  const RunResult s = run_program({"/bin/true"}, {{"LD_PRELOAD", preload_library()},
                                                  {"L6470EMU_CHAIN", "chips=L6470"},
                                                  {"L6470EMU_CHECK_ALLOW", "SPI_MODE,WRONG_COMMAND"}});
  EXPECT_EQ(s.status, 2);
  EXPECT_NE(s.err.find("l6470emu: L6470EMU_CHECK_ALLOW names no rule 'WRONG_COMMAND'"), std::string::npos) << s.err;
}

}  // namespace
}  // namespace l6470emu::test
