// Virtual host time (time=virtual) with real programs under the preload library: python3-spidev,
// python3-libgpiod with threads, and a C program making every kind of timed wait. Virtual
// quantities are asserted exactly; real time only with generous one-sided bounds.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

#include <gtest/gtest.h>

#include "daisychain/chain.hpp"
#include "daisychain/host.hpp"
#include "spi/trace_native.hpp"
#include "run_program.hpp"

namespace l6470emu::test {
namespace {

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> parts;
  std::istringstream in(s);
  std::string p;
  while (std::getline(in, p, sep)) parts.push_back(p);
  return parts;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Times (ns since tick 0) of the native trace's "pin 0 BUSY LEVEL" lines.
std::vector<long long> busy_times(const std::string& trace, int level) {
  std::vector<long long> times;
  std::istringstream in(trace);
  std::string line;
  const std::string tail = " pin 0 BUSY " + std::to_string(level);
  while (std::getline(in, line))
    if (line.size() > tail.size() && line.compare(line.size() - tail.size(), tail.size(), tail) == 0)
      times.push_back(std::llround(std::stod(line) * 1e9));
  return times;
}

class VirtualTime : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string why = missing_prerequisites();
    if (!why.empty()) GTEST_SKIP() << why;
  }
  // idle=off unless a test is about the idle grace: a machine stalled for a second must not
  // move time on (and make a run differ from the next).
  static Env env(const std::string& extra = "idle=off") {
    return {{"LD_PRELOAD", preload_library()},
            {"L6470EMU_CHAIN", "bus=0 cs=0 chips=L6470; time=virtual" + (extra.empty() ? "" : " " + extra)}};
  }
  static RunResult python(const std::vector<std::string>& args, Env e = env(), double* wall_s = nullptr) {
    std::vector<std::string> argv = {system_python(), script("virtual_time.py")};
    argv.insert(argv.end(), args.begin(), args.end());
    const auto t0 = std::chrono::steady_clock::now();
    RunResult r = run_program(argv, e, 60);
    if (wall_s) *wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return r;
  }
};

TEST_F(VirtualTime, PySpidevRunsOneSecondAtFullSpeedInAFractionOfASecondAndReadsThePositionTheProfileGives) {
  const std::uint32_t spd = 0x4000;  // 244 step/s, below the power-up MAX_SPEED (0x041 = 992 step/s)
  const RunResult r = python({"run-sleep", std::to_string(spd)});
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const auto f = key_values(r.out);
  EXPECT_EQ(f.at("slept_ns"), "1000000000");  // time.sleep(1), on the program's own clock
  const long long latch_ns = std::stoll(f.at("latch_ns"));
  ASSERT_EQ(latch_ns % 250, 0);
  EXPECT_EQ(latch_ns, 1'000'000'000 + 12'000) << "one more one-byte message after the sleep";
  EXPECT_LT(std::stod(f.at("real_sleep_s")), 0.5) << "the second of sleep took real time";

  // The chip's own profile from the decoded Run to the frame that latches ABS_POS: the power-up
  // ACC = 0x08A ramps to SPD, which it then keeps.
  Chain c(1);
  ChainHost h(c, 0);
  h.get_status(0);
  h.run(0, true, spd);
  c.advance_to(c.now() + static_cast<Tick>(latch_ns / 250));
  EXPECT_EQ(std::stoi(f.at("abs_pos")), c.chip(0).position());
  EXPECT_EQ(std::stoul(f.at("speed")), c.chip(0).peek(Reg::SPEED));
  EXPECT_EQ(std::stoul(f.at("speed")), spd);
  EXPECT_GT(c.chip(0).position(), 200);  // about 244 steps/s for 1 s, less the ramp
}

