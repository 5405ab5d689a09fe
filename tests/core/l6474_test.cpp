// The L6474 (docs/l6474.md): no motion engine. Its reset values read over a chain, the motion
// commands refused with WRONG_CMD, Enable and Disable, STCK pulses moving ABS_POS in the
// direction of the DIR pin only while enabled, 1/16 microstepping, its STATUS word, standby as
// its only reset, and no BUSY or SW pin.
#include <gtest/gtest.h>

#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "core/chip.hpp"
#include "core/variant.hpp"
#include "support/test_support.hpp"

namespace l6470emu {
namespace {

std::string hex(std::uint32_t v) {
  std::ostringstream s;
  s << "0x" << std::hex << std::uppercase << v;
  return s.str();
}

constexpr std::uint16_t kHiZ = 1u << 0;
constexpr std::uint16_t kDir = 1u << 4;
constexpr std::uint16_t kNotperf = 1u << 7;
constexpr std::uint16_t kWrongCmd = 1u << 8;
constexpr std::uint16_t kQuiet = 0xFE03;  // after the first GetStatus: HiZ, bits 15:13 and 1 high

/// A chain of `n` L6474s and a host that sends one byte per frame.
struct Rig {
  explicit Rig(std::size_t n = 1) : chain(n, l6474()), host(chain) {}
  Chain chain;
  ChainHost host;
  Chip& chip(std::size_t k = 0) { return chain.chip(k); }
  void pulses(std::size_t k, int n) {
    for (int i = 0; i < n; ++i) {
      chip(k).set_stck_pin(true);
      chip(k).set_stck_pin(false);
    }
  }
  std::int32_t abs_pos(std::size_t k = 0) { return sign_extend(host.get_param(k, Reg::ABS_POS), 22); }
};

// ---------------------------------------------------------------- registers

TEST(L6474, AThreeChipChainAnswersTheResetValueOfEveryRegisterThroughGetParam) {
  // The check: an L6474 chain answers its reset values (docs/l6474.md's table).
  Rig rig(3);
  const std::pair<Reg, std::uint32_t> resets[] = {
      {Reg::ABS_POS, 0x000000}, {Reg::EL_POS, 0x000}, {Reg::MARK, 0x000000}, {Reg::TVAL, 0x29},
      {Reg::T_FAST, 0x19},      {Reg::TON_MIN, 0x29}, {Reg::TOFF_MIN, 0x29}, {Reg::ADC_OUT, 0x00},
      {Reg::OCD_TH, 0x8},       {Reg::STEP_MODE, 0x07}, {Reg::ALARM_EN, 0xFF}, {Reg::CONFIG, 0x2E88},
      {Reg::STATUS, 0xFC03},
  };
  ASSERT_EQ(std::size(resets), l6474().registers.size());
  for (std::size_t k = 0; k < 3; ++k)
    for (const auto& [reg, value] : resets) {
      SCOPED_TRACE("chip " + std::to_string(k) + " " + std::string(l6474().find(reg)->name));
      EXPECT_EQ(hex(rig.host.get_param(k, reg)), hex(value));
    }
}

TEST(L6474, StandbyIsItsOnlyResetAndBringsEveryRegisterBack) {
  // No ResetDevice: STBY\RST low then high returns the power-up state.
  Rig rig;
  rig.host.set_param(0, Reg::TVAL, 0x11);
  rig.host.set_param(0, Reg::STEP_MODE, 0x8C);
  rig.host.set_param(0, Reg::CONFIG, 0x2C08);
  rig.host.enable(0);
  rig.chip().set_dir_pin(true);
  rig.pulses(0, 5);
  rig.host.reset_device(0);  // ResetDevice's opcode: no command here
  EXPECT_EQ(rig.host.get_param(0, Reg::TVAL), 0x11u);
  rig.chip().set_stby_rst_pin(false);
  rig.chip().set_stby_rst_pin(true);
  EXPECT_EQ(hex(rig.host.get_status(0)), hex(0xFC03 | kDir)) << "HiZ, UVLO latched; DIR follows the pin";
  for (const RegisterInfo& r : l6474().registers)
    if (!r.is_live()) {
      EXPECT_EQ(hex(rig.host.get_param(0, r.id)), hex(r.reset)) << r.name;
    }
  EXPECT_EQ(rig.abs_pos(), 0);
}

// ---------------------------------------------------------------- commands

TEST(L6474, RefusesMoveWithWrongCmdAndDecodesItsArgumentBytesAsCommands) {
  // The check: Move is no command on an L6474. Its three would-be argument bytes are
  // decoded as commands; the GetStatus in their place answers at once.
  Rig rig;
  rig.host.get_status(0);
  const std::vector<std::uint8_t> tx{0x41, 0xD0, 0x00, 0x00};
  const auto miso = rig.host.send(0, tx);
  EXPECT_EQ(miso, (std::vector<std::uint8_t>{0x00, 0x00, 0xFF, 0x03}));  // 0xFE03 | WRONG_CMD
  EXPECT_EQ(hex(rig.host.get_status(0)), hex(kQuiet));
  EXPECT_EQ(rig.abs_pos(), 0);
  EXPECT_TRUE(rig.chip().hiz());
}

TEST(L6474, RefusesEveryMotionCommandAndResetWithWrongCmd) {
  // Run, StepClock, Move, GoTo, GoTo_DIR, GoUntil, ReleaseSW, GoHome, GoMark, ResetPos,
  // ResetDevice, SoftStop, SoftHiZ: none exists on the L6474 (ST's command set: NOP, SetParam,
  // GetParam, Enable, Disable, GetStatus).
  const std::uint8_t opcodes[] = {0x50, 0x51, 0x58, 0x59, 0x40, 0x60, 0x68, 0x69, 0x82, 0x8B,
                                  0x92, 0x9B, 0x70, 0x78, 0xD8, 0xC0, 0xB0, 0xA0, 0xEB, 0xF8};
  for (std::uint8_t op : opcodes) {
    SCOPED_TRACE(hex(op));
    Rig rig;
    rig.host.set_param(0, Reg::ABS_POS, 1234);
    rig.host.get_status(0);
    rig.host.send(0, std::vector<std::uint8_t>{op});
    EXPECT_EQ(hex(rig.host.get_status(0)), hex(kQuiet | kWrongCmd));
    EXPECT_EQ(rig.abs_pos(), 1234) << "ResetPos and ResetDevice do nothing either";
    EXPECT_EQ(rig.chip().variant().opcodes[op].command, op >= 0xEB ? Command::Reserved : Command::Unknown);
  }
}

TEST(L6474, EnableTakesTheBridgesOutOfHiZAndDisablePutsThemBack) {
  Rig rig;
  rig.host.get_status(0);
  EXPECT_TRUE(rig.chip().hiz());
  rig.host.enable(0);  // 0xB8
  EXPECT_FALSE(rig.chip().hiz());
  EXPECT_EQ(hex(rig.host.get_status(0)), hex(kQuiet & ~kHiZ)) << "no flag: Enable is a command";
  rig.host.disable(0);  // 0xA8
  EXPECT_TRUE(rig.chip().hiz());
  EXPECT_EQ(hex(rig.host.get_status(0)), hex(kQuiet));
  EXPECT_EQ(l6474().opcodes[0xB8].command, Command::Enable);
  EXPECT_EQ(l6474().opcodes[0xA8].command, Command::Disable);
}

TEST(L6474, RefusesWhRegistersWithNotperfCmdWhileEnabledAndTakesThemInHiZ) {
  Rig rig;
  rig.host.enable(0);
  rig.host.get_status(0);
  rig.host.set_param(0, Reg::STEP_MODE, 0x8C);
  EXPECT_EQ(hex(rig.host.get_status(0)), hex((kQuiet & ~kHiZ) | kNotperf));
  EXPECT_EQ(rig.host.get_param(0, Reg::STEP_MODE), 0x07u);
  rig.host.set_param(0, Reg::TVAL, 0x20);  // WR: any time
  EXPECT_EQ(rig.host.get_param(0, Reg::TVAL), 0x20u);
  rig.host.disable(0);
  rig.host.set_param(0, Reg::STEP_MODE, 0x8C);
  EXPECT_EQ(rig.host.get_param(0, Reg::STEP_MODE), 0x8Cu);
}

TEST(L6474, EnableWhileAFaultHoldsTheBridgesInHiZLeavesThemThereWithoutAFlag) {
  // UNCONFIRMED (docs/l6474.md): Enable is HardStop's opcode and acts as HardStop does on the
  // others when a fault forces HiZ.
  Rig rig;
  rig.host.get_status(0);
  rig.chip().set_thermal(Thermal::bridge_shutdown);
  rig.host.get_status(0);
  rig.host.enable(0);
  EXPECT_TRUE(rig.chip().hiz());
  const std::uint16_t s = rig.host.get_status(0);
  EXPECT_EQ(s & (kNotperf | kWrongCmd), 0u) << hex(s);
  rig.chip().set_thermal(Thermal::normal);
  rig.host.get_status(0);
  rig.host.enable(0);
  EXPECT_FALSE(rig.chip().hiz()) << "cooled down: Enable works again";
}

// ---------------------------------------------------------------- STCK and DIR

TEST(L6474, MovesAbsPosByExactlyTheStckPulsesInTheDirectionOfItsDirPin) {
  // The check: ABS_POS moves by exactly the pulses given, DIR high forward.
  Rig rig(2);
  rig.host.enable(1);
  rig.chip(1).set_dir_pin(true);
  rig.pulses(1, 1000);
  EXPECT_EQ(rig.abs_pos(1), 1000);
  rig.chip(1).set_dir_pin(false);
  rig.pulses(1, 1300);
  EXPECT_EQ(rig.abs_pos(1), -300);
  rig.chip(1).set_dir_pin(true);
  rig.pulses(1, 300);
  EXPECT_EQ(rig.abs_pos(1), 0);
  EXPECT_EQ(rig.abs_pos(0), 0) << "the other chip saw no pulse";
  // A level held, or a falling edge, moves nothing: only rising edges do.
  rig.chip(1).set_stck_pin(true);
  rig.chip(1).set_stck_pin(true);
  rig.chip(1).set_stck_pin(false);
  rig.chip(1).set_stck_pin(false);
  EXPECT_EQ(rig.abs_pos(1), 1);
}

TEST(L6474, AbsPosWrapsIn22BitsAsOnTheOtherParts) {
  Rig rig;
  rig.host.set_param(0, Reg::ABS_POS, 0x1FFFFF);  // 2^21 - 1
  rig.host.enable(0);
  rig.chip().set_dir_pin(true);
  rig.pulses(0, 1);
  EXPECT_EQ(rig.abs_pos(), -(1 << 21));
}

TEST(L6474, DirHighIsForwardAndShowsOnStatusDir) {
  // UNCONFIRMED (docs/l6474.md): DIR high steps forward, as ST's drivers drive it.
  Rig rig;
  rig.host.get_status(0);
  EXPECT_EQ(rig.host.get_status(0) & kDir, 0u) << "DIR low at power-up";
  rig.chip().set_dir_pin(true);
  EXPECT_EQ(rig.host.get_status(0) & kDir, kDir);
  EXPECT_EQ(rig.host.get_param(0, Reg::STATUS) & kDir, kDir);
  rig.host.enable(0);
  rig.pulses(0, 3);
  EXPECT_EQ(rig.abs_pos(), 3);
  rig.chip().set_dir_pin(false);
  EXPECT_EQ(rig.host.get_status(0) & kDir, 0u);
}

TEST(L6474, StckEdgesAreIgnoredWithTheBridgesInHiZ) {
  // UNCONFIRMED (docs/l6474.md): the position moves only while Enable holds the bridges on.
  Rig rig;
  rig.chip().set_dir_pin(true);
  rig.pulses(0, 10);
  EXPECT_EQ(rig.abs_pos(), 0) << "power-up: HiZ";
  rig.host.enable(0);
  rig.pulses(0, 10);
  rig.host.disable(0);
  rig.pulses(0, 10);
  EXPECT_EQ(rig.abs_pos(), 10);
  rig.host.enable(0);
  rig.chip().set_undervoltage(true);  // a fault forces HiZ
  rig.pulses(0, 10);
  EXPECT_EQ(rig.abs_pos(), 10);
}

TEST(L6474, StepModeSixteenthMovesElPosBy8PerPulseAndFullStepBy128) {
  // ABS_POS counts microsteps of STEP_SEL's size, EL_POS 1/128 step (as the L6472's).
  Rig rig;
  rig.chip().set_dir_pin(true);
  rig.host.set_param(0, Reg::STEP_MODE, 0x8C);  // ST's value: 1/16 (STEP_SEL 100), bits 7 and 3 set
  rig.host.enable(0);
  rig.pulses(0, 1);
  EXPECT_EQ(rig.host.get_param(0, Reg::EL_POS), 8u);
  rig.pulses(0, 15);
  EXPECT_EQ(rig.host.get_param(0, Reg::EL_POS), 0x080u) << "16 pulses: one full step";
  EXPECT_EQ(rig.abs_pos(), 16);
  rig.host.disable(0);
  rig.host.set_param(0, Reg::STEP_MODE, 0x88);  // full step
  rig.host.enable(0);
  rig.pulses(0, 1);
  EXPECT_EQ(rig.host.get_param(0, Reg::EL_POS), 0x100u);
  EXPECT_EQ(rig.abs_pos(), 17);
}

TEST(L6474, StepSel5To7ActAsSixteenthAndAreStoredAsWritten) {
  // UNCONFIRMED (docs/l6474.md): STEP_SEL 1xx is 1/16.
  for (std::uint32_t step_mode : {0x05u, 0x06u, 0x07u, 0x8Fu}) {
    SCOPED_TRACE(hex(step_mode));
    Rig rig;
    rig.host.set_param(0, Reg::STEP_MODE, step_mode);
    EXPECT_EQ(rig.host.get_param(0, Reg::STEP_MODE), step_mode);
    rig.chip().set_dir_pin(true);
    rig.host.enable(0);
    rig.pulses(0, 2);
    EXPECT_EQ(rig.host.get_param(0, Reg::EL_POS), 16u);
  }
}

// ---------------------------------------------------------------- STATUS and pins

TEST(L6474, StatusReadsFC03AtPowerUpAndFE03AfterGetStatusWithBits15To13And1High) {
  // UNCONFIRMED bits 15, 14, 13 and 1 (public reports: 0xFE03 after start-up, docs/l6474.md).
  Rig rig;
  EXPECT_EQ(hex(rig.host.get_param(0, Reg::STATUS)), hex(0xFC03));
  EXPECT_EQ(hex(rig.host.get_status(0)), hex(0xFC03));
  EXPECT_EQ(hex(rig.host.get_status(0)), hex(0xFE03));
  rig.chip().set_overcurrent(true);
  rig.chip().set_thermal(Thermal::warning);
  rig.host.send(0, std::vector<std::uint8_t>{0x40});  // Move: WRONG_CMD
  EXPECT_EQ(hex(rig.host.get_status(0)), hex((0xFE03 & ~(1u << 12) & ~(1u << 10)) | kWrongCmd));
  // Nothing the others put on bits 6:5 (MOT_STATUS), 3 (SW_EVN), 2 (SW_F) shows here.
  rig.chip().set_sw_pin(false);
  rig.host.enable(0);
  EXPECT_EQ(rig.host.get_status(0) & 0x006C, 0u);
}

TEST(L6474, HasNoBusyPinAndNoSwInput) {
  Rig rig;
  EXPECT_FALSE(l6474().pins.busy_sync);
  EXPECT_FALSE(l6474().pins.sw);
  EXPECT_TRUE(l6474().pins.dir);
  rig.host.get_status(0);
  rig.host.set_param(0, Reg::STEP_MODE, 0x8C);  // bit 7: SYNC_EN on the others
  rig.host.enable(0);
  rig.chip().set_dir_pin(true);
  for (int i = 0; i < 40; ++i) {
    rig.pulses(0, 1);
    EXPECT_TRUE(rig.chip().busy_sync_pin()) << "no BUSY\\SYNC pin: nothing pulls it low";
  }
  rig.chip().set_sw_pin(false);  // no SW input: no turn-on event, no hard stop
  EXPECT_TRUE(rig.chip().sw_pin());
  EXPECT_FALSE(rig.chip().hiz());
  EXPECT_TRUE(rig.chip().flag_pin());
}

TEST(L6474, OtherPartsIgnoreTheDirPin) {
  Chain chain(1, l6470());
  ChainHost host(chain);
  host.step_clock(0, false);
  chain.chip(0).set_dir_pin(true);
  chain.chip(0).set_stck_pin(true);
  EXPECT_EQ(chain.chip(0).position(), -1) << "StepClock's direction, not the pin's";
}

TEST(L6474, AnAxisFollowsTheStckPulsesWithTheTvalCurrent) {
  Rig rig;
  rig.chip().attach_axis(AxisSpec{});
  rig.host.set_param(0, Reg::STEP_MODE, 0x8C);  // 1/16: a pulse is 8/128 step
  rig.chip().set_dir_pin(true);
  rig.host.enable(0);
  rig.pulses(0, 160);  // ten full steps
  ASSERT_NE(rig.chip().axis(), nullptr);
  EXPECT_EQ(rig.chip().axis()->true_position(), 10 * 128);
  EXPECT_EQ(rig.chip().axis()->lost_steps(), 0);
}

}  // namespace
}  // namespace l6470emu
