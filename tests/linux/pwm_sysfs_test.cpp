// The Linux pwm sysfs class on the chips' STCK (/sys/class/pwm/pwmchipN, DeviceBoard::pwm_write):
// a C program under the preload library exports a channel, sets period and duty in nanoseconds
// and enables it; the chip steps once per pulse, counted exactly in virtual time. Bad writes get
// the kernel's errors. Against a DeviceBoard directly: the attributes' errors, a change of period
// from the next period, and an hour of 10 kHz applied in bulk.
#include <errno.h>
#include <gtest/gtest.h>
#include <linux/spi/spidev.h>
#include <unistd.h>

#include <cstdint>
#include <string>
#include <vector>

#include "linux/device_board.hpp"
#include "linux/pwm_state.hpp"
#include "run_program.hpp"
#include "support/board_config_support.hpp"

namespace l6470emu::test {
namespace {

// ---- the attributes' parsing, as drivers/pwm/sysfs.c ---------------------------------

TEST(PwmState, APeriodIsTakenInDecimalHexOrOctalWithOneNewlineAndNothingElse) {
  std::uint64_t v = 0;
  EXPECT_EQ(parse_kernel_u64("1000000\n", v), 0);
  EXPECT_EQ(v, 1000000u);
  EXPECT_EQ(parse_kernel_u64("0x10", v), 0);
  EXPECT_EQ(v, 16u);
  EXPECT_EQ(parse_kernel_u64("010", v), 0);
  EXPECT_EQ(v, 8u);
  EXPECT_EQ(parse_kernel_u64("+7", v), 0);
  EXPECT_EQ(v, 7u);
  EXPECT_EQ(parse_kernel_u64("", v), -EINVAL);
  EXPECT_EQ(parse_kernel_u64("1 ms", v), -EINVAL);
  EXPECT_EQ(parse_kernel_u64("-1", v), -EINVAL);
  EXPECT_EQ(parse_kernel_u64("1\n\n", v), -EINVAL);
  EXPECT_EQ(parse_kernel_u64("18446744073709551616", v), -ERANGE);
}

TEST(PwmState, AStateWithoutAPeriodOrWithMoreDutyThanPeriodIsRefusedAsPwmApplyRefusesIt) {
  PwmSettings s, out;
  EXPECT_EQ(pwm_settings_after(s, PwmAttr::duty_cycle, "10", out), -EINVAL);
  EXPECT_EQ(pwm_settings_after(s, PwmAttr::enable, "1", out), -EINVAL);
  ASSERT_EQ(pwm_settings_after(s, PwmAttr::period, "100", out), 0);
  s = out;
  EXPECT_EQ(pwm_settings_after(s, PwmAttr::duty_cycle, "101", out), -EINVAL);
  ASSERT_EQ(pwm_settings_after(s, PwmAttr::duty_cycle, "100", out), 0);
  s = out;
  EXPECT_EQ(pwm_settings_after(s, PwmAttr::period, "99", out), -EINVAL);
  EXPECT_EQ(pwm_settings_after(s, PwmAttr::enable, "2", out), -EINVAL);
  EXPECT_EQ(pwm_settings_after(s, PwmAttr::enable, "-1", out), -EINVAL);
  EXPECT_EQ(pwm_settings_after(s, PwmAttr::polarity, "Normal", out), -EINVAL);
  ASSERT_EQ(pwm_settings_after(s, PwmAttr::polarity, "inversed\n", out), 0);
  EXPECT_EQ(pwm_attr_text(out, PwmAttr::polarity), "inversed\n");
  EXPECT_EQ(pwm_attr_text(out, PwmAttr::period), "100\n");
}

// ---- a DeviceBoard in virtual time -------------------------------------------------------

struct Rig {
  DiagnosticLog log{"off"};
  DeviceBoard board;
  NewFile spi;

