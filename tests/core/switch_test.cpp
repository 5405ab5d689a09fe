// The SW input: GoUntil / ReleaseSW homing, the HardStop interrupt of SW_MODE = 0,
// SW_F and SW_EVN, and a switch already closed when the logic leaves reset
// (spec §6.3, §9 item 1; docs/motion-rules.md "Switch events"). Not motion profiles.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <functional>

#include "core/chip.hpp"
#include "support/test_support.hpp"

namespace l6470emu {
namespace {

using namespace test::status_bits;


constexpr std::uint32_t kConfigReset = 0x2E88;
constexpr std::uint32_t kSwMode = 1u << 4;

double acc_in_steps_per_s2(std::uint32_t reg) { return reg * std::ldexp(1.0, -40) / (250e-9 * 250e-9); }

struct Rig : test::OneChip {
  ChainHost& h() { return host; }
  std::uint16_t status() { return static_cast<std::uint16_t>(host.get_param(0, Reg::STATUS)); }
  std::int32_t abs_pos() { return sign_extend(host.get_param(0, Reg::ABS_POS), 22); }
  std::int32_t mark() { return sign_extend(host.get_param(0, Reg::MARK), 22); }
  std::uint32_t speed() { return host.get_param(0, Reg::SPEED); }
  bool busy() { return !chip().busy_sync_pin(); }
  void wait_s(double s) { host.wait(static_cast<Tick>(s * kTicksPerSecond)); }
  void sw_mode(bool user_disposal) { host.set_param(0, Reg::CONFIG, user_disposal ? (kConfigReset | kSwMode) : kConfigReset); }
  /// Advances in small chunks until `done` holds (or `limit_s` passes); returns whether it held.
  bool advance_until(const std::function<bool()>& done, double limit_s = 3.0, Tick chunk = 16) {
    const Tick limit = chain.now() + static_cast<Tick>(limit_s * kTicksPerSecond);
    while (!done()) {
      if (chain.now() >= limit) return false;
      chain.advance_to(chain.now() + chunk);
    }
    return true;
  }
  void wait_until_idle(double limit_s = 3.0) { advance_until([&] { return !busy(); }, limit_s, 64); }
};

// ---- GoUntil -----------------------------------------------------------------

TEST(Switch, GoUntilWithAct0ResetsAbsPosAtTheSwitchThenSoftStops) {
  Rig r;
  r.sw_mode(true);
  r.h().set_param(0, Reg::ABS_POS, 20000);
  r.h().set_param(0, Reg::MARK, 777);
  const std::uint32_t spd = test::spd_from_steps_per_s(400);
  r.h().go_until(0, /*copy_to_mark=*/false, /*forward=*/false, spd);
  r.wait_s(0.3);  // at speed by now (0.2 s ramp), switch still open
  EXPECT_EQ(r.speed(), spd);
  EXPECT_TRUE(r.busy()) << "GoUntil keeps BUSY low at target speed until the switch event";
  ASSERT_TRUE(r.advance_until([&] { return r.chip().position() <= 10000; }));
  r.chip().set_sw_pin(false);
  EXPECT_EQ(r.chip().position(), 0) << "ABS_POS reset at the edge";
  EXPECT_TRUE(r.busy()) << "still decelerating";
  auto s = r.status();
  EXPECT_EQ(mot(s), 2u);
  EXPECT_TRUE(s & kSwEvn);
  EXPECT_TRUE(s & kSwF);
  r.wait_until_idle();
  // SoftStop from 400 step/s with DEC 2008 step/s², MIN_SPEED 0: 39.8 full steps past the switch.
  const double ideal = 400.0 * 400.0 / (2 * acc_in_steps_per_s2(0x08A)) * 128;
  EXPECT_NEAR(r.abs_pos(), -ideal, ideal * 0.01);
  s = r.status();
  EXPECT_TRUE(s & kBusyN);
  EXPECT_EQ(mot(s), kStopped);
  EXPECT_FALSE(s & kHiZ);
  EXPECT_FALSE(s & kDir);
  EXPECT_EQ(r.speed(), 0u);
  EXPECT_EQ(r.mark(), 777) << "ACT = 0 leaves MARK alone";
}

TEST(Switch, GoUntilWithAct1CopiesAbsPosToMarkThenSoftStops) {
  Rig r;
  r.sw_mode(true);
  r.h().set_param(0, Reg::ABS_POS, 20000);
  r.h().go_until(0, /*copy_to_mark=*/true, /*forward=*/false, test::spd_from_steps_per_s(400));
  ASSERT_TRUE(r.advance_until([&] { return r.chip().position() <= 10000; }));
  const std::int32_t at_edge = r.chip().position();
  r.chip().set_sw_pin(false);
  EXPECT_EQ(sign_extend(r.chip().peek(Reg::MARK), 22), at_edge);
  r.wait_until_idle();
  EXPECT_EQ(r.mark(), at_edge);
  const double ideal = 400.0 * 400.0 / (2 * acc_in_steps_per_s2(0x08A)) * 128;
  EXPECT_NEAR(r.abs_pos(), at_edge - ideal, ideal * 0.01) << "ABS_POS is not reset with ACT = 1";
  EXPECT_FALSE(r.busy());
}

TEST(Switch, GoUntilWithSwMode0HardStopsAtTheSwitch) {
  Rig r;  // CONFIG reset value: SW_MODE = 0
  r.h().set_param(0, Reg::ABS_POS, 20000);
  r.h().go_until(0, /*copy_to_mark=*/false, /*forward=*/false, test::spd_from_steps_per_s(400));
  ASSERT_TRUE(r.advance_until([&] { return r.chip().position() <= 10000; }));
  r.chip().set_sw_pin(false);
  EXPECT_FALSE(r.busy()) << "HardStop: stopped at once";
  EXPECT_EQ(r.abs_pos(), 0);
  EXPECT_EQ(r.speed(), 0u);
  r.wait_s(0.05);
  EXPECT_EQ(r.abs_pos(), 0);
  const auto s = r.status();
  EXPECT_EQ(mot(s), kStopped);
  EXPECT_FALSE(s & kHiZ);
  EXPECT_TRUE(s & kSwEvn);
}

TEST(Switch, GoUntilWithAct1AndSwMode0StopsWithMarkEqualToAbsPos) {
  Rig r;
  r.h().set_param(0, Reg::ABS_POS, 100);
  r.h().go_until(0, /*copy_to_mark=*/true, /*forward=*/true, test::spd_from_steps_per_s(400));
  ASSERT_TRUE(r.advance_until([&] { return r.chip().position() >= 9000; }));
  r.chip().set_sw_pin(false);
  const std::int32_t p = r.abs_pos();
  EXPECT_GE(p, 9000);
  EXPECT_EQ(r.mark(), p);
  r.wait_s(0.05);
  EXPECT_EQ(r.abs_pos(), p);
  EXPECT_FALSE(r.busy());
}

TEST(Switch, GoUntilSpeedIsClampedToMaxSpeedAndMinSpeed) {
  Rig r;
  r.h().set_param(0, Reg::MAX_SPEED, 0x020);
  r.h().go_until(0, false, true, test::spd_from_steps_per_s(5000));
  r.wait_s(0.5);
  EXPECT_EQ(r.speed(), 0x020u << 10);
  r.h().hard_stop(0);

  Rig q;
  const std::uint32_t min = test::min_speed_from_steps_per_s(150);
  q.h().set_param(0, Reg::MIN_SPEED, min);
  q.h().go_until(0, false, true, test::spd_from_steps_per_s(10));
  q.wait_s(0.05);
  EXPECT_EQ(q.speed(), min << 4);
  EXPECT_TRUE(q.busy()) << "still waiting for the switch";
}

TEST(Switch, GoUntilWithTheSwitchAlreadyClosedRunsUntilTheNextClosingEdge) {
  Rig r;
  r.sw_mode(true);
  r.chip().set_sw_pin(false);
  r.h().get_status(0);
  r.h().go_until(0, false, true, test::spd_from_steps_per_s(300));
  r.wait_s(0.3);
  EXPECT_TRUE(r.busy());
  EXPECT_GT(r.abs_pos(), 0);
  r.chip().set_sw_pin(true);
  r.wait_s(0.01);
  EXPECT_TRUE(r.busy());
  r.chip().set_sw_pin(false);
  EXPECT_EQ(r.chip().position(), 0);
  r.wait_until_idle();
  EXPECT_FALSE(r.busy());
}

// ---- ReleaseSW ------------------------------------------------------------------

TEST(Switch, ReleaseSwRunsAtMinSpeedAndHardStopsWhenTheSwitchOpens) {
  Rig r;
  const std::uint32_t min = test::min_speed_from_steps_per_s(40);
  r.h().set_param(0, Reg::MIN_SPEED, min);
  r.chip().set_sw_pin(false);  // sitting on the switch (SW_MODE 0: a HardStop interrupt, nothing moves)
  r.h().set_param(0, Reg::ABS_POS, static_cast<std::uint32_t>(-3000) & 0x3FFFFF);
  r.h().get_status(0);
  r.h().release_sw(0, /*copy_to_mark=*/false, /*forward=*/true);
  EXPECT_TRUE(r.busy());
  EXPECT_EQ(r.speed(), min << 4) << "ReleaseSW has no ramp";
  auto s = r.status();
  EXPECT_EQ(mot(s), kConst);
  EXPECT_TRUE(s & kDir);
  EXPECT_FALSE(s & kHiZ);
  r.wait_s(0.1);
  EXPECT_EQ(r.speed(), min << 4);
  // 40 step/s at 1/128 = 5120 microsteps/s.
  ASSERT_TRUE(r.advance_until([&] { return r.chip().position() >= -2000; }));
  r.chip().set_sw_pin(true);
  EXPECT_FALSE(r.busy());
  EXPECT_EQ(r.abs_pos(), 0);
  EXPECT_EQ(r.speed(), 0u);
  r.wait_s(0.05);
  EXPECT_EQ(r.abs_pos(), 0);
  s = r.status();
  EXPECT_EQ(mot(s), kStopped);
  EXPECT_FALSE(s & kSwF);
  EXPECT_FALSE(s & kSwEvn) << "an opening edge is no turn-on event";
  EXPECT_FALSE(s & kHiZ);
}

TEST(Switch, ReleaseSwWithAct1CopiesAbsPosToMark) {
  Rig r;
  r.h().set_param(0, Reg::MIN_SPEED, test::min_speed_from_steps_per_s(40));
  r.chip().set_sw_pin(false);
  r.h().release_sw(0, /*copy_to_mark=*/true, /*forward=*/false);
  ASSERT_TRUE(r.advance_until([&] { return r.chip().position() <= -500; }));
  r.chip().set_sw_pin(true);
  const std::int32_t p = r.abs_pos();
  EXPECT_LE(p, -500);
  EXPECT_EQ(r.mark(), p);
  EXPECT_FALSE(r.busy());
}

TEST(Switch, ReleaseSwBelowFiveStepsPerSecondRunsAtFive) {
  Rig r;  // MIN_SPEED 0
  r.chip().set_sw_pin(false);
  r.h().release_sw(0, false, true);
  EXPECT_NEAR(test::steps_per_s_from_speed(r.speed()), 5.0, 0.02);
  const std::int32_t p0 = r.abs_pos();
  r.wait_s(1.0);
  EXPECT_NEAR(r.abs_pos() - p0, 5 * 128, 2);  // 5 full steps in one second
  EXPECT_TRUE(r.busy());
}

TEST(Switch, ReleaseSwJustBelowFiveStepsPerSecondAlsoRunsAtFive) {
  Rig r;
  r.h().set_param(0, Reg::MIN_SPEED, test::min_speed_from_steps_per_s(4.5));
  r.chip().set_sw_pin(false);
  r.h().release_sw(0, false, true);
  EXPECT_NEAR(test::steps_per_s_from_speed(r.speed()), 5.0, 0.02);
}

TEST(Switch, ReleaseSwWithLspdOptRunsAtFiveStepsPerSecondWhateverMinSpeed) {
  Rig r;
  r.h().set_param(0, Reg::MIN_SPEED, 0x1000 | test::min_speed_from_steps_per_s(100));
  r.chip().set_sw_pin(false);
  r.h().release_sw(0, false, false);
  EXPECT_NEAR(test::steps_per_s_from_speed(r.speed()), 5.0, 0.02);
  const std::int32_t p0 = r.abs_pos();
  r.wait_s(0.5);
  EXPECT_NEAR(r.abs_pos() - p0, -320, 2);
}

TEST(Switch, ReleaseSwWithTheSwitchAlreadyOpenRunsUntilTheNextOpeningEdge) {
  Rig r;
  r.h().set_param(0, Reg::MIN_SPEED, test::min_speed_from_steps_per_s(40));
  r.sw_mode(true);
  r.h().release_sw(0, false, true);
  r.wait_s(0.05);
  EXPECT_TRUE(r.busy());
  EXPECT_GT(r.abs_pos(), 0);
  r.chip().set_sw_pin(false);
  r.wait_s(0.01);
  EXPECT_TRUE(r.busy()) << "SW_MODE 1: closing does not stop it";
  r.chip().set_sw_pin(true);
  EXPECT_FALSE(r.busy());
  EXPECT_EQ(r.abs_pos(), 0);
}

// ---- SW_MODE outside GoUntil ---------------------------------------------------------

TEST(Switch, SwMode0HardStopsARunOnASwitchClosure) {
  Rig r;
  r.h().run(0, true, test::spd_from_steps_per_s(500));
  r.wait_s(0.4);
  ASSERT_EQ(r.speed(), test::spd_from_steps_per_s(500));
  r.chip().set_sw_pin(false);
  const std::int32_t p = r.chip().position();
  EXPECT_EQ(r.speed(), 0u);
  EXPECT_FALSE(r.busy());
  r.wait_s(0.05);
  EXPECT_EQ(r.abs_pos(), p) << "ABS_POS is kept: no ACT outside GoUntil";
  EXPECT_NE(p, 0);
  const auto s = r.status();
  EXPECT_TRUE(s & kSwEvn);
  EXPECT_FALSE(s & kHiZ);
}

TEST(Switch, SwMode0HardStopsAPositioningMove) {
  Rig r;
  r.h().move(0, false, 100000);
  r.wait_s(0.3);
  r.chip().set_sw_pin(false);
  const std::int32_t p = r.chip().position();
  EXPECT_FALSE(r.busy());
  r.wait_s(0.05);
  EXPECT_EQ(r.abs_pos(), p);
  EXPECT_GT(p, -100000);
}

TEST(Switch, SwMode1SwitchClosureOnlySetsSwEvn) {
  Rig r;
  r.sw_mode(true);
  const std::uint32_t spd = test::spd_from_steps_per_s(500);
  r.h().run(0, true, spd);
  r.wait_s(0.4);
  r.h().get_status(0);
  r.chip().set_sw_pin(false);
  const std::int32_t p = r.abs_pos();
  r.wait_s(0.05);
  EXPECT_GT(r.abs_pos(), p) << "still running";
  EXPECT_EQ(r.speed(), spd);
  const auto s = r.status();
  EXPECT_TRUE(s & kSwEvn);
  EXPECT_TRUE(s & kSwF);
  EXPECT_EQ(mot(s), kConst);
}

// ---- SW_F and SW_EVN --------------------------------------------------------------------

TEST(Switch, SwFFollowsThePinWithoutAnyLatching) {
  Rig r;
  r.sw_mode(true);
  EXPECT_FALSE(r.status() & kSwF);
  r.chip().set_sw_pin(false);
  EXPECT_TRUE(r.status() & kSwF);
  r.chip().set_sw_pin(true);
  EXPECT_FALSE(r.status() & kSwF);
  r.chip().set_sw_pin(false);
  r.h().get_status(0);
  EXPECT_TRUE(r.status() & kSwF) << "GetStatus does not clear SW_F while the switch is closed";
}

TEST(Switch, SwEvnIsLatchedUntilGetStatus) {
  Rig r;
  r.sw_mode(true);
  r.h().get_status(0);
  r.chip().set_sw_pin(false);
  r.chip().set_sw_pin(true);  // closed and open again
  auto s = r.status();
  EXPECT_TRUE(s & kSwEvn);
  EXPECT_FALSE(s & kSwF);
  EXPECT_TRUE(r.status() & kSwEvn) << "GetParam(STATUS) clears nothing";
  s = r.h().get_status(0);
  EXPECT_TRUE(s & kSwEvn) << "GetStatus answers with the value before clearing";
  EXPECT_FALSE(r.h().get_status(0) & kSwEvn);
}

TEST(Switch, OnlyTheClosingEdgeIsATurnOnEvent) {
  Rig r;
  r.sw_mode(true);
  r.chip().set_sw_pin(false);
  r.h().get_status(0);
  r.chip().set_sw_pin(true);  // opening
  EXPECT_FALSE(r.status() & kSwEvn);
  r.chip().set_sw_pin(true);  // no edge
  EXPECT_FALSE(r.status() & kSwEvn);
}

// ---- switch closed when the logic leaves reset -----------------------------------------

void expect_switch_turn_on_at_reset(Rig& r) {
  const auto s = r.status();
  EXPECT_TRUE(s & kSwEvn) << "a closed switch at reset exit is a turn-on event";
  EXPECT_TRUE(s & kSwF);
  EXPECT_FALSE(s & kHiZ) << "the HardStop interrupt takes the bridges out of HiZ";
  EXPECT_TRUE(s & kBusyN);
  // WH registers can no longer be written (spec §9 item 1).
  r.h().get_status(0);
  r.h().set_param(0, Reg::STEP_MODE, 0x03);
  EXPECT_TRUE(r.h().get_status(0) & kNotPerf);
  EXPECT_EQ(r.h().get_param(0, Reg::STEP_MODE), 0x07u);
  r.h().set_param(0, Reg::CONFIG, kConfigReset | kSwMode);
  EXPECT_TRUE(r.h().get_status(0) & kNotPerf);
  EXPECT_EQ(r.h().get_param(0, Reg::CONFIG), kConfigReset);
  // Back in HiZ they can.
  r.h().hard_hiz(0);
  r.h().set_param(0, Reg::STEP_MODE, 0x03);
  EXPECT_FALSE(r.h().get_status(0) & kNotPerf);
  EXPECT_EQ(r.h().get_param(0, Reg::STEP_MODE), 0x03u);
}

TEST(Switch, SwitchClosedWhenStandbyEndsIsATurnOnEventThatLeavesHiZ) {
  Rig r;
  r.chip().set_stby_rst_pin(false);
  r.h().wait(ticks_from_us(20));
  r.chip().set_sw_pin(false);
  r.h().wait(ticks_from_us(20));
  r.chip().set_stby_rst_pin(true);
  r.h().wait(ticks_from_us(50));
  expect_switch_turn_on_at_reset(r);
}

TEST(Switch, SwitchClosedAtResetDeviceIsATurnOnEventThatLeavesHiZ) {
  Rig r;
  r.sw_mode(true);
  r.chip().set_sw_pin(false);  // SW_MODE 1: no interrupt now, bridges stay HiZ
  ASSERT_TRUE(r.status() & kHiZ);
  r.h().reset_device(0);       // CONFIG back to SW_MODE 0, switch still closed
  r.h().wait(ticks_from_us(50));
  EXPECT_EQ(r.h().get_param(0, Reg::CONFIG), kConfigReset);
  expect_switch_turn_on_at_reset(r);
}

TEST(Switch, SwitchOpenAtResetIsNoEvent) {
  Rig r;
  r.h().reset_device(0);
  const auto s = r.status();
  EXPECT_FALSE(s & kSwEvn);
  EXPECT_TRUE(s & kHiZ);
}

}  // namespace
}  // namespace l6470emu
