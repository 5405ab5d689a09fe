// What the variants do differently, through SPI (spec §2-§5, §8, §9 item 3): CONFIG detection
// as drivers do it, 1/16 microstepping on the L6472/L6482, ACC = 0xFFF, threshold widths,
// BOOST_MODE, GATECFG1's two bytes, the powerSTEP01's current mode and conditional
// ResetDevice, and a daisy chain mixing variants.
#include <gtest/gtest.h>

#include <cstdint>
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
constexpr std::uint8_t kHardHiZ = 0xA8;
constexpr std::uint8_t kSoftStop = 0xB0;
constexpr std::uint8_t kResetDevice = 0xC0;
constexpr std::uint16_t kBit7 = 1u << 7;

unsigned mot_status(std::uint16_t s) { return (s >> 5) & 3u; }
constexpr unsigned kStopped = 0, kAccel = 1, kDecel = 2, kConst = 3;

std::vector<std::uint8_t> with_value(std::uint8_t opcode, std::uint32_t value, unsigned bytes) {
  std::vector<std::uint8_t> out{opcode};
  for (unsigned i = bytes; i-- > 0;) out.push_back(static_cast<std::uint8_t>(value >> (8 * i)));
  return out;
}

/// One chip behind its own chip-select; the host sends one byte per frame.
struct Rig {
  explicit Rig(const Variant& v, Quirks q = {}) : chain(1, v, q), host(chain) {}
  Chain chain;
  ChainHost host;
  Chip& chip() { return chain.chip(0); }
  std::vector<std::uint8_t> send(const std::vector<std::uint8_t>& bytes) { return host.send(0, bytes); }
  void set(std::uint8_t address, std::uint32_t value, unsigned bytes) { send(with_value(address, value, bytes)); }
  /// GetParam(address), `bytes` answer bytes and one more; returns every MISO byte.
  std::vector<std::uint8_t> get_bytes(std::uint8_t address, unsigned bytes) {
    std::vector<std::uint8_t> tx(bytes + 2, 0x00);
    tx[0] = static_cast<std::uint8_t>(0x20 | address);
    return send(tx);
  }
  std::uint32_t get(std::uint8_t address, unsigned bytes) {
    const auto m = get_bytes(address, bytes);
    std::uint32_t v = 0;
    for (unsigned i = 1; i <= bytes; ++i) v = (v << 8) | m[i];
    return v;
  }
  std::uint16_t get_status() {
    const auto m = send({kGetStatus, 0x00, 0x00});
    return static_cast<std::uint16_t>(m[1] << 8 | m[2]);
  }
  std::uint16_t get_param_status() {
    // STATUS is at 0x19 on the L6470/L6472 and at 0x1B on the gate-driver parts (spec §8)
    const std::uint8_t at = chip().variant().name == "L6470" || chip().variant().name == "L6472" ? 0x19 : 0x1B;
    return static_cast<std::uint16_t>(get(at, 2));
  }
  void run(bool forward, std::uint32_t spd) { set(static_cast<std::uint8_t>(0x50 | forward), spd, 3); }
  void move(bool forward, std::uint32_t n) { set(static_cast<std::uint8_t>(0x40 | forward), n, 3); }
  void pulse_stck() {
    chip().set_stck_pin(true);
    chip().set_stck_pin(false);
  }
};

bool is_gate_driver(const Variant& v) { return v.name == "L6480" || v.name == "L6482" || v.name == "powerSTEP01"; }
bool is_sixteenth_part(const Variant& v) { return v.name == "L6472" || v.name == "L6482" || v.name == "L6474"; }

/// The parts with a motion engine (all but the L6474).
std::vector<const Variant*> motion_variants() {
  std::vector<const Variant*> out;
  for (const Variant* v : all_variants())
    if (v->motion_engine) out.push_back(v);
  return out;
}

std::string variant_label(const ::testing::TestParamInfo<const Variant*>& i) { return std::string(i.param->name); }

// ---------------------------------------------------------------- CONFIG detection

TEST(VariantConfigDetection, GetParam0x18ReadsConfig0x2E88OnTheL6470) {
  Rig rig(l6470());
  EXPECT_EQ(rig.get_bytes(0x18, 2), (std::vector<std::uint8_t>{0x00, 0x2E, 0x88, 0x00}));
}

TEST(VariantConfigDetection, GetParam0x18ReadsGatecfg1ZeroOnTheL6480AndPowerStep01WhoseConfig0x2C88IsAt0x1A) {
  for (const Variant* v : {&l6480(), &powerstep01()}) {
    SCOPED_TRACE(std::string(v->name));
    Rig rig(*v);
    EXPECT_EQ(rig.get_bytes(0x18, 2), (std::vector<std::uint8_t>{0x00, 0x00, 0x00, 0x00})) << "GATECFG1";
    EXPECT_EQ(rig.get_bytes(0x1A, 2), (std::vector<std::uint8_t>{0x00, 0x2C, 0x88, 0x00})) << "CONFIG";
    EXPECT_EQ(rig.get_status() & kBit7, 0u) << "both are real registers";
  }
}

