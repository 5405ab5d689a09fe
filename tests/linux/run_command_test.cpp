// `l6470emu run` end to end: real programs under the preload with a scenario, each way a run
// can end mapped to its own exit status (the cause read from the preload's report, not from the
// program's status), usage errors before the program starts, JUnit XML, and a recording of a
// run that replays with the scenario's actions in it.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <tuple>

#include "board/run_report.hpp"
#include "linux/virtual_scheduler.hpp"
#include "run_program.hpp"

namespace l6470emu::test {
namespace {

namespace fs = std::filesystem;

class RunCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string why = missing_prerequisites();
    if (!why.empty()) GTEST_SKIP() << why;
    dir_ = fs::temp_directory_path() / ("l6470emu-run-test-" + std::to_string(getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string file(const std::string& name, const std::string& text) {
    const std::string path = (dir_ / name).string();
    std::ofstream(path) << text;
    return path;
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  static RunResult run(std::vector<std::string> args, const std::vector<std::string>& program) {
    std::vector<std::string> argv{l6470emu_program(), "run"};
    argv.insert(argv.end(), args.begin(), args.end());
    argv.push_back("--");
    argv.insert(argv.end(), program.begin(), program.end());
    return run_program(argv, {}, 60);
  }
  // A Python driver: `body` runs with `s` an open spidev (mode 3) and status() reading GetStatus.
  std::vector<std::string> python(const std::string& body) {
    return {system_python(), file("driver.py", "import spidev, time, sys\n"
                                               "s = spidev.SpiDev(); s.open(0, 0); s.mode = 3; s.max_speed_hz = 1000000\n"
                                               "def status():\n"
                                               "    r = [s.xfer2([b])[0] for b in (0xD0, 0, 0)]\n"
                                               "    return r[1] << 8 | r[2]\n" +
                                                   body)};
  }
  fs::path dir_;
};

const char* kSwitchScenario = R"(name: switch
steps:
  - at: 100ms
    do: {sw: close}
  - at: end
    expect: {status: {SW_F: 1}}
  - at: end
    expect: {register: ABS_POS, value: 5, tolerance: 1}
)";

TEST_F(RunCommand, AFailedExpectationIsStatusOneAndSaysWhatWhenWhichChipExpectedAndSeen) {
  const RunResult r = run({"--chain", "chips=L6470", "--scenario", file("s.yaml", kSwitchScenario)},
                          python("time.sleep(0.5)\nstatus()\n"));
  EXPECT_EQ(r.status, kRunExpectationFailed) << r.err;
  EXPECT_NE(r.err.find("s.yaml:7: spidev0.0 chip 0: ABS_POS at 0.5"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(": expected 5 ± 1, seen 0\n"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("2 expectations, 1 failed; exit 1: an expectation failed"), std::string::npos) << r.err;
}

TEST_F(RunCommand, AScenarioOrBoardThatIsADeviceOrADirectoryIsOneLineAndTheProgramNeverStarts) {
  const std::string marker = path("started");
  const std::vector<std::string> program{"/bin/sh", "-c", "touch " + marker};
  RunResult r = run({"--chain", "chips=L6470", "--scenario", "/dev/zero"}, program);
  EXPECT_EQ(r.status, kRunUsage);
  EXPECT_EQ(r.err, "l6470emu: scenario /dev/zero: is a device, not a file: it could block or never end\n");
  r = run({"--chain", "chips=L6470", "--scenario", dir_.string()}, program);
  EXPECT_EQ(r.status, kRunUsage);
  EXPECT_EQ(r.err, "l6470emu: scenario " + dir_.string() + ": is a directory\n");
  r = run({"--board", "/dev/zero"}, program);
  EXPECT_EQ(r.status, kRunUsage);
  EXPECT_EQ(r.err, "l6470emu: config file /dev/zero: is a device, not a file: it could block or never end\n");
  EXPECT_FALSE(fs::exists(marker));
}

TEST_F(RunCommand, AReportThatCannotBeWrittenOrWouldOverwriteAnInputEndsTheRunBeforeTheProgramStarts) {
  const std::string scenario = file("s.yaml", kSwitchScenario);
  const std::string marker = path("started");
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases{
      {{"--junit", "/dev/full"}, "cannot write --junit '/dev/full': not a regular file"},
      {{"--junit", "/proc/version"}, "cannot write --junit '/proc/version': a read-only file"},
      {{"--junit", ""}, "cannot write --junit '': an empty path"},
      {{"--junit", path("no/such/folder/r.xml")}, "No such file or directory"},
      {{"--junit", scenario}, "an output never overwrites an input"},
      {{"--record", scenario}, "an output never overwrites an input"},
      {{"--junit", path("x"), "--record", path("x")}, "--junit and --record name the same file"},
  };
  for (const auto& [extra, said] : cases) {
    std::vector<std::string> args{"--chain", "chips=L6470", "--scenario", scenario};
    args.insert(args.end(), extra.begin(), extra.end());
    const RunResult r = run(args, {"/bin/sh", "-c", "touch " + marker});
    EXPECT_EQ(r.status, kRunUsage) << r.err;
    EXPECT_NE(r.err.find(said), std::string::npos) << said << "\n" << r.err;
    EXPECT_FALSE(fs::exists(marker)) << "the program ran";
  }
  std::ifstream in(scenario);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), kSwitchScenario) << "the scenario was overwritten";
}

TEST_F(RunCommand, StoppedBySigtermItPassesTheSignalOnAndWritesTheJUnitReportWithTheProgramStopped) {
  // sigwait() (not a covered call) blocks where virtual time cannot see: only a signal ends it.
  const std::string marker = path("paused");
  Background b({l6470emu_program(), "run", "--chain", "chips=L6470", "--junit", path("r.xml"), "--", system_python(), "-c",
                "import signal, spidev\ns = spidev.SpiDev(); s.open(0, 0); s.mode = 3\n[s.xfer2([b]) for b in (0xD0, 0, 0)]\n"
                "open('" + marker + "', 'w').close()\nsignal.sigwait([signal.SIGUSR1])\n"});
  for (int i = 0; i < 1000 && !fs::exists(marker); ++i) usleep(10'000);
  ASSERT_TRUE(fs::exists(marker)) << "the program never reached its pause";
  const RunResult r = b.stop(SIGTERM, 30);
  EXPECT_EQ(r.status, 128 + SIGTERM) << r.err;
  EXPECT_NE(r.err.find("was stopped: l6470emu run got signal 15"), std::string::npos) << r.err;
  std::ifstream in(path("r.xml"));
  std::stringstream xml;
  xml << in.rdbuf();
  EXPECT_NE(xml.str().find("<error type=\"run was stopped by a signal\""), std::string::npos) << xml.str();
}

TEST_F(RunCommand, AllExpectationsHeldIsStatusZeroAndTheJUnitReportIsWellFormed) {
  const std::string scenario = file("s.yaml", R"(steps:
  - at: 100ms
    do: {sw: close}
  - at: end
    expect: {status: {SW_F: 1}}
  - at: end
    expect: {command: GetStatus, count: 1}
  - at: end
    expect: {frames: 3}
)");
  const std::string junit = path("report.xml");
  const RunResult r = run({"--chain", "chips=L6470", "--scenario", scenario, "--junit", junit},
                          python("time.sleep(0.5)\nstatus()\n"));
  EXPECT_EQ(r.status, kRunPassed) << r.err;
  // The variables run sets for the program are known to the preload: no warning about them.
  EXPECT_EQ(r.err.find("unknown environment variable"), std::string::npos) << r.err;
  // JUnit as CI systems read it: testsuites > testsuite > testcase, counts that add up.
  const RunResult check = run_program(
      {system_python(), "-c",
       "import sys, xml.etree.ElementTree as ET\n"
       "root = ET.parse(sys.argv[1]).getroot()\n"
       "assert root.tag == 'testsuites', root.tag\n"
       "suites = root.findall('testsuite'); assert len(suites) == 1\n"
       "cases = suites[0].findall('testcase')\n"
       "assert int(suites[0].get('tests')) == len(cases) == 4, len(cases)\n"
       "assert int(suites[0].get('failures')) == 0 and int(suites[0].get('errors')) == 0\n"
       "assert all(c.get('classname') and c.get('name') for c in cases)\n"
       "float(suites[0].get('time'))\n"
       "print('ok')\n",
       junit});
  EXPECT_EQ(check.out, "ok\n") << check.err;
}

TEST_F(RunCommand, AnL6474DriverStepsItThroughItsGpiochipsStckAndDirLines) {
  // An X-NUCLEO-IHM01A1-style driver under `run --chain L6474`: configure, Enable, DIR and STCK
  // pulses through libgpiod on the chip's own lines (the DIR line after the usual five). The
  // scenario checks the position the pulses made.
  const std::string scenario = file("s.yaml", R"(steps:
  - at: end
    expect: {register: ABS_POS, value: -7}
  - at: end
    expect: {command: Enable, count: 1}
  - at: end
    expect: {status: {HiZ: 0, DIR: 0}}
)");
  const RunResult r = run({"--chain", "L6474", "--scenario", scenario},
                          python("import gpiod\n"
                                 "chip = gpiod.Chip('gpiochip0')\n"
                                 "assert chip.num_lines() == 6, chip.num_lines()\n"
                                 "stck, dirl = chip.find_line('STCK'), chip.find_line('DIR')\n"
                                 "assert dirl.offset() == 5\n"
                                 "stck.request(consumer='t', type=gpiod.LINE_REQ_DIR_OUT, default_val=0)\n"
                                 "dirl.request(consumer='t', type=gpiod.LINE_REQ_DIR_OUT, default_val=1)\n"
                                 "status()\n"
                                 "for b in (0x16, 0x8C, 0xB8): s.xfer2([b])\n"
                                 "def pulses(n):\n"
                                 "    for _ in range(n):\n"
                                 "        stck.set_value(1); time.sleep(0.0001); stck.set_value(0); time.sleep(0.0001)\n"
                                 "pulses(3)\n"
                                 "dirl.set_value(0)\n"
                                 "pulses(10)\n"
                                 "st = status()\n"
                                 "sys.exit(0 if st == 0xFE02 else 3)\n"));
  EXPECT_EQ(r.status, kRunPassed) << r.out << r.err;
}

TEST_F(RunCommand, AFailedExpectationIsAFailureElementInTheJUnitReport) {
  const std::string junit = path("report.xml");
  run({"--chain", "chips=L6470", "--scenario", file("s.yaml", kSwitchScenario), "--junit", junit},
      python("time.sleep(0.5)\nstatus()\n"));
  const RunResult check = run_program(
      {system_python(), "-c",
       "import sys, xml.etree.ElementTree as ET\n"
       "s = ET.parse(sys.argv[1]).getroot().find('testsuite')\n"
       "f = [c for c in s.findall('testcase') if c.find('failure') is not None]\n"
       "assert s.get('failures') == '1' and len(f) == 1\n"
       "print(f[0].get('name'), '|', f[0].find('failure').get('message'))\n",
       junit});
  EXPECT_EQ(check.out, path("s.yaml") + ":7: ABS_POS | expected 5 ± 1, seen 0\n") << check.err;
}

TEST_F(RunCommand, AnExpectationsJUnitTestcaseHasTheSameNameAndPlaceWhetherItHoldsOrNot) {
  const std::string scenario = file("s.yaml", kSwitchScenario);
  const std::string names =
      "import sys, xml.etree.ElementTree as ET\n"
      "s = ET.parse(sys.argv[1]).getroot().find('testsuite')\n"
      "print([(c.get('name').rsplit('/', 1)[-1], c.find('failure') is not None) for c in s.findall('testcase')[1:]])\n";
  run({"--chain", "chips=L6470", "--scenario", scenario, "--junit", path("a.xml")}, python("time.sleep(0.5)\nstatus()\n"));
  // Move forward 5 microsteps: ABS_POS holds this time.
  run({"--chain", "chips=L6470", "--scenario", scenario, "--junit", path("b.xml")},
      python("[s.xfer2([b]) for b in (0x41, 0, 0, 5)]\ntime.sleep(0.5)\nstatus()\n"));
  const RunResult a = run_program({system_python(), "-c", names, path("a.xml")});
  const RunResult b = run_program({system_python(), "-c", names, path("b.xml")});
  EXPECT_EQ(a.out, "[('s.yaml:5: STATUS', False), ('s.yaml:7: ABS_POS', True)]\n") << a.err;
  EXPECT_EQ(b.out, "[('s.yaml:5: STATUS', False), ('s.yaml:7: ABS_POS', False)]\n") << b.err;
}

TEST_F(RunCommand, TheSimulatedTimeLimitEndsTheRunWithItsOwnStatus) {
  const RunResult r = run({"--chain", "chips=L6470", "--timeout", "2s"}, python("time.sleep(3600)\n"));
  EXPECT_EQ(r.status, kRunTimedOut) << r.err;
  EXPECT_NE(r.err.find("stopped at the simulated time limit 2.000000 s at 2.000000 s of virtual time"), std::string::npos)
      << r.err;
}

TEST_F(RunCommand, AProgramThatOnlyTheTimeLimitCouldWakeIsDeadlockedNotTimedOut) {
  // A semaphore nobody posts: the limit would end the run, but nothing else ever could.
  const RunResult r = run({"--chain", "bus=0 cs=0 chips=L6470", "--timeout", "10s"}, {client("virtual_deadlock"), "sem"});
  EXPECT_EQ(r.status, kRunDeadlocked) << r.err;
  EXPECT_NE(r.err.find("deadlocked in virtual time"), std::string::npos) << r.err;
}

TEST_F(RunCommand, InWallTimeRunEnforcesTheLimitItself) {
  const RunResult r = run({"--time", "wall", "--chain", "chips=L6470", "--timeout", "200ms"}, python("time.sleep(30)\n"));
  EXPECT_EQ(r.status, kRunTimedOut) << r.err;
  EXPECT_NE(r.err.find("stopped at the simulated time limit 0.200000 s at 0.200000 s of board time"), std::string::npos)
      << r.err;
}

TEST_F(RunCommand, AProgramBlockedWhereVirtualTimeCannotSeeItIsEndedByTheWallClockGuard) {
  // (1.5 s: the program must be blocked before the guard ends it, and Python with the preload under
  // ASan on a loaded machine takes some hundred milliseconds to get there.)
  // In wall time pause() waits for a signal where nothing can see it: the guard ends it, with the
  // simulated time limit's status and its own words. (A read on its own pipe the same way: wall
  // time has no view of the waits.)
  for (const std::string& program : {std::string("import signal\nsignal.pause()\n"),
                                     std::string("import os\nr, w = os.pipe()\nos.read(r, 1)\n")}) {
    const RunResult r = run({"--time", "wall", "--chain", "chips=L6470", "--timeout", "10s", "--wall-timeout", "1500ms"},
                            python(program));
    EXPECT_EQ(r.status, kRunTimedOut) << r.err;
    EXPECT_NE(r.err.find("was stopped by the wall-clock guard after 1.500000 s of the host's time (--wall-timeout)"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(r.err.find("of virtual time"), std::string::npos) << r.err;  // when, in board time, nobody knows
    // And what the program was blocked in, as the kernel shows it.
    EXPECT_NE(r.err.find("what each thread was blocked in when the guard ended it (the kernel's view, from /proc"),
              std::string::npos)
        << r.err;
#if defined(__x86_64__)
    EXPECT_NE(r.err.find(program.find("pause") != std::string::npos ? ": pause()" : ": read() of fd "), std::string::npos)
        << r.err;
#endif
  }
}

TEST_F(RunCommand, InVirtualTimeACallTheLibraryDoesNotCoverIsEndedByTheGuardWhichSaysWhatEachThreadWasBlockedIn) {
  // sigwait() is no covered call: the thread counts as running, virtual time cannot judge it.
  const RunResult r = run({"--chain", "chips=L6470", "--timeout", "10s", "--wall-timeout", "1500ms"},
                          python("import signal\nsignal.sigwait([signal.SIGUSR1])\n"));
  EXPECT_EQ(r.status, kRunTimedOut) << r.err;
  EXPECT_NE(r.err.find("was stopped by the wall-clock guard after 1.500000 s"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("(the kernel's view, from /proc"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(" (python3) thread "), std::string::npos) << r.err;
#if defined(__x86_64__)
  EXPECT_NE(r.err.find(": rt_sigtimedwait()"), std::string::npos) << r.err;
#endif
}

TEST_F(RunCommand, InVirtualTimeAPauseOrAPollOfItsOwnPipeNothingCanEndIsADeadlockNamingTheCall) {
  for (const auto& [program, call] : std::vector<std::pair<std::string, std::string>>{
           {"import signal\nsignal.pause()\n", "pause()"},
           {"import ctypes\nctypes.CDLL(None).sigsuspend(ctypes.create_string_buffer(128))\n", "sigsuspend()"},
           // A poll on its own pipe: no other process holds it, and no thread is left to write it.
           {"import os, select\nr, w = os.pipe()\np = select.poll()\np.register(r, select.POLLIN)\np.poll()\n",
            "(a pipe no other process holds)"}}) {
    const RunResult r = run({"--chain", "chips=L6470", "--timeout", "10s", "--wall-timeout", "30"}, python(program));
    EXPECT_EQ(r.status, kRunDeadlocked) << r.err;
    EXPECT_NE(r.err.find(call), std::string::npos) << r.err;
  }
  // A timer armed to send a signal is a wake-up: the handler runs and pause() returns.
  const RunResult woke = run({"--chain", "chips=L6470", "--wall-timeout", "30"},
                             python("import signal\nsignal.signal(signal.SIGALRM, lambda *a: None)\n"
                                    "signal.setitimer(signal.ITIMER_REAL, 0.05)\nsignal.pause()\nprint('woke')\n"));
  EXPECT_EQ(woke.status, kRunPassed) << woke.err;
  EXPECT_EQ(woke.out, "woke\n") << woke.err;
}

// A C client's mode (tests/linux/clients/virtual_deadlock.c) under run, with a wall-clock guard
// far above what any of them takes: a deadlock must be found by virtual time, not by the guard.
RunResult run_client(const std::string& mode, const std::vector<std::string>& extra = {}) {
  std::vector<std::string> args{"--chain", "bus=0 cs=0 chips=L6470", "--wall-timeout", "30"};
  args.insert(args.end(), extra.begin(), extra.end());
  std::vector<std::string> argv{l6470emu_program(), "run"};
  argv.insert(argv.end(), args.begin(), args.end());
  argv.push_back("--");
  argv.push_back(client("virtual_deadlock"));
  argv.push_back(mode);
  return run_program(argv, {}, 60);
}

// How many times `part` occurs in `text`.
std::size_t occurrences(const std::string& text, const std::string& part) {
  std::size_t n = 0;
  for (std::size_t at = text.find(part); at != std::string::npos; at = text.find(part, at + part.size())) ++n;
  return n;
}

TEST_F(RunCommand, AReadOfItsOwnPipeOrSocketPairThatNoThreadOrProcessCanWriteIsADeadlockNamingTheCall) {
  for (const auto& [mode, call, times] : std::vector<std::tuple<std::string, std::string, std::size_t>>{
           {"pipe-read", "read() on fd ", 1},
           {"pipe-readv", "readv() on fd ", 1},
           {"socketpair-recv", "recv() on fd ", 1},
           {"pipe-read-threads", "read() on fd ", 2}}) {  // two readers, and the main thread joining one
    const RunResult r = run_client(mode);
    EXPECT_EQ(r.status, kRunDeadlocked) << mode << "\n" << r.err;
    EXPECT_EQ(occurrences(r.err, call), times) << mode << "\n" << r.err;
    EXPECT_NE(r.err.find(mode.starts_with("socket") ? " (a socket pair no other process holds), no timeout\n"
                                                    : " (a pipe no other process holds), no timeout\n"),
              std::string::npos)
        << r.err;
  }
  // Python's os.read the same way.
  const RunResult r = run({"--chain", "chips=L6470", "--timeout", "10s", "--wall-timeout", "30"},
                          python("import os\nr, w = os.pipe()\nos.read(r, 1)\n"));
  EXPECT_EQ(r.status, kRunDeadlocked) << r.err;
  EXPECT_NE(r.err.find("read() on fd "), std::string::npos) << r.err;
}

TEST_F(RunCommand, AReadOfItsOwnPipeOrSocketPairThatAThreadAProcessOrASignalWillEndIsNoDeadlock) {
  // Another thread writes after 100 ms of virtual time: the read waits exactly that long.
  RunResult r = run_client("pipe-read-thread", {"--timeout", "5s"});
  EXPECT_EQ(r.status, kRunPassed) << r.err;
  EXPECT_EQ(r.out, "mode pipe-read-thread\nread returned 1 (errno 0)\nat 100 ms\ndone\n") << r.err;
  r = run_client("socketpair-recv-thread", {"--timeout", "5s"});
  EXPECT_EQ(r.status, kRunPassed) << r.err;
  EXPECT_EQ(r.out, "mode socketpair-recv-thread\nrecv returned 1 (errno 0) at 100 ms\ndone\n") << r.err;
  r = run_client("socketpair-recv-child", {"--timeout", "5s"});
  EXPECT_EQ(r.status, kRunPassed) << r.err;
  EXPECT_EQ(r.out, "mode socketpair-recv-child\nrecv returned 1 (errno 0) at 0 ms\ndone\n") << r.err;
  // A child writes in real time: neither a deadlock nor a jump to the time limit meanwhile.
  r = run_client("pipe-read-child", {"--timeout", "5s"});
  EXPECT_EQ(r.status, kRunPassed) << r.err;
  EXPECT_EQ(r.out, "mode pipe-read-child\nread returned 1 (errno 0)\ndone\n") << r.err;
  // An armed alarm: its handler (no SA_RESTART) ends the read with EINTR, as the kernel's read.
  r = run_client("pipe-read-alarm", {"--timeout", "5s"});
  EXPECT_EQ(r.status, kRunPassed) << r.err;
  EXPECT_EQ(r.out, "mode pipe-read-alarm\nread returned -1 (errno 4)\ndone\n") << r.err;
}

TEST_F(RunCommand, AnAbbaMutexDeadlockIsADeadlockNamingEachThreadsLockAndItsHolder) {
  RunResult r = run_client("mutex-abba");
  EXPECT_EQ(r.status, kRunDeadlocked) << r.err;
  EXPECT_EQ(occurrences(r.err, "pthread_mutex_lock() on the mutex at 0x"), 2u) << r.err;
  EXPECT_EQ(occurrences(r.err, ", held by thread "), 2u) << r.err;
  EXPECT_NE(r.err.find("pthread_join() of thread "), std::string::npos) << r.err;
  // A plain mutex its owner locks again blocks for ever on a real kernel too.
  r = run_client("mutex-self");
  EXPECT_EQ(r.status, kRunDeadlocked) << r.err;
  EXPECT_NE(r.err.find("pthread_mutex_lock() on the mutex at 0x"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(", held by this thread itself, no timeout"), std::string::npos) << r.err;
}

TEST_F(RunCommand, AMutexThatAnotherThreadWillReleaseIsNoDeadlock) {
  // Held across a 100 ms virtual sleep: the lock is taken when the sleep ends, exactly.
  RunResult r = run_client("mutex-sleeper", {"--timeout", "5s"});
  EXPECT_EQ(r.status, kRunPassed) << r.err;
  EXPECT_EQ(r.out, "mode mutex-sleeper\nlocked at 100 ms\ndone\n") << r.err;
  // Held while the holder computes (it runs): no time passes, no verdict.
  r = run_client("mutex-worker", {"--timeout", "5s"});
  EXPECT_EQ(r.status, kRunPassed) << r.err;
  EXPECT_EQ(r.out, "mode mutex-worker\nlocked at 0 ms\ndone\n") << r.err;
  // An error-checking mutex keeps its EDEADLK.
  r = run_client("mutex-errorcheck");
  EXPECT_EQ(r.status, kRunPassed) << r.err;
  EXPECT_EQ(r.out, "mode mutex-errorcheck\nsecond lock EDEADLK\ndone\n") << r.err;
}

TEST_F(RunCommand, AWaitForADeadlockedChildEndsAsADeadlockNamingTheChildsCallAndASlowChildIsWaitedFor) {
  // The child reports its own deadlock and ends; the parent's waitpid returns it, the run is a deadlock.
  RunResult r = run_client("child-pause");
  EXPECT_EQ(r.status, kRunDeadlocked) << r.err;
  EXPECT_EQ(r.out, "mode child-pause\nchild exited 87\ndone\n") << r.err;
  EXPECT_NE(r.err.find("pause(), no timeout"), std::string::npos) << r.err;
  // A child that takes 300 ms of real time: the parent's waitpid waits for it, its clock stays
  // (no jump to the time limit meanwhile).
  r = run_client("child-slow", {"--timeout", "1s"});
  EXPECT_EQ(r.status, kRunPassed) << r.err;
  EXPECT_EQ(r.out, "mode child-slow\nchild exited 3 at 0 ms\ndone\n") << r.err;
}

TEST_F(RunCommand, AParentWaitingForAChildThatReadsAPipeOnlyTheParentCouldWriteIsADeadlockAcrossProcesses) {
  // Each process says what it waits on; run sees that only the other could end it.
  RunResult r = run_client("child-hung", {"--timeout", "5s"});
  EXPECT_EQ(r.status, kRunDeadlocked) << r.err;
  EXPECT_NE(r.err.find("deadlocked in virtual time, its processes waiting on each other"), std::string::npos) << r.err;
  EXPECT_EQ(occurrences(r.err, "\n    process "), 2u) << r.err;
  EXPECT_NE(r.err.find("): waitpid() on fd "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(" (child "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("): read() on fd "), std::string::npos) << r.err;
  // The same two processes, the parent writing after 100 ms of its own time: no deadlock.
  r = run_client("child-fed", {"--timeout", "5s"});
  EXPECT_EQ(r.status, kRunPassed) << r.err;
  EXPECT_EQ(r.out, "mode child-fed\nread returned 1 (errno 0)\nchild exited 0\ndone\n") << r.err;
  // A socket pair the same way.
  r = run_client("child-socketpair-hung", {"--timeout", "5s"});
  EXPECT_EQ(r.status, kRunDeadlocked) << r.err;
  EXPECT_NE(r.err.find("its processes waiting on each other"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("): recv() on fd "), std::string::npos) << r.err;
  r = run_client("child-socketpair-fed", {"--timeout", "5s"});
  EXPECT_EQ(r.status, kRunPassed) << r.err;
  EXPECT_EQ(r.out, "mode child-socketpair-fed\nrecv returned 1 (errno 0) at 0 ms\nchild exited 0\ndone\n") << r.err;
}

TEST_F(RunCommand, APythonParentWaitingForACatWhoseInputItNeverClosesIsADeadlockAndCommunicateIsNot) {
  // Popen.wait() with the child's stdin still open: the parent waits for cat, cat for its input.
  RunResult r = run({"--chain", "chips=L6470", "--timeout", "10s", "--wall-timeout", "30"},
                    python("import subprocess\n"
                           "subprocess.Popen(['cat'], stdin=subprocess.PIPE, stdout=subprocess.PIPE).wait()\n"));
  EXPECT_EQ(r.status, kRunDeadlocked) << r.err;
  EXPECT_NE(r.err.find("its processes waiting on each other"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(" (cat): thread "), std::string::npos) << r.err;
  // communicate() feeds it and closes its input; a child that takes real time is waited for.
  r = run({"--chain", "chips=L6470", "--timeout", "10s", "--wall-timeout", "30"},
          python("import subprocess\n"
                 "out, _ = subprocess.Popen(['cat'], stdin=subprocess.PIPE, stdout=subprocess.PIPE).communicate(b'fed')\n"
                 "print(out.decode())\n"
                 "r = subprocess.run(['sh', '-c', 'sleep 0.2; echo slow'], capture_output=True)\n"
                 "print(r.stdout.decode().strip(), r.returncode)\n"));
  EXPECT_EQ(r.status, kRunPassed) << r.err;
  EXPECT_EQ(r.out, "fed\nslow 0\n") << r.err;
}

TEST_F(RunCommand, APythonProcessJoiningAChildThatWaitsOnAMultiprocessingPipeNobodySendsOnIsADeadlock) {
  const std::string start = "import multiprocessing as mp\n"
                            "def child(conn):\n    print('child got', conn.recv(), flush=True)\n"
                            "mp.set_start_method('fork')\n"
                            "a, b = mp.Pipe()\np = mp.Process(target=child, args=(b,))\np.start()\n";
  RunResult r = run({"--chain", "chips=L6470", "--timeout", "10s", "--wall-timeout", "30"}, python(start + "p.join()\n"));
  EXPECT_EQ(r.status, kRunDeadlocked) << r.err;
  EXPECT_NE(r.err.find("its processes waiting on each other"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("): waitpid() on fd "), std::string::npos) << r.err;
  // Sent on after a second of the parent's time: the child gets it, the join returns.
  r = run({"--chain", "chips=L6470", "--timeout", "10s", "--wall-timeout", "30"},
          python(start + "time.sleep(1); a.send('hello'); p.join(); print('exit', p.exitcode)\n"));
  EXPECT_EQ(r.status, kRunPassed) << r.err;
  EXPECT_EQ(r.out, "child got hello\nexit 0\n") << r.err;
}

TEST_F(RunCommand, APythonAbbaDeadlockOfTwoLocksIsADeadlockNamingEachThreadsWait) {
  const RunResult r = run({"--chain", "chips=L6470", "--wall-timeout", "30"},
                          python("import threading\n"
                                 "a, b = threading.Lock(), threading.Lock()\n"
                                 "ea, eb = threading.Event(), threading.Event()\n"
                                 "def one():\n    with a:\n        ea.set(); eb.wait()\n        with b: pass\n"
                                 "def two():\n    with b:\n        eb.set(); ea.wait()\n        with a: pass\n"
                                 "t1 = threading.Thread(target=one); t2 = threading.Thread(target=two)\n"
                                 "t1.start(); t2.start(); t1.join()\n"));
  EXPECT_EQ(r.status, kRunDeadlocked) << r.err;
  EXPECT_EQ(occurrences(r.err, "sem_wait() on the object at 0x"), 3u) << r.err;  // (CPython's locks are semaphores)
}

TEST_F(RunCommand, AShellPipelineWhoseWriterEndsWhileItsReaderWaitsIsNoDeadlock) {
  // The writer's last close races the reader's look at who holds the pipe: end of file, never a
  // deadlock. Several times, for the race's sake.
  for (int i = 0; i < 5; ++i) {
    const RunResult r = run({"--chain", "chips=L6470", "--wall-timeout", "30"},
                            {"/bin/sh", "-c", "{ printf abc; head -c 20000 /dev/zero; printf def; } | cat | wc -c"});
    EXPECT_EQ(r.out, "20006\n") << r.err;
    EXPECT_EQ(r.err.find("deadlock"), std::string::npos) << r.err;
  }
}

TEST_F(RunCommand, TheWallClockGuardIsADurationAndLeavesAProgramThatEndsInTimeAlone) {
  const auto program = python("print(hex(status()))\n");
  RunResult r = run({"--chain", "chips=L6470", "--wall-timeout", "0"}, program);
  EXPECT_EQ(r.status, kRunUsage);
  EXPECT_EQ(r.err, "l6470emu run: --wall-timeout '0' is not a duration (30, 2.5s, 250ms, 1min)\n");
  r = run({"--chain", "chips=L6470", "--wall-timeout", "later"}, program);
  EXPECT_EQ(r.status, kRunUsage);
  r = run({"--chain", "chips=L6470", "--wall-timeout", "1000000000000"}, program);  // a century at most: no overflow
  EXPECT_EQ(r.status, kRunPassed) << r.err;
  r = run({"--chain", "chips=L6470", "--wall-timeout", "30"}, program);
  EXPECT_EQ(r.status, kRunPassed) << r.err;
  EXPECT_EQ(r.out, "0x7c03\n") << r.err;
}

TEST_F(RunCommand, ADeadlockIsItsOwnStatusAndAScenarioStepToComeIsAWakeUp) {
  // The client waits for a BUSY edge an idle chip never makes; the scenario's step at 1 s is a
  // wake-up, so the deadlock is found only after it.
  const RunResult r = run({"--chain", "bus=0 cs=0 chips=L6470", "--scenario",
                           file("s.yaml", "steps:\n  - at: 1s\n    do: {sw: close}\n")},
                          {client("virtual_deadlock"), "read"});
  EXPECT_EQ(r.status, kRunDeadlocked) << r.err;
  EXPECT_NE(r.err.find("deadlock at t=1.000000 s"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("deadlocked in virtual time at 1.000000 s"), std::string::npos) << r.err;
  // Said once: run prints the preload's report, which then stays off the program's stderr.
  EXPECT_EQ(r.err.find("deadlock at t="), r.err.rfind("deadlock at t=")) << r.err;
}

TEST_F(RunCommand, AProgramEndingWithoutAReportIsStatusSevenWithOrWithoutAScenario) {
  // os._exit skips the preload's report at exit: nothing says how the run went.
  const RunResult r = run({"--chain", "chips=L6470"}, python("import os\nstatus()\nos._exit(0)\n"));
  EXPECT_EQ(r.status, kRunNotStarted) << r.err;
  EXPECT_NE(r.err.find("(when, in virtual time, is unknown: it left no report)"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("at 0.000000 s"), std::string::npos) << r.err;
}

TEST_F(RunCommand, TheSameRunGivesTheSameHtmlPageByteForByte) {
  // Without --record the page is made from a temporary recording: its name must not reach the page.
  std::string pages[2];
  for (int i = 0; i < 2; ++i) {
    const std::string page = path("page" + std::to_string(i) + ".html");
    const RunResult r = run({"--chain", "chips=L6470", "--html", page}, python("status()\n"));
    ASSERT_EQ(r.status, 0) << r.err;
    std::ifstream in(page, std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    pages[i] = text.str();
  }
  EXPECT_FALSE(pages[0].empty());
  EXPECT_TRUE(pages[0] == pages[1]) << "two runs of one program give two different pages";
}

TEST_F(RunCommand, EndsWhatTheProgramLeftRunningSetsidGrandchildrenTooAndSaysSoInOneLine) {
  // Three grandchildren in sessions of their own (setsid: out of the program's process group),
  // holding run's standard output: one ends by itself within the grace period, one is ended by
  // SIGTERM, one ignores SIGTERM and is ended by SIGKILL. Outside the preload, so that their
  // sleeps take the host's time.
  const std::string ends = path("ends.pid"), termed = path("termed.pid"), killed = path("killed.pid");
  const std::string program = file(
      "leaves.sh", "setsid /bin/sh -c 'echo $$ > " + ends + "; exec env -u LD_PRELOAD sleep 0.05' &\n"
                   "setsid /bin/sh -c 'echo $$ > " + termed + "; exec env -u LD_PRELOAD sleep 60' &\n"
                   "setsid /bin/sh -c 'trap \"\" TERM; echo $$ > " + killed + "; exec env -u LD_PRELOAD sleep 60' &\n"
                   "while [ ! -s " + ends + " ] || [ ! -s " + termed + " ] || [ ! -s " + killed + " ]; do :; done\n");
  // Through a pipe, as a CI job reads it: the reader sees its end when run returns, not 60 s later.
  const std::string line = l6470emu_program() + " run --chain chips=L6470 -- /bin/sh " + program + " | cat";
  const auto start = std::chrono::steady_clock::now();
  const RunResult r = run_program({"/bin/sh", "-c", line}, {}, 40);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::vector<pid_t> pids;
  for (const std::string& f : {ends, termed, killed}) {
    std::ifstream in(f);
    pid_t pid = 0;
    in >> pid;
    pids.push_back(pid);
  }
  for (const pid_t pid : pids) {
    EXPECT_GT(pid, 0);
    if (pid > 0 && kill(pid, 0) == 0) {
      ADD_FAILURE() << "process " << pid << " is still running";
      kill(pid, SIGKILL);
    }
  }
  EXPECT_LT(seconds, 20.0);
  EXPECT_NE(r.status, 128 + SIGKILL) << r.err;
  const std::string said = "l6470emu run: the program left 2 processes running (";
  const std::size_t at = r.err.find(said);
  ASSERT_NE(at, std::string::npos) << r.err;
  const std::string rest = r.err.substr(at, r.err.find('\n', at) - at);
  EXPECT_NE(rest.find(std::to_string(pids[1]) + " sleep"), std::string::npos) << rest;
  EXPECT_NE(rest.find(std::to_string(pids[2]) + " sleep"), std::string::npos) << rest;
  EXPECT_NE(rest.find(") 2 s after it ended: ended them with SIGTERM, then SIGKILL"), std::string::npos) << rest;
}

TEST_F(RunCommand, TheProgramsOwnStatusEvenEightySixIsNotADeadlock) {
  for (const char* code : {"3", "86", "87"}) {
    const RunResult r = run({"--chain", "chips=L6470"}, {"/bin/sh", "-c", std::string("exit ") + code});
    EXPECT_EQ(r.status, kRunProgramFailed) << code << r.err;
    EXPECT_NE(r.err.find(std::string("exited with status ") + code), std::string::npos) << r.err;
  }
  const RunResult killed = run({"--chain", "chips=L6470"}, {"/bin/sh", "-c", "kill -9 $$"});
  EXPECT_EQ(killed.status, kRunProgramFailed) << killed.err;
  EXPECT_NE(killed.err.find("was killed by signal 9"), std::string::npos) << killed.err;
}

TEST_F(RunCommand, ASanitizerEndIsTakenFromTheReportNotFromTheStatus) {
  // The driver sanitizer (check=error) ends programs with status 86 (a deadlock with 87); its
  // report block (preload::end_run(RunEnd::sanitizer, ...)) is what tells run. Written here by
  // hand, as the sanitizer's error path writes it.
  const RunResult r = run({"--chain", "chips=L6470"},
                          {"/bin/sh", "-c",
                           "printf 'l6470emu-run-report 1\\npid 1\\nend sanitizer\\ntick 40\\ndevices 1\\nscenario 0\\n"
                           "judged 0\\ndetail CS held low across two commands\\n.\\n' >> \"$L6470EMU_RUN_REPORT\"; exit 86"});
  EXPECT_EQ(r.status, kRunSanitizerError) << r.err;
  EXPECT_NE(r.err.find("stopped by the driver sanitizer"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("  CS held low across two commands\n"), std::string::npos) << r.err;
}

TEST_F(RunCommand, AMode0DriverIsStoppedByTheSanitizerWithStatusFiveUnlessTheDescriptionSaysCheck) {
  // The most common bring-up mistake: a py-spidev driver that never sets mode 3. A run checks at
  // check=error by default; the preload's sanitizer path writes its report block, run says 5.
  const std::vector<std::string> program{
      system_python(), file("mode0.py", "import spidev\ns = spidev.SpiDev(); s.open(0, 0); s.max_speed_hz = 1000000\n"
                                        "print([s.xfer2([b])[0] for b in (0x38, 0, 0)])\n")};
  RunResult r = run({"--chain", "L6470"}, program);
  EXPECT_EQ(r.status, kRunSanitizerError) << r.err;
  EXPECT_NE(r.err.find("stopped by the driver sanitizer"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("SPI_MODE on spidev0.0, chip 0"), std::string::npos) << r.err;
  r = run({"--chain", "chips=L6470 check=warn"}, program);
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.out, "[0, 46, 8]\n") << r.err;  // CONFIG 0x2E88 read in mode 0: the stale latch's 0 for bit 7
  // At check=warn the program runs on; a scenario can still require that no rule was broken.
  const std::string clean = file("clean.yaml", "steps:\n  - at: end\n    expect: {sanitizer: clean}\n");
  r = run({"--chain", "chips=L6470 check=warn", "--scenario", clean}, program);
  EXPECT_EQ(r.status, kRunExpectationFailed) << r.err;
  EXPECT_NE(r.err.find("FAILED " + clean + ":2: the board: driver sanitizer at "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("expected no rule broken, seen 1 broken, the first spidev0.0: chip 0: SPI_MODE"),
            std::string::npos)
      << r.err;
  r = run({"--chain", "chips=L6470 check=warn", "--scenario", clean},
          python("print(hex(status()))\n"));  // mode 3, byte frames: nothing broken
  EXPECT_EQ(r.status, kRunPassed) << r.err;
}

TEST_F(RunCommand, UsageAndScenarioErrorsAreStatusTwoAndTheProgramNeverStarts) {
  const std::string marker = path("started");
  const std::vector<std::string> program{"/bin/sh", "-c", "touch " + marker};
  RunResult r = run({"--chain", "chips=L6470", "--scenario", file("bad.yaml", "steps:\n  - at: 1s\n    do: {sw: shut}\n")},
                    program);
  EXPECT_EQ(r.status, kRunUsage);
  EXPECT_EQ(r.err, "l6470emu: scenario " + path("bad.yaml") + ":3: key 'sw': 'shut' is not one of close, open\n");
  r = run({"--chain", "chips=L6470,L6470", "--scenario",
           file("chip.yaml", "steps:\n  - at: end\n    expect: {register: ABS_POS, value: 0, chip: 2}\n")},
          program);
  EXPECT_EQ(r.status, kRunUsage);
  EXPECT_NE(r.err.find("chip.yaml:2: no chip 2 on spidev0.0 (chips 0..1"), std::string::npos) << r.err;
  r = run({"--chain", "chips=L6470", "--timeout", "soon"}, program);
  EXPECT_EQ(r.status, kRunUsage);
  r = run({"--chain", "chips=L6471"}, program);
  EXPECT_EQ(r.status, kRunUsage);
  r = run({}, program);
  EXPECT_EQ(r.status, kRunUsage);
  EXPECT_FALSE(fs::exists(marker));
}

TEST_F(RunCommand, KernelNodesRunInWallTimeAndWithoutThemTheProgramNeverStarts) {
  // The kernel's nodes themselves are exercised in the VM test (tests/vm: a static Go driver);
  // here what any machine can show: the refusals, before and when the nodes cannot be made.
  const std::string marker = path("started");
  const std::vector<std::string> program{"/bin/sh", "-c", "touch " + marker};
  RunResult r = run({"--nodes", "kernel", "--time", "virtual", "--chain", "chips=L6470"}, program);
  EXPECT_EQ(r.status, kRunUsage);
  EXPECT_NE(r.err.find("--nodes kernel runs in wall time"), std::string::npos) << r.err;
  r = run({"--nodes", "kernle", "--chain", "chips=L6470"}, program);
  EXPECT_EQ(r.status, kRunUsage) << r.err;
  if (access("/dev/cuse", R_OK | W_OK) == 0 && access("/dev/uhid", R_OK | W_OK) == 0) {
    std::cout << "this machine can make CUSE and UHID nodes: the refusal without them is not shown here\n";
  } else {
    r = run({"--nodes", "kernel", "--chain", "chips=L6470"}, program);
    EXPECT_EQ(r.status, kRunNotStarted) << r.err;
    EXPECT_NE(r.err.find("the kernel's nodes could not be made"), std::string::npos) << r.err;
  }
  EXPECT_FALSE(fs::exists(marker));
}

TEST_F(RunCommand, ARecordingOfARunReplaysWithTheScenariosActionsInIt) {
  const std::string trace = path("run.trace");
  const RunResult r = run({"--chain", "chips=L6470", "--scenario", file("s.yaml", R"(steps:
  - at: 100ms
    do: {sw: close}
  - at: 200ms
    do: {fault: ocd}
  - at: end
    expect: {status: {SW_F: 1, OCD: 0}}
)"),
                           "--record", trace},
                          python("status()\ntime.sleep(0.5)\nprint(hex(status()))\n"));
  ASSERT_EQ(r.status, kRunPassed) << r.err;
  std::ifstream in(trace);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("pin 0 SW 0"), std::string::npos) << text;
  EXPECT_NE(text.find("fault 0 OCD on"), std::string::npos) << text;
  // The replay gets the same MISO only with the switch and the fault where the run had them.
  const RunResult replay = run_program({l6470emu_program(), "replay", trace});
  EXPECT_EQ(replay.status, 0) << replay.out << replay.err;
  // Without the actions the same frames diverge: the recording is what carries them.
  std::string without;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);)
    if (line.find(" SW ") == std::string::npos && line.find(" fault ") == std::string::npos) without += line + "\n";
  const RunResult diverged = run_program({l6470emu_program(), "replay", "--no-pins", file("bare.trace", without)});
  EXPECT_EQ(diverged.status, 1) << diverged.out << diverged.err;
}

TEST_F(RunCommand, AScenariosLoadChangeIsALoadEventOfTheRecording) {
  const std::string trace = path("load.trace");
  const RunResult r = run({"--chain", "chips=L6470 axis.0=switch=home@-12800", "--scenario", file("load.yaml", R"(steps:
  - at: 50ms
    do: {load: {inertia_g_mm2: 5000, friction_uNm: 200000, force_uNm: 0}}
)"),
                           "--record", trace},
                          python("status()\ntime.sleep(0.2)\nstatus()\n"));
  ASSERT_EQ(r.status, kRunPassed) << r.err;
  std::ifstream in(trace);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("0.05000000 load 0 inertia=5000 friction=200000 force=0"), std::string::npos) << text;
  const RunResult replay = run_program({l6470emu_program(), "replay", trace});
  EXPECT_EQ(replay.status, 0) << replay.out << replay.err;
}

TEST(RunReport, BlocksReadBackAndACutBlockIsSkipped) {
  RunReport a;
  a.pid = 42;
  a.end = RunEnd::timeout;
  a.tick = 8'000'000;
  a.devices = true;
  a.scenario = true;
  a.detail = {"the limit\twas reached"};
  a.outcome.judged = 2;
  a.outcome.failures.push_back(ScenarioFailure{"s.yaml:3", "ABS_POS", 7, "spidev0.0 chip 1", "0", "12"});
  a.outcome.passed = {"s.yaml:4: frames = 3"};
  a.outcome.pin_reads.push_back({"spidev0.1", 2, "FLAG", 123456});
  const std::string text = format_run_report(a) + "l6470emu-run-report 1\npid 43\nend exit\n";
  const auto blocks = parse_run_reports(text);
  ASSERT_EQ(blocks.size(), 1u);
  EXPECT_EQ(blocks[0].pid, 42);
  EXPECT_EQ(blocks[0].end, RunEnd::timeout);
  EXPECT_EQ(blocks[0].detail[0], "the limit was reached");
  ASSERT_EQ(blocks[0].outcome.failures.size(), 1u);
  EXPECT_EQ(blocks[0].outcome.failures[0].seen, "12");
  EXPECT_EQ(blocks[0].outcome.failures[0].tick, 7u);
  ASSERT_EQ(blocks[0].outcome.pin_reads.size(), 1u);
  EXPECT_EQ(blocks[0].outcome.pin_reads[0].chain, "spidev0.1");
  EXPECT_EQ(blocks[0].outcome.pin_reads[0].chip, 2u);
  EXPECT_EQ(blocks[0].outcome.pin_reads[0].pin, "FLAG");
  EXPECT_EQ(blocks[0].outcome.pin_reads[0].tick, 123456u);
}

}  // namespace
}  // namespace l6470emu::test
