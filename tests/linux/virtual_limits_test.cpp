// Where virtual time used to hang or lie, with real programs under the preload library: a program
// waiting for what can never come ends at once with the deadlock report and its exit status (C
// with pthreads, Python with threads, every covered kind of wait), and only then; the kernel's
// timespec rules and KTIME_MAX saturation at every time entry point (clocks never wrap); a host
// polling every 2·10^7 s records a trace its own reader takes.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <regex>
#include <string>
#include <vector>

#include "linux/virtual_scheduler.hpp"
#include "run_program.hpp"

namespace l6470emu::test {
namespace {

class VirtualLimits : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string why = missing_prerequisites();
    if (!why.empty()) GTEST_SKIP() << why;
  }
  static Env env(const std::string& extra = "") {
    return {{"LD_PRELOAD", preload_library()},
            {"L6470EMU_CHAIN", "bus=0 cs=0 chips=L6470; time=virtual idle=off" + extra}};
  }
};

const std::string kHeader =
    "l6470emu: virtual time: deadlock at t=0.000000 s: every thread waits and nothing can wake any of them (no "
    "timeout, timer or line edge to come); the run ends with exit status 87\n";
const std::string kBoard =
    "l6470emu:   /dev/spidev0.0: 1 chip (L6470), /dev/gpiochip0: chip 0 BUSY high (no command running), FLAG low "
    "(alarm)\n";

/// Whether `part` is in `text` with every descriptor number written "fd N" (the numbers depend
/// on what the test runner leaves open).
bool contains(const std::string& text, const std::string& part) {
  static const std::regex fd_number("fd [0-9]+");
  return std::regex_replace(text, fd_number, "fd N").find(part) != std::string::npos;
}

TEST_F(VirtualLimits, TheDeadlockStatusIsDistinctFromTheCommonOnes) {
  EXPECT_EQ(kDeadlockExitStatus, 87);
  for (int common : {0, 1, 2, 3, 4, 5, 23, 64, 66, 70, 77, 78, 86, 99, 124, 125, 126, 127})  // 86: the sanitizer's
    EXPECT_NE(kDeadlockExitStatus, common);
  EXPECT_LT(kDeadlockExitStatus, 128);  // not a signal's
}

TEST_F(VirtualLimits, ACProgramWaitingForAnEdgeAnIdleChipNeverMakesEndsWithTheReportInEveryKindOfWait) {
  const std::vector<std::pair<std::string, std::string>> modes = {
      {"read", "read() on fd N (a line request on /dev/gpiochip0), no timeout"},
      {"poll", "poll() on fd N (a line request on /dev/gpiochip0), no timeout"},
      {"ppoll", "ppoll() on fd N (a line request on /dev/gpiochip0), no timeout"},
      {"select", "select() on fd N (a line request on /dev/gpiochip0), no timeout"},
      {"epoll", "epoll_wait() on fd N (an epoll set of fd N (a line request on /dev/gpiochip0)), no timeout"},
      {"sem", "sem_wait() on the object at 0x"},
      {"sleep-forever", "nanosleep(), its timeout past the last time the clocks can show (it never ends)"},
      {"timerfd", "read() on fd N (a timerfd that is not armed), no timeout"},
  };
  for (const auto& [mode, waits_on] : modes) {
    const RunResult r = run_program({client("virtual_deadlock"), mode}, env(), 30);
    EXPECT_EQ(r.status, kDeadlockExitStatus) << mode << "\n" << r.out << r.err;
    EXPECT_EQ(r.out, "mode " + mode + "\n") << mode;
    EXPECT_EQ(r.err.rfind(kHeader, 0), 0u) << mode << "\n" << r.err;
    EXPECT_TRUE(contains(r.err, " (virtual_deadloc): " + waits_on)) << mode << "\n" << r.err;
    EXPECT_TRUE(contains(r.err, kBoard)) << r.err;
    EXPECT_TRUE(contains(r.err, "l6470emu:   gpiochip0 line 0 (BUSY): requested by \"deadlock\" as input with edge events\n"))
        << r.err;
    EXPECT_TRUE(contains(r.err, "l6470emu:   no BUSY or FLAG edge is to come on a line with edge events\n")) << r.err;
  }
}

TEST_F(VirtualLimits, AThreadedCProgramIsReportedThreadByThread) {
  RunResult r = run_program({client("virtual_deadlock"), "threads"}, env(), 30);
  EXPECT_EQ(r.status, kDeadlockExitStatus) << r.out << r.err;
  EXPECT_TRUE(contains(r.err, "(virtual_deadloc): pthread_join() of thread ")) << r.err;
  EXPECT_TRUE(contains(r.err, "(virtual_deadloc): read() on fd N (a line request on /dev/gpiochip0), no timeout"))
      << r.err;
  r = run_program({client("virtual_deadlock"), "cond"}, env(), 30);
  EXPECT_EQ(r.status, kDeadlockExitStatus) << r.out << r.err;
  EXPECT_TRUE(contains(r.err, "(virtual_deadloc): pthread_join() of thread ")) << r.err;
  EXPECT_TRUE(contains(r.err, "(virtual_deadloc): pthread_cond_wait() on the object at 0x")) << r.err;
}

