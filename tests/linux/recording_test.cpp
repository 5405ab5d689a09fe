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

#include "run_program.hpp"
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
  EXPECT_EQ(text.rfind("l6470emu-trace 2\nchain L6470\nboard bus=0 cs=0 path=/dev/spidev0.0 chips=L6470 ", 0), 0u) << text;
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
  for (int i = 0; i < 300 && hammer.out().find("running") == std::string::npos; ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
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

}  // namespace
}  // namespace l6470emu::test
