// The driver sanitizer through the preload, with real programs (Debian's python3-spidev and
// python3-libgpiod, a C client): each rule a program can break over spidev ends the run under
// check=error with exit status 86 and one report naming the chip, frame, byte, rule and the
// datasheet's place; check=warn logs it and the program runs on; through `l6470emu serve` the
// client ends the same way and the daemon serves the next one. (CS_DESELECT_TIME and
// CS_SETUP_TIME need a front that times CS itself: tests/board.)
#include <signal.h>

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "board/check_rules.hpp"
#include "run_program.hpp"

namespace l6470emu::test {
namespace {

// What every Python case starts with: a driver that does things right until it does not.
constexpr const char* kPrelude =
    "import spidev\n"
    "s = spidev.SpiDev(); s.open(0, 0); s.mode = 3; s.max_speed_hz = 1000000\n"
    "def b(*bs): return [s.xfer2([x])[0] for x in bs]\n";

struct Case {
  const char* rule;
  const char* chips;                    // chips= of the board
  const char* python;                   // the program after kPrelude ("" = the C client spidev_split)
  std::vector<const char*> in_report;   // fragments of the report
};

const std::vector<Case>& cases() {
  static const std::vector<Case> all = {
      {"SPI_MODE", "L6470", "s.mode = 0\nb(0x38, 0, 0)\n",
       {"SPI_MODE on spidev0.0, chip 0, frame 1, byte 0", "SPI mode 0 (CPOL=0, CPHA=0)", "§8 Serial interface"}},
      {"LSB_FIRST", "L6470", "s.lsbfirst = True\nb(0x0B, 0, 0)\n",
       {"LSB_FIRST on spidev0.0, chip 0, frame 1, byte 0", "bit-reversed", "most significant bit first"}},
      {"CS_ACTIVE_HIGH", "L6470", "s.cshigh = True\nb(0xD0)\n",
       {"CS_ACTIVE_HIGH on spidev0.0, chip 0", "never selected", "CS is forced low"}},
      {"WORD_SIZE", "2xL6470", "s.bits_per_word = 16\ns.xfer2([0xD0, 0xD0])\n",
       {"WORD_SIZE on spidev0.0, every chip, frame 1, byte 0", "16-bit words", "as 2 bytes"}},
      {"SCK_SPEED", "L6470", "s.max_speed_hz = 8000000\nb(0xD0)\n",
       {"SCK_SPEED on spidev0.0, chip 0, frame 1, byte 0", "SCK is 8 MHz", "f_CK,MAX = 5 MHz"}},
      {"FRAME_LENGTH", "2xL6470", "s.xfer2([0xD0])\n",
       {"FRAME_LENGTH on spidev0.0, every chip, frame 1", "1 byte in a frame for a chain of 2", "Figure 18"}},
      {"FRAME_PASS_THROUGH", "L6470", "s.xfer2([0x38, 0x00, 0x00])\n",
       {"FRAME_PASS_THROUGH on spidev0.0, chip 0, frame 1", "CS held low over 3 bytes for a single chip"}},
      {"COMMAND_SPLIT", "2xL6470", "",
       {"COMMAND_SPLIT on spidev0.0, chip 1", "a message of 2 frames ends while this chip still waits for 2 argument "
                                              "bytes of Move and chip 0 has finished its command", "§9.2.1"}},
      {"WRONG_CMD", "L6470", "b(0xE5)\n",
       {"WRONG_CMD on spidev0.0, chip 0, frame 1, byte 0", "byte 0xE5: no such command", "§9.2.1 Command management"}},
      {"NOTPERF_CMD", "L6470", "b(0x51, 0x00, 0x10, 0x00)\nb(0x16, 0x03)\n",
       {"NOTPERF_CMD on spidev0.0, chip 0, frame 6, byte 0", "SetParam of STEP_MODE while the bridges are enabled",
        "§9.2.3 SetParam"}},
      {"NOTPERF_CMD", "L6470", "b(0x41, 0x00, 0x10, 0x00)\nb(0x41, 0x00, 0x00, 0x01)\n",
       {"NOTPERF_CMD on spidev0.0, chip 0, frame 8, byte 0", "Move while the motor runs"}},
      {"READ_ONLY_WRITE", "L6470", "b(0x04, 0x00, 0x00, 0x10)\n",
       {"READ_ONLY_WRITE on spidev0.0, chip 0, frame 1, byte 0", "SetParam of a read-only register", "Table 9"}},
      {"UNUSED_BITS", "L6470", "b(0x07, 0x04, 0x00)\n",
       {"UNUSED_BITS on spidev0.0, chip 0, frame 3, byte 0",
        "SetParam(MAX_SPEED) value 0x0400 has bits above the 10 the register has (0x0400): the chip keeps 0x0000"}},
      {"ANSWER_LOST", "L6470", "b(0x21, 0x00, 0xD0)\n",
       {"ANSWER_LOST on spidev0.0, chip 0, frame 3, byte 0", "1 byte of an earlier answer never shifted out",
        "Figure 21"}},
      {"STANDBY_BYTE", "L6470",
       "import gpiod\nline = gpiod.Chip('gpiochip0').find_line('STBY_RST')\n"
       "line.request(consumer='t', type=gpiod.LINE_REQ_DIR_OUT, default_vals=[0])\nb(0xD0)\n",
       {"STANDBY_BYTE on spidev0.0, chip 0, frame 1, byte 0", "the command byte 0xD0 is lost", "§6.12"}},
      {"RESERVED_BITS", "L6470", "b(0x16, 0x0F)\n",
       {"RESERVED_BITS on spidev0.0, chip 0, frame 2, byte 0",
        "SetParam(STEP_MODE) value 0x0F sets bit 3, which is to be written 0: §9.1.19 Table 17, note 1"}},
  };
  return all;
}

class Sanitizer : public ::testing::TestWithParam<std::size_t> {
 protected:
  void SetUp() override {
    const std::string why = missing_prerequisites();
    if (!why.empty()) GTEST_SKIP() << why;
  }
  static std::vector<std::string> argv(const Case& c) {
    if (*c.python == '\0') return {client("spidev_split"), "/dev/spidev0.0"};
    return {system_python(), "-c", std::string(kPrelude) + c.python + "print('ran to the end')\n"};
  }
};

TEST_P(Sanitizer, UnderCheckErrorTheProgramEndsWithTheReportAndTheSanitizersStatus) {
  const Case& c = cases()[GetParam()];
  const RunResult r = run_program(argv(c), {{"LD_PRELOAD", preload_library()},
                                            {"L6470EMU_CHAIN", std::string("bus=0 cs=0 chips=") + c.chips + " check=error"}});
  EXPECT_EQ(r.status, kSanitizerExitStatus) << r.out << r.err;
  EXPECT_EQ(r.out.find("ran to the end"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("l6470emu: driver sanitizer: "), std::string::npos) << r.err;
  for (const char* fragment : c.in_report) EXPECT_NE(r.err.find(fragment), std::string::npos) << fragment << "\n" << r.err;
  EXPECT_NE(r.err.find(std::string("check.allow=") + c.rule), std::string::npos) << r.err;
  // One report: the first broken rule only.
  EXPECT_EQ(r.err.find("driver sanitizer", r.err.find("driver sanitizer") + 1), std::string::npos) << r.err;
}

TEST_P(Sanitizer, TheEnvironmentAloneSetsTheLevel) {
  // No check= in the description: L6470EMU_CHECK=error by itself ends the program.
  const Case& c = cases()[GetParam()];
  const RunResult r = run_program(argv(c), {{"LD_PRELOAD", preload_library()},
                                            {"L6470EMU_CHAIN", std::string("bus=0 cs=0 chips=") + c.chips},
                                            {"L6470EMU_CHECK", "error"}});
  EXPECT_EQ(r.status, kSanitizerExitStatus) << r.out << r.err;
  EXPECT_EQ(r.out.find("ran to the end"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find(std::string("check.allow=") + c.rule), std::string::npos) << r.err;
}

TEST_P(Sanitizer, UnderCheckWarnTheProgramRunsOnAndTheLogNamesTheRule) {
  const Case& c = cases()[GetParam()];
  if (*c.python == '\0') GTEST_SKIP() << "the C client prints no end line";
  const RunResult r = run_program(argv(c), {{"LD_PRELOAD", preload_library()},
                                            {"L6470EMU_CHAIN", std::string("bus=0 cs=0 chips=") + c.chips}});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("ran to the end"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find(std::string(": ") + c.rule + ": "), std::string::npos) << r.err;
}

TEST_P(Sanitizer, AnAllowedRuleLetsTheProgramRunToTheEnd) {
  const Case& c = cases()[GetParam()];
  if (*c.python == '\0') GTEST_SKIP() << "the C client prints no end line";
  const RunResult r = run_program(argv(c), {{"LD_PRELOAD", preload_library()},
                                            {"L6470EMU_CHAIN", std::string("bus=0 cs=0 chips=") + c.chips},
                                            {"L6470EMU_CHECK", "error"},
                                            {"L6470EMU_CHECK_ALLOW", c.rule}});
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("ran to the end"), std::string::npos) << r.out;
}

INSTANTIATE_TEST_SUITE_P(EveryRuleASpidevProgramCanBreak, Sanitizer, ::testing::Range<std::size_t>(0, cases().size()),
                         [](const ::testing::TestParamInfo<std::size_t>& info) {
                           return std::string(cases()[info.param].rule) + "_" + std::to_string(info.param);
                         });

TEST(SanitizerDaemon, TheClientEndsWithTheReportAndTheDaemonServesTheNextOne) {
  const std::string why = missing_prerequisites();
  if (!why.empty()) GTEST_SKIP() << why;
  ServeDaemon daemon("bus=0 cs=0 chips=L6470 check=error", {"--virtual-time"});
  ASSERT_TRUE(daemon.ready()) << daemon.process().out();
  // Its first message (a NOP) breaks the rule, so it leaves no answer pending for the next client.
  const std::string bad = std::string(kPrelude) + "s.mode = 0\nb(0x00, 0x38, 0, 0)\nprint('ran to the end')\n";
  const RunResult r = run_program({system_python(), "-c", bad}, daemon.env());
  EXPECT_EQ(r.status, kSanitizerExitStatus) << r.out << r.err;
  EXPECT_NE(r.err.find("driver sanitizer: SPI_MODE on spidev0.0, chip 0, frame 1, byte 0"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("SPI mode 0 (CPOL=0, CPHA=0)"), std::string::npos) << r.err;
  // The next client, a correct one, is served.
  const std::string good = std::string(kPrelude) + "print('status=0x%02X%02X' % tuple(b(0xD0, 0, 0)[1:]))\n";
  const RunResult g = run_program({system_python(), "-c", good}, daemon.env());
  EXPECT_EQ(g.status, 0) << g.err;
  EXPECT_NE(g.out.find("status=0x"), std::string::npos) << g.out;
  const RunResult stopped = daemon.process().stop(SIGTERM);
  EXPECT_NE(stopped.err.find("driver sanitizer: SPI_MODE on spidev0.0, chip 0, frame 1, byte 0"), std::string::npos)
      << stopped.err << stopped.out;
}

TEST(SanitizerDaemon, ServeCheckOverridesTheDescription) {
  const std::string why = missing_prerequisites();
  if (!why.empty()) GTEST_SKIP() << why;
  ServeDaemon daemon("bus=0 cs=0 chips=L6470 check=off", {"--virtual-time", "--check", "error"});
  ASSERT_TRUE(daemon.ready()) << daemon.process().out();
  const RunResult r = run_program({system_python(), "-c", std::string(kPrelude) + "b(0xE5)\nprint('ran to the end')\n"},
                                  daemon.env());
  EXPECT_EQ(r.status, kSanitizerExitStatus) << r.out << r.err;
  EXPECT_NE(r.err.find("driver sanitizer: WRONG_CMD on spidev0.0, chip 0, frame 1, byte 0"), std::string::npos) << r.err;
}

TEST(SanitizerDaemon, AWarnDaemonLogsAndServes) {
  const std::string why = missing_prerequisites();
  if (!why.empty()) GTEST_SKIP() << why;
  ServeDaemon daemon("bus=0 cs=0 chips=L6470", {"--virtual-time"});
  ASSERT_TRUE(daemon.ready()) << daemon.process().out();
  const RunResult r = run_program({system_python(), "-c", std::string(kPrelude) + "b(0xE5)\nprint('ran to the end')\n"},
                                  daemon.env());
  EXPECT_EQ(r.status, 0) << r.err;
  const RunResult stopped = daemon.process().stop(SIGTERM);
  EXPECT_NE((stopped.err + stopped.out).find("chip 0: WRONG_CMD: byte 0xE5: no such command (frame 1, byte 0)"),
            std::string::npos)
      << stopped.err << stopped.out;
}

}  // namespace
}  // namespace l6470emu::test