TEST_F(VirtualLimits, APythonProgramWaitingForAnEdgeEndsWithTheReportAloneOrWithAThreadJoiningIt) {
  RunResult r = run_program({system_python(), script("deadlock.py"), "read"}, env(), 60);
  EXPECT_EQ(r.status, kDeadlockExitStatus) << r.out << r.err;
  EXPECT_EQ(r.out, "mode read\n");
  EXPECT_EQ(r.err.rfind(kHeader, 0), 0u) << r.err;
  EXPECT_TRUE(contains(r.err, "(python3): read() on fd N")) << r.err;
  EXPECT_TRUE(contains(r.err, " (a v1 line event request on /dev/gpiochip0), no timeout\n")) << r.err;
  EXPECT_TRUE(contains(r.err, "requested by \"waiter\" as input with edge events")) << r.err;

  r = run_program({system_python(), script("deadlock.py"), "threads"}, env(), 60);
  EXPECT_EQ(r.status, kDeadlockExitStatus) << r.out << r.err;
  EXPECT_TRUE(contains(r.err, ": read() on fd N")) << r.err;
  EXPECT_TRUE(contains(r.err, ": sem_wait() on the object at 0x")) << r.err;  // Thread.join: a lock's semaphore

  r = run_program({system_python(), script("deadlock.py"), "timeout"}, env(), 60);
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_EQ(r.out, "mode timeout\nedge within 10 s: False\ndone\n");
}

TEST_F(VirtualLimits, NothingIsDeclaredWhileSomethingOutsideTheCoveredCallsCanStillWakeAThread) {
  // An armed real timer (its signal ends the read), a pipe another process writes to, a
  // process-shared semaphore another process posts: each ends normally.
  RunResult r = run_program({client("virtual_deadlock"), "alarm"}, env(), 30);
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_EQ(r.out, "mode alarm\nread returned -1 (errno 4)\ndone\n");
  EXPECT_EQ(r.err,
            "l6470emu: virtual time: every thread waits and nothing in the process can wake them, but an alarm() or "
            "setitimer(ITIMER_REAL) timer is armed: waiting for its signal in real time\n");
  r = run_program({client("virtual_deadlock"), "pipe"}, env(), 30);
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_EQ(r.out, "mode pipe\npoll returned 1, pipe readable 1\ndone\n");
  EXPECT_EQ(r.err, "");
  r = run_program({client("virtual_deadlock"), "shared-sem"}, env(), 30);
  EXPECT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_EQ(r.out, "mode shared-sem\nsem_wait returned 0\ndone\n");
  // A thread blocked in a pipe read (outside the covered calls) holds the verdict off; once it
  // got its byte and ended, the main thread's wait on the idle line is a deadlock.
  r = run_program({client("virtual_deadlock"), "outside-thread"}, env(), 30);
  EXPECT_EQ(r.status, kDeadlockExitStatus) << r.out << r.err;
  EXPECT_EQ(r.out, "mode outside-thread\npipe reader got 1 byte 'x'\n");
  EXPECT_TRUE(contains(r.err, "(virtual_deadloc): poll() on fd N")) << r.err;
  EXPECT_FALSE(contains(r.err, "read()")) << r.err;
}

TEST_F(VirtualLimits, ADeadlockedProgramLeavesItsTraceCompleteAndItsLogFileHasTheReport) {
  const std::string trace = temp_socket_path("deadlock") + ".trace.gz";
  const std::string log = temp_socket_path("deadlock") + ".log";
  Env e = env();
  e.emplace_back("L6470EMU_TRACE", trace);
  e.emplace_back("L6470EMU_LOG", log);
  const RunResult r = run_program(
      {system_python(), "-c",
       "import gpiod, spidev\n"
       "s = spidev.SpiDev(); s.open(0, 0); s.mode = 3\n"
       "for b in (0xD0, 0, 0): s.xfer2([b])\n"
       "line = gpiod.Chip('gpiochip0').get_line(0)\n"
       "line.request(consumer='waiter', type=gpiod.LINE_REQ_EV_BOTH_EDGES)\n"
       "line.event_read()\n"},
      e, 60);
  EXPECT_EQ(r.status, kDeadlockExitStatus) << r.out << r.err;
  const std::string header = "l6470emu: virtual time: deadlock at t=0.000035 s: every thread waits";
  EXPECT_EQ(r.err.rfind(header, 0), 0u) << r.err;  // on standard error as a sanitizer's report
  FILE* f = std::fopen(log.c_str(), "r");
  ASSERT_NE(f, nullptr);
  std::string log_text;
  for (int c; (c = std::fgetc(f)) != EOF;) log_text += static_cast<char>(c);
  std::fclose(f);
  EXPECT_EQ(log_text.rfind(header, 0), 0u) << log_text;  // and in the log file
  // The gzip trace was finished: it reads to its end, every frame there.
  const RunResult replay = run_program({l6470emu_program(), "replay", trace}, {}, 30);
  EXPECT_EQ(replay.status, 0) << replay.out << replay.err;
  EXPECT_TRUE(contains(replay.out, "3 frames, 3 MISO bytes compared")) << replay.out;
  unlink(trace.c_str());
  unlink(log.c_str());
}