TEST(VariantConfigDetection, GetParam0x1AIsAnUnknownCommandOnTheL6470) {
  Rig rig(l6470());
  rig.get_status();
  EXPECT_EQ(rig.get_bytes(0x1A, 2), (std::vector<std::uint8_t>{0x00, 0x00, 0x00, 0x00}));
  EXPECT_EQ(rig.get_status(), 0x7E03 | (1u << 8)) << "WRONG_CMD";
}

TEST(VariantConfigDetection, TheCurrentModePartsAnswerAsTheirVoltageModeSiblings) {
  // L6472: CONFIG at 0x18 (its reset value is an UNCONFIRMED choice, 0x2E88); L6482: GATECFG1 at 0x18.
  Rig l6472_rig(l6472());
  EXPECT_EQ(l6472_rig.get(0x18, 2), 0x2E88u);
  Rig l6482_rig(l6482());
  EXPECT_EQ(l6482_rig.get(0x18, 2), 0x0000u);
  EXPECT_EQ(l6482_rig.get(0x1A, 2), 0x2C88u);
}

TEST(VariantConfigDetection, ADriverTellsTheFamiliesApartFromGetParam0x18Alone) {
  // What host libraries (AMY, Marlin's L64XX) do: 0x2E88 at 0x18 → L6470-style map.
  for (const Variant* v : all_variants()) {
    SCOPED_TRACE(std::string(v->name));
    Rig rig(*v);
    const bool looks_like_l647x = rig.get(0x18, 2) == 0x2E88;
    EXPECT_EQ(looks_like_l647x, !is_gate_driver(*v));
  }
}

// ---------------------------------------------------------------- microstepping

class FinestStep : public ::testing::TestWithParam<const Variant*> {};
INSTANTIATE_TEST_SUITE_P(VariantMicrostepping, FinestStep, ::testing::ValuesIn(all_variants()), variant_label);

TEST_P(FinestStep, StepSel7MovesElPosBy1OnThe128thPartsAndBy8OnThe16thParts) {
  // Spec §8: max microstep 1/128 (L6470, L6480, powerSTEP01) or 1/16 (L6472, L6482). EL_POS
  // counts 1/128 step (spec §3.2), ABS_POS counts microsteps of the selected mode (§3.1).
  const Variant& v = *GetParam();
  const std::uint32_t per_microstep = is_sixteenth_part(v) ? 8 : 1;
  Rig rig(v);
  ASSERT_EQ(rig.get(0x16, 1), 0x07u);
  if (v.motion_engine) {
    rig.send({0x59});  // StepClock forward
  } else {
    rig.chip().set_dir_pin(true);  // the L6474: DIR forward, then Enable (HardStop's opcode)
    rig.send({kHardStop});
  }
  rig.pulse_stck();
  EXPECT_EQ(rig.get(0x02, 2), per_microstep);
  EXPECT_EQ(rig.get(0x01, 3), 1u);
  const std::uint32_t per_full_step = 128 / per_microstep;
  for (std::uint32_t i = 1; i < per_full_step; ++i) rig.pulse_stck();
  EXPECT_EQ(rig.get(0x02, 2), 0x080u) << "one full step: STEP = 1, MICROSTEP = 0";
  EXPECT_EQ(rig.get(0x01, 3), per_full_step);
}

TEST(VariantMicrostepping, StepSel4To7AllMove8ElPosUnitsPerMicrostepOnTheL6472AndL6482) {
  for (const Variant* v : {&l6472(), &l6482()}) {
    for (std::uint8_t step_sel = 4; step_sel <= 7; ++step_sel) {
      SCOPED_TRACE(std::string(v->name) + " STEP_SEL " + std::to_string(step_sel));
      Rig rig(*v);
      rig.set(0x16, step_sel, 1);
      EXPECT_EQ(rig.get(0x16, 1), step_sel) << "stored as written";
      rig.send({0x59});
      for (int i = 0; i < 3; ++i) rig.pulse_stck();
      EXPECT_EQ(rig.get(0x02, 2), 24u);
      EXPECT_EQ(rig.get(0x01, 3), 3u) << "ABS_POS counts 1/16 steps";
    }
  }
}

TEST(VariantMicrostepping, StepSel0To3KeepTheirMeaningOnTheL6472AndL6482) {
  for (const Variant* v : {&l6472(), &l6482()}) {
    for (std::uint8_t step_sel = 0; step_sel <= 3; ++step_sel) {
      SCOPED_TRACE(std::string(v->name) + " STEP_SEL " + std::to_string(step_sel));
      Rig rig(*v);
      rig.set(0x16, step_sel, 1);
      rig.send({0x59});
      rig.pulse_stck();
      EXPECT_EQ(rig.get(0x02, 2), 128u >> step_sel);
    }
  }
}

