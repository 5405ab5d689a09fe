// STATUS of all six family members (spec §4.1 layouts, §4.2 latching, §3.9 ALARM_EN, §8;
// the L6474: docs/l6474.md):
// power-up words, where the error, step-clock, thermal, ADC-undervoltage and stall flags sit,
// the stall-bit quirk, and which ALARM_EN bit pulls FLAG low on which part.
// Expected words are worked out bit by bit from the spec's layouts.
#include <gtest/gtest.h>

#include <cstdint>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

#include "core/chip.hpp"
#include "core/quirks.hpp"
#include "core/variant.hpp"
#include "support/test_support.hpp"

namespace l6470emu {
namespace {

std::string hex(std::uint32_t v) {
  std::ostringstream s;
  s << "0x" << std::hex << std::uppercase << v;
  return s.str();
}

constexpr std::uint8_t kGetStatus = 0xD0;
constexpr std::uint8_t kHardStop = 0xB8;
constexpr std::uint8_t kUnknownOpcode = 0xE0;  // in no command table (spec §5.1)

constexpr std::uint16_t bit(unsigned n) { return static_cast<std::uint16_t>(1u << n); }

// Spec §4.1. STATUS words below are built from these positions:
//   L6470:  15 SCK_MOD, 14 STEP_LOSS_B_n, 13 STEP_LOSS_A_n, 12 OCD_n, 11 TH_SD_n, 10 TH_WRN_n,
//           9 UVLO_n, 8 WRONG_CMD, 7 NOTPERF_CMD, 6:5 MOT_STATUS, 4 DIR, 3 SW_EVN, 2 SW_F, 1 BUSY_n, 0 HiZ
//   L6472:  the L6470 layout, bits 14:13 unused (read 0, the documented choice)
//   L6480 / powerSTEP01: 15 STALL_B_n, 14 STALL_A_n, 13 OCD_n, 12:11 TH_STATUS, 10 UVLO_ADC_n,
//           9 UVLO_n, 8 STCK_MOD, 7 CMD_ERROR, 6:0 as the L6470
//   L6482:  the L6480 layout, bits 15:14 unused (read 0)
//   L6474:  the L6470's flags where the L6470 has them, without BUSY, SW_F, SW_EVN, MOT_STATUS,
//           STEP_LOSS or SCK_MOD; bits 15, 14, 13 and 1 read 1, bits 6, 5, 3 and 2 read 0
// At power-up: HiZ = 1, BUSY_n = 1 (not busy), DIR = 0, UVLO latched (bit 9 = 0), every other
// active-low flag inactive (1), UVLO_ADC inactive, TH_STATUS 00.
struct Case {
  const Variant* variant;
  std::uint8_t status_address;
  bool cmd_error;                  // one CMD_ERROR bit 7 instead of WRONG_CMD 8 + NOTPERF_CMD 7
  std::uint16_t power_up;
  std::uint16_t quiet;             // after one GetStatus: UVLO released
  std::string label;
};

Case case_for(const Variant* v) {
  const std::string_view n = v->name;
  Case c{v, 0x19, false, 0, 0, std::string(n)};
  if (n == "L6470") {
    c.power_up = bit(14) | bit(13) | bit(12) | bit(11) | bit(10) | bit(1) | bit(0);  // 0x7C03
  } else if (n == "L6472") {
    c.power_up = bit(12) | bit(11) | bit(10) | bit(1) | bit(0);  // 0x1C03
  } else if (n == "L6480" || n == "powerSTEP01") {
    c.status_address = 0x1B;
    c.cmd_error = true;
    c.power_up = bit(15) | bit(14) | bit(13) | bit(10) | bit(1) | bit(0);  // 0xE403
  } else if (n == "L6482") {
    c.status_address = 0x1B;
    c.cmd_error = true;
    c.power_up = bit(13) | bit(10) | bit(1) | bit(0);  // 0x2403
  } else if (n == "L6474") {
    c.power_up = bit(15) | bit(14) | bit(13) | bit(12) | bit(11) | bit(10) | bit(1) | bit(0);  // 0xFC03
  }
  c.quiet = c.power_up | bit(9);
  return c;
}

/// gtest prints a case by its label.
void PrintTo(const Case& c, std::ostream* os) { *os << c.label; }

std::vector<Case> all_cases() {
  std::vector<Case> out;
  for (const Variant* v : all_variants()) out.push_back(case_for(v));
  return out;
}

/// The parts with a motion engine (Run, Move, StepClock): all but the L6474.
std::vector<Case> motion_cases() {
  std::vector<Case> out;
  for (const Variant* v : all_variants())
    if (v->motion_engine) out.push_back(case_for(v));
  return out;
}

/// One chip behind its own chip-select; the host sends one byte per frame.
struct Rig {
  explicit Rig(const Variant& v, Quirks q = {}) : chain(1, v, q), host(chain) {}
  Chain chain;
  ChainHost host;
  Chip& chip() { return chain.chip(0); }
  std::vector<std::uint8_t> send(const std::vector<std::uint8_t>& bytes) { return host.send(0, bytes); }
  std::uint16_t get_status() {
    const auto m = send({kGetStatus, 0x00, 0x00});
    return static_cast<std::uint16_t>(m[1] << 8 | m[2]);
  }
  std::uint16_t get_param_status(std::uint8_t address) {
    const auto m = send({static_cast<std::uint8_t>(0x20 | address), 0x00, 0x00});
    return static_cast<std::uint16_t>(m[1] << 8 | m[2]);
  }
};

class EveryVariantsStatus : public ::testing::TestWithParam<Case> {
 protected:
  const Case& kase() const { return GetParam(); }
  const Variant& variant() const { return *GetParam().variant; }
};

INSTANTIATE_TEST_SUITE_P(VariantStatus, EveryVariantsStatus, ::testing::ValuesIn(all_cases()),
                         [](const ::testing::TestParamInfo<Case>& i) { return i.param.label; });

/// The same, on the parts that run a motor by themselves.
class EveryMotionVariantsStatus : public EveryVariantsStatus {};

INSTANTIATE_TEST_SUITE_P(VariantStatus, EveryMotionVariantsStatus, ::testing::ValuesIn(motion_cases()),
                         [](const ::testing::TestParamInfo<Case>& i) { return i.param.label; });

TEST_P(EveryVariantsStatus, IsOneTheSpecDescribes) { ASSERT_NE(kase().power_up, 0) << variant().name; }

// ---------------------------------------------------------------- power-up

TEST_P(EveryVariantsStatus, ReadsThePowerUpWordThroughGetParamWithoutClearingIt) {
  Rig rig(variant());
  EXPECT_EQ(hex(rig.get_param_status(kase().status_address)), hex(kase().power_up));
  EXPECT_EQ(hex(rig.get_param_status(kase().status_address)), hex(kase().power_up));
}

TEST_P(EveryVariantsStatus, AnswersThePowerUpWordToTheFirstGetStatusAndTheQuietWordToTheSecond) {
  Rig rig(variant());
  EXPECT_EQ(hex(rig.get_status()), hex(kase().power_up));
  EXPECT_EQ(hex(rig.get_status()), hex(kase().quiet));
  EXPECT_EQ(hex(rig.get_param_status(kase().status_address)), hex(kase().quiet));
}

TEST(VariantStatus, PowerUpWordsAreTheOnesWorkedOutFromTheLayouts) {
  // The same numbers as above, written as the hex words a reader would look for.
  EXPECT_EQ(case_for(&l6470()).power_up, 0x7C03);
  EXPECT_EQ(case_for(&l6470()).quiet, 0x7E03);
  EXPECT_EQ(case_for(&l6472()).power_up, 0x1C03);
  EXPECT_EQ(case_for(&l6472()).quiet, 0x1E03);
  EXPECT_EQ(case_for(&l6480()).power_up, 0xE403);
  EXPECT_EQ(case_for(&l6480()).quiet, 0xE603);
  EXPECT_EQ(case_for(&l6482()).power_up, 0x2403);
  EXPECT_EQ(case_for(&l6482()).quiet, 0x2603);
  EXPECT_EQ(case_for(&powerstep01()).power_up, 0xE403);
  EXPECT_EQ(case_for(&powerstep01()).quiet, 0xE603);
  EXPECT_EQ(case_for(&l6474()).power_up, 0xFC03);
  EXPECT_EQ(case_for(&l6474()).quiet, 0xFE03);
}

// ---------------------------------------------------------------- command errors

TEST_P(EveryVariantsStatus, FlagsAnUnknownOpcodeOnWrongCmdBit8OrOnCmdErrorBit7) {
  Rig rig(variant());
  rig.get_status();
  rig.send({kUnknownOpcode});
  const std::uint16_t flag = kase().cmd_error ? bit(7) : bit(8);
  EXPECT_EQ(hex(rig.get_status()), hex(kase().quiet | flag));
  EXPECT_EQ(hex(rig.get_status()), hex(kase().quiet));
}

TEST_P(EveryMotionVariantsStatus, FlagsARefusedCommandOnBit7NotperfCmdOrCmdError) {
  // Move while the motor runs is not performable (spec §5.2).
  Rig rig(variant());
  rig.get_status();
  rig.send({0x51, 0x00, 0x40, 0x00});  // Run forward
  rig.host.wait_ms(2);
  const std::uint16_t running = rig.get_status();
  ASSERT_NE(running & (3u << 5), 0u);
  rig.send({0x41, 0x00, 0x00, 0x10});  // Move forward 16: refused
  const std::uint16_t s = rig.get_status();
  EXPECT_EQ(s & bit(7), bit(7)) << hex(s);
  EXPECT_EQ(s & bit(8), 0u) << hex(s) << ": bit 8 is WRONG_CMD / STCK_MOD, not for refusals";
  EXPECT_EQ(rig.get_status() & bit(7), 0u);
}

TEST_P(EveryVariantsStatus, FlagsASetParamRefusedByItsWriteConditionOnBit7) {
  Rig rig(variant());
  rig.get_status();
  rig.send({kHardStop});           // bridges enabled
  rig.send({0x16, 0x03});          // STEP_MODE is WH: refused
  const std::uint16_t s = rig.get_status();
  EXPECT_EQ(s & bit(7), bit(7)) << hex(s);
  EXPECT_EQ(s & bit(8), 0u) << hex(s);
}

TEST(VariantStatus, GateDriverPartsShowBothKindsOfErrorOnTheOneCmdErrorBit7) {
  for (const Variant* v : {&l6480(), &l6482(), &powerstep01()}) {
    SCOPED_TRACE(std::string(v->name));
    const Case c = case_for(v);
    Rig rig(*v);
    rig.get_status();
    rig.send({kUnknownOpcode});
    EXPECT_EQ(hex(rig.get_status()), hex(c.quiet | bit(7)));
    rig.send({kHardStop, 0x16, 0x03});  // WH write with the bridges enabled
    EXPECT_EQ(hex(rig.get_status()), hex((c.quiet & ~bit(0)) | bit(7)));
  }
}

TEST(VariantStatus, L6470AndL6472KeepWrongCmdOnBit8ApartFromNotperfCmdOnBit7) {
  for (const Variant* v : {&l6470(), &l6472()}) {
    SCOPED_TRACE(std::string(v->name));
    const Case c = case_for(v);
    Rig rig(*v);
    rig.get_status();
    rig.send({kUnknownOpcode, kHardStop, 0x16, 0x03});
    EXPECT_EQ(hex(rig.get_status()), hex((c.quiet & ~bit(0)) | bit(8) | bit(7)));
  }
}

TEST(VariantStatus, CmdErrorLatchesUntilGetStatusAndGetParamDoesNotClearIt) {
  // UNCONFIRMED (L6480/powerSTEP01 "latch like the L6470 flags"): the flag outlives the command.
  for (const Variant* v : {&l6480(), &l6482(), &powerstep01()}) {
    SCOPED_TRACE(std::string(v->name));
    const Case c = case_for(v);
    Rig rig(*v);
    rig.get_status();
    rig.send({kUnknownOpcode});
    rig.host.wait_ms(10);
    EXPECT_EQ(hex(rig.get_param_status(0x1B)), hex(c.quiet | bit(7)));
    EXPECT_EQ(hex(rig.get_param_status(0x1B)), hex(c.quiet | bit(7)));
    EXPECT_EQ(hex(rig.get_status()), hex(c.quiet | bit(7)));
    EXPECT_EQ(hex(rig.get_status()), hex(c.quiet));
  }
}

// ---------------------------------------------------------------- step-clock mode

TEST_P(EveryMotionVariantsStatus, ShowsStepClockModeOnStckModBit8OrSckModBit15) {
  Rig rig(variant());
  rig.get_status();
  rig.send({0x59});  // StepClock forward: bridges enabled, DIR forward, BUSY not pulled low
  const std::uint16_t flag = kase().cmd_error ? bit(8) : bit(15);
  const std::uint16_t want = static_cast<std::uint16_t>((kase().quiet & ~bit(0)) | bit(4) | flag);
  EXPECT_EQ(hex(rig.get_status()), hex(want));
  // Stop commands keep step-clock mode (docs/motion-rules.md); a constant-speed command leaves it.
  rig.send({kHardStop});
  EXPECT_EQ(rig.get_status() & flag, flag);
  rig.send({0x51, 0x00, 0x10, 0x00});  // Run forward
  EXPECT_EQ(rig.get_status() & flag, 0u);
}

TEST(VariantStatus, StepClockWordsAreTheOnesWorkedOutFromTheLayouts) {
  const std::uint16_t want[] = {0xFE12, 0x9E12, 0xE712, 0x2712, 0xE712};
  std::size_t i = 0;
  for (const Variant* v : {&l6470(), &l6472(), &l6480(), &l6482(), &powerstep01()}) {  // the L6474 has no StepClock
    SCOPED_TRACE(std::string(v->name));
    Rig rig(*v);
    rig.get_status();
    rig.send({0x59});
    EXPECT_EQ(hex(rig.get_status()), hex(want[i++]));
  }
}

// ---------------------------------------------------------------- thermal

struct ThermalWords {
  std::uint16_t warning, bridge_shutdown, device_shutdown;
};

ThermalWords thermal_words(const Case& c) {
  if (c.cmd_error)  // TH_STATUS on 12:11: 01 warning, 10 bridge shutdown, 11 device shutdown
    return {static_cast<std::uint16_t>(c.quiet | bit(11)), static_cast<std::uint16_t>(c.quiet | bit(12)),
            static_cast<std::uint16_t>(c.quiet | bit(12) | bit(11))};
  // TH_WRN_n on 10, TH_SD_n on 11: a shutdown is above the warning level too
  const auto w = static_cast<std::uint16_t>(c.quiet & ~bit(10));
  const auto sd = static_cast<std::uint16_t>(c.quiet & ~bit(10) & ~bit(11));
  return {w, sd, sd};
}

TEST_P(EveryVariantsStatus, EncodesTheDieTemperatureAsTheLayoutSays) {
  const ThermalWords words = thermal_words(kase());
  const std::pair<Thermal, std::uint16_t> steps[] = {
      {Thermal::warning, words.warning},
      {Thermal::bridge_shutdown, words.bridge_shutdown},
      {Thermal::device_shutdown, words.device_shutdown},
  };
  for (const auto& [t, want] : steps) {
    SCOPED_TRACE(static_cast<int>(t));
    Rig rig(variant());
    rig.get_status();
    rig.chip().set_thermal(t);
    EXPECT_EQ(hex(rig.get_param_status(kase().status_address)), hex(want));
    // Latched: the die cools, the flag stays until GetStatus reports it.
    rig.chip().set_thermal(Thermal::normal);
    EXPECT_EQ(hex(rig.get_status()), hex(want));
    EXPECT_EQ(hex(rig.get_status()), hex(kase().quiet));
  }
}

TEST(VariantStatus, ThStatusOnTheGateDriverPartsIs01ForAWarning10ForABridgeShutdownAnd11ForADeviceShutdown) {
  for (const Variant* v : {&l6480(), &l6482(), &powerstep01()}) {
    SCOPED_TRACE(std::string(v->name));
    for (const auto& [t, code] : {std::pair{Thermal::warning, 1u}, std::pair{Thermal::bridge_shutdown, 2u},
                                  std::pair{Thermal::device_shutdown, 3u}}) {
      Rig rig(*v);
      rig.get_status();
      rig.chip().set_thermal(t);
      const std::uint16_t s = rig.get_status();
      EXPECT_EQ((s >> 11) & 3u, code) << hex(s);
      EXPECT_EQ(s & bit(10), bit(10)) << "UVLO_ADC untouched";
      EXPECT_EQ(s & bit(13), bit(13)) << "OCD untouched";
    }
  }
}

TEST(VariantStatus, ThStatusLatchesUntilGetStatusAndStaysWhileTheDieIsHot) {
  // UNCONFIRMED (L6480 list): TH_STATUS latches like the L6470's TH_WRN/TH_SD.
  Rig rig(l6480());
  rig.get_status();
  rig.chip().set_thermal(Thermal::warning);
  EXPECT_EQ(hex(rig.get_status()), hex(0xEE03));
  EXPECT_EQ(hex(rig.get_status()), hex(0xEE03)) << "still hot: GetStatus cannot release it";
  rig.chip().set_thermal(Thermal::normal);
  EXPECT_EQ(hex(rig.get_param_status(0x1B)), hex(0xEE03)) << "latched";
  EXPECT_EQ(hex(rig.get_status()), hex(0xEE03));
  EXPECT_EQ(hex(rig.get_status()), hex(0xE603));
}

// ---------------------------------------------------------------- ADC undervoltage

TEST_P(EveryVariantsStatus, ShowsAnAdcUndervoltageOnUvloAdcBit10OnlyOnTheGateDriverParts) {
  Rig rig(variant());
  rig.get_status();
  rig.chip().set_adc_undervoltage(true);
  const std::uint16_t want = kase().cmd_error ? static_cast<std::uint16_t>(kase().quiet & ~bit(10)) : kase().quiet;
  EXPECT_EQ(hex(rig.get_status()), hex(want));
  EXPECT_EQ(hex(rig.get_status()), hex(want)) << "the condition is still there";
  rig.chip().set_adc_undervoltage(false);
  EXPECT_EQ(hex(rig.get_param_status(kase().status_address)), hex(want)) << "latched until GetStatus";
  EXPECT_EQ(hex(rig.get_status()), hex(want));
  EXPECT_EQ(hex(rig.get_status()), hex(kase().quiet));
}

TEST(VariantStatus, UvloAdcLatchesUntilGetStatusOnTheL6480) {
  Rig rig(l6480());
  rig.get_status();
  rig.chip().set_adc_undervoltage(true);
  rig.chip().set_adc_undervoltage(false);  // a short dip
  EXPECT_EQ(hex(rig.get_status()), hex(0xE203));
  EXPECT_EQ(hex(rig.get_status()), hex(0xE603));
}

// ---------------------------------------------------------------- stall flags

struct StallWords {
  std::uint16_t a, b;
};

Quirks stall_order(StallBitOrder o) {
  Quirks q;
  q.stall_bits = o;
  return q;
}

StallWords stall_words(const Variant& v, StallBitOrder order) {
  Rig rig(v, stall_order(order));
  rig.get_status();
  rig.chip().set_stall(Bridge::A, true);
  const std::uint16_t a = rig.get_status();
  rig.chip().set_stall(Bridge::A, false);
  rig.get_status();
  rig.chip().set_stall(Bridge::B, true);
  const std::uint16_t b = rig.get_status();
  return {a, b};
}

TEST(VariantStatus, StallAIsBit14AndStallBIsBit15OnTheL6480AndPowerStep01ByDefault) {
  for (const Variant* v : {&l6480(), &powerstep01()}) {
    SCOPED_TRACE(std::string(v->name));
    const StallWords w = stall_words(*v, StallBitOrder::a_on_14);
    EXPECT_EQ(hex(w.a), hex(0xE603 & ~bit(14)));  // 0xA603
    EXPECT_EQ(hex(w.b), hex(0xE603 & ~bit(15)));  // 0x6603
  }
}

TEST(VariantStatus, StallBitsSwapWithTheQuirkAOn15) {
  for (const Variant* v : {&l6480(), &powerstep01()}) {
    SCOPED_TRACE(std::string(v->name));
    const StallWords w = stall_words(*v, StallBitOrder::a_on_15);
    EXPECT_EQ(hex(w.a), hex(0xE603 & ~bit(15)));
    EXPECT_EQ(hex(w.b), hex(0xE603 & ~bit(14)));
  }
}

TEST(VariantStatus, StallFlagsLatchUntilGetStatus) {
  Rig rig(powerstep01());
  rig.get_status();
  rig.chip().set_stall(Bridge::B, true);
  rig.chip().set_stall(Bridge::B, false);
  EXPECT_EQ(hex(rig.get_param_status(0x1B)), hex(0x6603));
  EXPECT_EQ(hex(rig.get_status()), hex(0x6603));
  EXPECT_EQ(hex(rig.get_status()), hex(0xE603));
}

TEST(VariantStatus, L6470KeepsStepLossAOnBit13AndStepLossBOnBit14) {
  const StallWords w = stall_words(l6470(), StallBitOrder::a_on_14);
  EXPECT_EQ(hex(w.a), hex(0x7E03 & ~bit(13)));  // 0x5E03
  EXPECT_EQ(hex(w.b), hex(0x7E03 & ~bit(14)));  // 0x3E03
}

TEST(VariantStatus, StallBitQuirkLeavesTheL6470Alone) {
  // The STALL_A/STALL_B conflict (spec §4.1) is about the gate-driver parts only; the L6470's
  // STEP_LOSS_A = 13, STEP_LOSS_B = 14 is [C] (DS70r3 Table 34). quirks.hpp documents the
  // switch as "on the L6480 and powerSTEP01".
  // (Regression: the quirk once swapped the L6470's bits 13/14 too.)
  const StallWords w = stall_words(l6470(), StallBitOrder::a_on_15);
  EXPECT_EQ(hex(w.a), hex(0x5E03));
  EXPECT_EQ(hex(w.b), hex(0x3E03));
}

TEST(VariantStatus, L6472AndL6482HaveNoStallBitsWhateverTheQuirk) {
  for (const Variant* v : {&l6472(), &l6482()}) {
    for (StallBitOrder o : {StallBitOrder::a_on_14, StallBitOrder::a_on_15}) {
      SCOPED_TRACE(std::string(v->name) + (o == StallBitOrder::a_on_14 ? " a_on_14" : " a_on_15"));
      const std::uint16_t quiet = case_for(v).quiet;
      const StallWords w = stall_words(*v, o);
      EXPECT_EQ(hex(w.a), hex(quiet));
      EXPECT_EQ(hex(w.b), hex(quiet));
    }
  }
}

TEST(VariantStatus, L6472ReadsBits13And14AsZeroAndL6482ReadsBits14And15AsZero) {
  Rig l6472_rig(l6472());
  EXPECT_EQ(l6472_rig.get_status() & (bit(13) | bit(14)), 0u);
  Rig l6482_rig(l6482());
  EXPECT_EQ(l6482_rig.get_status() & (bit(14) | bit(15)), 0u);
}

// ---------------------------------------------------------------- ALARM_EN and FLAG (spec §3.9)

enum class Event { adc_uvlo, stall_a, stall_b };

const char* to_string(Event e) {
  switch (e) {
    case Event::adc_uvlo: return "ADC undervoltage";
    case Event::stall_a: return "stall on bridge A";
    case Event::stall_b: return "stall on bridge B";
  }
  return "?";
}

/// FLAG after `e` with only `alarm_en` enabled, starting from a quiet chip.
bool flag_low_after(const Variant& v, std::uint8_t alarm_en, Event e) {
  Rig rig(v);
  rig.get_status();
  rig.send({0x17, alarm_en});  // ALARM_EN (WS; the motor is stopped)
  EXPECT_TRUE(rig.chip().flag_pin()) << "FLAG released before the event";
  switch (e) {
    case Event::adc_uvlo: rig.chip().set_adc_undervoltage(true); break;
    case Event::stall_a: rig.chip().set_stall(Bridge::A, true); break;
    case Event::stall_b: rig.chip().set_stall(Bridge::B, true); break;
  }
  return !rig.chip().flag_pin();
}

struct AlarmExpectation {
  std::uint8_t alarm_en;
  Event event;
  bool flag_low;
};

void expect_alarms(const Variant& v, std::initializer_list<AlarmExpectation> rows) {
  for (const auto& r : rows) {
    EXPECT_EQ(flag_low_after(v, r.alarm_en, r.event), r.flag_low)
        << v.name << ": ALARM_EN " << hex(r.alarm_en) << ", " << to_string(r.event);
  }
}

TEST(VariantAlarms, L6470Bit4IsStallAAndBit5IsStallB) {
  expect_alarms(l6470(), {{0x10, Event::stall_a, true},
                          {0x10, Event::stall_b, false},
                          {0x10, Event::adc_uvlo, false},
                          {0x20, Event::stall_a, false},
                          {0x20, Event::stall_b, true},
                          {0x20, Event::adc_uvlo, false}});
}

TEST(VariantAlarms, L6480AndPowerStep01Bit4IsAdcUvloAndBit5IsAStallOnEitherBridge) {
  for (const Variant* v : {&l6480(), &powerstep01()}) {
    expect_alarms(*v, {{0x10, Event::adc_uvlo, true},
                       {0x10, Event::stall_a, false},
                       {0x10, Event::stall_b, false},
                       {0x20, Event::adc_uvlo, false},
                       {0x20, Event::stall_a, true},
                       {0x20, Event::stall_b, true}});
  }
}

TEST(VariantAlarms, L6482Bit4IsAdcUvloAndBit5EnablesNothing) {
  expect_alarms(l6482(), {{0x10, Event::adc_uvlo, true},
                          {0x10, Event::stall_a, false},
                          {0x10, Event::stall_b, false},
                          {0x20, Event::adc_uvlo, false},
                          {0x20, Event::stall_a, false},
                          {0x20, Event::stall_b, false}});
}

TEST(VariantAlarms, L6472Bits4And5EnableNothing) {
  expect_alarms(l6472(), {{0x10, Event::adc_uvlo, false},
                          {0x10, Event::stall_a, false},
                          {0x10, Event::stall_b, false},
                          {0x20, Event::adc_uvlo, false},
                          {0x20, Event::stall_a, false},
                          {0x20, Event::stall_b, false},
                          {0xFF, Event::adc_uvlo, false},
                          {0xFF, Event::stall_a, false},
                          {0xFF, Event::stall_b, false}});
}

TEST(VariantAlarms, L6474Bits4To6EnableNothing) {
  // No stall detection, no ADC undervoltage, no SW input: ALARM_EN bits 4, 5 and 6 have nothing
  // to enable (docs/l6474.md, UNCONFIRMED).
  expect_alarms(l6474(), {{0x70, Event::adc_uvlo, false}, {0x70, Event::stall_a, false}, {0x70, Event::stall_b, false}});
  Rig rig(l6474());
  rig.get_status();
  rig.send({0x17, 0x40});
  rig.chip().set_sw_pin(false);  // the pin is not there: no turn-on event
  EXPECT_TRUE(rig.chip().flag_pin());
  EXPECT_EQ(hex(rig.get_status()), hex(0xFE03));
}

TEST_P(EveryVariantsStatus, SharesTheMeaningOfAlarmBits0To3And6And7) {
  // bit 0 overcurrent, 1 thermal shutdown, 2 thermal warning, 3 UVLO, 6 switch turn-on,
  // 7 wrong or not-performable command: the same on every part (spec §3.9; L6472 assumed;
  // the L6474, without a SW input, has nothing for bit 6 to enable: VariantAlarms.L6474*).
  struct Trigger {
    std::uint8_t bit;
    const char* what;
    void (*fire)(Rig&);
  };
  const Trigger triggers[] = {
      {0, "overcurrent", [](Rig& r) { r.chip().set_overcurrent(true); }},
      {1, "thermal shutdown", [](Rig& r) { r.chip().set_thermal(Thermal::bridge_shutdown); }},
      {2, "thermal warning", [](Rig& r) { r.chip().set_thermal(Thermal::warning); }},
      {3, "undervoltage", [](Rig& r) { r.chip().set_undervoltage(true); }},
      {6, "switch turn-on", [](Rig& r) { r.chip().set_sw_pin(false); }},
      {7, "unknown opcode", [](Rig& r) { r.send({kUnknownOpcode}); }},
      {7, "refused command", [](Rig& r) { r.send({kHardStop, 0x16, 0x03}); }},
  };
  for (const Trigger& t : triggers) {
    if (t.bit == 6 && !variant().pins.sw) continue;  // no SW input (the L6474): nothing turns on
    for (std::uint8_t enabled : {static_cast<std::uint8_t>(1u << t.bit), static_cast<std::uint8_t>(~(1u << t.bit))}) {
      SCOPED_TRACE(std::string(t.what) + ", ALARM_EN " + hex(enabled));
      Rig rig(variant());
      rig.get_status();
      rig.send({0x17, enabled});
      ASSERT_TRUE(rig.chip().flag_pin());
      t.fire(rig);
      const bool own_bit = (enabled >> t.bit) & 1u;
      // the warning is also below a shutdown, so "thermal shutdown" sets bit 2's alarm too
      const bool also = t.bit == 1 && ((enabled >> 2) & 1u);
      EXPECT_EQ(!rig.chip().flag_pin(), own_bit || also);
    }
  }
}

TEST_P(EveryVariantsStatus, PullsFlagLowAtPowerUpThroughTheUvloAlarmAndReleasesItOnGetStatus) {
  Rig rig(variant());
  EXPECT_FALSE(rig.chip().flag_pin());
  rig.get_status();
  EXPECT_TRUE(rig.chip().flag_pin());
}

}  // namespace
}  // namespace l6470emu