TEST_F(VirtualLimits, EveryTimeEntryPointRefusesOrSaturatesAsTheKernelDoesAndTheClocksNeverWrap) {
  const RunResult r = run_program({client("virtual_limits")}, env(), 30);
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const auto f = key_values(r.out);
  const std::vector<std::pair<std::string, std::string>> expected = {
      {"clock_nanosleep_abs_negative", "22"},  // EINVAL, as Linux: it used to return 0 here
      {"clock_nanosleep_rel_negative", "22"},
      {"clock_nanosleep_abs_bad_ns", "22"},
      {"nanosleep_negative", "-1/22"},
      {"nanosleep_negative_ns", "-1/22"},
      {"select_negative_usec", "-1/22"},
      {"pselect_bad_ns", "-1/22"},
      {"ppoll_negative", "-1/22"},
      {"sem_timedwait_bad_ns", "-1/22"},
      {"sem_timedwait_negative", "-1/110"},  // ETIMEDOUT: glibc takes a negative time as past
      {"timerfd_settime_negative", "-1/22"},
      {"after_refusals_ns", "0"},
      // {INT64_MAX, 999999999} never ends; a real timer's signal interrupts it, twice, and the
      // clocks did not move (they used to jump 146 years, then wrap to 0).
      {"nanosleep_forever_0", "-1/4"},
      {"nanosleep_forever_1", "-1/4"},
      {"rem_beyond_2262", "1"},
      {"after_forever_sleeps_ns", "0,0"},
      {"select_2500000us", "0/2500000000"},  // microseconds carry into seconds (it waited in real time)
      {"timerfd_forever_left_s_positive", "1"},
      {"slept_beside_forever", "1000000000"},  // threads waiting for KTIME_MAX do not pull time there
      {"sem_timedwait_forever", "0"},
      {"cond_timedwait_forever", "0"},
      {"woken_at_ns", "1000000000,1000000000"},
      {"monotonic_elapsed", "3500000000"},
      {"realtime_elapsed", "3500000000"},
      {"failures", "0"},
  };
  for (const auto& [key, value] : expected) {
    ASSERT_TRUE(f.count(key)) << key << "\n" << r.out;
    EXPECT_EQ(f.at(key), value) << key << "\n" << r.out;
  }
}

TEST_F(VirtualLimits, AHostPollingEveryTwentyMillionSecondsRecordsATraceItsOwnReaderTakes) {
  const std::string trace = temp_socket_path("slow-poll") + ".trace";
  Env e = env();
  e.emplace_back("L6470EMU_TRACE", trace);
  const RunResult r = run_program({system_python(), "-c",
                                   "import spidev, time\n"
                                   "s = spidev.SpiDev(); s.open(0, 0); s.mode = 3\n"
                                   "for i in range(6):\n"
                                   "    for b in (0xD0, 0, 0): s.xfer2([b])\n"
                                   "    time.sleep(2e7)\n"
                                   "print(time.monotonic())\n"},
                                  e, 60);
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  FILE* f = std::fopen(trace.c_str(), "r");
  ASSERT_NE(f, nullptr);
  std::string text;
  for (int c; (c = std::fgetc(f)) != EOF;) text += static_cast<char>(c);
  std::fclose(f);
  // The period: 2·10^7 s and the three messages' bus time (the old reader refused anything
  // beyond 9·10^6 s).
  // Three groups in full, then an open repeat line whose count went up as the polls came.
  EXPECT_TRUE(contains(text, " repeat 3 frames every 20000000000035.25us times ")) << text;
  const RunResult replay = run_program({l6470emu_program(), "replay", trace}, {}, 30);
  EXPECT_EQ(replay.status, 0) << replay.out << replay.err << text;
  EXPECT_TRUE(contains(replay.out, "18 frames, 18 MISO bytes compared")) << replay.out;
  unlink(trace.c_str());
}

}  // namespace
}  // namespace l6470emu::test
