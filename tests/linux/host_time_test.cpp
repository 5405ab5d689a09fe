// Time as real host programs see it on their own clock (wall mode), in process and through
// `l6470emu serve`: py-spidev and a C driver polling a Move, a Run polled for a second, a ported
// vendor example that sleeps, and BUSY edges arriving as libgpiod events. Bounds are one-sided
// where the design guarantees them (the board never runs ahead of the host) and generous where
// the scheduler adds noise, so they cannot flake.
#include <functional>
#include <map>
#include <sstream>

#include <gtest/gtest.h>

#include "run_program.hpp"
#include "support/test_support.hpp"

namespace l6470emu::test {
namespace {

double seconds(Tick t) { return static_cast<double>(t) / static_cast<double>(kTicksPerSecond); }

/// Runs each scenario in process (param false) or through a daemon (param true).
class HostTime : public ::testing::TestWithParam<bool> {
 protected:
  void SetUp() override {
    const std::string why = missing_prerequisites();
    if (!why.empty()) GTEST_SKIP() << why;
    if (!GetParam()) return;
    daemon_ = std::make_unique<ServeDaemon>(kChain);
    ASSERT_TRUE(daemon_->ready()) << daemon_->process().out();
  }
  Env env() const {
    if (GetParam()) return daemon_->env();
    return {{"LD_PRELOAD", preload_library()}, {"L6470EMU_CHAIN", kChain}};
  }
  std::map<std::string, std::string> python(const std::vector<std::string>& args) {
    std::vector<std::string> argv = {system_python(), script("host_time.py")};
    argv.insert(argv.end(), args.begin(), args.end());
    const RunResult r = run_program(argv, env(), 60);
    EXPECT_EQ(r.status, 0) << r.out << r.err;
    return key_values(r.out);
  }

  static constexpr const char* kChain = "bus=0 cs=0 chips=L6470 log=off";
  std::unique_ptr<ServeDaemon> daemon_;
};

/// A polled Move, as the host measured it: never shorter than the profile (the board cannot run
/// ahead of the host's clock), and within 5 % plus scheduling noise of it. `measure` runs the move
/// and returns what the host printed. The lower bound holds on every run; the upper one is load's
/// to break (a stall of the host between the Move and its poll), so it must hold on one of three.
void expect_move_seen_to_last_its_profile(const std::function<std::map<std::string, std::string>()>& measure,
                                          std::uint32_t full_steps, double poll_s) {
  const double profile = seconds(move_profile_ticks(true, full_steps * 128));
  const double bound = profile * 1.05 + poll_s + 0.25;
  double seen = 0;
  for (int attempt = 0; attempt < 3; ++attempt) {
    const auto f = measure();
    ASSERT_TRUE(f.count("released")) << "no result";
    seen = std::stod(f.at("released")) - std::stod(f.at("start"));
    EXPECT_GE(seen, profile) << full_steps << " full steps";
    if (seen <= bound) return;
  }
  ADD_FAILURE() << full_steps << " full steps: seen " << seen << " s, more than " << bound << " s, three times";
}

TEST_P(HostTime, PySpidevPollingAMoveSeesBusyReleasedAfterTheProfileDuration) {
  for (std::uint32_t steps : {200u, 1000u})
    expect_move_seen_to_last_its_profile([&] { return python({"poll-move", std::to_string(steps), "5000000"}); },
                                         steps, 0.001);
}

TEST_P(HostTime, PySpidevPollingAt10kHzSeesTheSameDuration) {
  expect_move_seen_to_last_its_profile([&] { return python({"poll-move", "200", "10000"}); }, 200,
                                       3 * 8 / 10'000.0 + 0.001);  // one GetStatus at 10 kHz
}

TEST_P(HostTime, ACDriverPollingAMoveSeesBusyReleasedAfterTheProfileDuration) {
  for (const char* hz : {"10000", "5000000"}) {
    expect_move_seen_to_last_its_profile(
        [&] {
          const RunResult r = run_program({client("poll_move"), "/dev/spidev0.0", "200", hz}, env(), 60);
          EXPECT_EQ(r.status, 0) << r.out << r.err;
          return key_values(r.out);
        },
        200, 0.003);
  }
}

TEST_P(HostTime, PollingARunForOneSecondMovesTheMotorOneSecondsWorth) {
  const auto f = python({"run-poll", "100000"});
  ASSERT_TRUE(f.count("abs_pos"));
  const double elapsed = std::stod(f.at("elapsed"));
  const long pos = std::stol(f.at("abs_pos"));
  // 200 full steps/s after a 0.1 s ramp at the power-up ACC: 190 full steps in the first second.
  EXPECT_GE(pos, 189 * 128) << "the motor lags the host";
  EXPECT_LE(pos, static_cast<long>(200 * 128 * elapsed)) << "the motor ran ahead of the host's clock";
}

TEST_P(HostTime, AVendorExampleThatRunsSleepsAndReadsSpeedSeesFullSpeed) {
  auto f = python({"run-sleep"});
  EXPECT_EQ(f["speed"], "0x0346E");  // 200 step/s in 2^-28 step/tick: reached after 0.1 s of ramp
  EXPECT_GE(std::stol(f["abs_pos"]), 189 * 128);
}

TEST_P(HostTime, ABusyEdgeAfterHeavyPollingArrivesOnTimeStampedWithTheHostClock) {
  // The stamps hold on every run; the delivery's lateness is load's to break, so it must be under
  // 0.2 s on one of three runs.
  double late = 0;
  for (int attempt = 0; attempt < 3; ++attempt) {
    const auto f = python({"edge-after-poll"});
    ASSERT_NE(f.count("edge"), 0u);
    ASSERT_NE(f.at("edge"), "None") << "no rising edge within 5 s";
    const double profile = seconds(move_profile_ticks(false, 200 * 128));
    const double start = std::stod(f.at("start")) / 1e9, sent = std::stod(f.at("sent")) / 1e9;
    const double edge = std::stod(f.at("edge")) / 1e9, received = std::stod(f.at("received")) / 1e9;
    // The Move was decoded between start and sent; its edge is stamped at the host's clock then.
    EXPECT_GE(edge - start, profile - 0.001);
    EXPECT_LE(edge - sent, profile + 0.001);
    EXPECT_GE(received, edge);
    late = received - edge;
    if (late < 0.2) return;
  }
  ADD_FAILURE() << "the edge reached the host late three times, the last by " << late << " s";
}

INSTANTIATE_TEST_SUITE_P(InProcessAndThroughTheDaemon, HostTime, ::testing::Values(false, true),
                         [](const auto& info) { return info.param ? "Daemon" : "InProcess"; });

}  // namespace
}  // namespace l6470emu::test