TEST_F(VirtualTime, AScriptThatSleepsSixtySecondsAroundMovesFinishesInWellUnderItsOwnDuration) {
  double wall_s = 0;
  const RunResult r = python({"sleep-around-moves"}, env(), &wall_s);
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const auto f = key_values(r.out);
  const long long elapsed = std::stoll(f.at("elapsed_ns"));
  EXPECT_GE(elapsed, 60'000'000'000LL);
  EXPECT_LT(elapsed, 60'010'000'000LL);  // 60 s of sleeps plus the bus time of 12 x 8 messages
  EXPECT_EQ(f.at("positions"), "1600,3200,4800,6400,8000,9600,11200,12800,14400,16000,17600,19200");
  EXPECT_LT(wall_s, 20.0);
}

TEST_F(VirtualTime, ACProgramSeesEveryKindOfTimedWaitLastExactlyTheTimeItAskedFor) {
  const RunResult r = run_program({client("virtual_waits")}, env(), 30);
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const auto f = key_values(r.out);
  const std::map<std::string, std::string> expected = {
      {"clock_nanosleep_abstime", "1250000"},
      {"clock_nanosleep_realtime_relative", "2000000"},
      {"nanosleep", "3000000"},
      {"usleep", "4000000"},
      {"sleep", "2000000000"},
      {"realtime_during_sleep", "2000000000"},
      {"gettimeofday_during_sleep_us", "2000000"},
      {"time_during_sleep_s", "2"},
      {"select", "5000000"},
      {"left", "0"},
      {"pselect", "5500000"},
      {"poll", "6000000"},
      {"ppoll", "6500000"},
      {"epoll_wait", "7000000"},
      {"pthread_cond_timedwait_realtime", "8000000"},
      {"pthread_cond_timedwait_monotonic", "8500000"},
      {"pthread_cond_clockwait", "9000000"},
      {"sem_timedwait", "10000000"},
      {"sem_clockwait", "11000000"},
      {"timerfd_oneshot", "12000000"},
      {"timerfd_poll", "6000000"},  // a 1 ms periodic timer read after 5.5 ms: next expiry at 6 ms
      {"timerfd_gettime_left", "1000000"},
      {"timerfd_epoll", "1000000"},
      {"sem_wait_for_a_post", "13000000"},
      {"cond_wait_for_a_signal", "14000000"},
      {"join_of_a_sleeper", "15000000"},
      {"cancelled", "2"},  // pthread_cancel ended a sleep and a condition wait
      {"after", "0"},
      {"nanosleep_with_sigalrm", "-1"},  // a real SIGALRM interrupts a virtual sleep with EINTR
      {"elapsed", "0"},
      {"rem", "100000000000"},
      {"failures", "0"},
  };
  for (const auto& [key, value] : expected) {
    ASSERT_TRUE(f.count(key)) << key << "\n" << r.out;
    EXPECT_EQ(f.at(key), value) << key << "\n" << r.out;
  }
  EXPECT_NE(r.out.find("timerfd_oneshot=12000000 count=1\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("timerfd_periodic_after_5.5ms count=5\n"), std::string::npos) << r.out;
}

TEST_F(VirtualTime, AThreadedLibgpiodProgramRunsTheSameTwiceAndSeesEachEdgeAtItsOwnTick) {
  std::string out[2], trace[2];
  for (int run = 0; run < 2; ++run) {
    const std::string path = temp_socket_path("virtual-threads") + ".trace";
    Env e = env();
    e.emplace_back("L6470EMU_TRACE", path);
    const RunResult r = python({"threads"}, e);
    ASSERT_EQ(r.status, 0) << r.out << r.err;
    out[run] = r.out;
    trace[run] = slurp(path);
    std::remove(path.c_str());
  }
  EXPECT_EQ(out[0], out[1]);
  ASSERT_FALSE(trace[0].empty());
  EXPECT_EQ(trace[0], trace[1]) << "the native traces differ, timestamps included";

  // Thread A's events: each read at exactly the time it is stamped with; the edges at the end of
  // the moves (found by the board between bus messages) at the ticks the trace records.
  const auto f = key_values(out[0]);
  const std::vector<std::string> events = split(f.at("events"), ',');
  ASSERT_EQ(events.size(), 6u) << out[0];
  std::vector<long long> rising;
  for (const std::string& ev : events) {
    const auto at = ev.find('@'), slash = ev.find('/'), seen = ev.rfind('@');
    const long long stamp = std::stoll(ev.substr(at + 1, slash - at - 1));
    EXPECT_EQ(stamp, std::stoll(ev.substr(seen + 1))) << ev;
    if (ev.rfind("rising", 0) == 0) rising.push_back(stamp);
  }
  std::vector<long long> trace_rising = busy_times(trace[0], 1);
  ASSERT_EQ(trace_rising.size(), 4u) << trace[0];
  EXPECT_EQ(trace_rising.front(), 0);  // the level at the start of the recording
  trace_rising.erase(trace_rising.begin());
  EXPECT_EQ(rising, trace_rising);
  EXPECT_EQ(busy_times(trace[0], 0).size(), 3u);
  // Thread B polled every 10 ms: it saw each move end at its first poll after the edge.
  const std::vector<std::string> polls = split(f.at("polls"), ',');
  std::vector<long long> done;
  for (const std::string& p : polls)
    if (p.rfind("done", 0) == 0) done.push_back(std::stoll(p.substr(p.find('@') + 1)));
  ASSERT_EQ(done.size(), 3u);
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_GT(done[k], rising[k]);
    EXPECT_LT(done[k], rising[k] + 10'100'000);
  }
  EXPECT_EQ(f.at("abs_pos"), "-1600");  // back 800, forward 1600, back 2400
}

TEST_F(VirtualTime, AThreadBlockedOutsideAnyCoveredCallHoldsTimeOnlyForTheIdleGraceWhichIsLoggedOnce) {
  double wall_s = 0;
  const RunResult r = python({"idle"}, env("idle=0.2"), &wall_s);
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const auto f = key_values(r.out);
  EXPECT_EQ(f.at("slept_ns"), "5000000000");  // the jump still lands on the sleep's own deadline
  EXPECT_EQ(f.at("reader_got"), "x");
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("may not repeat exactly"), std::string::npos) << r.err;
  EXPECT_LT(wall_s, 20.0);
}

TEST_F(VirtualTime, AForkedChildSleepsOnItsOwnCopyOfTheClock) {
  const RunResult r = python({"fork"});
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const auto f = key_values(r.out);
  EXPECT_EQ(f.at("child_slept_ns"), "10000000000");
  EXPECT_EQ(f.at("parent_elapsed_ns"), "500000000");
}

TEST_F(VirtualTime, AChildProcessGetsItsOwnClockAndLeavesTheParentsDevicesAndTraceAlone) {
  const std::string path = temp_socket_path("virtual-subprocess") + ".trace";
  Env e = env();
  e.emplace_back("L6470EMU_TRACE", path);
  const RunResult r = python({"subprocess"}, e);
  const std::string trace = slurp(path);
  std::remove(path.c_str());
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const auto f = key_values(r.out);
  EXPECT_EQ(f.at("status_before"), "0x7C03");  // power-up: HiZ, UVLO latched
  EXPECT_EQ(f.at("child_slept_ns"), "5000000000");  // the child's own virtual clock
  EXPECT_EQ(f.at("status_after"), "0x7E03");  // the same open device, after the child closed its copies
  EXPECT_EQ(f.at("elapsed_ns"), "1500072000");  // 1.5 s of sleeps and six one-byte messages
  // The child (which opened no device) did not start a trace of its own over the parent's.
  EXPECT_EQ(trace.rfind("l6470emu-trace 3\nchain L6470\nboard ", 0), 0u) << trace;
  EXPECT_NE(trace.find("\nboard time=virtual idle=off\n# " + std::string(kNativeTraceNumbering) +
                       "\n0.00000000 pin 0 BUSY 1\n"),
            std::string::npos)
      << trace;
  EXPECT_NE(trace.find("\n0.50000000 frame 2.00us D0 | 00\n"), std::string::npos) << trace;
  EXPECT_NE(trace.find("\n1.50003600 frame 2.00us D0 | 00\n"), std::string::npos) << trace;
}

TEST_F(VirtualTime, WithoutTimeVirtualTheProgramsClockAndSleepsStayReal) {
  const auto t0 = std::chrono::steady_clock::now();
  const RunResult r = run_program({system_python(), "-c",
                                   "import time\n"
                                   "t0 = time.monotonic_ns(); time.sleep(0.2); print(f'slept_ns={time.monotonic_ns() - t0}')"},
                                  {{"LD_PRELOAD", preload_library()}, {"L6470EMU_CHAIN", "bus=0 cs=0 chips=L6470"}});
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_GE(std::stoll(key_values(r.out).at("slept_ns")), 200'000'000);
  EXPECT_GE(wall_s, 0.2);
}

}  // namespace
}  // namespace l6470emu::test