TEST(VariantMicrostepping, AMoveOf16MicrostepsIsOneFullStepOnTheL6472AndL6482WhateverTheFinerStepSel) {
  for (const Variant* v : {&l6472(), &l6482()}) {
    for (std::uint8_t step_sel = 4; step_sel <= 7; ++step_sel) {
      SCOPED_TRACE(std::string(v->name) + " STEP_SEL " + std::to_string(step_sel));
      Rig rig(*v);
      rig.set(0x16, step_sel, 1);
      rig.move(true, 16);
      rig.host.wait_ms(500);
      const std::uint16_t s = rig.get_status();
      EXPECT_EQ(mot_status(s), kStopped);
      EXPECT_EQ(rig.get(0x01, 3), 16u);
      EXPECT_EQ(rig.get(0x02, 2), 0x080u);
    }
  }
}

TEST(VariantMicrostepping, A16thPartFollowsThe128thPartsMotionAtAnEighthOfItsResolution) {
  // Speeds are per full step whatever STEP_SEL (spec §6.1): a Move of 16 sixteenths on the
  // L6472 and of 128 128ths on the L6470, same profile, are the same motion.
  Rig fine(l6470());
  Rig coarse(l6472());
  fine.move(true, 128);
  coarse.move(true, 16);
  for (int ms = 0; ms <= 200; ms += 5) {
    SCOPED_TRACE(std::to_string(ms) + " ms");
    const std::uint32_t el_fine = fine.chip().peek(Reg::EL_POS);
    const std::uint32_t el_coarse = coarse.chip().peek(Reg::EL_POS);
    EXPECT_EQ(el_coarse, el_fine & ~7u);
    EXPECT_EQ(mot_status(fine.chip().status()), mot_status(coarse.chip().status()));
    fine.host.wait_ms(5);
    coarse.host.wait_ms(5);
  }
  EXPECT_EQ(fine.chip().position(), 128);
  EXPECT_EQ(coarse.chip().position(), 16);
}

TEST(VariantMicrostepping, L6482StepModeBit3IsStoredAsWrittenAndChangesNothing) {
  // CSPIN: "bit 3 must be written 1" on the L6482; the emulator stores it without meaning.
  std::vector<std::uint32_t> el;
  for (std::uint8_t step_mode : {0x04, 0x0C}) {
    SCOPED_TRACE(hex(step_mode));
    Rig rig(l6482());
    rig.set(0x16, step_mode, 1);
    EXPECT_EQ(rig.get(0x16, 1), step_mode);
    EXPECT_EQ(rig.chip().registers().at_address(0x09)->id, Reg::TVAL_HOLD) << "no mode switch";
    rig.set(0x09, 0xFF, 1);
    EXPECT_EQ(rig.get(0x09, 1), 0x7Fu);
    EXPECT_EQ(rig.get_status() & kBit7, 0u);
    rig.move(true, 20);
    rig.host.wait_ms(500);
    EXPECT_EQ(rig.get(0x01, 3), 20u);
    el.push_back(rig.get(0x02, 2));
  }
  EXPECT_EQ(el[0], el[1]);
  EXPECT_EQ(el[0], 0x080u + 4 * 8);
}

TEST(VariantMicrostepping, PowerStep01Steps128thsInCurrentModeAsInVoltageMode) {
  for (std::uint8_t step_mode : {0x07, 0x0F}) {  // CM_VM = 0 / 1, STEP_SEL 1/128
    SCOPED_TRACE(hex(step_mode));
    Rig rig(powerstep01());
    rig.set(0x16, step_mode, 1);
    rig.send({0x59});
    rig.pulse_stck();
    EXPECT_EQ(rig.get(0x02, 2), 1u);
    rig.send({kHardStop});
    rig.move(true, 127);
    rig.host.wait_ms(500);
    EXPECT_EQ(rig.get(0x01, 3), 128u);
    EXPECT_EQ(rig.get(0x02, 2), 0x080u);
  }
}

// ---------------------------------------------------------------- ACC = 0xFFF

class InfiniteAcceleration : public ::testing::TestWithParam<const Variant*> {};
INSTANTIATE_TEST_SUITE_P(VariantAcceleration, InfiniteAcceleration, ::testing::ValuesIn(motion_variants()), variant_label);

