// A firmware program's recordings (L6470EMU_TRACE, Board::start_recording_all): a poll loop that
// becomes one run of repeated frames costs no system call per repetition, in a plain file (the
// shared mapping of spi/recording_output.hpp, as under the preload) or a .gz (flushed by size);
// and a program killed (SIGKILL, SIGTERM, SIGINT) leaves a plain trace that reads back to its last
// frame.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstring>
#include <cstdint>
#include <fstream>
#include <string>

#include "firmware/runtime.hpp"
#include "spi/trace_native.hpp"
#include "support/trace_test_support.hpp"

namespace l6470emu::test {
namespace {

constexpr int kCs = 10;

/// A runtime on two daisy-chained L6470s behind D10, polling both with GetStatus.
struct PollRig {
  static BoardConfig config() {
    ParseResult p = parse_board_config("chips=2xL6470 cs_pin=10", "test");
    EXPECT_TRUE(p.config) << p.error.message;
    return *p.config;
  }
  PollRig() : rt(config(), FirmwareFront::arduino, [](std::string_view) {}) {
    rt.set_pin_mode(kCs, McuPinMode::output);
    rt.write_pin(kCs, true);
  }
  void frame(std::uint8_t b) {
    std::array<std::uint8_t, 2> tx{b, b}, rx{};
    rt.call();
    rt.write_pin(kCs, false);
    rt.call();
    rt.transfer(0, BusSettings{}, tx, rx);
    rt.call();
    rt.write_pin(kCs, true);
  }
  /// GetStatus of both chips: three frames.
  void poll() {
    frame(0xD0);
    frame(0);
    frame(0);
  }
  FirmwareRuntime rt;
};

/// The write-like system calls (write, pwrite, writev...) this process has made so far
/// (/proc/self/io's syscw), or -1 when the kernel does not count them.
long long write_calls() {
  std::ifstream io("/proc/self/io");
  std::string key;
  long long value = 0;
  while (io >> key >> value)
    if (key == "syscw:") return value;
  return -1;
}

/// Frames in the trace at `path`, read to its end.
std::uint64_t frames_in(const std::string& path) {
  NativeTraceReader r(path, 0);
  TraceEvent e;
  std::uint64_t frames = 0;
  while (r.next(e)) frames += e.kind == TraceEventKind::frame;
  return frames;
}

TEST(FirmwareRecording, APollLoopCostsNoSystemCallPerRepetitionInAPlainFileOrAGzipOne) {
  if (write_calls() < 0) GTEST_SKIP() << "/proc/self/io counts no system calls here";
  TempDir dir;
  for (const std::string name : {"poll.trace", "poll.trace.gz"}) {
    SCOPED_TRACE(name);
    const std::string path = dir.file(name);
    PollRig rig;
    ASSERT_EQ(rig.rt.board().start_recording_all(path), "");
    for (int i = 0; i < 100; ++i) rig.poll();  // the run starts
    constexpr int kPolls = 20'000;
    const long long before = write_calls();
    for (int i = 0; i < kPolls; ++i) rig.poll();
    const long long calls = write_calls() - before;
    // Before the shared mapping, a plain file took a pwrite(2) (and an ftruncate and an lseek)
    // per repetition: 20 000 here.
    EXPECT_LE(calls, 4) << kPolls << " repetitions of a poll";
    rig.rt.finish();
    EXPECT_EQ(frames_in(path), 3u * (100 + kPolls)) << "every frame is in the file";
  }
}

/// Runs a polling child recording to `path` until it has reported `polls` polls done, then kills it
/// with `signal`; returns the polls it reported.
std::uint32_t poll_then_kill(const std::string& path, int signal, std::uint32_t polls) {
  int report[2];
  EXPECT_EQ(pipe(report), 0);
  const pid_t child = fork();
  EXPECT_GE(child, 0);
  if (child == 0) {
    // Polls, saying after each poll how many it has done, until it is killed.
    close(report[0]);
    PollRig rig;
    if (!rig.rt.board().start_recording_all(path).empty()) _exit(2);
    for (std::uint32_t done = 1; done < 2'000'000; ++done) {
      rig.poll();
      if (write(report[1], &done, sizeof done) != sizeof done) _exit(3);
    }
    _exit(4);
  }
  close(report[1]);
  std::uint32_t done = 0;
  while (done < polls && read(report[0], &done, sizeof done) == sizeof done) {
  }
  EXPECT_EQ(kill(child, signal), 0);
  int status = 0;
  EXPECT_EQ(waitpid(child, &status, 0), child);
  close(report[0]);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == signal) << "status " << status;
  return done;
}

TEST(FirmwareRecording, AProgramKilledMidRunLeavesAPlainTraceReadableToItsLastFrame) {
  TempDir dir;
  for (const int signal : {SIGKILL, SIGTERM, SIGINT}) {
    SCOPED_TRACE(strsignal(signal));
    const std::string path = dir.file("killed.trace");
    const std::uint32_t polls = poll_then_kill(path, signal, 5000);
    EXPECT_GE(polls, 5000u);
    // Every poll the child reported done is in the file (and those it did while the signal was
    // on its way), the last ones counted in its open repeat line.
    std::uint64_t frames = 0;
    ASSERT_NO_THROW(frames = frames_in(path));
    EXPECT_GE(frames, 3u * polls);
  }
}

}  // namespace
}  // namespace l6470emu::test
