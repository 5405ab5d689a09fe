// Unmodified programs against an emulator inside their own process (L6470EMU_CHAIN):
// Debian's python3-spidev, python3-libgpiod and gpiod tools, and plain C clients.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <utility>
#include <vector>

#include "run_program.hpp"

namespace l6470emu::test {
namespace {

class InProcess : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string why = missing_prerequisites();
    if (!why.empty()) GTEST_SKIP() << why;
  }
  Env env(const std::string& chain = "bus=0 cs=0 chips=L6470") const {
    return {{"LD_PRELOAD", preload_library()}, {"L6470EMU_CHAIN", chain}};
  }
};

bool has_line(const std::string& text, const std::string& line) {
  return ("\n" + text).find("\n" + line + "\n") != std::string::npos;
}

TEST_F(InProcess, PySpidevRunsGetStatusSetParamGetParamAndAMove) {
  const RunResult r = run_program({system_python(), script("spidev_sequence.py"), "0", "0"}, env());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(has_line(r.out, "settings=mode3 bits8 4000000Hz")) << r.out;
  EXPECT_TRUE(has_line(r.out, "status0=0x7C03")) << r.out;  // power-up: HiZ, UVLO latched
  EXPECT_TRUE(has_line(r.out, "status1=0x7E03")) << r.out;  // GetStatus cleared UVLO
  EXPECT_TRUE(has_line(r.out, "max_speed=0x030")) << r.out;
  EXPECT_TRUE(has_line(r.out, "acc=0x0FF")) << r.out;
  EXPECT_TRUE(has_line(r.out, "busy_after_move=1")) << r.out;
  EXPECT_TRUE(has_line(r.out, "abs_pos=6400")) << r.out;
  EXPECT_TRUE(has_line(r.out, "status_end=0x7E12")) << r.out;  // forward, stopped, bridges on
}

TEST_F(InProcess, CClientSendsMessagesOfSeveralTransfersWithCsChangeAndGetsTheKernelsErrors) {
  const RunResult r = run_program({client("spidev_messages"), "/dev/spidev0.0"}, env());
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_TRUE(has_line(r.out, "stat: char 153:0")) << r.out;
  EXPECT_TRUE(has_line(r.out, "settings: mode 3 mode32 3 bits 8 speed 4000000")) << r.out;
  EXPECT_TRUE(has_line(r.out, "GetStatus: r=3 7C03")) << r.out;
  EXPECT_TRUE(has_line(r.out, "MAX_SPEED: 0030")) << r.out;
  EXPECT_TRUE(has_line(r.out, "tx-only/rx-only: r=3 0030")) << r.out;
  EXPECT_TRUE(has_line(r.out, "held CS: echo 27")) << r.out;
  EXPECT_TRUE(has_line(r.out, "read: 2 7E03")) << r.out;
  EXPECT_TRUE(has_line(r.out, "empty message: 0")) << r.out;
  EXPECT_TRUE(has_line(r.out, "after dup+close: r=3")) << r.out;
  EXPECT_EQ(r.out.find("WRONG"), std::string::npos) << r.out;
}