TEST_P(InfiniteAcceleration, Acc0xFFFSkipsTheRampsExceptOnTheL6472WhereItIsAnOrdinaryAcceleration) {
  // Spec §6.2/§8: 0xFFF = infinite acceleration on the L6470/L6480/L6482/powerSTEP01; reserved on
  // the L6472, which the emulator runs as 4095 * 14.55 = 59590 step/s² (UNCONFIRMED choice).
  const Variant& v = *GetParam();
  const bool ordinary = v.name == "L6472";
  const std::uint32_t spd = test::spd_from_steps_per_s(500);
  Rig rig(v);
  rig.set(0x05, 0xFFF, 2);  // ACC
  rig.set(0x06, 0xFFF, 2);  // DEC
  rig.get_status();
  rig.run(true, spd);
  rig.host.wait_ms(1);
  std::uint16_t s = rig.get_status();
  std::uint32_t speed = rig.get(0x04, 3);
  if (ordinary) {
    EXPECT_EQ(mot_status(s), kAccel);
    const double sps = test::steps_per_s_from_speed(speed);
    EXPECT_GT(sps, 40.0);  // 1 ms at 59590 step/s² ≈ 60 step/s
    EXPECT_LT(sps, 80.0);
    rig.host.wait_ms(4);  // 5 ms ≈ 298 step/s
    EXPECT_NEAR(test::steps_per_s_from_speed(rig.get(0x04, 3)), 298.0, 10.0);
    rig.host.wait_ms(10);  // the ramp to 500 step/s takes 8.4 ms
    s = rig.get_status();
    speed = rig.get(0x04, 3);
  }
  EXPECT_EQ(mot_status(s), kConst);
  EXPECT_EQ(speed, spd);

  rig.send({kSoftStop});
  rig.host.wait_ms(1);
  s = rig.get_status();
  if (ordinary) {
    EXPECT_EQ(mot_status(s), kDecel) << "DEC = 0xFFF is a deceleration too";
    EXPECT_NEAR(test::steps_per_s_from_speed(rig.get(0x04, 3)), 440.0, 20.0);
    rig.host.wait_ms(10);
    s = rig.get_status();
  }
  EXPECT_EQ(mot_status(s), kStopped);
  EXPECT_EQ(rig.get(0x04, 3), 0u);
}

// ---------------------------------------------------------------- register widths

TEST(VariantThresholds, OcdThIs4BitsOnTheL6470AndL6472And5BitsOnTheGateDriverParts) {
  for (const Variant* v : all_variants()) {
    SCOPED_TRACE(std::string(v->name));
    Rig rig(*v);
    rig.set(0x13, 0xFF, 1);
    EXPECT_EQ(rig.get(0x13, 1), is_gate_driver(*v) ? 0x1Fu : 0x0Fu);
  }
}

TEST(VariantThresholds, StallThIs7BitsOnTheL6470And5BitsOnTheL6480AndPowerStep01) {
  for (const Variant* v : {&l6470(), &l6480(), &powerstep01()}) {
    SCOPED_TRACE(std::string(v->name));
    Rig rig(*v);
    rig.set(0x14, 0xFF, 1);
    EXPECT_EQ(rig.get(0x14, 1), v->name == "L6470" ? 0x7Fu : 0x1Fu);
  }
}

TEST(VariantThresholds, TheL6472AndL6482HaveNoStallThAt0x14) {
  for (const Variant* v : {&l6472(), &l6482()}) {
    SCOPED_TRACE(std::string(v->name));
    Rig rig(*v);
    rig.get_status();
    EXPECT_EQ(rig.get_bytes(0x14, 1), (std::vector<std::uint8_t>{0x00, 0x00, 0x00}));
    const std::uint16_t wrong = is_gate_driver(*v) ? kBit7 : 1u << 8;
    EXPECT_EQ(rig.get_status() & wrong, wrong);
  }
}

TEST(VariantBoostMode, FsSpdBit10IsWritableOnTheGateDriverPartsAndMaskedOnTheL6470AndL6472) {
  for (const Variant* v : motion_variants()) {  // the L6474 has no FS_SPD
    SCOPED_TRACE(std::string(v->name));
    Rig rig(*v);
    rig.set(0x15, 0x0400 | 0x027, 2);  // BOOST_MODE + the reset threshold
    EXPECT_EQ(rig.get(0x15, 2), is_gate_driver(*v) ? 0x427u : 0x027u);
    rig.set(0x15, 0xFFFF, 2);
    EXPECT_EQ(rig.get(0x15, 2), is_gate_driver(*v) ? 0x7FFu : 0x3FFu);
    EXPECT_EQ(rig.get_status() & kBit7, 0u);
  }
}

TEST(VariantGateConfig, Gatecfg1TakesTwoSpiBytesAndHolds12Bits) {
  for (const Variant* v : {&l6480(), &l6482(), &powerstep01()}) {
    SCOPED_TRACE(std::string(v->name));
    Rig rig(*v);
    rig.get_status();
    // two value bytes, then a GetStatus that must be decoded as a command
    const auto miso = rig.send({0x18, 0xFF, 0xFF, kGetStatus, 0x00, 0x00});
    const std::uint8_t quiet_msb = v->name == "L6482" ? 0x26 : 0xE6;  // 0x2603 / 0xE603 (spec §4.1)
    EXPECT_EQ(miso, (std::vector<std::uint8_t>{0x00, 0x00, 0x00, 0x00, quiet_msb, 0x03}));
    EXPECT_EQ(rig.get_bytes(0x18, 2), (std::vector<std::uint8_t>{0x00, 0x0F, 0xFF, 0x00}));
    rig.set(0x18, 0x0ABC, 2);
    EXPECT_EQ(rig.get(0x18, 2), 0xABCu);
  }
}