  explicit Rig(const std::string& text) : board(config_of(text), log) {
    spi = board.open(board.spidev_node(0), true);
    std::vector<std::uint8_t> mode{SPI_MODE_3};
    EXPECT_EQ(board.ioctl(spi.handle, SPI_IOC_WR_MODE, mode, nullptr), 0);
  }
  ~Rig() {
    ::close(spi.fd);
    board.closed(spi.handle);
  }
  std::uint8_t byte(std::uint8_t b) {
    std::vector<std::uint8_t> tx{b}, rx(1);
    spi_ioc_transfer t{};
    t.len = 1;
    t.tx_buf = 1;
    t.rx_buf = 1;
    EXPECT_EQ(board.spi_message(spi.handle, std::span(&t, 1), tx, rx), 1);
    return rx[0];
  }
  std::int32_t abs_pos() {
    byte(0x21);
    std::uint32_t v = static_cast<std::uint32_t>(byte(0)) << 16;
    v |= static_cast<std::uint32_t>(byte(0)) << 8;
    v |= byte(0);
    return static_cast<std::int32_t>(v << 10) >> 10;
  }
  long put(int channel, PwmAttr attr, const std::string& text) { return board.pwm_write(0, channel, attr, text); }
  void sleep_ms(std::uint64_t ms) { board.advance_to(board.time().now() + ticks_from_ms(ms)); }
};

std::int32_t wrap22(std::int64_t v) { return static_cast<std::int32_t>(static_cast<std::uint32_t>(v) << 10) >> 10; }

TEST(PwmDeviceBoard, ExportTwiceIsBusyAChannelPastNpwmIsNoDeviceAndAChannelNotExportedHasNoFiles) {
  Rig r("bus=0 cs=0 chips=L6474,L6474; time=virtual");
  std::string out;
  EXPECT_EQ(r.board.pwm_read(0, -1, PwmAttr::npwm, out), 0);
  EXPECT_EQ(out, "2\n");
  EXPECT_EQ(r.put(-1, PwmAttr::export_channel, "2"), -ENODEV);
  EXPECT_EQ(r.put(-1, PwmAttr::unexport_channel, "1"), -ENODEV);
  EXPECT_EQ(r.put(1, PwmAttr::period, "1000"), -ENOENT);
  EXPECT_EQ(r.put(-1, PwmAttr::export_channel, "1\n"), 2);
  EXPECT_EQ(r.put(-1, PwmAttr::export_channel, "1"), -EBUSY);
  EXPECT_EQ(r.board.pwm_read(0, 1, PwmAttr::period, out), 0);
  EXPECT_EQ(out, "0\n");
  EXPECT_EQ(r.board.pwm_read(0, 0, PwmAttr::period, out), -ENOENT);
  EXPECT_EQ(r.board.pwm_read(1, 0, PwmAttr::npwm, out), -ENODEV);
  EXPECT_EQ(r.put(-1, PwmAttr::unexport_channel, "1"), 1);
  EXPECT_FALSE(r.board.pwm_exported(0, 1));
}

TEST(PwmDeviceBoard, ANewPeriodWrittenWhileEnabledTakesEffectAtTheNextPeriod) {
  Rig r("bus=0 cs=0 chips=L6474; time=virtual");
  ASSERT_GT(r.put(-1, PwmAttr::export_channel, "0"), 0);
  ASSERT_GT(r.put(0, PwmAttr::period, "1000000"), 0);
  ASSERT_GT(r.put(0, PwmAttr::duty_cycle, "500000"), 0);
  ASSERT_GT(r.put(0, PwmAttr::enable, "1"), 0);  // pulses rise at 0, 1, 2 ... ms
  r.sleep_ms(2);                                  // the third rises now
  r.board.advance_to(r.board.time().now() + 1000);  // 250 µs into the third period
  ASSERT_GT(r.put(0, PwmAttr::duty_cycle, "100000"), 0);
  ASSERT_GT(r.put(0, PwmAttr::period, "200000"), 0);  // from 3 ms: every 0.2 ms
  EXPECT_EQ(r.board.pwm_rises(0, 0), 3u);
  r.board.advance_to(r.board.time().now() + 2999);  // 2.99975 ms: the fourth not yet risen
  EXPECT_EQ(r.board.pwm_rises(0, 0), 3u);
  r.board.advance_to(r.board.time().now() + 1);  // 3 ms
  EXPECT_EQ(r.board.pwm_rises(0, 0), 4u);
  r.sleep_ms(1);  // 4 ms: five more (3.2 ... 4.0 ms)
  EXPECT_EQ(r.board.pwm_rises(0, 0), 9u);
  ASSERT_GT(r.put(0, PwmAttr::enable, "0"), 0);
  r.sleep_ms(5);
  EXPECT_EQ(r.board.pwm_rises(0, 0), 9u);
}

TEST(PwmDeviceBoard, AnHourOf10kHzOnAnL6474StepsItOncePerPulseAppliedInBulkNotPulseByPulse) {
  Rig r("bus=0 cs=0 chips=L6474; time=virtual");
  r.byte(0xB8);  // Enable
  const std::int32_t before = r.abs_pos();
  ASSERT_GT(r.put(-1, PwmAttr::export_channel, "0"), 0);
  ASSERT_GT(r.put(0, PwmAttr::period, "100000"), 0);
  ASSERT_GT(r.put(0, PwmAttr::duty_cycle, "50000"), 0);
  ASSERT_GT(r.put(0, PwmAttr::enable, "1"), 0);
  r.sleep_ms(3'600'000);
  ASSERT_GT(r.put(0, PwmAttr::enable, "0"), 0);
  // One pulse at the enable and one every 100 µs after it, the one at the disable included.
  EXPECT_EQ(r.board.pwm_rises(0, 0), 36'000'001u);
  const std::int32_t after = r.abs_pos();
  EXPECT_TRUE(after == wrap22(before + 36'000'001) || after == wrap22(before - 36'000'001)) << before << " " << after;
  const Board::PulseTrainCounts counts = r.board.pulse_train_counts();
  EXPECT_GE(counts.bulk_pulses, 36'000'000u);
  EXPECT_LT(counts.single_edges, 10u);
}

TEST(PwmDeviceBoard, ADutyCycleOfZeroMakesNoStepOneOfTheWholePeriodOneAndInversedPolarityAsManyAsNormal) {
  Rig r("bus=0 cs=0 chips=L6474; time=virtual");
  r.byte(0xB8);  // Enable
  const std::int32_t start = r.abs_pos();
  ASSERT_GT(r.put(-1, PwmAttr::export_channel, "0"), 0);
  ASSERT_GT(r.put(0, PwmAttr::period, "1000000"), 0);
  ASSERT_GT(r.put(0, PwmAttr::enable, "1"), 0);  // duty 0: STCK held low
  r.sleep_ms(10);
  EXPECT_EQ(r.abs_pos(), start);
  ASSERT_GT(r.put(0, PwmAttr::duty_cycle, "1000000"), 0);  // the whole period: STCK held high
  r.sleep_ms(10);
  const std::int32_t one = r.abs_pos();
  EXPECT_EQ(std::abs(one - start), 1);
  ASSERT_GT(r.put(0, PwmAttr::enable, "0"), 0);
  ASSERT_GT(r.put(0, PwmAttr::duty_cycle, "250000"), 0);
  ASSERT_GT(r.put(0, PwmAttr::polarity, "inversed"), 0);  // high 750 µs of each millisecond
  ASSERT_GT(r.put(0, PwmAttr::enable, "1"), 0);
  r.sleep_ms(10);
  ASSERT_GT(r.put(0, PwmAttr::enable, "0"), 0);
  EXPECT_EQ(std::abs(r.abs_pos() - one), 11);  // rising at 0, 1, ..., 10 ms
}

// ---- a program under the preload library -----------------------------------------------

class PwmSysfs : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string why = missing_prerequisites();
    if (!why.empty()) GTEST_SKIP() << why;
  }
  static Env env(const std::string& chips) {
    return {{"LD_PRELOAD", preload_library()},
            {"L6470EMU_CHAIN", "bus=0 cs=0 chips=" + chips + "; time=virtual idle=off"}};
  }
};

