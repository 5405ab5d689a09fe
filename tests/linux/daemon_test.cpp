// Unmodified programs against `l6470emu serve` through the preload library: state kept from
// one program to the next, several programs at once, the ctl interface, clients that die.
#include <signal.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include "run_program.hpp"

namespace l6470emu::test {
namespace {

bool has_line(const std::string& text, const std::string& line) {
  return ("\n" + text).find("\n" + line + "\n") != std::string::npos;
}

class Daemon : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string why = missing_prerequisites();
    if (!why.empty()) GTEST_SKIP() << why;
    start("bus=0 cs=0 chips=L6470", {});
  }

  void start(const std::string& chain, std::vector<std::string> extra) {
    daemon_ = std::make_unique<ServeDaemon>(chain, extra);
    socket_ = daemon_->socket();
    ASSERT_TRUE(daemon_->ready()) << daemon_->process().out();
  }

  void TearDown() override {
    if (daemon_) {
      const RunResult r = daemon_->process().stop(SIGTERM);
      EXPECT_EQ(r.status, 0) << r.out << r.err;
      EXPECT_EQ(access(socket_.c_str(), F_OK), -1) << "the daemon leaves no socket behind";
    }
  }

  Env env() const { return daemon_->env(); }
  RunResult ctl(const std::string& command) {
    std::vector<std::string> words;
    std::istringstream in(command);
    for (std::string w; in >> w;) words.push_back(w);
    return daemon_->ctl(words);
  }

  std::string socket_;
  std::unique_ptr<ServeDaemon> daemon_;
};

TEST_F(Daemon, ChainStateSurvivesFromOneProgramRunToTheNext) {
  RunResult r = run_program({system_python(), script("spidev_sequence.py"), "0", "0"}, env());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(has_line(r.out, "status0=0x7C03")) << r.out;
  EXPECT_TRUE(has_line(r.out, "abs_pos=6400")) << r.out;
  r = run_program({system_python(), script("spidev_sequence.py"), "0", "0"}, env());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(has_line(r.out, "status0=0x7E12")) << r.out;  // no power-up this time
  EXPECT_TRUE(has_line(r.out, "abs_pos=12800")) << r.out;   // the second Move started at 6400
}

TEST_F(Daemon, CClientAndV2ClientWorkThroughTheDaemon) {
  RunResult r = run_program({client("spidev_messages"), "/dev/spidev0.0"}, env());
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_TRUE(has_line(r.out, "GetStatus: r=3 7C03")) << r.out;
  EXPECT_EQ(r.out.find("WRONG"), std::string::npos) << r.out;
  r = run_program({client("gpio_v2"), "/dev/gpiochip0", "/dev/spidev0.0"}, env());
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_TRUE(has_line(r.out, "BUSY after move: 1 (2 events)")) << r.out;
  EXPECT_EQ(r.out.find("WRONG"), std::string::npos) << r.out;
}