TEST(VariantGateConfig, Gatecfg2TakesOneSpiByte) {
  for (const Variant* v : {&l6480(), &l6482(), &powerstep01()}) {
    SCOPED_TRACE(std::string(v->name));
    Rig rig(*v);
    rig.get_status();
    const auto miso = rig.send({0x19, 0xA5, kGetStatus, 0x00, 0x00});
    EXPECT_NE(miso[3] | miso[4], 0) << "GetStatus answered";
    EXPECT_EQ(rig.get_bytes(0x19, 1), (std::vector<std::uint8_t>{0x00, 0xA5, 0x00}));
  }
}

TEST(VariantGateConfig, AOneByteGatecfg1WriteAsInCspinSwallowsTheNextCommand) {
  // CSPIN sends GATECFG1 with one byte (spec §2.3 CONFLICT, treated as a CSPIN bug): the chip
  // waits for the second value byte and takes the next command byte for it.
  Rig rig(l6480());
  rig.get_status();
  const auto miso = rig.send({0x18, 0x05, kGetStatus, 0x00, 0x00});
  EXPECT_EQ(miso, (std::vector<std::uint8_t>{0x00, 0x00, 0x00, 0x00, 0x00}));
  EXPECT_EQ(rig.get(0x18, 2), 0x5D0u) << "0x05D0: the GetStatus opcode became the low byte";
}

// ---------------------------------------------------------------- the BEMF write-condition quirk on CONFIG

TEST(VariantBemfQuirk, ConfigIsWhOnEveryVariantByDefault) {
  for (const Variant* v : all_variants()) {
    SCOPED_TRACE(std::string(v->name));
    Rig rig(*v);
    const std::uint8_t config = is_gate_driver(*v) ? 0x1A : 0x18;
    const std::uint32_t before = rig.get(config, 2);
    rig.get_status();
    rig.send({kHardStop});
    rig.set(config, before ^ 0x0010, 2);  // SW_MODE flipped
    EXPECT_EQ(rig.get_status() & kBit7, kBit7);
    EXPECT_EQ(rig.get(config, 2), before);
  }
}

TEST(VariantBemfQuirk, WhenStoppedLetsConfigBeWrittenWithTheBridgesEnabledOnEveryVariant) {
  // docs/quirks.md: `bemf_write` is the write condition of INT_SPEED, ST_SLP, FN_SLP_ACC,
  // FN_SLP_DEC and CONFIG, with no variant excepted; every variant has a CONFIG.
  // (Regression: the L6472/L6482 CONFIG rows once ignored the quirk.)
  Quirks q;
  q.bemf_write = BemfWriteCondition::when_stopped;
  for (const Variant* v : all_variants()) {
    SCOPED_TRACE(std::string(v->name));
    Rig rig(*v, q);
    const std::uint8_t config = is_gate_driver(*v) ? 0x1A : 0x18;
    const std::uint32_t before = rig.get(config, 2);
    rig.get_status();
    rig.send({kHardStop});
    rig.set(config, before ^ 0x0010, 2);
    EXPECT_EQ(rig.get_status() & kBit7, 0u);
    EXPECT_EQ(rig.get(config, 2), before ^ 0x0010);
  }
}

// ---------------------------------------------------------------- powerSTEP01 current mode

TEST(VariantCurrentMode, PowerStep01CmVmSetMakes0x09ReadAsTvalHoldWith7Bits) {
  Rig rig(powerstep01());
  rig.send({kHardStop, kHardHiZ});  // STEP_MODE is WH
  rig.set(0x16, 0x0F, 1);           // CM_VM = 1
  EXPECT_EQ(rig.get(0x16, 1), 0x0Fu);
  ASSERT_EQ(rig.chip().registers().at_address(0x09)->id, Reg::TVAL_HOLD);
  rig.set(0x09, 0xFF, 1);
  EXPECT_EQ(rig.get_bytes(0x09, 1), (std::vector<std::uint8_t>{0x00, 0x7F, 0x00}));
  EXPECT_EQ(rig.host.get_param(0, Reg::TVAL_HOLD), 0x7Fu);
}