TEST_F(InProcess, SettingsTheChipCannotUseAreServedAndReported) {
  const RunResult r = run_program(
      {system_python(), "-c",
       "import spidev\n"
       "s = spidev.SpiDev(); s.open(0, 0); s.mode = 0; s.max_speed_hz = 8000000\n"
       "print([hex(s.xfer2([b])[0]) for b in (0xD0, 0, 0)])\n"
       "s.mode = 3; s.lsbfirst = True\n"
       "print([hex(s.xfer2([b])[0]) for b in (0x0B, 0, 0)])\n"},  // 0x0B bit-reversed is 0xD0: GetStatus
      env());
  ASSERT_EQ(r.status, 0) << r.err;
  // Mode 0: the answer's first byte shows the SDO latch the GetStatus opcode 0xD0 left (its top
  // bit, 1) instead of its own top bit: 0x7C03 reads 0xFC03, as on silicon.
  EXPECT_TRUE(has_line(r.out, "['0x0', '0xfc', '0x3']")) << r.out;
  EXPECT_TRUE(has_line(r.out, "['0x0', '0x7e', '0xc0']")) << r.out;  // 0x7E03 with each byte bit-reversed
  EXPECT_NE(r.err.find("spidev0.0: chip 0: SPI_MODE: the host clocks in SPI mode 0"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("SCK_SPEED: SCK is 8 MHz; the chip is specified up to 5 MHz"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("LSB_FIRST: the host shifts bytes least significant bit first"), std::string::npos) << r.err;
}

TEST_F(InProcess, UnknownDevicePathsAndOtherFilesPassThroughToTheCLibrary) {
  const RunResult r = run_program(
      {system_python(), "-c",
       "import os, spidev\n"
       "try:\n  spidev.SpiDev().open(9, 9)\nexcept OSError as e:\n  print('spidev9.9', e.errno)\n"
       "print('dev-null', len(open('/dev/null', 'rb').read()))\n"
       "print('proc', open('/proc/self/stat').read().split()[1])\n"
       "print('listing-has-spidev0.0', 'spidev0.0' in os.listdir('/dev'))\n"
       "print('stat-chr', os.stat('/dev/spidev0.0').st_mode & 0o170000 == 0o020000)\n"},
      env());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(has_line(r.out, "spidev9.9 2")) << r.out;  // ENOENT from the real /dev
  EXPECT_TRUE(has_line(r.out, "dev-null 0")) << r.out;
  EXPECT_TRUE(has_line(r.out, "proc (python3)")) << r.out;
  EXPECT_TRUE(has_line(r.out, "listing-has-spidev0.0 True")) << r.out;
  EXPECT_TRUE(has_line(r.out, "stat-chr True")) << r.out;
}

TEST_F(InProcess, WithoutAConfigTheLibraryStaysOutOfTheWay) {
  const RunResult r = run_program({system_python(), "-c",
                                   "import os\nprint(os.path.exists('/dev/spidev0.0'), os.path.exists('/dev/gpiochip0'))"},
                                  {{"LD_PRELOAD", preload_library()}});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, "False False\n");
  EXPECT_EQ(r.err, "");
}

TEST_F(InProcess, AMalformedConfigGivesOneClearErrorLineAndANonZeroExit) {
  for (const std::string& chain : std::vector<std::string>{
           "bus=0 cs=0 chips=L6471", "bus=x chips=L6470", "chips=L6470 colour=blue", "time=sometimes",
           "bus=0 bus=1 chips=L6470", "chips=257xL6470", "chips=0xL6470", "chips=L6470 path=/dev/null",
           "chips=L6470 scale=1e-300", "chips=L6470 time=virtual idle=0", "bus= chips=L6470",
           "chips=L6470 log=a\x01" "b", "chips=" + std::string(100'000, 'z')}) {
    const RunResult r = run_program({"/bin/true"}, {{"LD_PRELOAD", preload_library()}, {"L6470EMU_CHAIN", chain}});
    EXPECT_EQ(r.status, 2) << chain;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_EQ(r.err.rfind("l6470emu: config L6470EMU_CHAIN, clause 1: ", 0), 0u) << r.err;
    EXPECT_LT(r.err.size(), 340u) << r.err;  // the key list is the longest line
  }
  for (const auto& [file, error] : std::vector<std::pair<std::string, std::string>>{
           {"/nonexistent.conf", "cannot be read (No such file or directory)"},
           {"/tmp", "is a directory (give the board description file)"},
           {"/dev/zero", "is a device, not a file: it could block or never end"}}) {
    const RunResult r = run_program({"/bin/true"}, {{"LD_PRELOAD", preload_library()}, {"L6470EMU_CONFIG", file}});
    EXPECT_EQ(r.status, 2);
    EXPECT_EQ(r.err, "l6470emu: config file " + file + ": " + error + "\n");
  }
}

TEST_F(InProcess, ALogFileThatCannotBeOpenedIsReportedOnceAndTheProgramRuns) {
  const RunResult r = run_program({system_python(), "-c",
                                   "import spidev\ns = spidev.SpiDev(); s.open(0, 0); s.mode = 3\n"
                                   "print([hex(s.xfer2([b])[0]) for b in (0xD0, 0, 0)])\n"},
                                  env("bus=0 cs=0 chips=L6470 log=/nonexistent-dir/emu.log"));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(has_line(r.out, "['0x0', '0x7c', '0x3']")) << r.out;
  EXPECT_EQ(r.err,
            "l6470emu: log file '/nonexistent-dir/emu.log' cannot be opened (No such file or directory): diagnostics go "
            "to stderr\n");
}

TEST_F(InProcess, GpiodToolsSeeTheChipAndItsNamedLines) {
  const Env e = env("bus=0 cs=0 chips=2xL6470");
  RunResult r = run_program({"/usr/bin/gpiodetect"}, e);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, "gpiochip0 [l6470emu spidev0.0] (10 lines)\n");
  r = run_program({"/usr/bin/gpioinfo", "gpiochip0"}, e);
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* name : {"\"BUSY0\"", "\"FLAG0\"", "\"SW0\"", "\"STCK0\"", "\"STBY_RST0\"", "\"BUSY1\"", "\"STBY_RST1\""})
    EXPECT_NE(r.out.find(name), std::string::npos) << name << "\n" << r.out;
  r = run_program({"/usr/bin/gpioget", "gpiochip0", "0", "1", "2", "3", "4"}, e);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, "1 0 1 0 1\n");  // BUSY released, FLAG low (UVLO at power-up), SW open, STCK low, STBY high
  r = run_program({"/usr/bin/gpiofind", "FLAG1"}, e);
  EXPECT_EQ(r.out, "gpiochip0 6\n");
}