TEST_F(PwmSysfs, AProgramStepsAnL6474TenThousandAndOneTimesWithTenSecondsOfAOneMillisecondPwm) {
  const RunResult r = run_program({client("pwm_stck"), "steps", "L6474", "1000000", "500000", "10"}, env("L6474"), 60);
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const auto f = key_values(r.out);
  EXPECT_EQ(f.at("period"), "1000000");
  EXPECT_EQ(f.at("duty_cycle"), "500000");
  EXPECT_EQ(f.at("enable"), "1");
  EXPECT_EQ(f.at("polarity"), "normal");
  EXPECT_EQ(f.at("slept_ns"), "10000000000");
  EXPECT_EQ(f.at("enable_after"), "0");
  // Rising edges at 0, 1, ..., 10000 ms after the enable: the one at the disable's instant counts.
  // DIR is low (nothing drives it): the L6474 steps in reverse.
  EXPECT_EQ(f.at("abs_pos"), "-10001") << r.out;
}

TEST_F(PwmSysfs, AProgramSleepingAnHourOf10kHzStepsAnL6474ThirtySixMillionAndOneTimes) {
  const RunResult r = run_program({client("pwm_stck"), "steps", "L6474", "100000", "50000", "3600"}, env("L6474"), 60);
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const auto f = key_values(r.out);
  EXPECT_EQ(f.at("slept_ns"), "3600000000000");
  // -36 000 001 in ABS_POS's 22 bits.
  EXPECT_EQ(std::stoi(f.at("abs_pos")), wrap22(-36'000'001)) << r.out;
}