TEST(VariantCurrentMode, PowerStep01CmVmClearedBringsKvalHoldBackWith8Bits) {
  Rig rig(powerstep01());
  rig.send({kHardHiZ});
  rig.set(0x16, 0x0F, 1);
  rig.set(0x16, 0x07, 1);  // CM_VM = 0
  ASSERT_EQ(rig.chip().registers().at_address(0x09)->id, Reg::KVAL_HOLD);
  rig.set(0x09, 0xFF, 1);
  EXPECT_EQ(rig.get(0x09, 1), 0xFFu);
  EXPECT_EQ(rig.host.get_param(0, Reg::KVAL_HOLD), 0xFFu);
}

TEST(VariantCurrentMode, PowerStep01ModesShareStorageReadAndWrittenAtTheWidthInForce) {
  // Documented choice (powerSTEP01 `unconfirmed`): one storage per address, the mode in force
  // sets the width, so a TVAL read masks bit 7 of a KVAL and a TVAL write stores 7 bits.
  Rig rig(powerstep01());
  rig.send({kHardHiZ});
  rig.set(0x09, 0xFF, 1);  // KVAL_HOLD
  rig.set(0x0E, 0xAB, 1);  // ST_SLP
  rig.set(0x0F, 0xFF, 1);  // FN_SLP_ACC
  rig.set(0x10, 0x80, 1);  // FN_SLP_DEC
  rig.set(0x16, 0x0F, 1);
  EXPECT_EQ(rig.get(0x09, 1), 0x7Fu) << "TVAL_HOLD sees 7 of KVAL_HOLD's 8 bits";
  EXPECT_EQ(rig.get(0x0E, 1), 0xABu) << "T_FAST is ST_SLP's storage, 8 bits";
  EXPECT_EQ(rig.get(0x0F, 1), 0x7Fu) << "TON_MIN";
  EXPECT_EQ(rig.get(0x10, 1), 0x00u) << "TOFF_MIN";
  rig.set(0x16, 0x07, 1);
  EXPECT_EQ(rig.get(0x09, 1), 0xFFu) << "reading masked; the stored KVAL_HOLD is intact";
  EXPECT_EQ(rig.get(0x10, 1), 0x80u);
  rig.set(0x16, 0x0F, 1);
  rig.set(0x09, 0xFF, 1);  // TVAL_HOLD write: 7 bits stored
  rig.set(0x0A, 0x55, 1);  // TVAL_RUN
  rig.set(0x16, 0x07, 1);
  EXPECT_EQ(rig.get(0x09, 1), 0x7Fu) << "KVAL_HOLD after a TVAL_HOLD write of 0xFF";
  EXPECT_EQ(rig.get(0x0A, 1), 0x55u) << "KVAL_RUN";
  EXPECT_EQ(rig.get_status() & kBit7, 0u);
}

TEST(VariantCurrentMode, PowerStep01CannotSwitchModeWithTheBridgesEnabled) {
  Rig rig(powerstep01());
  rig.get_status();
  rig.send({kHardStop});
  rig.set(0x16, 0x0F, 1);
  EXPECT_EQ(rig.get_status() & kBit7, kBit7) << "STEP_MODE is WH: CMD_ERROR";
  EXPECT_EQ(rig.get(0x16, 1), 0x07u);
  EXPECT_EQ(rig.chip().registers().at_address(0x09)->id, Reg::KVAL_HOLD);
}

TEST(VariantCurrentMode, ResetDeviceReturnsThePowerStep01ToVoltageMode) {
  Rig rig(powerstep01());
  rig.set(0x16, 0x0F, 1);
  rig.send({kResetDevice});
  EXPECT_EQ(rig.get(0x16, 1), 0x07u);
  EXPECT_EQ(rig.chip().registers().at_address(0x09)->id, Reg::KVAL_HOLD);
  rig.set(0x09, 0xFF, 1);
  EXPECT_EQ(rig.get(0x09, 1), 0xFFu);
}

TEST(VariantCurrentMode, StepModeBit3SwitchesNothingOnTheOtherParts) {
  for (const Variant* v : {&l6470(), &l6472(), &l6480(), &l6482()}) {
    SCOPED_TRACE(std::string(v->name));
    Rig rig(*v);
    const Reg before = rig.chip().registers().at_address(0x09)->id;
    rig.set(0x16, 0x0F, 1);
    EXPECT_EQ(rig.chip().registers().at_address(0x09)->id, before);
    rig.set(0x09, 0xFF, 1);
    EXPECT_EQ(rig.get(0x09, 1), before == Reg::KVAL_HOLD ? 0xFFu : 0x7Fu);
  }
}

// ---------------------------------------------------------------- ResetDevice while enabled (spec §5.2, §9 item 3)

Quirks reset_device_as(ResetDeviceWhenEnabled r) {
  Quirks q;
  q.reset_device = r;
  return q;
}

