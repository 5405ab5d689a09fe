// The register maps of all six family members (spec §2.1-§2.5, §8; the L6474: docs/l6474.md) checked row by row
// and through SPI: reset values, SPI lengths, widths, write conditions, holes, read-only
// registers, and the look-up of variants by name. Expected tables are written from the spec.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <optional>
#include <ostream>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "core/chip.hpp"
#include "core/quirks.hpp"
#include "core/variant.hpp"
#include "support/test_support.hpp"

namespace l6470emu {
namespace {

// ---------------------------------------------------------------- the spec's tables

struct Row {
  std::uint8_t address;
  Reg id;
  const char* name;
  std::uint8_t bits;
  std::uint8_t bytes;                  // SPI length: ceil(bits / 8) (spec §2 preamble)
  std::optional<std::uint32_t> reset;  // nullopt: "depends" (ADC_OUT on the ADCIN pin, STATUS)
  Access access;
};

using Table = std::vector<Row>;
using enum Access;

// Spec §2.1 (DS70r3 Table 9), [C].
const Table kL6470 = {
    {0x01, Reg::ABS_POS, "ABS_POS", 22, 3, 0x000000, WS},
    {0x02, Reg::EL_POS, "EL_POS", 9, 2, 0x000, WS},
    {0x03, Reg::MARK, "MARK", 22, 3, 0x000000, WR},
    {0x04, Reg::SPEED, "SPEED", 20, 3, 0x00000, R},
    {0x05, Reg::ACC, "ACC", 12, 2, 0x08A, WS},
    {0x06, Reg::DEC, "DEC", 12, 2, 0x08A, WS},
    {0x07, Reg::MAX_SPEED, "MAX_SPEED", 10, 2, 0x041, WR},
    {0x08, Reg::MIN_SPEED, "MIN_SPEED", 13, 2, 0x000, WS},
    {0x09, Reg::KVAL_HOLD, "KVAL_HOLD", 8, 1, 0x29, WR},
    {0x0A, Reg::KVAL_RUN, "KVAL_RUN", 8, 1, 0x29, WR},
    {0x0B, Reg::KVAL_ACC, "KVAL_ACC", 8, 1, 0x29, WR},
    {0x0C, Reg::KVAL_DEC, "KVAL_DEC", 8, 1, 0x29, WR},
    {0x0D, Reg::INT_SPEED, "INT_SPEED", 14, 2, 0x0408, WH},
    {0x0E, Reg::ST_SLP, "ST_SLP", 8, 1, 0x19, WH},
    {0x0F, Reg::FN_SLP_ACC, "FN_SLP_ACC", 8, 1, 0x29, WH},
    {0x10, Reg::FN_SLP_DEC, "FN_SLP_DEC", 8, 1, 0x29, WH},
    {0x11, Reg::K_THERM, "K_THERM", 4, 1, 0x0, WR},
    {0x12, Reg::ADC_OUT, "ADC_OUT", 5, 1, std::nullopt, R},
    {0x13, Reg::OCD_TH, "OCD_TH", 4, 1, 0x8, WR},
    {0x14, Reg::STALL_TH, "STALL_TH", 7, 1, 0x40, WR},
    {0x15, Reg::FS_SPD, "FS_SPD", 10, 2, 0x027, WR},
    {0x16, Reg::STEP_MODE, "STEP_MODE", 8, 1, 0x07, WH},
    {0x17, Reg::ALARM_EN, "ALARM_EN", 8, 1, 0xFF, WS},
    {0x18, Reg::CONFIG, "CONFIG", 16, 2, 0x2E88, WH},
    {0x19, Reg::STATUS, "STATUS", 16, 2, std::nullopt, R},
};

// Spec §2.2: the L6470 map with TVAL_* (7 bits) at 0x09-0x0C, T_FAST/TON_MIN/TOFF_MIN at
// 0x0E-0x10, no INT_SPEED, K_THERM or STALL_TH. UNCONFIRMED in the spec; the widths of
// T_FAST (8: two 4-bit fields) and TON_MIN/TOFF_MIN (7: 0.5..64 us) are the L6482's (§2.4),
// access classes those of the L6470 rows at the same addresses, reset values the
// variant's documented choice (L6470/L6482 values; CONFIG 0x2E88 as on the L6470).
const Table kL6472 = {
    {0x01, Reg::ABS_POS, "ABS_POS", 22, 3, 0x000000, WS},
    {0x02, Reg::EL_POS, "EL_POS", 9, 2, 0x000, WS},
    {0x03, Reg::MARK, "MARK", 22, 3, 0x000000, WR},
    {0x04, Reg::SPEED, "SPEED", 20, 3, 0x00000, R},
    {0x05, Reg::ACC, "ACC", 12, 2, 0x08A, WS},
    {0x06, Reg::DEC, "DEC", 12, 2, 0x08A, WS},
    {0x07, Reg::MAX_SPEED, "MAX_SPEED", 10, 2, 0x041, WR},
    {0x08, Reg::MIN_SPEED, "MIN_SPEED", 13, 2, 0x000, WS},
    {0x09, Reg::TVAL_HOLD, "TVAL_HOLD", 7, 1, 0x29, WR},
    {0x0A, Reg::TVAL_RUN, "TVAL_RUN", 7, 1, 0x29, WR},
    {0x0B, Reg::TVAL_ACC, "TVAL_ACC", 7, 1, 0x29, WR},
    {0x0C, Reg::TVAL_DEC, "TVAL_DEC", 7, 1, 0x29, WR},
    {0x0E, Reg::T_FAST, "T_FAST", 8, 1, 0x19, WH},
    {0x0F, Reg::TON_MIN, "TON_MIN", 7, 1, 0x29, WH},
    {0x10, Reg::TOFF_MIN, "TOFF_MIN", 7, 1, 0x29, WH},
    {0x12, Reg::ADC_OUT, "ADC_OUT", 5, 1, std::nullopt, R},
    {0x13, Reg::OCD_TH, "OCD_TH", 4, 1, 0x8, WR},
    {0x15, Reg::FS_SPD, "FS_SPD", 10, 2, 0x027, WR},
    {0x16, Reg::STEP_MODE, "STEP_MODE", 8, 1, 0x07, WH},
    {0x17, Reg::ALARM_EN, "ALARM_EN", 8, 1, 0xFF, WS},
    {0x18, Reg::CONFIG, "CONFIG", 16, 2, 0x2E88, WH},
    {0x19, Reg::STATUS, "STATUS", 16, 2, std::nullopt, R},
};

// Spec §2.3: 5-bit OCD_TH (0x08) and STALL_TH (0x10), FS_SPD 11 bits (BOOST_MODE bit 10),
// GATECFG1 (12 bits, 2 bytes) and GATECFG2 at 0x18/0x19, CONFIG 0x2C88 at 0x1A, STATUS at 0x1B.
const Table kL6480 = {
    {0x01, Reg::ABS_POS, "ABS_POS", 22, 3, 0x000000, WS},
    {0x02, Reg::EL_POS, "EL_POS", 9, 2, 0x000, WS},
    {0x03, Reg::MARK, "MARK", 22, 3, 0x000000, WR},
    {0x04, Reg::SPEED, "SPEED", 20, 3, 0x00000, R},
    {0x05, Reg::ACC, "ACC", 12, 2, 0x08A, WS},
    {0x06, Reg::DEC, "DEC", 12, 2, 0x08A, WS},
    {0x07, Reg::MAX_SPEED, "MAX_SPEED", 10, 2, 0x041, WR},
    {0x08, Reg::MIN_SPEED, "MIN_SPEED", 13, 2, 0x000, WS},
    {0x09, Reg::KVAL_HOLD, "KVAL_HOLD", 8, 1, 0x29, WR},
    {0x0A, Reg::KVAL_RUN, "KVAL_RUN", 8, 1, 0x29, WR},
    {0x0B, Reg::KVAL_ACC, "KVAL_ACC", 8, 1, 0x29, WR},
    {0x0C, Reg::KVAL_DEC, "KVAL_DEC", 8, 1, 0x29, WR},
    {0x0D, Reg::INT_SPEED, "INT_SPEED", 14, 2, 0x0408, WH},
    {0x0E, Reg::ST_SLP, "ST_SLP", 8, 1, 0x19, WH},
    {0x0F, Reg::FN_SLP_ACC, "FN_SLP_ACC", 8, 1, 0x29, WH},
    {0x10, Reg::FN_SLP_DEC, "FN_SLP_DEC", 8, 1, 0x29, WH},
    {0x11, Reg::K_THERM, "K_THERM", 4, 1, 0x0, WR},
    {0x12, Reg::ADC_OUT, "ADC_OUT", 5, 1, std::nullopt, R},
    {0x13, Reg::OCD_TH, "OCD_TH", 5, 1, 0x08, WR},
    {0x14, Reg::STALL_TH, "STALL_TH", 5, 1, 0x10, WR},
    {0x15, Reg::FS_SPD, "FS_SPD", 11, 2, 0x027, WR},
    {0x16, Reg::STEP_MODE, "STEP_MODE", 8, 1, 0x07, WH},
    {0x17, Reg::ALARM_EN, "ALARM_EN", 8, 1, 0xFF, WS},
    {0x18, Reg::GATECFG1, "GATECFG1", 12, 2, 0x000, WH},
    {0x19, Reg::GATECFG2, "GATECFG2", 8, 1, 0x00, WH},
    {0x1A, Reg::CONFIG, "CONFIG", 16, 2, 0x2C88, WH},
    {0x1B, Reg::STATUS, "STATUS", 16, 2, std::nullopt, R},
};

// Spec §2.4: holes at 0x0D, 0x11, 0x14; TVAL_*/TON_MIN/TOFF_MIN 7 bits, T_FAST 8; OCD_TH 5 bits;
// reset values ST's cSPIN defaults (UNCONFIRMED, the variant's documented choice); access
// classes those of the L6480 rows at the same addresses (spec silent).
const Table kL6482 = {
    {0x01, Reg::ABS_POS, "ABS_POS", 22, 3, 0x000000, WS},
    {0x02, Reg::EL_POS, "EL_POS", 9, 2, 0x000, WS},
    {0x03, Reg::MARK, "MARK", 22, 3, 0x000000, WR},
    {0x04, Reg::SPEED, "SPEED", 20, 3, 0x00000, R},
    {0x05, Reg::ACC, "ACC", 12, 2, 0x08A, WS},
    {0x06, Reg::DEC, "DEC", 12, 2, 0x08A, WS},
    {0x07, Reg::MAX_SPEED, "MAX_SPEED", 10, 2, 0x041, WR},
    {0x08, Reg::MIN_SPEED, "MIN_SPEED", 13, 2, 0x000, WS},
    {0x09, Reg::TVAL_HOLD, "TVAL_HOLD", 7, 1, 0x29, WR},
    {0x0A, Reg::TVAL_RUN, "TVAL_RUN", 7, 1, 0x29, WR},
    {0x0B, Reg::TVAL_ACC, "TVAL_ACC", 7, 1, 0x29, WR},
    {0x0C, Reg::TVAL_DEC, "TVAL_DEC", 7, 1, 0x29, WR},
    {0x0E, Reg::T_FAST, "T_FAST", 8, 1, 0x19, WH},
    {0x0F, Reg::TON_MIN, "TON_MIN", 7, 1, 0x29, WH},
    {0x10, Reg::TOFF_MIN, "TOFF_MIN", 7, 1, 0x29, WH},
    {0x12, Reg::ADC_OUT, "ADC_OUT", 5, 1, std::nullopt, R},
    {0x13, Reg::OCD_TH, "OCD_TH", 5, 1, 0x08, WR},
    {0x15, Reg::FS_SPD, "FS_SPD", 11, 2, 0x027, WR},
    {0x16, Reg::STEP_MODE, "STEP_MODE", 8, 1, 0x07, WH},
    {0x17, Reg::ALARM_EN, "ALARM_EN", 8, 1, 0xFF, WS},
    {0x18, Reg::GATECFG1, "GATECFG1", 12, 2, 0x000, WH},
    {0x19, Reg::GATECFG2, "GATECFG2", 8, 1, 0x00, WH},
    {0x1A, Reg::CONFIG, "CONFIG", 16, 2, 0x2C88, WH},
    {0x1B, Reg::STATUS, "STATUS", 16, 2, std::nullopt, R},
};

// Spec §2.5: the powerSTEP01 has the L6480 map (reset values assumed the L6480's); in current
// mode (STEP_MODE.CM_VM = 1) 0x09-0x0C read as TVAL_* (7 bits), 0x0E as T_FAST (8 bits),
// 0x0F/0x10 as TON_MIN/TOFF_MIN (7 bits); 0x0D stays INT_SPEED. Storage is shared, so the
// reset values are the voltage-mode ones seen through the current-mode width.
const Table& kPowerStep01 = kL6480;
const Table kPowerStep01CurrentMode = [] {
  Table t = kL6480;
  const Row aliases[] = {
      {0x09, Reg::TVAL_HOLD, "TVAL_HOLD", 7, 1, 0x29, WR}, {0x0A, Reg::TVAL_RUN, "TVAL_RUN", 7, 1, 0x29, WR},
      {0x0B, Reg::TVAL_ACC, "TVAL_ACC", 7, 1, 0x29, WR},   {0x0C, Reg::TVAL_DEC, "TVAL_DEC", 7, 1, 0x29, WR},
      {0x0E, Reg::T_FAST, "T_FAST", 8, 1, 0x19, WH},       {0x0F, Reg::TON_MIN, "TON_MIN", 7, 1, 0x29, WH},
      {0x10, Reg::TOFF_MIN, "TOFF_MIN", 7, 1, 0x29, WH},
  };
  for (const Row& a : aliases)
    for (Row& r : t)
      if (r.address == a.address) r = a;
  return t;
}();

// docs/l6474.md: the position registers, one TVAL, the L6472's current-control timings, no
// speed profile registers; CONFIG and STATUS where the L6470 has them. Reset values UNCONFIRMED.
const Table kL6474 = {
    {0x01, Reg::ABS_POS, "ABS_POS", 22, 3, 0x000000, WS},
    {0x02, Reg::EL_POS, "EL_POS", 9, 2, 0x000, WS},
    {0x03, Reg::MARK, "MARK", 22, 3, 0x000000, WR},
    {0x09, Reg::TVAL, "TVAL", 7, 1, 0x29, WR},
    {0x0E, Reg::T_FAST, "T_FAST", 8, 1, 0x19, WH},
    {0x0F, Reg::TON_MIN, "TON_MIN", 7, 1, 0x29, WH},
    {0x10, Reg::TOFF_MIN, "TOFF_MIN", 7, 1, 0x29, WH},
    {0x12, Reg::ADC_OUT, "ADC_OUT", 5, 1, std::nullopt, R},
    {0x13, Reg::OCD_TH, "OCD_TH", 4, 1, 0x8, WR},
    {0x16, Reg::STEP_MODE, "STEP_MODE", 8, 1, 0x07, WH},
    {0x17, Reg::ALARM_EN, "ALARM_EN", 8, 1, 0xFF, WS},
    {0x18, Reg::CONFIG, "CONFIG", 16, 2, 0x2E88, WH},
    {0x19, Reg::STATUS, "STATUS", 16, 2, std::nullopt, R},
};

// ---------------------------------------------------------------- the cases

struct Case {
  const Variant* variant;
  bool current_mode;           // powerSTEP01 with STEP_MODE.CM_VM = 1
  const Table* table;          // the table in force
  std::vector<std::uint8_t> holes;  // addresses 0x01..0x1F with no register (spec §2, §8)
  bool cmd_error;              // one CMD_ERROR bit 7 (gate-driver parts) instead of WRONG_CMD b8 + NOTPERF b7
  std::uint16_t after_get_status;  // STATUS after power-up and one GetStatus (spec §4.1, §4.2)
  std::string label;
};

/// What the spec says about the variant called `name`; the variant itself comes from all_variants().
Case case_for(const Variant* v, bool current_mode) {
  Case c{v, current_mode, nullptr, {}, false, 0, std::string(v->name) + (current_mode ? "_current_mode" : "")};
  const std::string_view n = v->name;
  if (n == "L6470") {
    c.table = &kL6470;
    c.holes = {0x1A, 0x1B, 0x1C, 0x1D, 0x1E, 0x1F};
    c.after_get_status = 0x7E03;  // L6470: 0x7C03 at power-up, UVLO (b9) released by GetStatus
  } else if (n == "L6472") {
    c.table = &kL6472;
    c.holes = {0x0D, 0x11, 0x14, 0x1A, 0x1B, 0x1C, 0x1D, 0x1E, 0x1F};
    c.after_get_status = 0x1E03;  // the L6470 word with bits 14:13 (no STEP_LOSS) reading 0
  } else if (n == "L6480") {
    c.table = &kL6480;
    c.holes = {0x1C, 0x1D, 0x1E, 0x1F};
    c.cmd_error = true;
    c.after_get_status = 0xE603;  // STALL_B b15, STALL_A b14, OCD b13, UVLO_ADC b10, UVLO b9 inactive
  } else if (n == "L6482") {
    c.table = &kL6482;
    c.holes = {0x0D, 0x11, 0x14, 0x1C, 0x1D, 0x1E, 0x1F};
    c.cmd_error = true;
    c.after_get_status = 0x2603;  // bits 15:14 (no stall flags) read 0
  } else if (n == "powerSTEP01") {
    c.table = current_mode ? &kPowerStep01CurrentMode : &kPowerStep01;
    c.holes = {0x1C, 0x1D, 0x1E, 0x1F};
    c.cmd_error = true;
    c.after_get_status = 0xE603;
  } else if (n == "L6474") {
    c.table = &kL6474;
    c.holes = {0x04, 0x05, 0x06, 0x07, 0x08, 0x0A, 0x0B, 0x0C, 0x0D, 0x11, 0x14, 0x15,
               0x1A, 0x1B, 0x1C, 0x1D, 0x1E, 0x1F};
    c.after_get_status = 0xFE03;  // bits 15:13 and 1 read 1 (docs/l6474.md), HiZ, no flag
  }
  return c;
}

/// gtest prints a case by its label.
void PrintTo(const Case& c, std::ostream* os) { *os << c.label; }

std::vector<Case> all_cases() {
  std::vector<Case> out;
  for (const Variant* v : all_variants()) out.push_back(case_for(v, false));
  out.push_back(case_for(&powerstep01(), true));
  return out;
}

/// The cases of the parts with a motion engine (Run, ResetDevice): all but the L6474's.
std::vector<Case> motion_cases() {
  std::vector<Case> out;
  for (const Case& c : all_cases())
    if (c.variant->motion_engine) out.push_back(c);
  return out;
}

std::string hex(std::uint32_t v) {
  std::ostringstream s;
  s << "0x" << std::hex << std::uppercase << v;
  return s.str();
}

std::string trace(const Row& r) { return std::string(r.name) + " at " + hex(r.address); }

std::uint32_t all_ones(unsigned bytes) { return (1u << (8 * bytes)) - 1u; }
std::uint32_t mask_of(unsigned bits) { return (1u << bits) - 1u; }

/// The value bytes of `value` on SPI, MSB first.
std::vector<std::uint8_t> value_bytes(std::uint32_t value, unsigned bytes) {
  std::vector<std::uint8_t> out;
  for (unsigned i = bytes; i-- > 0;) out.push_back(static_cast<std::uint8_t>(value >> (8 * i)));
  return out;
}

std::vector<std::uint8_t> concat(std::vector<std::uint8_t> a, const std::vector<std::uint8_t>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

constexpr std::uint8_t kGetStatus = 0xD0;
constexpr std::uint8_t kHardStop = 0xB8;
constexpr std::uint8_t kHardHiZ = 0xA8;
constexpr std::uint8_t kResetDevice = 0xC0;
constexpr std::uint16_t kBit7 = 1u << 7;  // NOTPERF_CMD (L6470/L6472) or CMD_ERROR (gate-driver parts)

/// One chip of the case's variant behind its own chip-select; the host sends one byte per frame.
struct Rig {
  explicit Rig(const Case& c, Quirks q = {}) : kase(c), chain(1, *c.variant, q), host(chain) {
    if (c.current_mode) enter_current_mode();
  }
  const Case& kase;
  Chain chain;
  ChainHost host;

  Chip& chip() { return chain.chip(0); }
  std::vector<std::uint8_t> send(const std::vector<std::uint8_t>& bytes) { return host.send(0, bytes); }
  /// SetParam(STEP_MODE) with CM_VM (bit 3) set and STEP_SEL 1/128 — needs the bridges in HiZ.
  void enter_current_mode() { send({0x16, 0x0F}); }

  void set(std::uint8_t address, std::uint32_t value, unsigned bytes) {
    send(concat({address}, value_bytes(value, bytes)));
  }
  /// GetParam(address) and `bytes` + 1 NOPs: the opcode's MISO byte, the answer, one byte after it.
  std::vector<std::uint8_t> get_bytes(std::uint8_t address, unsigned bytes) {
    std::vector<std::uint8_t> tx(bytes + 2, 0x00);
    tx[0] = static_cast<std::uint8_t>(0x20 | address);
    return send(tx);
  }
  std::uint32_t get(std::uint8_t address, unsigned bytes) {
    const auto miso = get_bytes(address, bytes);
    std::uint32_t v = 0;
    for (unsigned i = 1; i <= bytes; ++i) v = (v << 8) | miso[i];
    return v;
  }
  /// GetStatus: the STATUS word, latched flags cleared afterwards.
  std::uint16_t get_status() {
    const auto miso = send({kGetStatus, 0x00, 0x00});
    return static_cast<std::uint16_t>(miso[1] << 8 | miso[2]);
  }
  std::uint16_t wrong_cmd_bit() const { return kase.cmd_error ? kBit7 : std::uint16_t{1u << 8}; }
};

/// What GetParam's MISO bytes must be: 0x00 for the opcode, the value MSB first, then 0x00.
std::vector<std::uint8_t> answer(std::uint32_t value, unsigned bytes) {
  return concat(concat({0x00}, value_bytes(value, bytes)), {0x00});
}

class EveryVariantsRegisterMap : public ::testing::TestWithParam<Case> {
 protected:
  const Case& kase() const { return GetParam(); }
  const Table& table() const { return *GetParam().table; }
};

INSTANTIATE_TEST_SUITE_P(VariantRegisters, EveryVariantsRegisterMap, ::testing::ValuesIn(all_cases()),
                         [](const ::testing::TestParamInfo<Case>& i) { return i.param.label; });

/// The same, on the parts that run a motor by themselves and reset by ResetDevice.
class EveryMotionVariantsRegisterMap : public EveryVariantsRegisterMap {};

INSTANTIATE_TEST_SUITE_P(VariantRegisters, EveryMotionVariantsRegisterMap, ::testing::ValuesIn(motion_cases()),
                         [](const ::testing::TestParamInfo<Case>& i) { return i.param.label; });

// ---------------------------------------------------------------- the table rows

TEST_P(EveryVariantsRegisterMap, IsOneTheSpecDescribes) {
  ASSERT_NE(kase().table, nullptr) << "no spec table for " << kase().variant->name;
}

TEST_P(EveryVariantsRegisterMap, HasExactlyTheSpecsRegistersWithTheirAddressWidthSpiLengthResetAndAccess) {
  ASSERT_NE(kase().table, nullptr);
  Rig rig(kase());
  const Variant& in_force = rig.chip().registers();
  ASSERT_EQ(in_force.registers.size(), table().size());
  for (std::size_t i = 0; i < table().size(); ++i) {
    const Row& want = table()[i];
    SCOPED_TRACE(trace(want));
    const RegisterInfo& got = in_force.registers[i];
    EXPECT_EQ(got.address, want.address);
    EXPECT_EQ(got.id, want.id);
    EXPECT_EQ(got.name, want.name);
    EXPECT_EQ(got.bits, want.bits);
    EXPECT_EQ(got.spi_bytes(), want.bytes);
    EXPECT_EQ(got.mask(), mask_of(want.bits));
    EXPECT_EQ(got.access, want.access) << "spec " << to_string(want.access) << ", model " << to_string(got.access);
    if (want.reset) {
      EXPECT_EQ(got.reset, *want.reset) << hex(got.reset);
    }
    EXPECT_EQ(in_force.at_address(want.address), &got);
    EXPECT_EQ(in_force.find(want.id), &got);
  }
  for (std::uint8_t a : kase().holes) EXPECT_EQ(in_force.at_address(a), nullptr) << hex(a);
  EXPECT_EQ(in_force.at_address(0x00), nullptr);
}

TEST_P(EveryVariantsRegisterMap, HasAHoleWhereverTheSpecListsNoRegister) {
  ASSERT_NE(kase().table, nullptr);
  std::vector<std::uint8_t> missing;
  for (std::uint8_t a = 0x01; a <= 0x1F; ++a)
    if (std::none_of(table().begin(), table().end(), [a](const Row& r) { return r.address == a; }))
      missing.push_back(a);
  EXPECT_EQ(missing, kase().holes);
}

// ---------------------------------------------------------------- reset values over SPI

TEST_P(EveryVariantsRegisterMap, ReadsEveryResetValueOverSpiAfterPowerUpWithTheSpecsSpiLength) {
  ASSERT_NE(kase().table, nullptr);
  Rig rig(kase());
  for (const Row& r : table()) {
    if (!r.reset) continue;
    SCOPED_TRACE(trace(r));
    std::uint32_t want = *r.reset;
    if (r.id == Reg::STEP_MODE && kase().current_mode) want = 0x0F;  // CM_VM written to enter current mode
    EXPECT_EQ(rig.get_bytes(r.address, r.bytes), answer(want, r.bytes));
  }
}

TEST_P(EveryMotionVariantsRegisterMap, ReadsEveryResetValueOverSpiAfterResetDevice) {
  ASSERT_NE(kase().table, nullptr);
  Rig rig(kase());
  // Move everything away from reset (bridges in HiZ so WH writes land), run, latch an error.
  for (const Row& r : table())
    if (r.access != R) rig.set(r.address, all_ones(r.bytes), r.bytes);
  rig.send({0xE0});  // no such command
  rig.send({0x51, 0x00, 0x40, 0x00});
  rig.host.wait_ms(20);
  ASSERT_NE(rig.chip().position(), 0);
  rig.send({kHardHiZ});  // so that the powerSTEP01 accepts ResetDevice (spec §5.2)
  rig.send({kResetDevice});

  // ResetDevice returns to the power-up state, voltage mode included on the powerSTEP01.
  EXPECT_EQ(rig.get(0x16, 1), 0x07u) << "STEP_MODE";
  if (kase().variant->current_mode != nullptr) {
    ASSERT_NE(rig.chip().registers().at_address(0x09), nullptr);
    EXPECT_EQ(rig.chip().registers().at_address(0x09)->id, Reg::KVAL_HOLD);
  }
  if (kase().current_mode) rig.enter_current_mode();
  for (const Row& r : table()) {
    if (!r.reset) continue;
    SCOPED_TRACE(trace(r));
    std::uint32_t want = *r.reset;
    if (r.id == Reg::STEP_MODE && kase().current_mode) want = 0x0F;
    EXPECT_EQ(rig.get_bytes(r.address, r.bytes), answer(want, r.bytes));
  }
  // UVLO latched again by the reset: one GetStatus away from the quiet word.
  const std::uint16_t uvlo_n = 1u << 9;
  EXPECT_EQ(rig.get_status(), kase().after_get_status & ~uvlo_n);
  EXPECT_EQ(rig.get_status(), kase().after_get_status);
}

// ---------------------------------------------------------------- the hardware-test-suite round trip

TEST_P(EveryVariantsRegisterMap, WritesAllOnesToEveryWritableRegisterAndReadsBackTheValueMaskedToItsWidth) {
  ASSERT_NE(kase().table, nullptr);
  Rig rig(kase());
  rig.send({kResetDevice, kHardHiZ});
  if (kase().current_mode) rig.enter_current_mode();
  ASSERT_EQ(rig.get_status() & 0x0001, 0x0001) << "bridges in HiZ";
  for (const Row& r : table()) {
    if (r.access == R) continue;
    SCOPED_TRACE(trace(r));
    // Exactly `bytes` value bytes are taken: the GetStatus right after them is decoded as a
    // command and answers in the two bytes after it, with no error flagged.
    const auto miso = rig.send(concat(concat({r.address}, value_bytes(all_ones(r.bytes), r.bytes)), {kGetStatus, 0, 0}));
    ASSERT_EQ(miso.size(), r.bytes + 4u);
    const std::uint16_t status = static_cast<std::uint16_t>(miso[r.bytes + 2] << 8 | miso[r.bytes + 3]);
    EXPECT_EQ(status, kase().after_get_status) << hex(status);
    EXPECT_EQ(rig.get_bytes(r.address, r.bytes), answer(mask_of(r.bits), r.bytes));
  }
  // All of them still hold their value afterwards. On the powerSTEP01 STEP_MODE = 0xFF has
  // set CM_VM, so the current-mode reading is in force (TVAL_*: 7 bits of the stored 0xFF).
  const Table& now = kase().variant->current_mode != nullptr ? kPowerStep01CurrentMode : table();
  for (const Row& r : now) {
    if (r.access == R) continue;
    SCOPED_TRACE("second pass, " + trace(r));
    EXPECT_EQ(rig.get(r.address, r.bytes), mask_of(r.bits));
  }
}

// ---------------------------------------------------------------- write conditions over SPI

/// Writes a value different from the current one; returns whether it landed, and whether bit 7
/// (NOTPERF_CMD / CMD_ERROR) rose.
struct WriteOutcome {
  bool landed;
  bool refused_flag;
};
WriteOutcome try_write(Rig& rig, const Row& r) {
  rig.get_status();  // clear
  const std::uint32_t before = rig.get(r.address, r.bytes);
  const std::uint32_t value = (before ^ 1u) & mask_of(r.bits);
  rig.set(r.address, value, r.bytes);
  const std::uint16_t status = rig.get_status();
  const std::uint32_t after = rig.get(r.address, r.bytes);
  EXPECT_TRUE(after == value || after == before) << hex(after);
  return {after == value, (status & kBit7) != 0};
}

TEST_P(EveryMotionVariantsRegisterMap, AcceptsWrOnlyWhileTheMotorRuns) {
  ASSERT_NE(kase().table, nullptr);
  for (const Row& r : table()) {
    if (r.access == R) continue;
    SCOPED_TRACE(trace(r));
    Rig rig(kase());
    rig.send({0x51, 0x00, 0x40, 0x00});  // Run forward, ~244 step/s
    rig.host.wait_ms(2);
    ASSERT_NE(rig.get_status() & (3u << 5), 0u) << "motor running";
    const WriteOutcome w = try_write(rig, r);
    EXPECT_EQ(w.landed, r.access == WR) << to_string(r.access);
    EXPECT_EQ(w.refused_flag, r.access != WR) << to_string(r.access);
  }
}

TEST_P(EveryVariantsRegisterMap, AcceptsWsAndWrButNotWhWhileStoppedWithTheBridgesEnabled) {
  ASSERT_NE(kase().table, nullptr);
  for (const Row& r : table()) {
    if (r.access == R) continue;
    SCOPED_TRACE(trace(r));
    Rig rig(kase());
    rig.send({kHardStop});  // leaves HiZ, motor stopped
    ASSERT_EQ(rig.get_status() & 0x0061, 0u) << "stopped, bridges enabled";
    const WriteOutcome w = try_write(rig, r);
    EXPECT_EQ(w.landed, r.access != WH) << to_string(r.access);
    EXPECT_EQ(w.refused_flag, r.access == WH) << to_string(r.access);
  }
}

TEST_P(EveryVariantsRegisterMap, AcceptsEveryWritableRegisterWithTheBridgesInHiZ) {
  ASSERT_NE(kase().table, nullptr);
  for (const Row& r : table()) {
    if (r.access == R) continue;
    SCOPED_TRACE(trace(r));
    Rig rig(kase());
    const WriteOutcome w = try_write(rig, r);
    EXPECT_TRUE(w.landed);
    EXPECT_FALSE(w.refused_flag);
  }
}

// ---------------------------------------------------------------- read-only registers

TEST_P(EveryVariantsRegisterMap, RefusesSetParamOfEachReadOnlyRegisterAtTheCommandByteAndDecodesTheNextByteAsACommand) {
  // Default quirk (docs/quirks.md, spec §5.3 CONFLICT): WRONG_CMD at the opcode byte, so the
  // following GetStatus is a command. On the gate-driver parts the flag is CMD_ERROR, bit 7.
  ASSERT_NE(kase().table, nullptr);
  int read_only = 0;
  for (const Row& r : table()) {
    if (r.access != R) continue;
    ++read_only;
    SCOPED_TRACE(trace(r));
    Rig rig(kase());
    rig.get_status();
    const auto miso = rig.send({r.address, kGetStatus, 0x00, 0x00});
    const std::uint16_t want = kase().after_get_status | rig.wrong_cmd_bit();
    EXPECT_EQ(miso, (std::vector<std::uint8_t>{0x00, 0x00, static_cast<std::uint8_t>(want >> 8),
                                               static_cast<std::uint8_t>(want)}));
    EXPECT_EQ(rig.get_status(), kase().after_get_status) << "GetStatus cleared it";
  }
  EXPECT_EQ(read_only, kase().variant->motion_engine ? 3 : 2) << "SPEED (the motion engine's), ADC_OUT, STATUS";
}

TEST_P(EveryVariantsRegisterMap, WithTheNotperfQuirkConsumesTheValueOfAReadOnlyRegisterThenRaisesBit7) {
  ASSERT_NE(kase().table, nullptr);
  Quirks q;
  q.read_only_write = ReadOnlyWrite::notperf_after_value;
  for (const Row& r : table()) {
    if (r.access != R) continue;
    SCOPED_TRACE(trace(r));
    Rig rig(kase(), q);
    rig.get_status();
    // The GetStatus opcodes inside the value are value bytes; the last one is a command.
    std::vector<std::uint8_t> tx{r.address};
    for (unsigned i = 0; i < r.bytes; ++i) tx.push_back(kGetStatus);
    const auto miso = rig.send(concat(tx, {kGetStatus, 0x00, 0x00}));
    const std::uint16_t want = kase().after_get_status | kBit7;
    EXPECT_EQ(miso[r.bytes + 2], static_cast<std::uint8_t>(want >> 8));
    EXPECT_EQ(miso[r.bytes + 3], static_cast<std::uint8_t>(want));
    for (unsigned i = 0; i <= r.bytes + 1u; ++i) EXPECT_EQ(miso[i], 0x00) << i;
  }
}

// ---------------------------------------------------------------- holes

TEST_P(EveryVariantsRegisterMap, TreatsSetParamOfEachHoleAsAnUnknownCommandAndDecodesTheFollowingBytesAsCommands) {
  ASSERT_NE(kase().table, nullptr);
  for (std::uint8_t a : kase().holes) {
    SCOPED_TRACE(hex(a));
    Rig rig(kase());
    rig.get_status();
    // A swallowed value would hide the GetStatus; decoded as a command it answers at once.
    const auto miso = rig.send({a, kGetStatus, 0x00, 0x00});
    const std::uint16_t want = kase().after_get_status | rig.wrong_cmd_bit();
    EXPECT_EQ(miso, (std::vector<std::uint8_t>{0x00, 0x00, static_cast<std::uint8_t>(want >> 8),
                                               static_cast<std::uint8_t>(want)}));
    // and a motion command right after the hole is performed, not taken as a value
    rig.send({a, kHardStop});
    EXPECT_EQ(rig.get_status() & 0x0001, 0u) << "HardStop enabled the bridges";
  }
}

TEST_P(EveryVariantsRegisterMap, TreatsGetParamOfEachHoleAsAnUnknownCommandThatAnswersNothing) {
  ASSERT_NE(kase().table, nullptr);
  std::vector<std::uint8_t> addresses = kase().holes;
  addresses.push_back(0x00);  // GetParam 0x20: no register 0 on any variant (spec §5.3)
  for (std::uint8_t a : addresses) {
    SCOPED_TRACE(hex(a));
    Rig rig(kase());
    rig.get_status();
    const auto silent = rig.send({static_cast<std::uint8_t>(0x20 | a), 0x00, 0x00});
    EXPECT_EQ(silent, (std::vector<std::uint8_t>{0x00, 0x00, 0x00}));
    EXPECT_EQ(rig.get_status(), kase().after_get_status | rig.wrong_cmd_bit());
    const auto miso = rig.send({static_cast<std::uint8_t>(0x20 | a), kGetStatus, 0x00, 0x00});
    const std::uint16_t want = kase().after_get_status | rig.wrong_cmd_bit();
    EXPECT_EQ(miso, (std::vector<std::uint8_t>{0x00, 0x00, static_cast<std::uint8_t>(want >> 8),
                                               static_cast<std::uint8_t>(want)}));
  }
}

// ---------------------------------------------------------------- the brief's hole lists, spelled out

TEST(VariantHoles, L6472AndL6482HaveNoRegisterAt0x0D0x11And0x14) {
  for (const Variant* v : {&l6472(), &l6482()}) {
    SCOPED_TRACE(std::string(v->name));
    Chip chip(*v);
    for (std::uint8_t a : {0x0D, 0x11, 0x14}) EXPECT_EQ(chip.registers().at_address(a), nullptr) << hex(a);
    EXPECT_FALSE(v->has(Reg::INT_SPEED));
    EXPECT_FALSE(v->has(Reg::K_THERM));
    EXPECT_FALSE(v->has(Reg::STALL_TH));
  }
}

TEST(VariantHoles, L6470HasNoRegisterAt0x1AUpTo0x1FWhereTheGateDriverPartsKeepConfigAndStatus) {
  for (std::uint8_t a = 0x1A; a <= 0x1F; ++a) EXPECT_EQ(l6470().at_address(a), nullptr) << hex(a);
  for (const Variant* v : {&l6480(), &l6482(), &powerstep01()}) {
    ASSERT_NE(v->at_address(0x1A), nullptr);
    ASSERT_NE(v->at_address(0x1B), nullptr);
    EXPECT_EQ(v->at_address(0x1A)->id, Reg::CONFIG) << v->name;
    EXPECT_EQ(v->at_address(0x1B)->id, Reg::STATUS) << v->name;
  }
}

// ---------------------------------------------------------------- look-up by name

TEST(VariantLookUp, AllVariantsListsTheSixFamilyMembersInOrder) {
  const auto all = all_variants();
  ASSERT_EQ(all.size(), 6u);
  const std::string_view names[] = {"L6470", "L6472", "L6480", "L6482", "powerSTEP01", "L6474"};
  for (std::size_t i = 0; i < 6; ++i) EXPECT_EQ(all[i]->name, names[i]);
  EXPECT_EQ(all[0], &l6470());
  EXPECT_EQ(all[1], &l6472());
  EXPECT_EQ(all[2], &l6480());
  EXPECT_EQ(all[3], &l6482());
  EXPECT_EQ(all[4], &powerstep01());
  EXPECT_EQ(all[5], &l6474());
}

TEST(VariantLookUp, FindsEachVariantByItsNameInAnyCase) {
  EXPECT_EQ(find_variant("L6470"), &l6470());
  EXPECT_EQ(find_variant("l6470"), &l6470());
  EXPECT_EQ(find_variant("L6472"), &l6472());
  EXPECT_EQ(find_variant("l6480"), &l6480());
  EXPECT_EQ(find_variant("L6482"), &l6482());
  EXPECT_EQ(find_variant("powerSTEP01"), &powerstep01());
  EXPECT_EQ(find_variant("powerstep01"), &powerstep01());
  EXPECT_EQ(find_variant("POWERSTEP01"), &powerstep01());
  EXPECT_EQ(find_variant("PowerStep01"), &powerstep01());
  EXPECT_EQ(find_variant("L6474"), &l6474());
  EXPECT_EQ(find_variant("l6474"), &l6474());
}

TEST(VariantLookUp, FindsNothingForOtherNames) {
  EXPECT_EQ(find_variant(""), nullptr);
  EXPECT_EQ(find_variant("L6475"), nullptr);
  EXPECT_EQ(find_variant("L647"), nullptr);
  EXPECT_EQ(find_variant("L64700"), nullptr);
  EXPECT_EQ(find_variant(" L6470"), nullptr);
  EXPECT_EQ(find_variant("powerSTEP"), nullptr);
}

TEST(VariantLookUp, FindsThePowerStep01InItsVoltageModeWithTheCurrentModeReadingAttached) {
  const Variant* v = find_variant("powerstep01");
  ASSERT_NE(v, nullptr);
  EXPECT_EQ(v->at_address(0x09)->id, Reg::KVAL_HOLD);
  ASSERT_NE(v->current_mode, nullptr);
  EXPECT_EQ(v->current_mode->at_address(0x09)->id, Reg::TVAL_HOLD);
  for (const Variant* other : {&l6470(), &l6472(), &l6480(), &l6482(), &l6474()}) EXPECT_EQ(other->current_mode, nullptr);
}

// ---------------------------------------------------------------- the UNCONFIRMED choices

// Each variant's `unconfirmed` list names the choices made where the sources are single or
// silent. Every entry is pinned here to the tests that cover it; a new entry fails this test
// until it is given a test and listed.
struct Covered {
  std::string_view variant;
  std::string_view phrase;  // a phrase of the entry
  std::string_view tests;   // gtest_filter-style patterns of the tests that cover it, ", "-separated
};
const Covered kCovered[] = {
    {"L6472", "register map 0x09-0x10", "VariantRegisters/EveryVariantsRegisterMap.*/L6472, VariantHoles.L6472*"},
    {"L6472", "reset values of TVAL_*", "VariantRegisters/EveryVariantsRegisterMap.ReadsEveryResetValue*/L6472"},
    {"L6472", "STATUS bits 13 and 14", "VariantStatus/EveryVariantsStatus.*/L6472, VariantStatus.L6472*"},
    {"L6472", "ALARM_EN bits 4 and 5", "VariantAlarms.L6472*"},
    {"L6472", "STEP_SEL 101..111", "VariantMicrostepping.StepSel4To7*, VariantMicrostepping.AMoveOf16*"},
    {"L6472", "ACC = 0xFFF", "VariantAcceleration/InfiniteAcceleration.*/L6472"},
    {"L6480", "write conditions", "VariantRegisters/EveryVariantsRegisterMap.Accepts*/L6480"},
    {"L6480", "STALL_A on STATUS bit 14", "VariantStatus.Stall*"},
    {"L6480", "ACC = 0xFFF", "VariantAcceleration/InfiniteAcceleration.*/L6480"},
    {"L6480", "UVLO_ADC, TH_STATUS and CMD_ERROR latch",
     "VariantStatus.CmdErrorLatches*, VariantStatus.ThStatusLatches*, VariantStatus.UvloAdcLatches*"},
    {"L6482", "reset values of TVAL_*", "VariantRegisters/EveryVariantsRegisterMap.ReadsEveryResetValue*/L6482"},
    {"L6482", "STATUS bits 15 and 14", "VariantStatus/EveryVariantsStatus.*/L6482, VariantStatus.L6472AndL6482*"},
    {"L6482", "STEP_MODE bit 3", "VariantMicrostepping.L6482StepModeBit3*"},
    {"L6482", "STEP_SEL 101..111", "VariantMicrostepping.StepSel4To7*, VariantMicrostepping.AMoveOf16*"},
    {"L6482", "hole (0x0D, 0x11, 0x14)", "VariantRegisters/EveryVariantsRegisterMap.*Hole*/L6482"},
    {"powerSTEP01", "reset values", "VariantRegisters/EveryVariantsRegisterMap.ReadsEveryResetValue*/powerSTEP01*"},
    {"powerSTEP01", "share the storage", "VariantCurrentMode.PowerStep01ModesShareStorage*"},
    {"powerSTEP01", "ResetDevice while the bridges are enabled", "VariantResetDevice.*"},
    {"powerSTEP01", "STALL_A on STATUS bit 14", "VariantStatus.Stall*"},
    {"powerSTEP01", "1/128 microstepping in both modes", "VariantMicrostepping.PowerStep01*"},
    {"L6474", "reset values of TVAL", "VariantRegisters/EveryVariantsRegisterMap.ReadsEveryResetValue*/L6474, L6474.AThreeChipChain*"},
    {"L6474", "STATUS bits 15, 14, 13 and 1", "VariantStatus/EveryVariantsStatus.*/L6474, L6474.StatusReads*"},
    {"L6474", "only while the bridges are enabled", "L6474.StckEdgesAreIgnored*"},
    {"L6474", "DIR high steps forward", "L6474.DirHighIsForward*"},
    {"L6474", "Enable while a fault", "L6474.EnableWhileAFault*"},
    {"L6474", "STEP_SEL 101..111", "L6474.StepSel5To7*, VariantMicrostepping/FinestStep.*/L6474"},
    {"L6474", "ALARM_EN bits 4, 5 and 6", "VariantAlarms.L6474*"},
};

/// Glob match with '*' (any run) and '?' (any one character), as in --gtest_filter.
bool glob(std::string_view pattern, std::string_view text) {
  if (pattern.empty()) return text.empty();
  if (pattern[0] == '*') return glob(pattern.substr(1), text) || (!text.empty() && glob(pattern, text.substr(1)));
  return !text.empty() && (pattern[0] == '?' || pattern[0] == text[0]) && glob(pattern.substr(1), text.substr(1));
}

/// Whether some registered test's full name (suite.name) matches `pattern`.
bool some_test_matches(std::string_view pattern) {
  const ::testing::UnitTest& all = *::testing::UnitTest::GetInstance();
  for (int i = 0; i < all.total_test_suite_count(); ++i) {
    const ::testing::TestSuite& suite = *all.GetTestSuite(i);
    for (int j = 0; j < suite.total_test_count(); ++j) {
      const std::string full = std::string(suite.name()) + "." + suite.GetTestInfo(j)->name();
      if (glob(pattern, full)) return true;
    }
  }
  return false;
}

TEST(VariantUnconfirmed, EveryUnconfirmedChoiceOfEveryVariantIsCoveredByATest) {
  for (const Variant* v : all_variants()) {
    SCOPED_TRACE(std::string(v->name));
    std::size_t listed = 0;
    for (const Covered& c : kCovered)
      if (c.variant == v->name) ++listed;
    EXPECT_EQ(v->unconfirmed.size(), listed) << "an UNCONFIRMED choice was added or removed: cover it and list it here";
    for (const Covered& c : kCovered) {
      if (c.variant != v->name) continue;
      const bool found = std::any_of(v->unconfirmed.begin(), v->unconfirmed.end(),
                                     [&](std::string_view e) { return e.find(c.phrase) != std::string_view::npos; });
      EXPECT_TRUE(found) << "no entry mentions \"" << c.phrase << "\"";
      // every pattern names at least one test that exists
      std::string_view rest = c.tests;
      while (!rest.empty()) {
        const auto comma = rest.find(", ");
        const std::string_view pattern = rest.substr(0, comma);
        EXPECT_TRUE(some_test_matches(pattern)) << "no test matches " << pattern << " (for \"" << c.phrase << "\")";
        rest = comma == std::string_view::npos ? std::string_view{} : rest.substr(comma + 2);
      }
    }
  }
}

}  // namespace
}  // namespace l6470emu