TEST_F(PwmSysfs, AnL6470InStepClockModeMovesOneMicrostepForwardPerPulse) {
  const RunResult r = run_program({client("pwm_stck"), "steps", "L6470", "250000", "1000", "1"}, env("L6470"), 60);
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_EQ(key_values(r.out).at("abs_pos"), "4001") << r.out;
}

TEST_F(PwmSysfs, BadWritesGetTheKernelsErrors) {
  const RunResult r = run_program({client("pwm_stck"), "errors"}, env("L6474"), 60);
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const auto f = key_values(r.out);
  const std::map<std::string, std::string> expected = {
      {"npwm", "1"},
      {"stat_chip", "0"},
      {"stat_pwm0_before_export", std::to_string(ENOENT)},
      {"export_past_npwm", std::to_string(ENODEV)},
      {"export_not_a_number", std::to_string(EINVAL)},
      {"export", "0"},
      {"export_again", std::to_string(EBUSY)},
      {"stat_pwm0", "0"},
      {"list_chip", "export,npwm,pwm0,unexport"},
      {"list_pwm0", "duty_cycle,enable,period,polarity"},
      {"stat_period_mode", std::to_string(0644)},
      {"period_at_export", "0"},
      {"duty_without_period", std::to_string(EINVAL)},
      {"enable_without_period", std::to_string(EINVAL)},
      {"period", "0"},
      {"duty_over_period", std::to_string(EINVAL)},
      {"duty", "0"},
      {"duty_read", "1000"},
      {"period_zero", std::to_string(EINVAL)},
      {"period_under_duty", std::to_string(EINVAL)},
      {"period_not_a_number", std::to_string(EINVAL)},
      {"period_negative", std::to_string(EINVAL)},
      {"period_over_64_bits", std::to_string(ERANGE)},
      {"enable_two", std::to_string(EINVAL)},
      {"polarity_sideways", std::to_string(EINVAL)},
      {"polarity_inversed", "0"},
      {"polarity_read", "inversed"},
      {"enable", "0"},
      {"open_npwm_for_writing", std::to_string(EACCES)},
      {"open_export_for_reading", std::to_string(EACCES)},
      {"unexport_past_npwm", std::to_string(ENODEV)},
      {"unexport", "0"},
      {"unexport_again", std::to_string(ENODEV)},
      {"stat_pwm0_after_unexport", std::to_string(ENOENT)},
      {"period_after_unexport", std::to_string(ENOENT)},
      {"stat_pwmchip1", std::to_string(ENOENT)},
  };
  for (const auto& [k, v] : expected) EXPECT_EQ(f.count(k) ? f.at(k) : "(missing)", v) << k << "\n" << r.out;
}