TEST(VariantResetDevice, PowerStep01RefusesItWhileEnabledAsInTheCommunityReport0xE012To0xE092) {
  // The report: STATUS 0xE012 before, 0xE092 after ResetDevice. 0xE0xx has UVLO (b9) and
  // UVLO_ADC (b10) active: UVLO still latched from power-up (no GetStatus yet) and an ADC input
  // under its threshold (ADCIN left unconnected); 0x12 = DIR forward, not BUSY, bridges enabled.
  Rig rig(powerstep01());
  rig.chip().set_adc_undervoltage(true);
  rig.set(0x0A, 0x40, 1);                     // KVAL_RUN, to see whether a reset happens
  rig.run(true, test::spd_from_steps_per_s(100));
  rig.send({kHardStop});
  EXPECT_EQ(hex(rig.get_param_status()), hex(0xE012));
  rig.send({kResetDevice});
  EXPECT_EQ(hex(rig.get_param_status()), hex(0xE092)) << "CMD_ERROR";
  EXPECT_EQ(rig.get(0x0A, 1), 0x40u) << "nothing was reset";
  EXPECT_FALSE(rig.chip().hiz());

  rig.send({kHardHiZ, kResetDevice});  // works with the bridges in HiZ
  EXPECT_EQ(rig.get(0x0A, 1), 0x29u);
  EXPECT_TRUE(rig.chip().hiz());
  // power-up word; the ADC input is still low, so UVLO_ADC shows at once
  EXPECT_EQ(hex(rig.get_param_status()), hex(0xE403 & ~(1u << 10)));
}

TEST(VariantResetDevice, PowerStep01ResetDeviceRefusalTurnsStatus12Into92) {
  Rig rig(powerstep01());
  rig.get_status();
  rig.run(true, test::spd_from_steps_per_s(100));
  rig.send({kHardStop});
  EXPECT_EQ(hex(rig.get_status()), hex(0xE612));
  rig.send({kResetDevice});
  EXPECT_EQ(hex(rig.get_status()), hex(0xE692));
}

TEST(VariantResetDevice, TheOtherPartsResetWhileEnabledByDefault) {
  for (const Variant* v : {&l6470(), &l6472(), &l6480(), &l6482()}) {
    SCOPED_TRACE(std::string(v->name));
    Rig rig(*v);
    rig.get_status();
    rig.set(0x0A, 0x40, 1);
    rig.send({kHardStop, kResetDevice});
    EXPECT_EQ(rig.get(0x0A, 1), 0x29u);
    EXPECT_TRUE(rig.chip().hiz());
  }
}

TEST(VariantResetDevice, QuirkPerformedMakesThePowerStep01ResetWhileEnabled) {
  Rig rig(powerstep01(), reset_device_as(ResetDeviceWhenEnabled::performed));
  rig.get_status();
  rig.set(0x0A, 0x40, 1);
  rig.send({kHardStop, kResetDevice});
  EXPECT_EQ(rig.get(0x0A, 1), 0x29u);
  EXPECT_TRUE(rig.chip().hiz());
  EXPECT_EQ(hex(rig.get_status()), hex(0xE403));
}

TEST(VariantResetDevice, QuirkRefusedMakesTheL6470RefuseWhileEnabledWithNotperfCmd) {
  Rig rig(l6470(), reset_device_as(ResetDeviceWhenEnabled::refused));
  rig.get_status();
  rig.set(0x0A, 0x40, 1);
  rig.run(true, test::spd_from_steps_per_s(100));
  rig.send({kHardStop});
  EXPECT_EQ(hex(rig.get_status()), hex(0x7E12));
  rig.send({kResetDevice});
  EXPECT_EQ(hex(rig.get_status()), hex(0x7E92)) << "NOTPERF_CMD, bit 7";
  EXPECT_EQ(rig.get(0x0A, 1), 0x40u);
  rig.send({kHardHiZ, kResetDevice});
  EXPECT_EQ(rig.get(0x0A, 1), 0x29u);
  EXPECT_EQ(hex(rig.get_status()), hex(0x7C03));
}

TEST(VariantResetDevice, QuirkRefusedMakesThePowerStep01RefuseAsByDefault) {
  Rig rig(powerstep01(), reset_device_as(ResetDeviceWhenEnabled::refused));
  rig.get_status();
  rig.send({kHardStop, kResetDevice});
  EXPECT_EQ(rig.get_status() & kBit7, kBit7);
  EXPECT_FALSE(rig.chip().hiz());
}

TEST(VariantResetDevice, QuirkPerformedKeepsTheL6470Resetting) {
  Rig rig(l6470(), reset_device_as(ResetDeviceWhenEnabled::performed));
  rig.get_status();
  rig.set(0x0A, 0x40, 1);
  rig.send({kHardStop, kResetDevice});
  EXPECT_EQ(rig.get(0x0A, 1), 0x29u);
  EXPECT_EQ(hex(rig.get_status()), hex(0x7C03));
}

// ---------------------------------------------------------------- a mixed daisy chain

