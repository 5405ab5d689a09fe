// The chip's pins as a board sees them: BUSY\SYNC, FLAG with ALARM_EN masking,
// STBY\RST and the ADCIN conversion (spec §1 last row, §3.5, §3.9, §6.5;
// docs/chip-model.md "Pins"). Not the SW input (switch_test) nor fault effects (faults_test).
#include <gtest/gtest.h>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/chip.hpp"
#include "support/test_support.hpp"

namespace l6470emu {
namespace {

using namespace test::status_bits;

constexpr std::uint16_t kPowerUpStatus = 0x7C03;

struct Rig : test::OneChip {
  ChainHost& h() { return host; }
  std::uint16_t status() { return static_cast<std::uint16_t>(host.get_param(0, Reg::STATUS)); }
  std::int32_t abs_pos() { return sign_extend(host.get_param(0, Reg::ABS_POS), 22); }
  bool busy_pin() { return chip().busy_sync_pin(); }
  bool flag_pin() { return chip().flag_pin(); }
  void wait_s(double s) { host.wait(static_cast<Tick>(s * kTicksPerSecond)); }
};

// ---- BUSY -------------------------------------------------------------------------

TEST(Pins, BusyPinIsReleasedAtPowerUp) {
  Rig r;
  EXPECT_TRUE(r.busy_pin());
  EXPECT_TRUE(r.status() & kBusyN);
}

TEST(Pins, BusyPinMirrorsTheBusyFlagThroughAMove) {
  Rig r;
  r.h().set_param(0, Reg::ACC, 0x400);
  r.h().set_param(0, Reg::DEC, 0x400);
  r.h().move(0, true, 20000);
  int busy_samples = 0, idle_samples = 0;
  for (int i = 0; i < 800; ++i) {
    r.h().wait(2000);  // 0.5 ms
    const bool pin = r.busy_pin();
    const bool flag = (r.chip().status() & kBusyN) != 0;
    ASSERT_EQ(pin, flag) << "at sample " << i;
    (pin ? idle_samples : busy_samples)++;
  }
  EXPECT_GT(busy_samples, 10);
  EXPECT_GT(idle_samples, 10);
  EXPECT_EQ(r.abs_pos(), 20000);
}

TEST(Pins, BusyPinIsLowWhileARunRampsAndReleasedAtTargetSpeed) {
  Rig r;
  r.h().run(0, true, test::spd_from_steps_per_s(400));
  EXPECT_FALSE(r.busy_pin());
  EXPECT_FALSE(r.status() & kBusyN);
  r.wait_s(0.3);  // 0.2 s ramp at 2008 step/s²
  EXPECT_TRUE(r.busy_pin());
  EXPECT_TRUE(r.status() & kBusyN);
}

// ---- SYNC --------------------------------------------------------------------------

TEST(Pins, SyncModeOutputsElPosBit7MinusSyncSel) {
  for (std::uint32_t step_sel : {7u, 4u, 2u}) {
    for (std::uint32_t sync_sel = 0; sync_sel <= step_sel; ++sync_sel) {
      SCOPED_TRACE("STEP_SEL " + std::to_string(step_sel) + " SYNC_SEL " + std::to_string(sync_sel));
      Rig r;
      r.h().set_param(0, Reg::STEP_MODE, 0x80 | (sync_sel << 4) | step_sel);
      r.h().step_clock(0, true);
      const unsigned bit = 7 - sync_sel;
      int highs = 0, lows = 0;
      for (int i = 0; i < 600; ++i) {
        const std::uint32_t el = r.chip().peek(Reg::EL_POS);
        const bool expected = ((el >> bit) & 1u) != 0;
        ASSERT_EQ(r.busy_pin(), expected) << "EL_POS " << el;
        (expected ? highs : lows)++;
        r.chip().set_stck_pin(true);
        r.h().wait(2);
        r.chip().set_stck_pin(false);
        r.h().wait(2);
      }
      EXPECT_GT(highs, 0);
      EXPECT_GT(lows, 0);
    }
  }
}

TEST(Pins, SyncModeReplacesBusyDuringAMove) {
  Rig r;
  r.h().set_param(0, Reg::STEP_MODE, 0x80 | (1u << 4) | 7u);  // SYNC_SEL 1: EL_POS bit 6, f_FS
  r.h().move(0, true, 50000);
  int toggles = 0;
  bool last = r.busy_pin();
  for (int i = 0; i < 2000; ++i) {
    r.h().wait(200);
    const bool pin = r.busy_pin();
    ASSERT_EQ(pin, ((r.chip().peek(Reg::EL_POS) >> 6) & 1u) != 0);
    if (pin != last) ++toggles;
    last = pin;
  }
  EXPECT_GT(toggles, 10) << "a clock, not a BUSY level";
  EXPECT_FALSE(r.chip().status() & kBusyN) << "the move is still going";
}

// ---- FLAG --------------------------------------------------------------------------

TEST(Pins, FlagIsLowAtPowerUpAndReleasedByGetStatus) {
  Rig r;
  EXPECT_FALSE(r.flag_pin());
  EXPECT_EQ(r.status(), kPowerUpStatus);
  EXPECT_FALSE(r.flag_pin()) << "GetParam(STATUS) clears nothing";
  EXPECT_EQ(r.h().get_status(0), kPowerUpStatus);
  EXPECT_TRUE(r.flag_pin());
  EXPECT_EQ(r.status(), 0x7E03);
}

TEST(Pins, FlagIsLowAgainAfterResetDevice) {
  Rig r;
  r.h().get_status(0);
  ASSERT_TRUE(r.flag_pin());
  r.h().reset_device(0);
  EXPECT_FALSE(r.flag_pin());
  EXPECT_EQ(r.status(), kPowerUpStatus);
}

/// One ALARM_EN bit and a way to raise its alarm. `also` lists ALARM_EN bits the
/// same event raises too (thermal shutdown is also above the warning level).
struct AlarmCase {
  const char* name;
  unsigned bit;
  std::uint8_t also;
  std::function<void(Rig&)> raise;
};

std::vector<AlarmCase> alarm_cases() {
  return {
      {"Overcurrent", 0, 0, [](Rig& r) { r.chip().set_overcurrent(true); r.chip().set_overcurrent(false); }},
      {"ThermalShutdown", 1, 1u << 2,
       [](Rig& r) { r.chip().set_thermal(Thermal::bridge_shutdown); r.chip().set_thermal(Thermal::normal); }},
      {"ThermalWarning", 2, 0, [](Rig& r) { r.chip().set_thermal(Thermal::warning); r.chip().set_thermal(Thermal::normal); }},
      {"Undervoltage", 3, 0, [](Rig& r) { r.chip().set_undervoltage(true); r.chip().set_undervoltage(false); }},
      {"StallA", 4, 0, [](Rig& r) { r.chip().set_stall(Bridge::A, true); r.chip().set_stall(Bridge::A, false); }},
      {"StallB", 5, 0, [](Rig& r) { r.chip().set_stall(Bridge::B, true); r.chip().set_stall(Bridge::B, false); }},
      {"SwitchTurnOn", 6, 0, [](Rig& r) { r.chip().set_sw_pin(false); }},
      {"WrongCommand", 7, 0, [](Rig& r) { const std::uint8_t b[] = {0xE0}; r.h().send(0, b); }},
      {"NotPerformableCommand", 7, 0,
       [](Rig& r) { r.h().hard_stop(0); r.h().set_param(0, Reg::STEP_MODE, 0x03); }},  // WH while enabled
  };
}

TEST(Pins, EachAlarmEnBitLetsItsAlarmPullFlagLow) {
  for (const auto& c : alarm_cases()) {
    SCOPED_TRACE(c.name);
    Rig r;
    r.h().get_status(0);
    r.h().set_param(0, Reg::ALARM_EN, 1u << c.bit);
    ASSERT_TRUE(r.flag_pin());
    c.raise(r);
    EXPECT_FALSE(r.flag_pin());
    r.h().get_status(0);
    EXPECT_TRUE(r.flag_pin()) << "released once GetStatus cleared the flag";
  }
}

TEST(Pins, AClearedAlarmEnBitMasksItsAlarmFromFlagButNotFromStatus) {
  for (const auto& c : alarm_cases()) {
    SCOPED_TRACE(c.name);
    Rig r;
    r.h().get_status(0);
    r.h().set_param(0, Reg::ALARM_EN, 0xFFu & ~(1u << c.bit) & ~static_cast<unsigned>(c.also));
    const std::uint16_t before = r.status();
    c.raise(r);
    EXPECT_TRUE(r.flag_pin());
    EXPECT_NE(r.status() & 0x7F88, before & 0x7F88) << "the STATUS flag is raised anyway";
  }
}

TEST(Pins, FlagStaysLowWhileTheAlarmConditionPersists) {
  Rig r;
  r.h().get_status(0);
  r.chip().set_thermal(Thermal::warning);
  EXPECT_FALSE(r.flag_pin());
  r.h().get_status(0);
  EXPECT_FALSE(r.flag_pin()) << "TH_WRN stays while the die is still hot";
  r.chip().set_thermal(Thermal::normal);
  EXPECT_FALSE(r.flag_pin()) << "latched until GetStatus";
  r.h().get_status(0);
  EXPECT_TRUE(r.flag_pin());
}

TEST(Pins, MaskingUvloAtPowerUpNeedsAlarmEnWhichResetRestores) {
  Rig r;
  r.h().set_param(0, Reg::ALARM_EN, 0xF7);  // UVLO masked, flag still latched
  EXPECT_TRUE(r.flag_pin());
  EXPECT_FALSE(r.status() & kUvloN);
  r.h().reset_device(0);
  EXPECT_EQ(r.h().get_param(0, Reg::ALARM_EN), 0xFFu);
  EXPECT_FALSE(r.flag_pin());
}

// ---- STBY\RST ----------------------------------------------------------------------------

TEST(Pins, StandbyMakesSpiSilent) {
  Rig r;
  r.h().get_status(0);
  r.chip().set_stby_rst_pin(false);
  EXPECT_FALSE(r.chip().spi_enabled());
  EXPECT_EQ(r.h().get_status(0), 0x0000);
  EXPECT_EQ(r.h().get_param(0, Reg::CONFIG), 0x0000u);
  EXPECT_EQ(r.h().get_param(0, Reg::MAX_SPEED), 0x0000u);
}

TEST(Pins, CommandsSentInStandbyAreIgnored) {
  Rig r;
  r.chip().set_stby_rst_pin(false);
  r.h().set_param(0, Reg::ACC, 0x123);
  r.h().run(0, true, test::spd_from_steps_per_s(500));
  const std::uint8_t junk[] = {0xE0, 0xFF};
  r.h().send(0, junk);
  r.wait_s(0.05);
  r.chip().set_stby_rst_pin(true);
  r.h().wait(ticks_from_us(50));
  EXPECT_EQ(r.h().get_param(0, Reg::ACC), 0x08Au);
  EXPECT_EQ(r.abs_pos(), 0);
  EXPECT_EQ(r.status(), kPowerUpStatus) << "no WRONG_CMD, no motion";
}

TEST(Pins, StandbyResetsRegistersAndReleaseIsThePowerUpState) {
  Rig r;
  r.h().set_param(0, Reg::ACC, 0x123);
  r.h().set_param(0, Reg::MAX_SPEED, 0x200);
  r.h().set_param(0, Reg::STEP_MODE, 0x03);
  r.h().set_param(0, Reg::MARK, 4242);
  r.h().set_param(0, Reg::ALARM_EN, 0x0F);
  r.h().get_status(0);
  r.h().move(0, true, 2000);
  r.wait_s(1.0);
  ASSERT_EQ(r.abs_pos(), 2000);
  r.chip().set_stby_rst_pin(false);
  r.h().wait(ticks_from_us(20));
  r.chip().set_stby_rst_pin(true);
  r.h().wait(ticks_from_us(50));
  EXPECT_TRUE(r.chip().spi_enabled());
  EXPECT_EQ(r.h().get_param(0, Reg::ACC), 0x08Au);
  EXPECT_EQ(r.h().get_param(0, Reg::MAX_SPEED), 0x041u);
  EXPECT_EQ(r.h().get_param(0, Reg::STEP_MODE), 0x07u);
  EXPECT_EQ(r.h().get_param(0, Reg::MARK), 0u);
  EXPECT_EQ(r.h().get_param(0, Reg::ALARM_EN), 0xFFu);
  EXPECT_EQ(r.h().get_param(0, Reg::CONFIG), 0x2E88u);
  EXPECT_EQ(r.abs_pos(), 0);
  EXPECT_EQ(r.h().get_param(0, Reg::EL_POS), 0u);
  EXPECT_EQ(r.status(), kPowerUpStatus);
  EXPECT_FALSE(r.flag_pin());
  EXPECT_TRUE(r.busy_pin());
  EXPECT_EQ(r.h().get_status(0), kPowerUpStatus);
  EXPECT_EQ(r.h().get_status(0), 0x7E03);
}

TEST(Pins, StandbyStopsAMovingMotorAndOpensTheBridges) {
  Rig r;
  r.h().run(0, true, test::spd_from_steps_per_s(500));
  r.wait_s(0.3);
  r.chip().set_stby_rst_pin(false);
  EXPECT_TRUE(r.chip().hiz());
  EXPECT_TRUE(r.busy_pin());
  r.wait_s(0.1);
  r.chip().set_stby_rst_pin(true);
  r.h().wait(ticks_from_us(50));
  EXPECT_EQ(r.abs_pos(), 0);
  EXPECT_EQ(r.h().get_param(0, Reg::SPEED), 0u);
  EXPECT_TRUE(r.status() & kHiZ);
}

TEST(Pins, FaultsComingAndGoingInStandbyAreNotLatched) {
  Rig r;
  r.chip().set_stby_rst_pin(false);
  r.chip().set_thermal(Thermal::warning);
  r.chip().set_stall(Bridge::A, true);
  r.chip().set_overcurrent(true);
  r.chip().set_thermal(Thermal::normal);
  r.chip().set_stall(Bridge::A, false);
  r.chip().set_overcurrent(false);
  r.chip().set_stby_rst_pin(true);
  r.h().wait(ticks_from_us(50));
  EXPECT_EQ(r.status(), kPowerUpStatus);
}

TEST(Pins, WrongCommandsDoNotSurviveStandby) {
  Rig r;
  const std::uint8_t junk[] = {0xE0};
  r.h().send(0, junk);
  ASSERT_TRUE(r.status() & kWrongCmd);
  r.chip().set_stby_rst_pin(false);
  r.h().wait(ticks_from_us(20));
  r.chip().set_stby_rst_pin(true);
  r.h().wait(ticks_from_us(50));
  const auto s = r.status();
  EXPECT_FALSE(s & kWrongCmd);
  EXPECT_FALSE(s & kNotPerf);
}

// ---- ADCIN -------------------------------------------------------------------------------

TEST(Pins, AdcOutFollowsTheAdcInput) {
  Rig r;
  for (std::uint8_t code : {0, 1, 17, 30, 31}) {
    r.chip().set_adc_input(code);
    EXPECT_EQ(r.h().get_param(0, Reg::ADC_OUT), code);
  }
}

TEST(Pins, AdcOutSaturatesAt31) {
  Rig r;
  for (std::uint8_t code : {32, 40, 63, 255}) {
    r.chip().set_adc_input(code);
    EXPECT_EQ(r.h().get_param(0, Reg::ADC_OUT), 31u) << "input " << int{code};
  }
}

TEST(Pins, AdcOutIsReadableWithVoltageCompensationOff) {
  Rig r;
  ASSERT_EQ(r.h().get_param(0, Reg::CONFIG) & 0x20u, 0u);  // EN_VSCOMP = 0 at reset
  r.chip().set_adc_input(12);
  EXPECT_EQ(r.h().get_param(0, Reg::ADC_OUT), 12u);
}

}  // namespace
}  // namespace l6470emu