TEST_F(InProcess, PythonLibgpiodSeesBusyWhileAMoveRunsAndReleaseWhenItEnds) {
  const RunResult r = run_program({system_python(), script("busy_during_move.py"), "0", "0"}, env());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(has_line(r.out, "chip=gpiochip0 label=l6470emu spidev0.0 lines=5")) << r.out;
  EXPECT_TRUE(has_line(r.out, "busy_before=1 flag_before=0")) << r.out;
  EXPECT_TRUE(has_line(r.out, "flag_after_getstatus=1")) << r.out;
  EXPECT_TRUE(has_line(r.out, "busy_during=0")) << r.out;
  EXPECT_TRUE(has_line(r.out, "edges=falling,rising")) << r.out;
  EXPECT_TRUE(has_line(r.out, "busy_after=1")) << r.out;
  EXPECT_TRUE(has_line(r.out, "abs_pos=-25600")) << r.out;
}

TEST_F(InProcess, TimeScaleMakesTheMoveTakeLessWallTime) {
  const RunResult slow = run_program({system_python(), script("busy_during_move.py"), "0", "0"}, env());
  auto seconds = [](const std::string& out) {
    const auto at = out.find("move_seconds=");
    return at == std::string::npos ? -1.0 : std::stod(out.substr(at + 13));
  };
  EXPECT_GT(seconds(slow.out), 0.5) << slow.out;  // 25600 microsteps at the reset profile: about 0.63 s
  // 20 times faster: about 0.032 s plus scheduling, which a loaded machine can stretch on one run
  // (not on three: an unscaled move always takes its 0.63 s).
  RunResult fast;
  for (int attempt = 0; attempt < 3; ++attempt) {
    fast = run_program({system_python(), script("busy_during_move.py"), "0", "0"}, env("bus=0 cs=0 chips=L6470; scale=20"));
    ASSERT_EQ(fast.status, 0) << fast.err;
    EXPECT_TRUE(has_line(fast.out, "abs_pos=-25600")) << fast.out;
    if (seconds(fast.out) >= 0 && seconds(fast.out) < 0.1) break;
  }
  EXPECT_LT(seconds(fast.out), 0.1) << fast.out;
}