/// Chip 0 = L6470 (drives MISO), chip 1 = powerSTEP01, chip 2 = L6480.
struct MixedChain {
  Chain chain{std::vector<Chip>{Chip(l6470()), Chip(powerstep01()), Chip(l6480())}};
  ChainHost host{chain};
  std::vector<std::uint8_t> frame(std::vector<std::uint8_t> tx) {
    chain.advance_to(chain.now() + 8);
    return chain.frame(tx);
  }
  /// Every chip's STATUS by GetStatus in the same frames.
  std::vector<std::uint16_t> get_status_all() {
    frame({kGetStatus, kGetStatus, kGetStatus});
    const auto msb = frame({0, 0, 0});
    const auto lsb = frame({0, 0, 0});
    std::vector<std::uint16_t> out;
    for (std::size_t k = 0; k < 3; ++k) out.push_back(static_cast<std::uint16_t>(msb[k] << 8 | lsb[k]));
    return out;
  }
};

std::vector<std::string> hexes(const std::vector<std::uint16_t>& v) {
  std::vector<std::string> out;
  for (auto x : v) out.push_back(hex(x));
  return out;
}

TEST(VariantMixedChain, EachChipAnswersGetStatusInItsOwnSlotOfTheSameFrames) {
  MixedChain mc;
  EXPECT_EQ(hexes(mc.get_status_all()), (std::vector<std::string>{"0x7C03", "0xE403", "0xE403"}));
  EXPECT_EQ(hexes(mc.get_status_all()), (std::vector<std::string>{"0x7E03", "0xE603", "0xE603"}));
}

TEST(VariantMixedChain, EachChipAnswersGetParamConfigAtItsOwnAddressInItsOwnSlot) {
  MixedChain mc;
  mc.frame({0x38, 0x3A, 0x3A});
  EXPECT_EQ(mc.frame({0, 0, 0}), (std::vector<std::uint8_t>{0x2E, 0x2C, 0x2C}));
  EXPECT_EQ(mc.frame({0, 0, 0}), (std::vector<std::uint8_t>{0x88, 0x88, 0x88}));
}

TEST(VariantMixedChain, TheSameAddressMeansConfigOnTheL6470AndGatecfg1OnTheOthers) {
  MixedChain mc;
  mc.frame({0x38, 0x38, 0x38});
  EXPECT_EQ(mc.frame({0, 0, 0}), (std::vector<std::uint8_t>{0x2E, 0x00, 0x00}));
  EXPECT_EQ(mc.frame({0, 0, 0}), (std::vector<std::uint8_t>{0x88, 0x00, 0x00}));
}

TEST(VariantMixedChain, TheSameUnknownByteRaisesWrongCmdOnTheL6470AndCmdErrorOnTheOthers) {
  MixedChain mc;
  mc.get_status_all();
  mc.frame({0xE0, 0xE0, 0xE0});
  EXPECT_EQ(hexes(mc.get_status_all()), (std::vector<std::string>{"0x7F03", "0xE683", "0xE683"}));
}

TEST(VariantMixedChain, AMoveOnOneChipLeavesTheOthersUntouched) {
  MixedChain mc;
  mc.get_status_all();
  mc.host.move(1, true, 200);
  mc.host.wait_ms(2000);
  EXPECT_EQ(mc.host.get_param(1, Reg::ABS_POS), 200u);
  EXPECT_EQ(mc.host.get_param(0, Reg::ABS_POS), 0u);
  EXPECT_EQ(mc.host.get_param(2, Reg::ABS_POS), 0u);
  EXPECT_EQ(mc.host.get_param(0, Reg::EL_POS), 0u);
  EXPECT_EQ(mc.host.get_param(2, Reg::EL_POS), 0u);
  // the mover: stopped, bridges enabled, DIR forward; the others: as after power-up and GetStatus
  EXPECT_EQ(hexes(mc.get_status_all()), (std::vector<std::string>{"0x7E03", "0xE612", "0xE603"}));
}

TEST(VariantMixedChain, CommandsOfDifferentLengthsEndTogetherAndLandEachInItsOwnChip) {
  MixedChain mc;
  // L6470 CONFIG (2 bytes), powerSTEP01 GATECFG2 (1 byte), L6480 CONFIG at 0x1A (2 bytes)
  mc.host.send_all({{0x18, 0x2E, 0x98}, {0x19, 0x5A}, {0x1A, 0x2C, 0x98}});
  EXPECT_EQ(mc.host.get_param(0, Reg::CONFIG), 0x2E98u);
  EXPECT_EQ(mc.host.get_param(1, Reg::GATECFG2), 0x5Au);
  EXPECT_EQ(mc.host.get_param(2, Reg::CONFIG), 0x2C98u);
  EXPECT_EQ(mc.host.get_param(1, Reg::CONFIG), 0x2C88u);
  EXPECT_EQ(mc.host.get_param(2, Reg::GATECFG2), 0x00u);
}

}  // namespace
}  // namespace l6470emu