TEST_F(Daemon, GpiomonSeesTheBusyEdgesOfAMoveAnotherProgramStarts) {
  Background mon({"/usr/bin/gpiomon", "--num-events=2", "gpiochip0", "0"}, env());
  // gpiomon is ready once its line is requested: ctl dump lists it.
  for (int i = 0; i < 300 && ctl("dump").out.find("requested by \"gpiomon\"") == std::string::npos; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  const RunResult mover = run_program(
      {system_python(), "-c",
       "import spidev\ns = spidev.SpiDev(); s.open(0, 0); s.mode = 3\n"
       "for b in (0x41, 0x00, 0x0C, 0x80): s.xfer2([b])\n"},
      env());
  ASSERT_EQ(mover.status, 0) << mover.err;
  const RunResult r = mon.wait(10);
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("FALLING EDGE offset: 0"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("RISING EDGE offset: 0"), std::string::npos) << r.out;
  EXPECT_LT(r.out.find("FALLING"), r.out.find("RISING")) << r.out;
}

TEST_F(Daemon, PythonLibgpiodSeesBusyWhileAMoveRuns) {
  const RunResult r = run_program({system_python(), script("busy_during_move.py"), "0", "0"}, env());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(has_line(r.out, "busy_during=0")) << r.out;
  EXPECT_TRUE(has_line(r.out, "edges=falling,rising")) << r.out;
  EXPECT_TRUE(has_line(r.out, "busy_after=1")) << r.out;
  // gpioget in a later program: the lines were released when the first program ended.
  const RunResult g = run_program({"/usr/bin/gpioget", "gpiochip0", "0"}, env());
  EXPECT_EQ(g.status, 0) << g.err;
  EXPECT_EQ(g.out, "1\n");
}

TEST_F(Daemon, CtlReadsStatusAndRegistersWithoutSideEffects) {
  RunResult r = ctl("status");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string numbering =
      "# chip numbers count from the MISO end (chip 0 drives MISO and gets a full frame's first byte)\n";
  EXPECT_EQ(r.out, numbering + "chip 0 (L6470): STATUS 0x7C03  HiZ REV STOPPED UVLO\n");
  r = ctl("status");
  EXPECT_EQ(r.out, numbering + "chip 0 (L6470): STATUS 0x7C03  HiZ REV STOPPED UVLO\n");  // nothing was cleared
  EXPECT_EQ(ctl("get MAX_SPEED").out, "chip 0: MAX_SPEED = 0x041\n");
  EXPECT_EQ(ctl("get ABS_POS").out, "chip 0: ABS_POS = 0x000000 (0)\n");
  EXPECT_EQ(ctl("get NOSUCH").status, 1);
  EXPECT_EQ(ctl("frobnicate").status, 2);
  EXPECT_NE(ctl("dump").out.find("0x07 MAX_SPEED  = 0x0041"), std::string::npos);
  const RunResult t = ctl("trace stop");  // recording: tests/linux/recording_test.cpp
  EXPECT_EQ(t.status, 1);
  EXPECT_NE(t.err.find("nothing is being recorded"), std::string::npos);
}

TEST_F(Daemon, CtlDrivesTheSwitchAndInjectsFaultsThatHostProgramsSee) {
  ASSERT_EQ(ctl("sw closed").status, 0);
  RunResult r = run_program({system_python(), "-c",
                             "import spidev\ns = spidev.SpiDev(); s.open(0, 0); s.mode = 3\n"
                             "r = [s.xfer2([b])[0] for b in (0xD0, 0, 0)]\nprint(hex(r[1] << 8 | r[2]))\n"},
                            env());
  EXPECT_EQ(r.out, "0x7c0e\n") << r.err;  // SW_F (closed), SW_EVN latched; the hard stop enabled the bridges
  ASSERT_EQ(ctl("fault ocd on").status, 0);
  r = run_program({"/usr/bin/gpioget", "gpiochip0", "1"}, env());
  EXPECT_EQ(r.out, "0\n");  // FLAG low: OCD latched
  EXPECT_NE(ctl("status").out.find("\nchip 0 (L6470): STATUS 0x6E07  HiZ SW_F REV STOPPED OCD\n"), std::string::npos);
  EXPECT_EQ(ctl("fault thermal bogus").status, 2);
}

TEST_F(Daemon, CtlRaisesTheOneShotFaultsABrownOutALostFrameAndAFlippedBit) {
  // A power cycle: registers at reset, UVLO latched (bit 9 low), bridges HiZ.
  ASSERT_EQ(ctl("fault reset").status, 0);
  EXPECT_NE(ctl("status").out.find("STATUS 0x7C03"), std::string::npos) << ctl("status").out;
  const std::string status = "import spidev\ns = spidev.SpiDev(); s.open(0, 0); s.mode = 3\n"
                             "r = [s.xfer2([b])[0] for b in (0xD0, 0, 0)]\nprint(hex(r[1] << 8 | r[2]))\n";
  // The GetStatus opcode's frame is lost: the chip never decodes it and answers nothing.
  ASSERT_EQ(ctl("fault lost-frame").status, 0);
  RunResult r = run_program({system_python(), "-c", status}, env());
  EXPECT_EQ(r.out, "0x0\n") << r.err;
  // The next frame's answer byte has bit 0 flipped on the wire: the opcode's own answer (0x00).
  const RunResult flipped = ctl("fault miso-flip 0");
  EXPECT_EQ(flipped.status, 0);
  EXPECT_NE(flipped.out.find("miso-flip bit 0"), std::string::npos) << flipped.out;
  EXPECT_EQ(ctl("fault miso-flip 8").status, 2);
  EXPECT_EQ(ctl("fault reset now").status, 2);
}

TEST_F(Daemon, AClientKilledMidMessageLeavesTheDaemonServingTheOthers) {
  Background hammer({system_python(), script("hammer.py"), "0", "0"}, env());
  for (int i = 0; i < 300 && hammer.out().find("running") == std::string::npos; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  hammer.stop(SIGKILL);
  // A client that connects, sends half a request and vanishes.
  const int s = socket(AF_UNIX, SOCK_SEQPACKET, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  std::strncpy(addr.sun_path, socket_.c_str(), sizeof addr.sun_path - 1);
  ASSERT_EQ(connect(s, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
  const char junk[5] = {4, 0, 0, 0, 9};
  ASSERT_EQ(send(s, junk, sizeof junk, 0), 5);
  close(s);
  const RunResult r = run_program({system_python(), script("spidev_sequence.py"), "0", "0"}, env());
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(has_line(r.out, "max_speed=0x030")) << r.out;
  EXPECT_NE(ctl("dump").out.find("spidev0.0: 0 open"), std::string::npos) << "the killed client's file was released";
}

TEST_F(Daemon, TwoClientsOnOneBusAreSerialisedMessageByMessage) {
  ASSERT_EQ(run_program({system_python(), script("set_mark.py"), "0", "0", "0x12345"}, env()).status, 0);
  // Each read is one message of four one-byte transfers with CS released between them; if the
  // daemon let the two programs' transfers interleave, answers would come back torn.
  Background a({client("spidev_reader"), "/dev/spidev0.0", "20000", "0x03", "0x12345"}, env());
  Background b({client("spidev_reader"), "/dev/spidev0.0", "20000", "0x03", "0x12345"}, env());
  // 17 s at a load average of 26, 48 s in a full ctest run at 33: the limit only catches a hang.
  const RunResult ra = a.wait(180), rb = b.wait(180);
  EXPECT_EQ(ra.out, "reads=20000 torn=0\n") << ra.err;
  EXPECT_EQ(rb.out, "reads=20000 torn=0\n") << rb.err;
}

TEST_F(Daemon, AnUnreachableDaemonMeansNoDevicesAndOneDiagnosticLine) {
  const RunResult r = run_program({system_python(), "-c",
                                   "import os\nprint(os.path.exists('/dev/spidev0.0'))"},
                                  {{"LD_PRELOAD", preload_library()}, {"L6470EMU_SOCKET", socket_ + ".nobody"}});
  EXPECT_EQ(r.status, 0);
  EXPECT_EQ(r.out, "False\n");
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("cannot reach the daemon"), std::string::npos) << r.err;
}

TEST(DaemonConfig, AMalformedServeConfigGivesOneErrorLineAndExitStatus2) {
  const RunResult r = run_program({l6470emu_program(), "serve", "--chain", "bus=0 chips=L6470,Foo", "--socket",
                                   temp_socket_path("bad")});
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("unknown chip variant 'Foo'"), std::string::npos) << r.err;
}

class VirtualDaemon : public Daemon {
 protected:
  void SetUp() override {
    const std::string why = missing_prerequisites();
    if (!why.empty()) GTEST_SKIP() << why;
    start("bus=0 cs=0 chips=L6470", {"--virtual-time"});
  }
};

TEST_F(VirtualDaemon, VirtualTimeMovesOnlyWithTrafficAndAdvance) {
  const RunResult mover = run_program(
      {system_python(), "-c",
       "import spidev, time\ns = spidev.SpiDev(); s.open(0, 0); s.mode = 3\n"
       "for b in (0x41, 0x00, 0x0C, 0x80): s.xfer2([b])\ntime.sleep(0.5)\n"},
      env());
  ASSERT_EQ(mover.status, 0) << mover.err;
  EXPECT_EQ(ctl("get ABS_POS").out, "chip 0: ABS_POS = 0x000000 (0)\n");  // wall time does not count
  EXPECT_EQ(ctl("advance 1000").status, 0);
  EXPECT_EQ(ctl("get ABS_POS").out, "chip 0: ABS_POS = 0x000C80 (3200)\n");
}

}  // namespace
}  // namespace l6470emu::test
