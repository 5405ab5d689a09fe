// Traces recorded from real programs, in process (L6470EMU_TRACE, trace=) and by the daemon
// (serve --record, ctl trace), replay clean; a recording host killed mid-run leaves a complete file.
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include "run_program.hpp"
#include "board/trace_recorder.hpp"
#include "spi/trace_native.hpp"

namespace l6470emu::test {
namespace {

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::size_t count_of(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

/// `l6470emu replay` on the file: exit 0 and "matched".
::testing::AssertionResult replays_clean(const std::string& path) {
  const RunResult r = run_program({l6470emu_program(), "replay", path});
  if (r.status == 0 && r.out.find(": matched") != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "replay exit " << r.status << "\n" << r.out << r.err << "\n" << read_file(path);
}

class Recording : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string why = missing_prerequisites();
    if (!why.empty()) GTEST_SKIP() << why;
    trace_ = temp_socket_path("rec") + ".trace";
  }
  void TearDown() override { std::remove(trace_.c_str()); }
  std::string trace_;
};

TEST_F(Recording, InProcessCClientWithCsChangeMessagesIsRecordedFrameByFrameAndReplaysClean) {
  const RunResult r = run_program({client("spidev_messages"), "/dev/spidev0.0"},
                                  {{"LD_PRELOAD", preload_library()},
                                   {"L6470EMU_CHAIN", "bus=0 cs=0 chips=L6470"},
                                   {"L6470EMU_TRACE", trace_}});
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const std::string text = read_file(trace_);
  // The header: the chain, and its whole board description (what a replay builds).
  EXPECT_EQ(text.rfind("l6470emu-trace 3\nchain L6470\nboard bus=0 cs=0 path=/dev/spidev0.0 chips=L6470 ", 0), 0u) << text;
  // GetStatus as three one-byte transfers with cs_change between them: three CS frames.
  EXPECT_NE(text.find(" frame 2.00us D0 | 00\n"), std::string::npos) << text;
  EXPECT_NE(text.find(" frame 2.00us 00 | 7C\n"), std::string::npos) << text;
  // The held-CS echo: cs_change on the last transfer keeps CS low into the next message: one frame,
  // lasting the two bytes plus however long the host took between the two messages.
  EXPECT_NE(text.find("us 27 00 | 00 27\n"), std::string::npos) << text;
  EXPECT_TRUE(replays_clean(trace_));
}

TEST_F(Recording, InProcessPythonWithGpioPinsAndBusyEdgesReplaysClean) {
  const RunResult r = run_program({client("gpio_v2"), "/dev/gpiochip0", "/dev/spidev0.0"},
                                  {{"LD_PRELOAD", preload_library()},
                                   {"L6470EMU_CHAIN", "bus=0 cs=0 chips=L6470; trace=" + trace_}});
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const std::string text = read_file(trace_);
  EXPECT_NE(text.find(" pin 0 SW 0\n"), std::string::npos) << text;    // the host closed SW through gpio
  EXPECT_NE(text.find(" pin 0 BUSY 0\n"), std::string::npos) << text;  // the move
  EXPECT_NE(text.find(" pin 0 BUSY 1\n"), std::string::npos) << text;
  EXPECT_TRUE(replays_clean(trace_));

  const RunResult s = run_program(
      {system_python(), "-c",
       "import gpiod, spidev\n"
       "s = spidev.SpiDev(); s.open(0, 0); s.mode = 3\n"
       "def cmd(*bs): return [s.xfer2([b])[0] for b in bs]\n"
       "chip = gpiod.Chip('gpiochip0')\n"
       "stck = chip.find_line('STCK'); stck.request(consumer='t', type=gpiod.LINE_REQ_DIR_OUT, default_val=0)\n"
       "stby = chip.find_line('STBY_RST'); stby.request(consumer='t', type=gpiod.LINE_REQ_DIR_OUT, default_val=1)\n"
       "cmd(0x59)\n"
       "for _ in range(10): stck.set_value(1); stck.set_value(0)\n"
       "print(cmd(0x21, 0, 0, 0))\n"
       "stby.set_value(0); cmd(0xD0, 0, 0); stby.set_value(1); print(cmd(0xD0, 0, 0))\n"},
      {{"LD_PRELOAD", preload_library()}, {"L6470EMU_CHAIN", "bus=0 cs=0 chips=L6470"}, {"L6470EMU_TRACE", trace_}});
  ASSERT_EQ(s.status, 0) << s.err;
  EXPECT_EQ(s.out, "[0, 0, 0, 10]\n[0, 124, 3]\n");
  const std::string stck = read_file(trace_);
  EXPECT_EQ(count_of(stck, " pin 0 STCK 1\n"), 10u) << stck;
  EXPECT_EQ(count_of(stck, " pin 0 STBY 0\n"), 1u) << stck;
  EXPECT_TRUE(replays_clean(trace_));
}

TEST_F(Recording, AHostKilledMidRunLeavesATraceCompleteUpToItsLastFrame) {
  Background hammer({system_python(), script("hammer.py"), "0", "0"},
                    {{"LD_PRELOAD", preload_library()},
                     {"L6470EMU_CHAIN", "bus=0 cs=0 chips=L6470"},
                     {"L6470EMU_TRACE", trace_}});
  for (int i = 0; i < 1000 && hammer.out().find("running") == std::string::npos; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // a few thousand frames, more than 100 even under ASan
  hammer.stop(SIGKILL);
  // Written through a shared mapping: the file keeps its chunk's length, the unwritten rest
  // zero bytes where readers stop. The text before them ends with a whole line.
  const std::string file = read_file(trace_);
  const std::string text = file.substr(0, file.find('\0'));
  ASSERT_FALSE(text.empty());
  EXPECT_LT(text.size(), file.size()) << "killed before it was cut to its length";
  EXPECT_EQ(text.back(), '\n') << "the last line is whole";
  std::uint64_t frames = 0;
  try {
    NativeTraceReader reader(trace_);
    TraceEvent e;
    while (reader.next(e)) frames += e.kind == TraceEventKind::frame;
  } catch (const TraceError& e) {
    FAIL() << e.what();
  }
  EXPECT_GT(frames, 100u);
  EXPECT_TRUE(replays_clean(trace_));
}

// The chain of issue 25's headline: a mechanical axis whose home switch closes SW at 0.
constexpr const char* kHomingChain = "bus=0 cs=0 chips=L6470 axis.0=stops=-6400..300000,start=51200,switch=home@0:below:hyst=64";

/// `l6470emu decode` and `plot` of the file say nothing diverged (exit 0, no banner).
::testing::AssertionResult decodes_without_divergence(const std::string& path) {
  const RunResult r = run_program({l6470emu_program(), "decode", path});
  if (r.status != 0 || r.out.find("DIVERGED") != std::string::npos)
    return ::testing::AssertionFailure() << "decode exit " << r.status << "\n" << r.out << r.err;
  return ::testing::AssertionSuccess();
}

TEST_F(Recording, APreloadedHomingRunAgainstTheAxisSwitchRecordsItsWorldAndReplaysExactly) {
  const RunResult r = run_program({system_python(), script("spidev_homing.py"), "0", "0"},
                                  {{"LD_PRELOAD", preload_library()},
                                   {"L6470EMU_CHAIN", std::string(kHomingChain) + "; time=virtual"},
                                   {"L6470EMU_TRACE", trace_}});
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  ASSERT_NE(r.out.find("homed\n"), std::string::npos) << r.out;
  const std::string text = read_file(trace_);
  // The axis and its switch are in the recording's board description.
  EXPECT_NE(text.find("\nboard bus=0 cs=0 path=/dev/spidev0.0 chips=L6470 "), std::string::npos) << text;
  EXPECT_NE(text.find(" axis.0=stops=-6400..300000,start=51200,switch=home@0:below:no:hyst=64"), std::string::npos) << text;
  EXPECT_NE(text.find("\nboard time=virtual"), std::string::npos) << text;
  // Replayed through the world it ran in: every MISO byte and BUSY/FLAG/SW level as recorded.
  EXPECT_TRUE(replays_clean(trace_));
  const RunResult rep = run_program({l6470emu_program(), "replay", trace_});
  EXPECT_NE(rep.err.find("with an axis behind chip 0 (from the trace's board description)"), std::string::npos) << rep.err;
  EXPECT_TRUE(decodes_without_divergence(trace_));
  // Without the axis (the chain named on the command line) the switch never closes: the
  // replay, decode and plot all say so, and the latter two exit 1 unless told to accept it.
  const RunResult bare = run_program({l6470emu_program(), "replay", "--chain", "L6470", trace_});
  EXPECT_EQ(bare.status, 1) << bare.out << bare.err;
  // The first thing to differ: the switch the recorded axis closed, at its own tick.
  EXPECT_NE(bare.out.find("chip 0 SW (driven by its axis) expected low (switch closed), emulated high (switch open)"),
            std::string::npos)
      << bare.out;
  const RunResult dec = run_program({l6470emu_program(), "decode", "--chain", "L6470", trace_});
  EXPECT_EQ(dec.status, 1) << dec.out << dec.err;
  EXPECT_NE(dec.out.find("DIVERGED"), std::string::npos) << dec.out;
  EXPECT_NE(dec.err.find("--accept-divergence accepts it"), std::string::npos) << dec.err;
  EXPECT_EQ(run_program({l6470emu_program(), "decode", "--accept-divergence", "--chain", "L6470", trace_}).status, 0);
}

class RecordingDaemon : public Recording {
 protected:
  void start(std::vector<std::string> extra) {
    daemon_ = std::make_unique<ServeDaemon>("bus=0 cs=0 chips=L6470", extra);
    ASSERT_TRUE(daemon_->ready()) << daemon_->process().out();
  }
  RunResult ctl(std::vector<std::string> words) { return daemon_->ctl(words); }
  Env env() const { return daemon_->env(); }
  std::unique_ptr<ServeDaemon> daemon_;
};

TEST_F(RecordingDaemon, ServeRecordTakesProgramsCtlSwitchAndFaultsAndReplaysClean) {
  start({"--record", trace_});
  ASSERT_EQ(run_program({system_python(), script("spidev_sequence.py"), "0", "0"}, env()).status, 0);
  ASSERT_EQ(ctl({"sw", "closed"}).status, 0);
  ASSERT_EQ(ctl({"fault", "ocd", "on"}).status, 0);
  ASSERT_EQ(ctl({"adc", "17"}).status, 0);
  const RunResult g = run_program({system_python(), "-c",
                                   "import spidev\ns = spidev.SpiDev(); s.open(0, 0); s.mode = 3\n"
                                   "print([s.xfer2([b])[0] for b in (0xD0, 0, 0, 0x29, 0)])\n"},
                                  env());
  ASSERT_EQ(g.status, 0) << g.err;
  const RunResult d = daemon_->process().stop(SIGTERM);
  daemon_.reset();
  ASSERT_EQ(d.status, 0) << d.out << d.err;
  EXPECT_NE(d.out.find(" frames to " + trace_ + "\n"), std::string::npos) << d.out;
  const std::string text = read_file(trace_);
  EXPECT_NE(text.find(" pin 0 SW 0\n"), std::string::npos) << text;
  EXPECT_NE(text.find(" fault 0 OCD on\n"), std::string::npos) << text;
  EXPECT_NE(text.find(" fault 0 ADCIN 17\n"), std::string::npos) << text;
  EXPECT_TRUE(replays_clean(trace_));
}

TEST_F(RecordingDaemon, CtlTraceStartAndStopRecordWhatHappensInBetween) {
  start({"--virtual-time"});
  EXPECT_EQ(ctl({"trace", "stop"}).status, 1);  // nothing to stop
  EXPECT_EQ(ctl({"trace", "start", "/nonexistent-dir/x.trace"}).status, 1);
  const RunResult s = ctl({"trace", "start", trace_});
  ASSERT_EQ(s.status, 0) << s.err;
  EXPECT_NE(s.out.find("recording to " + trace_), std::string::npos) << s.out;
  ASSERT_EQ(run_program({client("spidev_messages"), "/dev/spidev0.0"}, env()).status, 0);
  ASSERT_EQ(ctl({"advance", "10"}).status, 0);
  const RunResult t = ctl({"trace", "stop"});
  ASSERT_EQ(t.status, 0) << t.err;
  EXPECT_NE(t.out.find("recorded 20 frames to " + trace_), std::string::npos) << t.out;
  EXPECT_TRUE(replays_clean(trace_));
  // Traffic after the stop is not recorded.
  const std::string before = read_file(trace_);
  ASSERT_EQ(run_program({client("spidev_messages"), "/dev/spidev0.0"}, env()).status, 0);
  EXPECT_EQ(read_file(trace_), before);
  const RunResult d = daemon_->process().stop(SIGTERM);
  daemon_.reset();
  EXPECT_EQ(d.status, 0) << d.err;
}

TEST_F(RecordingDaemon, ATracePathWithBlanksInItIsOneFileAndClientsTakesNoChip) {
  start({"--virtual-time"});
  const std::string spaced = trace_ + " run 1.trace";
  const RunResult s = ctl({"trace", "start", spaced});
  ASSERT_EQ(s.status, 0) << s.err;
  EXPECT_NE(s.out.find("recording to " + spaced + "\n"), std::string::npos) << s.out;
  ASSERT_EQ(ctl({"trace", "stop"}).status, 0);
  EXPECT_TRUE(replays_clean(spaced));
  std::remove(spaced.c_str());
  // `clients` lists every program: a chip makes no sense there, and the answer says so.
  const RunResult c = ctl({"clients", "--chip", "1"});
  EXPECT_EQ(c.status, 2);
  EXPECT_EQ(c.err, "ctl: usage: clients (it lists every connected program: no --chip, --chain or other word)\n");
  EXPECT_EQ(ctl({"clients"}).status, 0);
}

TEST_F(RecordingDaemon, ATracePathThatIsAFifoALinkOrADeviceIsRefusedAndTheDaemonServesOn) {
  start({});
  const std::string fifo = trace_ + ".fifo", link = trace_ + ".link", target = trace_ + ".target";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  { std::ofstream(target) << "someone else's file\n"; }
  ASSERT_EQ(symlink(target.c_str(), link.c_str()), 0);
  // A FIFO opened for writing would wait for a reader with the board's lock held: refused at once.
  const RunResult f = ctl({"trace", "start", fifo});
  EXPECT_EQ(f.status, 1);
  EXPECT_NE(f.err.find("not a regular file"), std::string::npos) << f.err;
  const RunResult l = ctl({"trace", "start", link});
  EXPECT_EQ(l.status, 1);
  EXPECT_NE(l.err.find("a symbolic link"), std::string::npos) << l.err;
  EXPECT_EQ(read_file(target), "someone else's file\n");
  EXPECT_EQ(ctl({"trace", "start", "/dev/null"}).status, 1);
  EXPECT_EQ(ctl({"status"}).status, 0) << "the daemon still answers";
  unlink(fifo.c_str());
  unlink(link.c_str());
  unlink(target.c_str());
}

TEST_F(RecordingDaemon, ADaemonKilledWhileRecordingLeavesACompleteTrace) {
  start({"--record", trace_});
  const RunResult host = run_program({system_python(), script("spidev_sequence.py"), "0", "0"}, env());
  ASSERT_EQ(host.status, 0) << host.err;
  const std::size_t at = host.out.find("frames=");
  ASSERT_NE(at, std::string::npos) << host.out;
  const std::string frames = host.out.substr(at + 7, host.out.find('\n', at) - at - 7);
  daemon_->process().stop(SIGKILL);
  unlink(daemon_->socket().c_str());
  daemon_.reset();
  const std::string file = read_file(trace_);
  const std::string text = file.substr(0, file.find('\0'));  // the unwritten rest of the mapped file
  // The program's last command (GetStatus, one frame per byte) is the file's last frame.
  EXPECT_EQ(text.substr(text.rfind(" frame ")), " frame 2.00us 00 | 12\n") << text;
  // Every frame the program sent is in the file (how many it sent depends on how often it
  // polled during the move, so on the machine's load: the program counts them).
  EXPECT_TRUE(replays_clean(trace_));
  const RunResult r = run_program({l6470emu_program(), "replay", trace_});
  EXPECT_NE(r.out.find(": " + frames + " frames, "), std::string::npos) << "the program sent " << frames << " frames\n"
                                                                        << r.out;
}

TEST_F(RecordingDaemon, AVirtualTimeDaemonWithAnAxisSeveralClientsLoadsFaultsAndAdvanceReplaysExactly) {
  // Two chains on one bus: the homing axis behind chip select 0, a plain chip behind 1.
  daemon_ = std::make_unique<ServeDaemon>(std::string(kHomingChain) + "; bus=0 cs=1 chips=L6470",
                                          std::vector<std::string>{"--virtual-time", "--record", trace_});
  ASSERT_TRUE(daemon_->ready()) << daemon_->process().out();
  const std::string homed_trace = trace_path_for_chain(trace_, "spidev0.0", 2);
  const std::string other_trace = trace_path_for_chain(trace_, "spidev0.1", 2);
  // The daemon's virtual time moves with bus traffic and `ctl advance` only (its clients' sleeps
  // are real): the test steps it, as a harness orchestrating several programs does, while a
  // homing run on spidev0.0 and a second program on spidev0.1 (a Move, status and position
  // polled) share the bus.
  auto home = [&](std::vector<std::string> argv) {
    Background homing(argv, env());
    for (int i = 0; i < 2000; ++i) {
      const std::string out = homing.out();
      if (out.find("homed\n") != std::string::npos || out.find("FAIL") != std::string::npos) break;
      ctl({"advance", "100"});
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return homing.wait(30);
  };
  Background watcher({system_python(), "-c",
                      "import spidev, time\ns = spidev.SpiDev(); s.open(0, 1); s.mode = 3\n"
                      "x = lambda *bs: [s.xfer2([b])[0] for b in bs]\n"
                      "x(0x51, 0, 0x20, 0)\n"
                      "for _ in range(100): x(0xD0, 0, 0); x(0x21, 0, 0, 0); time.sleep(0.002)\n"},
                     env());
  const RunResult first = home({system_python(), script("spidev_homing.py"), "0", "0"});
  ASSERT_EQ(first.status, 0) << first.out << first.err;
  const RunResult watched = watcher.wait(30);
  ASSERT_EQ(watched.status, 0) << watched.err;
  // Stimuli that do not come over the bus: a heavier load, time passing, a fault, the host's SW.
  ASSERT_EQ(ctl({"axis", "load", "friction=0.3", "--chip", "0"}).status, 0);
  ASSERT_EQ(ctl({"advance", "50"}).status, 0);
  const RunResult stalled = run_program({system_python(), "-c",
                                         "import spidev, time\ns = spidev.SpiDev(); s.open(0, 0); s.mode = 3\n"
                                         "x = lambda *bs: [s.xfer2([b])[0] for b in bs]\n"
                                         "x(0x41, 0, 0x32, 0)\n"},
                                        env());
  ASSERT_EQ(ctl({"advance", "1500"}).status, 0);  // the Move against 0.3 N·m of friction
  ASSERT_EQ(stalled.status, 0) << stalled.err;
  ASSERT_EQ(ctl({"fault", "ocd", "on"}).status, 0);
  ASSERT_EQ(ctl({"advance", "20"}).status, 0);
  ASSERT_EQ(ctl({"fault", "ocd", "off"}).status, 0);
  ASSERT_EQ(ctl({"axis", "load", "friction=0", "--chip", "0"}).status, 0);
  const RunResult last = home({system_python(), script("spidev_homing.py"), "0", "0", "3000"});
  ASSERT_EQ(last.status, 0) << last.out << last.err;
  const RunResult d = daemon_->process().stop(SIGTERM);
  daemon_.reset();
  ASSERT_EQ(d.status, 0) << d.out << d.err;
  const std::string text = read_file(homed_trace);
  EXPECT_NE(text.find(" axis.0=stops=-6400..300000,start=51200,switch=home@0:below:no:hyst=64"), std::string::npos) << text;
  EXPECT_EQ(count_of(text, " load 0 "), 2u) << text;
  EXPECT_GE(count_of(text, " advance\n"), 20u) << text;
  EXPECT_NE(text.find(" fault 0 OCD on\n"), std::string::npos) << text;
  EXPECT_TRUE(replays_clean(homed_trace));
  EXPECT_TRUE(decodes_without_divergence(homed_trace));
  const std::string other = read_file(other_trace);
  EXPECT_GE(count_of(other, " frame "), 500u) << other;
  EXPECT_TRUE(replays_clean(other_trace));
  std::remove(homed_trace.c_str());
  std::remove(other_trace.c_str());
}

}  // namespace
}  // namespace l6470emu::test
