// The L6470 register map (spec §2.1, datasheet Table 9) checked through SPI:
// addresses, widths, SPI lengths, reset values, access classes, masking and sign extension.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "core/chip.hpp"
#include "core/variant.hpp"
#include "support/test_support.hpp"

namespace l6470emu {
namespace {

using namespace test::status_bits;

// ---------------------------------------------------------------- the spec's table

struct Row {
  std::uint8_t address;
  Reg id;
  const char* name;
  std::uint8_t bits;
  std::uint8_t bytes;
  std::optional<std::uint32_t> reset;  // nullopt: "depends" in the datasheet (ADC_OUT, STATUS)
  Access access;
};

// Copied from spec/dspin-reference.md §2.1, not from the model.
const Row kSpecTable[] = {
    {0x01, Reg::ABS_POS, "ABS_POS", 22, 3, 0x000000, Access::WS},
    {0x02, Reg::EL_POS, "EL_POS", 9, 2, 0x000, Access::WS},
    {0x03, Reg::MARK, "MARK", 22, 3, 0x000000, Access::WR},
    {0x04, Reg::SPEED, "SPEED", 20, 3, 0x00000, Access::R},
    {0x05, Reg::ACC, "ACC", 12, 2, 0x08A, Access::WS},
    {0x06, Reg::DEC, "DEC", 12, 2, 0x08A, Access::WS},
    {0x07, Reg::MAX_SPEED, "MAX_SPEED", 10, 2, 0x041, Access::WR},
    {0x08, Reg::MIN_SPEED, "MIN_SPEED", 13, 2, 0x000, Access::WS},
    {0x09, Reg::KVAL_HOLD, "KVAL_HOLD", 8, 1, 0x29, Access::WR},
    {0x0A, Reg::KVAL_RUN, "KVAL_RUN", 8, 1, 0x29, Access::WR},
    {0x0B, Reg::KVAL_ACC, "KVAL_ACC", 8, 1, 0x29, Access::WR},
    {0x0C, Reg::KVAL_DEC, "KVAL_DEC", 8, 1, 0x29, Access::WR},
    {0x0D, Reg::INT_SPEED, "INT_SPEED", 14, 2, 0x0408, Access::WH},
    {0x0E, Reg::ST_SLP, "ST_SLP", 8, 1, 0x19, Access::WH},
    {0x0F, Reg::FN_SLP_ACC, "FN_SLP_ACC", 8, 1, 0x29, Access::WH},
    {0x10, Reg::FN_SLP_DEC, "FN_SLP_DEC", 8, 1, 0x29, Access::WH},
    {0x11, Reg::K_THERM, "K_THERM", 4, 1, 0x0, Access::WR},
    {0x12, Reg::ADC_OUT, "ADC_OUT", 5, 1, std::nullopt, Access::R},
    {0x13, Reg::OCD_TH, "OCD_TH", 4, 1, 0x8, Access::WR},
    {0x14, Reg::STALL_TH, "STALL_TH", 7, 1, 0x40, Access::WR},
    {0x15, Reg::FS_SPD, "FS_SPD", 10, 2, 0x027, Access::WR},
    {0x16, Reg::STEP_MODE, "STEP_MODE", 8, 1, 0x07, Access::WH},
    {0x17, Reg::ALARM_EN, "ALARM_EN", 8, 1, 0xFF, Access::WS},
    {0x18, Reg::CONFIG, "CONFIG", 16, 2, 0x2E88, Access::WH},
    {0x19, Reg::STATUS, "STATUS", 16, 2, std::nullopt, Access::R},
};

constexpr std::uint16_t kPowerUpStatus = 0x7C03;  // spec §4.2 / docs/chip-model.md

std::string hex(std::uint32_t v) {
  std::ostringstream s;
  s << "0x" << std::hex << std::uppercase << v;
  return s.str();
}

std::string trace(const Row& r) { return std::string(r.name) + " at " + hex(r.address); }

std::vector<std::uint8_t> send(test::OneChip& rig, std::vector<std::uint8_t> bytes) { return rig.host.send(0, bytes); }

/// SetParam(address, value) with `bytes` value bytes, MSB first, one CS frame per byte.
void set_param(test::OneChip& rig, std::uint8_t address, std::uint32_t value, unsigned bytes) {
  std::vector<std::uint8_t> tx{address};
  for (unsigned i = bytes; i-- > 0;) tx.push_back(static_cast<std::uint8_t>(value >> (8 * i)));
  send(rig, tx);
}

/// GetParam(address) followed by `bytes` NOPs; returns every MISO byte (opcode frame included).
std::vector<std::uint8_t> get_param_bytes(test::OneChip& rig, std::uint8_t address, unsigned bytes) {
  std::vector<std::uint8_t> tx(bytes + 1, 0x00);
  tx[0] = static_cast<std::uint8_t>(0x20 | address);
  return send(rig, tx);
}

/// What the MISO bytes of GetParam must be for `value`: 0x00 for the opcode, then MSB first.
std::vector<std::uint8_t> answer_bytes(std::uint32_t value, unsigned bytes) {
  std::vector<std::uint8_t> out{0x00};
  for (unsigned i = bytes; i-- > 0;) out.push_back(static_cast<std::uint8_t>(value >> (8 * i)));
  return out;
}

std::uint32_t all_ones(unsigned bytes) { return bytes >= 4 ? 0xFFFF'FFFFu : (1u << (8 * bytes)) - 1u; }
std::uint32_t mask_of(unsigned bits) { return (1u << bits) - 1u; }

constexpr std::uint16_t kNotPerfCmd = 1u << 7;

// ---------------------------------------------------------------- the table itself

TEST(RegisterTable, ListsExactlyTheTwentyFiveL6470RegistersInAddressOrder) {
  const Variant& v = l6470();
  ASSERT_EQ(v.registers.size(), std::size(kSpecTable));
  for (std::size_t i = 0; i < std::size(kSpecTable); ++i) {
    const Row& want = kSpecTable[i];
    SCOPED_TRACE(trace(want));
    const RegisterInfo& got = v.registers[i];
    EXPECT_EQ(got.address, want.address);
    EXPECT_EQ(got.id, want.id);
    EXPECT_EQ(got.name, want.name);
    EXPECT_EQ(got.bits, want.bits);
    EXPECT_EQ(got.spi_bytes(), want.bytes);
    EXPECT_EQ(got.mask(), mask_of(want.bits));
    EXPECT_EQ(got.access, want.access) << "table says " << to_string(want.access) << ", model has "
                                       << to_string(got.access);
    if (want.reset) {
      EXPECT_EQ(got.reset, *want.reset);
    }
  }
}

TEST(RegisterTable, FindsEachRegisterByAddressAndById) {
  const Variant& v = l6470();
  EXPECT_EQ(v.name, "L6470");
  for (const Row& want : kSpecTable) {
    SCOPED_TRACE(trace(want));
    const RegisterInfo* by_address = v.at_address(want.address);
    const RegisterInfo* by_id = v.find(want.id);
    ASSERT_NE(by_address, nullptr);
    ASSERT_NE(by_id, nullptr);
    EXPECT_EQ(by_address, by_id);
    EXPECT_TRUE(v.has(want.id));
  }
}

TEST(RegisterTable, HasNoRegisterAtAddressZeroNorAtTheReservedAddresses0x1AUpTo0x1F) {
  const Variant& v = l6470();
  EXPECT_EQ(v.at_address(0x00), nullptr);
  for (std::uint8_t a = 0x1A; a <= 0x1F; ++a) EXPECT_EQ(v.at_address(a), nullptr) << hex(a);
  EXPECT_EQ(v.at_address(0x20), nullptr);
}

TEST(RegisterTable, HasNoneOfTheGateDriverOrCurrentModeRegisters) {
  const Variant& v = l6470();
  for (Reg id : {Reg::GATECFG1, Reg::GATECFG2, Reg::TVAL_HOLD, Reg::TVAL_RUN, Reg::TVAL_ACC, Reg::TVAL_DEC,
                 Reg::T_FAST, Reg::TON_MIN, Reg::TOFF_MIN}) {
    EXPECT_FALSE(v.has(id)) << static_cast<int>(id);
  }
}

TEST(RegisterTable, MarksAbsPosAndMarkAsTheOnlySignedRegisters) {
  for (const RegisterInfo& r : l6470().registers) {
    const bool position = r.id == Reg::ABS_POS || r.id == Reg::MARK;
    EXPECT_EQ(r.is_signed(), position) << r.name;
  }
}

// ---------------------------------------------------------------- reset values over SPI

TEST(GetParam, ReadsEveryResetValueAfterPowerUp) {
  for (const Row& r : kSpecTable) {
    if (!r.reset) continue;
    SCOPED_TRACE(trace(r));
    test::OneChip rig;
    EXPECT_EQ(get_param_bytes(rig, r.address, r.bytes), answer_bytes(*r.reset, r.bytes));
  }
}

TEST(GetParam, ReadsStatus0x7C03AfterPowerUp) {
  test::OneChip rig;
  EXPECT_EQ(get_param_bytes(rig, 0x19, 2), (std::vector<std::uint8_t>{0x00, 0x7C, 0x03}));
}

TEST(GetParam, ReadsAdcOutAsTheConversionOfTheAdcinPin) {
  test::OneChip rig;
  rig.chip().set_adc_input(0x15);
  EXPECT_EQ(get_param_bytes(rig, 0x12, 1), (std::vector<std::uint8_t>{0x00, 0x15}));
  rig.chip().set_adc_input(0x1F);
  EXPECT_EQ(get_param_bytes(rig, 0x12, 1), (std::vector<std::uint8_t>{0x00, 0x1F}));
}

/// Moves every register away from its reset value (bridges in HiZ, motor stopped), then runs the motor.
void disturb_everything(test::OneChip& rig) {
  for (const Row& r : kSpecTable) {
    if (r.access == Access::R) continue;
    set_param(rig, r.address, all_ones(r.bytes), r.bytes);
  }
  send(rig, {0xEB});                    // latch WRONG_CMD
  send(rig, {0x51, 0x00, 0x10, 0x00});  // Run forward
  rig.host.wait_ms(5);
}

TEST(ResetDevice, RestoresEveryResetValueReadByGetParam) {
  test::OneChip rig;
  disturb_everything(rig);
  ASSERT_NE(rig.chip().peek(Reg::KVAL_RUN), 0x29u);
  send(rig, {0xC0});
  for (const Row& r : kSpecTable) {
    if (!r.reset) continue;
    SCOPED_TRACE(trace(r));
    EXPECT_EQ(get_param_bytes(rig, r.address, r.bytes), answer_bytes(*r.reset, r.bytes));
  }
  EXPECT_EQ(get_param_bytes(rig, 0x19, 2), answer_bytes(kPowerUpStatus, 2));
}

TEST(StbyRst, RisingEdgeRestoresEveryResetValue) {
  test::OneChip rig;
  disturb_everything(rig);
  rig.chip().set_stby_rst_pin(false);
  rig.host.wait(ticks_from_us(20));
  rig.chip().set_stby_rst_pin(true);
  rig.host.wait(ticks_from_us(45));
  for (const Row& r : kSpecTable) {
    if (!r.reset) continue;
    SCOPED_TRACE(trace(r));
    EXPECT_EQ(get_param_bytes(rig, r.address, r.bytes), answer_bytes(*r.reset, r.bytes));
  }
  EXPECT_EQ(get_param_bytes(rig, 0x19, 2), answer_bytes(kPowerUpStatus, 2));
}

// ---------------------------------------------------------------- write / read back

TEST(SetParam, WritesAllOnesToEveryWritableRegisterAndReadsBackTheMaskedValue) {
  // Like hardware test suites: power-up state (bridges HiZ, motor stopped), so WS and WH writes are accepted.
  for (const Row& r : kSpecTable) {
    if (r.access == Access::R) continue;
    SCOPED_TRACE(trace(r));
    test::OneChip rig;
    ASSERT_TRUE(rig.chip().hiz());
    set_param(rig, r.address, all_ones(r.bytes), r.bytes);
    EXPECT_EQ(get_param_bytes(rig, r.address, r.bytes), answer_bytes(mask_of(r.bits), r.bytes));
    EXPECT_EQ(rig.chip().peek(r.id), mask_of(r.bits));
    EXPECT_EQ(rig.chip().status() & (kWrongCmd | kNotPerfCmd), 0) << "write refused";
  }
}

TEST(SetParam, WritesAnAlternatingPatternToEveryWritableRegisterAndReadsItBack) {
  for (std::uint32_t pattern : {0x555555u, 0xAAAAAAu, 0x123456u}) {
    for (const Row& r : kSpecTable) {
      if (r.access == Access::R) continue;
      if (r.id == Reg::STEP_MODE) continue;  // a new STEP_SEL also moves EL_POS; covered elsewhere
      SCOPED_TRACE(trace(r) + " pattern " + hex(pattern));
      test::OneChip rig;
      const std::uint32_t value = pattern & all_ones(r.bytes);
      set_param(rig, r.address, value, r.bytes);
      EXPECT_EQ(get_param_bytes(rig, r.address, r.bytes), answer_bytes(value & mask_of(r.bits), r.bytes));
    }
  }
}

TEST(SetParam, IgnoresValueBitsAboveTheRegisterWidth) {
  for (const Row& r : kSpecTable) {
    if (r.access == Access::R || r.bits == 8u * r.bytes) continue;
    SCOPED_TRACE(trace(r));
    test::OneChip rig;
    const std::uint32_t above = all_ones(r.bytes) & ~mask_of(r.bits);
    set_param(rig, r.address, above | 0x1, r.bytes);
    EXPECT_EQ(get_param_bytes(rig, r.address, r.bytes), answer_bytes(0x1, r.bytes));
  }
}

TEST(SetParam, WritesOfOtherRegistersLeaveTheRestUnchanged) {
  test::OneChip rig;
  set_param(rig, 0x0A, 0x77, 1);       // KVAL_RUN
  set_param(rig, 0x03, 0x123456, 3);   // MARK
  for (const Row& r : kSpecTable) {
    if (!r.reset || r.id == Reg::KVAL_RUN || r.id == Reg::MARK) continue;
    EXPECT_EQ(rig.chip().peek(r.id), *r.reset) << r.name;
  }
  EXPECT_EQ(rig.chip().peek(Reg::KVAL_RUN), 0x77u);
  EXPECT_EQ(rig.chip().peek(Reg::MARK), 0x123456u);
}

// ---------------------------------------------------------------- 22-bit positions

TEST(AbsPos, MinusOneReads0x3FFFFFAndIsSignExtendedByTheModel) {
  test::OneChip rig;
  set_param(rig, 0x01, 0x3FFFFF, 3);
  EXPECT_EQ(get_param_bytes(rig, 0x01, 3), (std::vector<std::uint8_t>{0x00, 0x3F, 0xFF, 0xFF}));
  EXPECT_EQ(rig.chip().peek(Reg::ABS_POS), 0x3FFFFFu);
  EXPECT_EQ(rig.chip().position(), -1);
}

TEST(AbsPos, Bit21IsTheSignBit) {
  test::OneChip rig;
  set_param(rig, 0x01, 0x200000, 3);
  EXPECT_EQ(rig.chip().position(), -(1 << 21));
  EXPECT_EQ(get_param_bytes(rig, 0x01, 3), (std::vector<std::uint8_t>{0x00, 0x20, 0x00, 0x00}));
  set_param(rig, 0x01, 0x1FFFFF, 3);
  EXPECT_EQ(rig.chip().position(), (1 << 21) - 1);
  EXPECT_EQ(get_param_bytes(rig, 0x01, 3), (std::vector<std::uint8_t>{0x00, 0x1F, 0xFF, 0xFF}));
}

TEST(AbsPos, TopTwoBitsOfTheFirstValueByteDoNotMakeItNegative) {
  test::OneChip rig;
  set_param(rig, 0x01, 0xC00005, 3);
  EXPECT_EQ(rig.chip().position(), 5);
  EXPECT_EQ(get_param_bytes(rig, 0x01, 3), (std::vector<std::uint8_t>{0x00, 0x00, 0x00, 0x05}));
}

TEST(AbsPos, OneReverseMicrostepFromHomeReads0x3FFFFF) {
  test::OneChip rig;
  send(rig, {0x58});  // StepClock reverse
  rig.chip().set_stck_pin(true);
  rig.chip().set_stck_pin(false);
  EXPECT_EQ(get_param_bytes(rig, 0x01, 3), (std::vector<std::uint8_t>{0x00, 0x3F, 0xFF, 0xFF}));
  EXPECT_EQ(rig.chip().position(), -1);
}

TEST(AbsPos, WrapsFromPlusTwoToThe21MinusOneToMinusTwoToThe21) {
  // Natural 22-bit wrap (spec §3.1: UNCONFIRMED, assumed; docs/motion-rules.md).
  test::OneChip rig;
  set_param(rig, 0x01, 0x1FFFFF, 3);
  send(rig, {0x59});  // StepClock forward
  rig.chip().set_stck_pin(true);
  EXPECT_EQ(get_param_bytes(rig, 0x01, 3), (std::vector<std::uint8_t>{0x00, 0x20, 0x00, 0x00}));
  EXPECT_EQ(rig.chip().position(), -(1 << 21));
}

TEST(Mark, MinusOneReads0x3FFFFFAndTheDumpShowsTheSign) {
  test::OneChip rig;
  set_param(rig, 0x03, 0x3FFFFF, 3);
  EXPECT_EQ(get_param_bytes(rig, 0x03, 3), (std::vector<std::uint8_t>{0x00, 0x3F, 0xFF, 0xFF}));
  EXPECT_EQ(rig.chip().peek(Reg::MARK), 0x3FFFFFu);
  std::istringstream lines(rig.chip().dump());
  bool found = false;
  for (std::string line; std::getline(lines, line);) {
    if (line.find("MARK") == std::string::npos) continue;
    found = true;
    EXPECT_NE(line.find("(-1)"), std::string::npos) << line;
  }
  EXPECT_TRUE(found);
}

// ---------------------------------------------------------------- EL_POS and STEP_MODE

TEST(ElPos, KeepsTheFullStepIndexInBits8To7AndTheMicrostepInBits6To0) {
  test::OneChip rig;
  send(rig, {0x59});  // StepClock forward, 1/128 step: each STCK edge adds 1 to EL_POS
  for (int i = 0; i < 130; ++i) {
    rig.chip().set_stck_pin(true);
    rig.chip().set_stck_pin(false);
  }
  EXPECT_EQ(get_param_bytes(rig, 0x02, 2), answer_bytes(0x082, 2)) << "step 1, microstep 2";
}

TEST(ElPos, IsWrittenUnmaskedEvenWhenItDoesNotMatchTheStepMode) {
  // Spec §3.2: the device does not mask EL_POS to the selected step mode.
  test::OneChip rig;
  set_param(rig, 0x16, 0x00, 1);   // full step
  set_param(rig, 0x02, 0x0FF, 2);  // not a full-step position
  EXPECT_EQ(get_param_bytes(rig, 0x02, 2), answer_bytes(0x0FF, 2));
}

TEST(StepMode, ANewStepSelResetsElPosToTheFirstMicrostepOfItsStep) {
  // Spec §3.2 / DS70r3 §6.4; docs/chip-model.md: microstep bits cleared, full-step bits kept.
  test::OneChip rig;
  set_param(rig, 0x02, 0x1FF, 2);
  set_param(rig, 0x16, 0x03, 1);  // 1/8 step
  EXPECT_EQ(get_param_bytes(rig, 0x02, 2), answer_bytes(0x180, 2));
}

TEST(StepMode, RewritingTheSameStepSelLeavesElPos) {
  test::OneChip rig;
  set_param(rig, 0x02, 0x155, 2);
  set_param(rig, 0x16, 0x87, 1);  // SYNC_EN set, STEP_SEL still 1/128
  EXPECT_EQ(get_param_bytes(rig, 0x02, 2), answer_bytes(0x155, 2));
}

// ---------------------------------------------------------------- dump

TEST(Dump, ListsEveryRegisterWithItsAddressNameAndValue) {
  test::OneChip rig;
  set_param(rig, 0x01, 0x3FFFFF, 3);  // ABS_POS = -1
  set_param(rig, 0x0A, 0x77, 1);      // KVAL_RUN
  const std::string dump = rig.chip().dump();
  std::vector<std::string> lines;
  {
    std::istringstream in(dump);
    for (std::string line; std::getline(in, line);) lines.push_back(line);
  }
  EXPECT_NE(dump.find("L6470"), std::string::npos);
  for (const Row& r : kSpecTable) {
    SCOPED_TRACE(trace(r));
    char address[8];
    std::snprintf(address, sizeof address, "0x%02X", r.address);
    char value[16];
    std::snprintf(value, sizeof value, "0x%0*X", 2 * r.bytes, rig.chip().peek(r.id));
    int matches = 0;
    for (const auto& line : lines) {
      const auto at = line.find(std::string(" ") + r.name + " ");
      if (at == std::string::npos) continue;
      ++matches;
      EXPECT_NE(line.find(address), std::string::npos) << line;
      EXPECT_NE(line.find(value, at), std::string::npos) << line;
    }
    EXPECT_EQ(matches, 1) << dump;
  }
  // ABS_POS is signed: the dump shows the number as well.
  for (const auto& line : lines) {
    if (line.find(" ABS_POS ") != std::string::npos) {
      EXPECT_NE(line.find("(-1)"), std::string::npos) << line;
    }
  }
  EXPECT_EQ(dump.find("0x1A"), std::string::npos) << "reserved address listed";
  EXPECT_EQ(dump.find("0x1B"), std::string::npos) << "reserved address listed";
}

TEST(Dump, HasNoSideEffects) {
  test::OneChip rig;
  send(rig, {0xEB});  // WRONG_CMD latched
  const auto before = rig.chip().status();
  (void)rig.chip().dump();
  EXPECT_EQ(rig.chip().status(), before);
  EXPECT_EQ(get_param_bytes(rig, 0x19, 2), answer_bytes(before, 2));
}

}  // namespace
}  // namespace l6470emu
