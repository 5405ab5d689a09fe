// The speed-profile generator seen through SPI and the pins: positioning ends
// exactly on target in every step mode, move durations match the ideal
// trapezoid/triangle, Run speed tracking, reversal, GoTo paths, stops and
// step-clock mode (spec §5.2, §6; docs/motion-rules.md). Not switch events.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "core/chip.hpp"
#include "support/test_support.hpp"

namespace l6470emu {
namespace {

using namespace test::status_bits;

// STATUS bits of the L6470 (spec §4.1).
constexpr unsigned kStopped = 0, kAcc = 1, kDec = 2, kConst = 3;

constexpr std::int32_t k2p21 = 1 << 21;
constexpr std::uint32_t kPosMask = 0x3FFFFF;

// Register values to physical units (spec §6.1), for the ideal profile only.
double acc_in_steps_per_s2(std::uint32_t reg) { return reg * std::ldexp(1.0, -40) / (250e-9 * 250e-9); }
double max_speed_in_steps_per_s(std::uint32_t reg) { return reg * std::ldexp(1.0, -18) / 250e-9; }
double min_speed_in_steps_per_s(std::uint32_t reg) { return (reg & 0xFFF) * std::ldexp(1.0, -24) / 250e-9; }

/// Ideal duration of a positioning move: ramp from `vmin` with `acc`, cruise at
/// `vmax` if reached, ramp down with `dec` to `vmin` exactly at the target.
double ideal_move_seconds(double steps, double acc, double dec, double vmin, double vmax) {
  if (vmin > vmax) vmin = vmax;
  const double vp = std::sqrt(vmin * vmin + 2.0 * steps * acc * dec / (acc + dec));
  if (vp <= vmax) return (vp - vmin) / acc + (vp - vmin) / dec;
  const double d_acc = (vmax * vmax - vmin * vmin) / (2.0 * acc);
  const double d_dec = (vmax * vmax - vmin * vmin) / (2.0 * dec);
  return (vmax - vmin) / acc + (vmax - vmin) / dec + (steps - d_acc - d_dec) / vmax;
}

struct Rig : test::OneChip {
  ChainHost& h() { return host; }
  std::uint16_t status() { return static_cast<std::uint16_t>(host.get_param(0, Reg::STATUS)); }
  std::int32_t abs_pos() { return sign_extend(host.get_param(0, Reg::ABS_POS), 22); }
  std::uint32_t abs_pos_raw() { return host.get_param(0, Reg::ABS_POS); }
  std::uint32_t el_pos() { return host.get_param(0, Reg::EL_POS); }
  std::uint32_t speed() { return host.get_param(0, Reg::SPEED); }
  bool busy() { return !chip().busy_sync_pin(); }
  void profile(std::uint32_t acc, std::uint32_t dec, std::uint32_t max_speed, std::uint32_t min_speed = 0) {
    host.set_param(0, Reg::ACC, acc);
    host.set_param(0, Reg::DEC, dec);
    host.set_param(0, Reg::MAX_SPEED, max_speed);
    host.set_param(0, Reg::MIN_SPEED, min_speed);
  }
  void wait_s(double s) { host.wait(static_cast<Tick>(s * kTicksPerSecond)); }
  /// Lets time pass until BUSY is released (checked every `chunk` ticks); returns the tick.
  Tick wait_until_idle(double limit_s = 4.0, Tick chunk = 64) {
    const Tick limit = chain.now() + static_cast<Tick>(limit_s * kTicksPerSecond);
    while (busy() && chain.now() < limit) chain.advance_to(chain.now() + chunk);
    return chain.now();
  }
};

/// The first tick at which BUSY is released, found on copies of the chip (the rig is untouched).
Tick busy_release_tick(const Chip& chip, Tick limit) {
  Chip c = chip;
  constexpr Tick kChunk = 1024;
  while (!c.busy_sync_pin() == true && c.now() < limit) {
    Chip before = c;
    c.advance_to(c.now() + kChunk);
    if (c.busy_sync_pin()) {
      c = before;
      while (!c.busy_sync_pin()) c.advance_to(c.now() + 1);
      return c.now();
    }
  }
  return c.now();
}

// ---- positioning ends exactly on target ----------------------------------------

TEST(MotionProfile, MoveEndsExactlyOnTargetInEveryStepMode) {
  for (std::uint32_t sel = 0; sel <= 7; ++sel) {
    SCOPED_TRACE("STEP_SEL " + std::to_string(sel));
    Rig r;
    r.h().set_param(0, Reg::STEP_MODE, sel);
    r.profile(0x400, 0x400, 0x100);
    const std::uint32_t n = (100u << sel) + ((1u << sel) - 1u);  // 100 full steps and all but one microstep
    const std::uint32_t inc = 128u >> sel;
    r.h().move(0, true, n);
    EXPECT_TRUE(r.busy());
    r.wait_until_idle();
    EXPECT_EQ(r.abs_pos(), static_cast<std::int32_t>(n));
    EXPECT_EQ(r.el_pos(), (n * inc) & 0x1FF);
    EXPECT_EQ(r.speed(), 0u);
    const auto s = r.status();
    EXPECT_EQ(mot(s), kStopped);
    EXPECT_TRUE(s & kBusyN);
    EXPECT_TRUE(s & kDir);
    EXPECT_FALSE(s & kHiZ);

    r.h().move(0, false, 2 * n);
    r.wait_until_idle();
    EXPECT_EQ(r.abs_pos(), -static_cast<std::int32_t>(n));
    EXPECT_EQ(r.abs_pos_raw(), (0x400000u - n) & kPosMask);
    EXPECT_EQ(r.el_pos(), (512u - (n * inc) % 512u) % 512u);
    EXPECT_FALSE(r.status() & kDir);
  }
}

TEST(MotionProfile, GoToEndsExactlyOnTargetInEveryStepMode) {
  for (std::uint32_t sel = 0; sel <= 7; ++sel) {
    SCOPED_TRACE("STEP_SEL " + std::to_string(sel));
    Rig r;
    r.h().set_param(0, Reg::STEP_MODE, sel);
    r.profile(0x400, 0x400, 0x100);
    const std::int32_t targets[] = {static_cast<std::int32_t>(37u << sel) + 1, -static_cast<std::int32_t>(53u << sel) - 3, 0};
    for (std::int32_t target : targets) {
      r.h().go_to(0, target);
      r.wait_until_idle();
      EXPECT_EQ(r.abs_pos(), target);
      EXPECT_EQ(r.el_pos(), static_cast<std::uint32_t>(target * static_cast<std::int32_t>(128u >> sel)) & 0x1FFu);
      EXPECT_EQ(r.speed(), 0u);
      EXPECT_EQ(mot(r.status()), kStopped);
    }
  }
}

TEST(MotionProfile, SpeedsArePerFullStepWhateverTheStepMode) {
  // Infinite acceleration at MAX_SPEED 0x100 = 2^30 * 2^-40 step/tick: 200 full steps take
  // 200 * 2^40 / 2^30 = 204800 ticks in every step mode.
  for (std::uint32_t sel = 0; sel <= 7; ++sel) {
    SCOPED_TRACE("STEP_SEL " + std::to_string(sel));
    Rig r;
    r.h().set_param(0, Reg::STEP_MODE, sel);
    r.profile(0xFFF, 0x08A, 0x100);
    r.h().move(0, true, 200u << sel);
    const Tick t0 = r.chain.now();
    const Tick release = busy_release_tick(r.chip(), t0 + kTicksPerSecond);
    EXPECT_NEAR(static_cast<double>(release - t0), 204800.0, 1.0);
  }
}

// ---- durations against the ideal profile -----------------------------------------

struct ProfileCase {
  const char* name;
  std::uint32_t acc, dec, max_speed, min_speed;  // register values (MIN_SPEED may carry LSPD_OPT)
  std::uint32_t step_sel;
  std::uint32_t full_steps;
};

class MoveDuration : public ::testing::TestWithParam<ProfileCase> {};

TEST_P(MoveDuration, MatchesTheIdealProfileWithinOnePerMille) {
  const ProfileCase& pc = GetParam();
  Rig r;
  r.h().set_param(0, Reg::STEP_MODE, pc.step_sel);
  r.profile(pc.acc, pc.dec, pc.max_speed, pc.min_speed);
  const std::uint32_t n = pc.full_steps << pc.step_sel;
  r.h().move(0, true, n);
  const Tick t0 = r.chain.now();
  const Tick release = busy_release_tick(r.chip(), t0 + 4 * kTicksPerSecond);
  const double measured_s = static_cast<double>(release - t0) / kTicksPerSecond;

  const bool lspd_opt = (pc.min_speed & 0x1000) != 0;
  const double ideal_s = ideal_move_seconds(pc.full_steps, acc_in_steps_per_s2(pc.acc), acc_in_steps_per_s2(pc.dec),
                                            lspd_opt ? 0.0 : min_speed_in_steps_per_s(pc.min_speed),
                                            max_speed_in_steps_per_s(pc.max_speed));
  ASSERT_LT(ideal_s, 3.0) << "keep the case short";
  EXPECT_NEAR(measured_s, ideal_s, ideal_s * 1e-3) << pc.name;

  r.chain.advance_to(release);
  EXPECT_EQ(r.abs_pos(), static_cast<std::int32_t>(n));
  EXPECT_EQ(r.speed(), 0u);
}

INSTANTIATE_TEST_SUITE_P(
    MotionProfile, MoveDuration,
    ::testing::Values(
        // reset ACC/DEC/MAX_SPEED: 0.49 s ramps, 0.51 s cruise
        ProfileCase{"TrapezoidAtResetValues", 0x08A, 0x08A, 0x041, 0x000, 7, 1000},
        // peaks at 863 step/s, far below MAX_SPEED
        ProfileCase{"TriangleNeverReachingMaxSpeed", 0x040, 0x040, 0x3FF, 0x000, 7, 800},
        ProfileCase{"AsymmetricTrapezoid", 0x200, 0x080, 0x060, 0x000, 4, 1500},
        ProfileCase{"AsymmetricTriangle", 0x040, 0x180, 0x3FF, 0x000, 2, 400},
        // MIN_SPEED 839 = 200 step/s: ramps start and end there
        ProfileCase{"TrapezoidWithNonZeroMinSpeed", 0x08A, 0x08A, 0x041, 839, 3, 1200},
        ProfileCase{"TriangleWithNonZeroMinSpeed", 0x100, 0x0C0, 0x3FF, 839, 5, 1500},
        // LSPD_OPT: the profile's minimum speed is 0 whatever MIN_SPEED says
        ProfileCase{"LspdOptRampsFromZero", 0x08A, 0x08A, 0x041, 0x1000 | 839, 7, 1000},
        ProfileCase{"FullStepModeTrapezoid", 0x100, 0x100, 0x020, 0x000, 0, 1000},
        // MIN_SPEED above MAX_SPEED: the floor is capped at MAX_SPEED, so the move is flat
        ProfileCase{"MinSpeedAboveMaxSpeedRunsFlatAtMaxSpeed", 0x08A, 0x08A, 0x020, 0xFFF, 7, 500}),
    [](const ::testing::TestParamInfo<ProfileCase>& info) { return std::string(info.param.name); });

TEST(MotionProfile, InfiniteAccelerationSkipsBothRampsAndIgnoresDec) {
  Rig r;
  r.profile(0xFFF, 0x001, 0x041);  // DEC = 1 would take minutes to stop: it must be ignored
  r.h().move(0, true, 1000u << 7);
  const Tick t0 = r.chain.now();
  // At once at MAX_SPEED: SPEED = MAX_SPEED << 10, MOT_STATUS constant speed.
  EXPECT_EQ(r.speed(), 0x041u << 10);
  EXPECT_EQ(mot(r.status()), kConst);
  const Tick release = busy_release_tick(r.chip(), t0 + 2 * kTicksPerSecond);
  // 1000 full steps at 0x041 * 2^-18 step/tick.
  const double ideal_ticks = 1000.0 * std::ldexp(1.0, 18) / 0x041;
  EXPECT_NEAR(static_cast<double>(release - t0), ideal_ticks, 2.0);
  r.chain.advance_to(release);
  EXPECT_EQ(r.abs_pos(), 1000 << 7);
  EXPECT_EQ(r.speed(), 0u);
}

TEST(MotionProfile, MoveReportsAccelerationConstantSpeedAndDecelerationInTurn) {
  Rig r;  // reset profile: 0.49 s ramps, 1.50 s in all for 1000 full steps
  r.h().move(0, true, 1000u << 7);
  r.wait_s(0.2);
  EXPECT_EQ(mot(r.status()), kAcc);
  EXPECT_TRUE(r.busy());
  r.wait_s(0.55);  // 0.75 s
  EXPECT_EQ(mot(r.status()), kConst);
  EXPECT_EQ(r.speed(), 0x041u << 10);
  EXPECT_TRUE(r.busy());
  r.wait_s(0.55);  // 1.30 s
  EXPECT_EQ(mot(r.status()), kDec);
  EXPECT_TRUE(r.busy());
  r.wait_s(0.3);  // 1.60 s
  EXPECT_EQ(mot(r.status()), kStopped);
  EXPECT_FALSE(r.busy());
  EXPECT_EQ(r.abs_pos(), 1000 << 7);
}

TEST(MotionProfile, MoveWithZeroStepsFinishesAtOnce) {
  Rig r;
  r.h().move(0, true, 0);
  r.h().wait(16);
  EXPECT_FALSE(r.busy());
  EXPECT_EQ(r.abs_pos(), 0);
  EXPECT_FALSE(r.status() & kNotPerf);
}

TEST(MotionProfile, LoweringMaxSpeedDuringAMoveSlowsDownAndStillEndsOnTarget) {
  Rig r;
  r.profile(0x200, 0x200, 0x041);  // 7450 step/s²: 0.13 s to reach 991.8 step/s
  r.h().move(0, true, 1500u << 7);
  r.wait_s(0.3);
  EXPECT_EQ(r.speed(), 0x041u << 10);
  r.h().set_param(0, Reg::MAX_SPEED, 0x020);  // WR: accepted while moving
  EXPECT_FALSE(r.status() & kNotPerf);
  r.h().wait(4000);  // 1 ms into the slowdown
  EXPECT_EQ(mot(r.status()), kDec);
  EXPECT_LT(r.speed(), 0x041u << 10);
  EXPECT_GT(r.speed(), 0x020u << 10);
  EXPECT_TRUE(r.busy());
  r.wait_s(0.2);
  EXPECT_EQ(r.speed(), 0x020u << 10);
  EXPECT_EQ(mot(r.status()), kConst);
  // Remaining distance at 488 step/s: well over a second more; it ends exactly on target.
  r.wait_until_idle(4.0);
  EXPECT_EQ(r.abs_pos(), 1500 << 7);
  EXPECT_EQ(r.speed(), 0u);
}

// ---- Run ------------------------------------------------------------------------

TEST(MotionProfile, RunRampsToItsTargetSpeedAndThenReleasesBusy) {
  Rig r;  // ACC 0x08A, MIN_SPEED 0
  const std::uint32_t spd = test::spd_from_steps_per_s(500);
  r.h().run(0, true, spd);
  const Tick t0 = r.chain.now();
  auto s = r.status();
  EXPECT_FALSE(s & kBusyN);
  EXPECT_EQ(mot(s), kAcc);
  EXPECT_TRUE(s & kDir);
  EXPECT_FALSE(s & kHiZ);
  // Ramp from 0 by ACC per tick to SPD << 12 (2^-40 step/tick).
  const Tick ramp = (static_cast<Tick>(spd) * 4096 + 0x08A - 1) / 0x08A;
  Chip probe = r.chip();
  probe.advance_to(t0 + ramp - 2);
  EXPECT_FALSE(probe.busy_sync_pin());
  probe.advance_to(t0 + ramp + 1);
  EXPECT_TRUE(probe.busy_sync_pin());
  r.chain.advance_to(t0 + ramp + 1000);
  EXPECT_EQ(r.speed(), spd);
  s = r.status();
  EXPECT_TRUE(s & kBusyN);
  EXPECT_EQ(mot(s), kConst);
}

TEST(MotionProfile, SpeedRegisterReadsTheSpeedWhileRamping) {
  Rig r;
  r.h().run(0, true, test::spd_from_steps_per_s(900));
  const Tick t0 = r.chain.now();
  r.wait_s(0.1);
  // GetParam latches at the opcode's decode, one frame (8 ticks) after now().
  const Tick latch = r.chain.now() + 8;
  const double expected = static_cast<double>((latch - t0) * 0x08A) / 4096.0;
  EXPECT_NEAR(static_cast<double>(r.speed()), expected, 1.0 + 2.0 * 0x08A / 4096.0);
  EXPECT_NEAR(test::steps_per_s_from_speed(r.speed()), 0.1 * acc_in_steps_per_s2(0x08A), 2.0);
}

TEST(MotionProfile, RunAboveMaxSpeedIsExecutedAtMaxSpeed) {
  Rig r;
  r.profile(0x400, 0x400, 0x041);
  r.h().run(0, false, test::spd_from_steps_per_s(3000));
  r.wait_s(0.2);
  EXPECT_EQ(r.speed(), 0x041u << 10);
  EXPECT_FALSE(r.busy());
  EXPECT_EQ(mot(r.status()), kConst);
  EXPECT_FALSE(r.status() & kDir);
}

TEST(MotionProfile, RunBelowMinSpeedIsExecutedAtMinSpeed) {
  Rig r;
  const std::uint32_t min = test::min_speed_from_steps_per_s(100);
  r.profile(0x400, 0x400, 0x041, min);
  r.h().run(0, true, test::spd_from_steps_per_s(20));
  r.wait_s(0.01);
  EXPECT_EQ(r.speed(), min << 4);  // MIN_SPEED is 2^-24, SPEED 2^-28 step/tick
  EXPECT_FALSE(r.busy());
  EXPECT_EQ(mot(r.status()), kConst);
}

TEST(MotionProfile, RunWithLspdOptMayGoBelowMinSpeed) {
  Rig r;
  const std::uint32_t min = test::min_speed_from_steps_per_s(100);
  r.profile(0x400, 0x400, 0x041, 0x1000 | min);
  const std::uint32_t spd = test::spd_from_steps_per_s(20);
  r.h().run(0, true, spd);
  r.wait_s(0.01);
  EXPECT_EQ(r.speed(), spd);
  EXPECT_FALSE(r.busy());
}

TEST(MotionProfile, RunStartsFromMinSpeed) {
  Rig r;
  const std::uint32_t min = test::min_speed_from_steps_per_s(300);
  r.profile(0x08A, 0x08A, 0x041, min);
  r.h().run(0, true, test::spd_from_steps_per_s(900));
  const Tick t0 = r.chain.now();
  r.h().wait(4000);  // 1 ms
  const Tick latch = r.chain.now() + 8;
  const double expected = (static_cast<double>(min) * 65536.0 + static_cast<double>(latch - t0) * 0x08A) / 4096.0;
  EXPECT_NEAR(static_cast<double>(r.speed()), expected, 2.0);
}

TEST(MotionProfile, RunReportsDecelerationWhenSlowingToALowerTarget) {
  Rig r;
  r.h().run(0, true, test::spd_from_steps_per_s(800));
  r.wait_s(0.5);
  EXPECT_EQ(mot(r.status()), kConst);
  r.h().run(0, true, test::spd_from_steps_per_s(300));
  auto s = r.status();
  EXPECT_EQ(mot(s), kDec);
  EXPECT_FALSE(s & kBusyN);
  EXPECT_TRUE(s & kDir);
  r.wait_s(0.3);  // 500 step/s at 2008 step/s² = 0.25 s
  s = r.status();
  EXPECT_EQ(mot(s), kConst);
  EXPECT_TRUE(s & kBusyN);
  EXPECT_EQ(r.speed(), test::spd_from_steps_per_s(300));
}

TEST(MotionProfile, RunWithSpeedZeroAndNoMinSpeedStopsTheMotor) {
  Rig r;
  r.h().run(0, true, test::spd_from_steps_per_s(400));
  r.wait_s(0.3);
  r.h().run(0, true, 0);
  r.wait_s(0.3);  // 400 step/s at 2008 step/s²: 0.2 s
  EXPECT_EQ(r.speed(), 0u);
  const auto p = r.abs_pos();
  r.wait_s(0.05);
  EXPECT_EQ(r.abs_pos(), p);
  EXPECT_FALSE(r.busy());
}

TEST(MotionProfile, RunReversalDeceleratesToMinSpeedThenTurns) {
  Rig r;
  const std::uint32_t min = test::min_speed_from_steps_per_s(50);
  r.profile(0x08A, 0x08A, 0x041, min);
  const std::uint32_t spd = test::spd_from_steps_per_s(600);
  r.h().run(0, true, spd);
  r.wait_s(0.4);
  ASSERT_EQ(r.speed(), spd);
  const std::int32_t p0 = r.abs_pos();
  r.h().run(0, false, spd);
  const Tick t0 = r.chain.now();
  auto s = r.status();
  EXPECT_TRUE(s & kDir) << "still going forward while slowing down";
  EXPECT_EQ(mot(s), kDec);
  EXPECT_FALSE(s & kBusyN);

  // Watch the turn: DIR flips once the speed is down to MIN_SPEED.
  std::int32_t turn_pos = 0;
  Tick turn_tick = 0;
  std::int32_t last = p0;
  for (int i = 0; i < 20000; ++i) {
    r.chain.advance_to(r.chain.now() + 256);
    const std::int32_t p = r.chip().position();
    if (!(r.chip().status() & kDir)) {
      turn_tick = r.chain.now();
      turn_pos = last > p ? last : p;
      break;
    }
    EXPECT_GE(p, last);
    last = p;
  }
  ASSERT_NE(turn_tick, 0u) << "never turned";
  const double acc = acc_in_steps_per_s2(0x08A);
  const double v = test::steps_per_s_from_speed(spd), f = min_speed_in_steps_per_s(min);
  const double ideal_s = (v - f) / acc;
  const double ideal_steps = (v * v - f * f) / (2 * acc);
  EXPECT_NEAR(static_cast<double>(turn_tick - t0) / kTicksPerSecond, ideal_s, ideal_s * 0.01);
  EXPECT_NEAR((turn_pos - p0) / 128.0, ideal_steps, ideal_steps * 0.01);

  r.wait_s(0.4);
  s = r.status();
  EXPECT_FALSE(s & kDir);
  EXPECT_EQ(mot(s), kConst);
  EXPECT_TRUE(s & kBusyN);
  EXPECT_EQ(r.speed(), spd);
  EXPECT_LT(r.abs_pos(), turn_pos);
}

TEST(MotionProfile, LoweringMaxSpeedDuringRunPullsBusyLowUntilTheNewLimitIsReached) {
  Rig r;
  r.h().run(0, true, test::spd_from_steps_per_s(900));
  r.wait_s(0.6);
  ASSERT_FALSE(r.busy());
  r.h().set_param(0, Reg::MAX_SPEED, 0x020);
  r.h().wait(400);
  EXPECT_TRUE(r.busy());
  EXPECT_EQ(mot(r.status()), kDec);
  r.wait_s(0.3);  // 900 -> 488 step/s at 2008 step/s²: 0.21 s
  EXPECT_FALSE(r.busy());
  EXPECT_EQ(r.speed(), 0x020u << 10);
  EXPECT_EQ(mot(r.status()), kConst);
}

TEST(MotionProfile, RaisingMaxSpeedAgainLetsARunReachItsOwnSpeed) {
  Rig r;
  const std::uint32_t spd = test::spd_from_steps_per_s(900);
  r.h().run(0, true, spd);
  r.wait_s(0.6);
  r.h().set_param(0, Reg::MAX_SPEED, 0x020);
  r.wait_s(0.3);
  ASSERT_EQ(r.speed(), 0x020u << 10);
  r.h().set_param(0, Reg::MAX_SPEED, 0x041);
  r.h().wait(400);
  EXPECT_TRUE(r.busy());
  EXPECT_EQ(mot(r.status()), kAcc);
  r.wait_s(0.3);
  EXPECT_EQ(r.speed(), spd) << "the Run target is SPD, clamped afresh";
  EXPECT_FALSE(r.busy());
}

TEST(MotionProfile, AbsPosWrapsAround22BitsWhileRunningForward) {
  Rig r;
  r.h().set_param(0, Reg::ABS_POS, k2p21 - 300);
  r.profile(0xFFF, 0xFFF, 0x3FF);
  r.h().run(0, true, test::spd_from_steps_per_s(10000));  // 1.28 M microsteps/s
  std::uint32_t last = r.chip().peek(Reg::ABS_POS);
  bool wrapped = false;
  for (int i = 0; i < 400; ++i) {
    r.chain.advance_to(r.chain.now() + 16);
    const std::uint32_t now = r.chip().peek(Reg::ABS_POS);
    EXPECT_LT((now - last) & kPosMask, 16u) << "ABS_POS must advance by a few microsteps, modulo 2^22";
    if (last >= 0x1FFF00 && last <= 0x1FFFFF && now >= 0x200000) wrapped = true;
    last = now;
  }
  EXPECT_TRUE(wrapped);
  EXPECT_LT(r.abs_pos(), -k2p21 + 2000);
  EXPECT_EQ(r.chip().position(), sign_extend(r.chip().peek(Reg::ABS_POS), 22));
}

TEST(MotionProfile, AbsPosWrapsAround22BitsWhileRunningInReverse) {
  Rig r;
  r.h().set_param(0, Reg::ABS_POS, static_cast<std::uint32_t>(-k2p21 + 200) & kPosMask);
  r.profile(0xFFF, 0xFFF, 0x3FF);
  r.h().run(0, false, test::spd_from_steps_per_s(10000));
  r.wait_s(0.001);  // about 1280 microsteps
  const std::int32_t p = r.abs_pos();
  EXPECT_GT(p, k2p21 - 1500);
  EXPECT_LE(p, k2p21 - 1);
}

// ---- GoTo family ------------------------------------------------------------------

TEST(MotionProfile, GoToTakesTheShortPathAcrossThe22BitWrap) {
  Rig r;
  r.profile(0x400, 0x400, 0x100);
  r.h().set_param(0, Reg::ABS_POS, k2p21 - 100);
  r.h().go_to(0, -k2p21 + 100);  // 200 microsteps forward through the wrap
  EXPECT_TRUE(r.status() & kDir);
  r.wait_until_idle(0.5);
  EXPECT_EQ(r.abs_pos(), -k2p21 + 100);
  EXPECT_EQ(r.abs_pos_raw(), 0x200064u);
  EXPECT_EQ(r.el_pos(), 200u % 512u);

  r.h().go_to(0, k2p21 - 100);  // and back: 200 microsteps in reverse
  EXPECT_FALSE(r.status() & kDir);
  r.wait_until_idle(0.5);
  EXPECT_EQ(r.abs_pos(), k2p21 - 100);
  EXPECT_EQ(r.el_pos(), 0u);
}

struct PathCase {
  const char* name;
  std::int32_t from, to;
  bool forward;
};

class GoToPath : public ::testing::TestWithParam<PathCase> {};

TEST_P(GoToPath, GoesTheShorterWayRound) {
  const PathCase& pc = GetParam();
  Rig r;
  r.profile(0xFFF, 0xFFF, 0x3FF);
  r.h().set_param(0, Reg::ABS_POS, static_cast<std::uint32_t>(pc.from) & kPosMask);
  r.h().go_to(0, pc.to);
  EXPECT_EQ((r.status() & kDir) != 0, pc.forward);
  r.wait_s(0.001);
  const std::int32_t moved = sign_extend(static_cast<std::uint32_t>(r.abs_pos() - pc.from), 22);
  if (pc.forward) EXPECT_GT(moved, 0); else EXPECT_LT(moved, 0);
  r.h().hard_stop(0);
}

INSTANTIATE_TEST_SUITE_P(
    MotionProfile, GoToPath,
    ::testing::Values(PathCase{"JustUnderHalfWayGoesForward", 0, k2p21 - 1, true},
                      PathCase{"ExactlyHalfWayGoesInReverse", 0, -k2p21, false},
                      PathCase{"ExactlyHalfWayFromElsewhereGoesInReverse", 1000, 1000 - k2p21, false},
                      PathCase{"JustOverHalfWayGoesInReverse", 0, -k2p21 + 1, false},
                      PathCase{"NegativeTargetCloseByGoesInReverse", 10, -10, false},
                      PathCase{"AcrossTheWrapGoesForward", k2p21 - 5, -k2p21 + 5, true}),
    [](const ::testing::TestParamInfo<PathCase>& info) { return std::string(info.param.name); });

TEST(MotionProfile, GoToDirForcesTheLongWayRound) {
  Rig r;
  r.profile(0xFFF, 0xFFF, 0x3FF);  // 15610 step/s: the 2^22 - 20 microsteps take 2.1 s
  r.h().go_to_dir(0, false, 10);  // 10 is 10 ahead; reverse means 2^22 - 10 microsteps
  const Tick t0 = r.chain.now();
  EXPECT_FALSE(r.status() & kDir);
  r.wait_s(0.001);
  EXPECT_LT(r.abs_pos(), 0);
  const Tick release = busy_release_tick(r.chip(), t0 + 3 * kTicksPerSecond);
  const double ideal_ticks = (std::ldexp(1.0, 22) - 10) / 128.0 * std::ldexp(1.0, 18) / 0x3FF;
  EXPECT_NEAR(static_cast<double>(release - t0), ideal_ticks, 2.0);
  r.chain.advance_to(release);
  EXPECT_EQ(r.abs_pos(), 10);
  EXPECT_FALSE(r.busy());
}

TEST(MotionProfile, GoToDirGoesTheShortWayWhenThatIsTheForcedDirection) {
  Rig r;
  r.profile(0x400, 0x400, 0x100);
  r.h().go_to_dir(0, true, 1234);
  EXPECT_TRUE(r.status() & kDir);
  r.wait_until_idle(1.0);
  EXPECT_EQ(r.abs_pos(), 1234);
}

TEST(MotionProfile, GoHomeAndGoMarkTakeTheShortestPath) {
  Rig r;
  r.profile(0x400, 0x400, 0x100);
  r.h().set_param(0, Reg::MARK, static_cast<std::uint32_t>(-5000) & kPosMask);
  r.h().move(0, true, 3000);
  r.wait_until_idle();
  ASSERT_EQ(r.abs_pos(), 3000);
  r.h().go_mark(0);
  EXPECT_FALSE(r.status() & kDir);
  EXPECT_TRUE(r.busy());
  r.wait_until_idle();
  EXPECT_EQ(r.abs_pos(), -5000);
  r.h().go_home(0);
  EXPECT_TRUE(r.status() & kDir);
  r.wait_until_idle();
  EXPECT_EQ(r.abs_pos(), 0);
  EXPECT_EQ(sign_extend(r.h().get_param(0, Reg::MARK), 22), -5000) << "GoMark leaves MARK alone";
}

TEST(MotionProfile, GoMarkTakesTheShortWayAcrossTheWrap) {
  Rig r;
  r.profile(0x400, 0x400, 0x100);
  r.h().set_param(0, Reg::ABS_POS, static_cast<std::uint32_t>(k2p21 + 0) - 64);  // 2^21 - 64
  r.h().set_param(0, Reg::MARK, static_cast<std::uint32_t>(-k2p21 + 64) & kPosMask);
  r.h().go_mark(0);
  EXPECT_TRUE(r.status() & kDir);
  r.wait_until_idle(1.0);
  EXPECT_EQ(r.abs_pos(), -k2p21 + 64);
}

TEST(MotionProfile, PositioningCommandsAreRefusedWhileBusy) {
  Rig r;
  r.h().move(0, true, 100000);
  r.h().get_status(0);
  r.h().go_to(0, 5);
  EXPECT_TRUE(r.h().get_status(0) & kNotPerf);
  r.h().go_home(0);
  EXPECT_TRUE(r.h().get_status(0) & kNotPerf);
  r.h().go_mark(0);
  EXPECT_TRUE(r.h().get_status(0) & kNotPerf);
  r.h().go_to_dir(0, true, 5);
  EXPECT_TRUE(r.h().get_status(0) & kNotPerf);
  r.h().move(0, true, 5);
  EXPECT_TRUE(r.h().get_status(0) & kNotPerf);
  r.wait_until_idle();
  EXPECT_EQ(r.abs_pos(), 100000) << "the refused commands changed nothing";
}

TEST(MotionProfile, GoToIsAcceptedWhileARunCruisesButMoveIsNot) {
  Rig r;
  r.h().run(0, true, test::spd_from_steps_per_s(300));
  r.wait_s(0.3);
  ASSERT_FALSE(r.busy());
  r.h().get_status(0);
  r.h().move(0, true, 10);
  EXPECT_TRUE(r.h().get_status(0) & kNotPerf) << "Move needs the motor stopped";
  const std::int32_t target = r.abs_pos() + 20000;
  r.h().go_to(0, target);
  EXPECT_FALSE(r.h().get_status(0) & kNotPerf) << "GoTo needs BUSY released only";
  EXPECT_TRUE(r.busy());
  r.wait_until_idle(3.0);
  EXPECT_EQ(r.abs_pos(), target);
  EXPECT_EQ(r.speed(), 0u);
}

// ---- stop commands -------------------------------------------------------------

TEST(MotionProfile, SoftStopDeceleratesWithDecAndHolds) {
  Rig r;
  r.h().run(0, true, test::spd_from_steps_per_s(800));
  r.wait_s(0.5);
  const std::int32_t p0 = r.abs_pos();
  r.h().soft_stop(0);
  const Tick t0 = r.chain.now();
  auto s = r.status();
  EXPECT_FALSE(s & kBusyN);
  EXPECT_EQ(mot(s), kDec);
  const Tick end = r.wait_until_idle(1.0, 16);
  const double ideal_s = 800.0 / acc_in_steps_per_s2(0x08A);
  EXPECT_NEAR(static_cast<double>(end - t0) / kTicksPerSecond, ideal_s, ideal_s * 0.01);
  const double ideal_steps = 800.0 * 800.0 / (2 * acc_in_steps_per_s2(0x08A));
  EXPECT_NEAR((r.abs_pos() - p0) / 128.0, ideal_steps, ideal_steps * 0.01);
  s = r.status();
  EXPECT_EQ(mot(s), kStopped);
  EXPECT_FALSE(s & kHiZ);
  EXPECT_EQ(r.speed(), 0u);
}

TEST(MotionProfile, SoftHiZDeceleratesThenDisablesTheBridges) {
  Rig r;
  r.h().run(0, false, test::spd_from_steps_per_s(800));
  r.wait_s(0.5);
  r.h().soft_hiz(0);
  auto s = r.status();
  EXPECT_FALSE(s & kHiZ) << "bridges stay on while decelerating";
  EXPECT_FALSE(s & kBusyN);
  EXPECT_EQ(mot(s), kDec);
  r.wait_s(0.5);
  s = r.status();
  EXPECT_TRUE(s & kHiZ);
  EXPECT_TRUE(s & kBusyN);
  EXPECT_EQ(mot(s), kStopped);
  EXPECT_EQ(r.speed(), 0u);
}

TEST(MotionProfile, HardStopStopsAtOnceAndHolds) {
  Rig r;
  r.h().run(0, true, test::spd_from_steps_per_s(800));
  r.wait_s(0.5);
  r.h().hard_stop(0);
  const std::int32_t p = r.abs_pos();
  EXPECT_EQ(r.speed(), 0u);
  const auto s = r.status();
  EXPECT_TRUE(s & kBusyN);
  EXPECT_FALSE(s & kHiZ);
  EXPECT_EQ(mot(s), kStopped);
  r.wait_s(0.01);
  EXPECT_EQ(r.abs_pos(), p);
}

TEST(MotionProfile, HardHiZStopsAtOnceAndDisablesTheBridges) {
  Rig r;
  r.h().move(0, true, 200000);
  r.wait_s(0.5);
  r.h().hard_hiz(0);
  const std::int32_t p = r.abs_pos();
  EXPECT_EQ(r.speed(), 0u);
  const auto s = r.status();
  EXPECT_TRUE(s & kBusyN);
  EXPECT_TRUE(s & kHiZ);
  EXPECT_EQ(mot(s), kStopped);
  r.wait_s(0.01);
  EXPECT_EQ(r.abs_pos(), p);
}

TEST(MotionProfile, StopCommandsWhileStoppedOnlySwitchTheBridges) {
  Rig r;
  ASSERT_TRUE(r.status() & kHiZ);  // power-up
  r.h().soft_stop(0);
  EXPECT_FALSE(r.status() & kHiZ);
  r.h().hard_hiz(0);
  EXPECT_TRUE(r.status() & kHiZ);
  r.h().hard_stop(0);
  EXPECT_FALSE(r.status() & kHiZ);
  r.h().soft_hiz(0);
  EXPECT_TRUE(r.status() & kHiZ) << "SoftHiZ while stopped: HiZ at once";
  EXPECT_FALSE(r.busy());
  r.wait_s(0.01);
  EXPECT_EQ(r.abs_pos(), 0);
  EXPECT_EQ(r.speed(), 0u);
}

TEST(MotionProfile, SoftStopWithInfiniteAccelerationStopsAtOnce) {
  Rig r;
  r.profile(0xFFF, 0x010, 0x041);
  r.h().run(0, true, test::spd_from_steps_per_s(800));
  r.wait_s(0.01);
  r.h().soft_stop(0);
  r.h().wait(8);
  EXPECT_EQ(r.speed(), 0u);
  EXPECT_FALSE(r.busy());
}

// ---- step-clock mode -------------------------------------------------------------

void stck_pulses(Rig& r, int n) {
  for (int i = 0; i < n; ++i) {
    r.chip().set_stck_pin(true);
    r.h().wait(4);
    r.chip().set_stck_pin(false);
    r.h().wait(4);
  }
}

TEST(MotionProfile, StepClockModeMovesOneMicrostepPerStckRisingEdge) {
  Rig r;
  r.h().set_param(0, Reg::STEP_MODE, 3);  // 1/8: EL_POS moves by 16
  r.h().step_clock(0, true);
  auto s = r.status();
  EXPECT_TRUE(s & kSckMod);
  EXPECT_TRUE(s & kBusyN) << "StepClock does not pull BUSY low";
  EXPECT_FALSE(r.busy());
  EXPECT_EQ(mot(s), kStopped);
  EXPECT_TRUE(s & kDir);
  stck_pulses(r, 10);
  EXPECT_EQ(r.abs_pos(), 10);
  EXPECT_EQ(r.el_pos(), 160u);
  s = r.status();
  EXPECT_EQ(mot(s), kStopped) << "whatever the STCK frequency";
  EXPECT_EQ(r.speed(), 0u);
  EXPECT_FALSE(r.busy());

  r.chip().set_stck_pin(true);  // a rising edge without a falling one after it
  r.h().wait(4);
  EXPECT_EQ(r.abs_pos(), 11);
  r.chip().set_stck_pin(true);  // no edge
  EXPECT_EQ(r.abs_pos(), 11);
  r.chip().set_stck_pin(false);  // falling edge: nothing
  EXPECT_EQ(r.abs_pos(), 11);
}

TEST(MotionProfile, EachMicrostepMovesElPosBy128ShiftedRightByStepSelModulo512) {
  for (std::uint32_t sel = 0; sel <= 7; ++sel) {
    SCOPED_TRACE("STEP_SEL " + std::to_string(sel));
    Rig r;
    r.h().set_param(0, Reg::STEP_MODE, sel);
    const std::uint32_t inc = 128u >> sel;
    r.h().step_clock(0, true);
    std::uint32_t el = r.chip().peek(Reg::EL_POS);
    ASSERT_EQ(el, 0u);
    for (int i = 0; i < 20; ++i) {
      stck_pulses(r, 1);
      EXPECT_EQ(r.chip().peek(Reg::EL_POS), (el + inc) & 0x1FFu);
      el = r.chip().peek(Reg::EL_POS);
    }
    r.h().step_clock(0, false);
    for (int i = 0; i < 30; ++i) {
      stck_pulses(r, 1);
      EXPECT_EQ(r.chip().peek(Reg::EL_POS), (el - inc) & 0x1FFu);
      el = r.chip().peek(Reg::EL_POS);
    }
    EXPECT_EQ(r.abs_pos(), -10);
    EXPECT_EQ(r.el_pos(), static_cast<std::uint32_t>(-10 * static_cast<std::int32_t>(inc)) & 0x1FFu);
  }
}

TEST(MotionProfile, AnotherStepClockChangesDirectionWithoutLeavingTheMode) {
  Rig r;
  r.h().step_clock(0, true);
  stck_pulses(r, 5);
  r.h().get_status(0);
  r.h().step_clock(0, false);
  const auto s = r.h().get_status(0);
  EXPECT_FALSE(s & kNotPerf);
  EXPECT_TRUE(s & kSckMod);
  EXPECT_FALSE(s & kDir);
  stck_pulses(r, 8);
  EXPECT_EQ(r.abs_pos(), -3);
}

TEST(MotionProfile, StckEdgesDoNothingOutsideStepClockMode) {
  Rig r;
  r.h().hard_stop(0);
  stck_pulses(r, 10);
  EXPECT_EQ(r.abs_pos(), 0);
  EXPECT_FALSE(r.status() & kSckMod);
}

TEST(MotionProfile, StepClockIsRefusedWhileTheMotorRuns) {
  Rig r;
  r.h().run(0, true, test::spd_from_steps_per_s(300));
  r.wait_s(0.3);
  r.h().get_status(0);
  r.h().step_clock(0, true);
  const auto s = r.h().get_status(0);
  EXPECT_TRUE(s & kNotPerf);
  EXPECT_FALSE(s & kSckMod);
  EXPECT_EQ(r.speed(), test::spd_from_steps_per_s(300));
}

TEST(MotionProfile, StopCommandsDoNotLeaveStepClockMode) {
  Rig r;
  r.h().step_clock(0, true);
  r.h().hard_stop(0);
  EXPECT_TRUE(r.status() & kSckMod);
  r.h().soft_stop(0);
  EXPECT_TRUE(r.status() & kSckMod);
  r.h().hard_hiz(0);
  EXPECT_TRUE(r.status() & kSckMod);
  EXPECT_TRUE(r.status() & kHiZ);
  r.h().hard_stop(0);
  stck_pulses(r, 3);
  EXPECT_EQ(r.abs_pos(), 3);
  EXPECT_TRUE(r.status() & kSckMod);
}

TEST(MotionProfile, RunLeavesStepClockMode) {
  Rig r;
  r.h().step_clock(0, true);
  stck_pulses(r, 4);
  r.h().run(0, true, test::spd_from_steps_per_s(200));
  r.wait_s(0.2);
  const auto s = r.status();
  EXPECT_FALSE(s & kSckMod);
  EXPECT_NE(mot(s), kStopped);
  EXPECT_EQ(r.speed(), test::spd_from_steps_per_s(200));
  const std::int32_t p = r.abs_pos();
  stck_pulses(r, 20);  // 160 ticks at 200 step/s: far less than one microstep on its own
  EXPECT_LT(r.abs_pos() - p, 5) << "STCK no longer steps (20 edges)";
}

TEST(MotionProfile, MoveLeavesStepClockMode) {
  Rig r;
  r.profile(0x400, 0x400, 0x100);
  r.h().step_clock(0, false);
  stck_pulses(r, 4);
  ASSERT_EQ(r.abs_pos(), -4);
  r.h().move(0, true, 104);
  EXPECT_FALSE(r.status() & kSckMod);
  EXPECT_TRUE(r.busy());
  r.wait_until_idle();
  EXPECT_EQ(r.abs_pos(), 100);
}

}  // namespace
}  // namespace l6470emu