TEST_F(PwmSysfs, AStreamFopenMadeWritesToTheBoardAndItsFcloseFailsWithTheKernelsError) {
  const RunResult r = run_program({client("pwm_stck"), "stdio"}, env("L6474"), 60);
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const auto f = key_values(r.out);
  EXPECT_EQ(f.at("export"), "0");
  EXPECT_EQ(f.at("period"), "0");
  EXPECT_EQ(f.at("duty_over_period"), std::to_string(EINVAL));
  EXPECT_EQ(f.at("duty"), "0");
  EXPECT_EQ(f.at("duty_read"), "1000");
}

TEST_F(PwmSysfs, AShellsEchoIntoTheFilesReachesTheBoardWhenTheRedirectionEndsAndARefusalIsSaidInTheLog) {
  const std::string script =
      "C=/sys/class/pwm/pwmchip0; echo 0 > $C/export; echo 1000000 > $C/pwm0/period; "
      "echo 500000 > $C/pwm0/duty_cycle; echo 1 > $C/pwm0/enable; "
      "read p < $C/pwm0/period; read d < $C/pwm0/duty_cycle; read e < $C/pwm0/enable; "
      "echo period=$p duty_cycle=$d enable=$e; echo 3 > $C/pwm0/enable; read e < $C/pwm0/enable; echo after=$e";
  const RunResult r = run_program({"/bin/bash", "-c", script}, env("L6474"), 60);
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const auto f = key_values(r.out);
  EXPECT_EQ(f.at("period"), "1000000");
  EXPECT_EQ(f.at("duty_cycle"), "500000");
  EXPECT_EQ(f.at("enable"), "1");
  EXPECT_EQ(f.at("after"), "1");
  EXPECT_NE(r.err.find("/sys/class/pwm/pwmchip0/pwm0/enable: a write at close refused: Invalid argument"), std::string::npos)
      << r.err;
}

TEST_F(PwmSysfs, ThroughTheDaemonAChannelOutlivesTheProgramThatSetItAndStepsTheChipOnTheWallClock) {
  ServeDaemon d("bus=0 cs=0 chips=L6470");
  ASSERT_TRUE(d.ready());
  const RunResult set = run_program(
      {"/bin/bash", "-c", "C=/sys/class/pwm/pwmchip0; echo 0 > $C/export; echo 2000000 > $C/pwm0/period"}, d.env(), 60);
  ASSERT_EQ(set.status, 0) << set.out << set.err;
  const RunResult read = run_program({"/bin/cat", "/sys/class/pwm/pwmchip0/pwm0/period"}, d.env(), 60);
  EXPECT_EQ(read.out, "2000000\n") << read.err;
  const RunResult again = run_program({"/bin/bash", "-c", "echo 0 > /sys/class/pwm/pwmchip0/export"}, d.env(), 60);
  EXPECT_NE(again.err.find("export: a write at close refused: Device or resource busy"), std::string::npos) << again.err;
  ASSERT_EQ(run_program({"/bin/bash", "-c", "echo 0 > /sys/class/pwm/pwmchip0/unexport"}, d.env(), 60).status, 0);
  const RunResult r = run_program({client("pwm_stck"), "steps", "L6470", "1000000", "500000", "1"}, d.env(), 60);
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  // On the wall clock: at least the 1001 pulses of the second slept, a few more for the time around it.
  const int steps = std::stoi(key_values(r.out).at("abs_pos"));
  EXPECT_GE(steps, 1001);
  EXPECT_LT(steps, 1500);
}

}  // namespace
}  // namespace l6470emu::test