TEST_F(InProcess, StckPulsesAndStbyFromTheHostReachTheChipConfiguredByAFile) {
  const std::string conf = temp_socket_path("board") + ".conf";
  {
    FILE* f = std::fopen(conf.c_str(), "w");
    ASSERT_NE(f, nullptr);
    std::fputs("# one L6470 on /dev/spidev1.2\nbus=1 cs=2 chips=L6470 gpiochip=4\nlog=off\n", f);
    std::fclose(f);
  }
  const RunResult r = run_program(
      {system_python(), "-c",
       "import gpiod, spidev\n"
       "s = spidev.SpiDev(); s.open(1, 2); s.mode = 3\n"
       "def cmd(*bs): return [s.xfer2([b])[0] for b in bs]\n"
       "def pos(): r = cmd(0x21, 0, 0, 0); return r[1] << 16 | r[2] << 8 | r[3]\n"
       "chip = gpiod.Chip('gpiochip4')\n"
       "stck = chip.find_line('STCK'); stck.request(consumer='t', type=gpiod.LINE_REQ_DIR_OUT, default_val=0)\n"
       "stby = chip.find_line('STBY_RST'); stby.request(consumer='t', type=gpiod.LINE_REQ_DIR_OUT, default_val=1)\n"
       "cmd(0x59)\n"  // StepClock forward
       "for _ in range(10): stck.set_value(1); stck.set_value(0)\n"
       "print('after 10 STCK pulses', pos())\n"
       "stby.set_value(0); print('standby', cmd(0xD0, 0, 0)[1:])\n"
       "stby.set_value(1); print('reset', pos(), hex(cmd(0xD0, 0, 0)[1]))\n"},
      {{"LD_PRELOAD", preload_library()}, {"L6470EMU_CONFIG", conf}});
  std::remove(conf.c_str());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(has_line(r.out, "after 10 STCK pulses 10")) << r.out;
  EXPECT_TRUE(has_line(r.out, "standby [0, 0]")) << r.out;  // SPI silent while STBY/RST is low
  EXPECT_TRUE(has_line(r.out, "reset 0 0x7c")) << r.out;    // power-up state after the rising edge
  EXPECT_EQ(r.err, "");                                      // log=off
}

TEST_F(InProcess, V2ClientRequestsLinesReadsEdgeEventsAndDrivesSw) {
  const RunResult r = run_program({client("gpio_v2"), "/dev/gpiochip0", "/dev/spidev0.0"}, env());
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_TRUE(has_line(r.out, "chip: gpiochip0 [l6470emu spidev0.0] 5 lines")) << r.out;
  EXPECT_TRUE(has_line(r.out, "request fd: ok cloexec=1")) << r.out;
  EXPECT_TRUE(has_line(r.out, "info event: ok type 1 consumer v2-test")) << r.out;
  EXPECT_TRUE(has_line(r.out, "BUSY during move: 0")) << r.out;
  EXPECT_TRUE(has_line(r.out, "event: falling offset 0 seqno 1 line_seqno 1")) << r.out;
  EXPECT_TRUE(has_line(r.out, "event: rising offset 0 seqno 2 line_seqno 2")) << r.out;
  EXPECT_TRUE(has_line(r.out, "BUSY after move: 1 (2 events)")) << r.out;
  EXPECT_TRUE(has_line(r.out, "STATUS with SW closed: 7E0E")) << r.out;  // SW_F and SW_EVN set
  EXPECT_TRUE(has_line(r.out, "SW info: consumer v2-sw output=1 active_low=1 used=1")) << r.out;
  EXPECT_EQ(r.out.find("WRONG"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace l6470emu::test
