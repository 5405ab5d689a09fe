// Register descriptions shared by every variant: the identity of each register,
// its access class and the attributes derived from its width. Values live in RegisterFile.
#pragma once

#include <cstdint>
#include <string_view>

namespace l6470emu {

/// Every register any family member has, by datasheet name. A variant's table
/// maps addresses to these; powerSTEP01 current-mode aliases share an address.
enum class Reg : std::uint8_t {
  ABS_POS, EL_POS, MARK, SPEED, ACC, DEC, MAX_SPEED, MIN_SPEED,
  KVAL_HOLD, KVAL_RUN, KVAL_ACC, KVAL_DEC,
  INT_SPEED, ST_SLP, FN_SLP_ACC, FN_SLP_DEC, K_THERM, ADC_OUT,
  OCD_TH, STALL_TH, FS_SPD, STEP_MODE, ALARM_EN, CONFIG, STATUS,
  GATECFG1, GATECFG2,
  TVAL_HOLD, TVAL_RUN, TVAL_ACC, TVAL_DEC, T_FAST, TON_MIN, TOFF_MIN,
  TVAL,  ///< the L6474's one torque register (0x09), where the others have four
  count
};

/// Write condition of a register, as the datasheet's register table marks it.
enum class Access : std::uint8_t {
  R,   ///< read only
  WR,  ///< writable at any time
  WS,  ///< writable only while the motor is stopped
  WH,  ///< writable only while the bridges are in high impedance
};

/// Attribute bits of a register description.
enum RegFlag : std::uint8_t {
  kNoFlags = 0,
  kSigned = 1 << 0,         ///< 22-bit two's complement position (ABS_POS, MARK)
  kLive = 1 << 1,           ///< value produced by the model, not stored (SPEED, STATUS...)
  kWriteConflict = 1 << 2,  ///< WH in the table, "not while running" in the text (quirk)
  kUnconfirmed = 1 << 3,    ///< width, reset value or presence from a single non-datasheet source
};

/// One row of a variant's register table.
struct RegisterInfo {
  std::uint8_t address;   ///< 5-bit PARAM field of SetParam/GetParam
  Reg id;                 ///< which register this is
  std::string_view name;  ///< datasheet name
  std::uint8_t bits;      ///< width in bits
  std::uint32_t reset;    ///< value after power-up / ResetDevice
  Access access;          ///< write condition
  std::uint8_t flags;     ///< RegFlag bits

  /// Bytes of the value on SPI: the width rounded up to whole bytes.
  constexpr std::uint8_t spi_bytes() const { return static_cast<std::uint8_t>((bits + 7) / 8); }
  /// The bits the register holds; SPI bits above them are ignored.
  constexpr std::uint32_t mask() const { return bits >= 32 ? 0xFFFF'FFFFu : (1u << bits) - 1u; }
  constexpr bool is_signed() const { return (flags & kSigned) != 0; }
  constexpr bool is_live() const { return (flags & kLive) != 0; }
};

/// Sign-extends a value of `bits` width to a 32-bit integer.
constexpr std::int32_t sign_extend(std::uint32_t value, unsigned bits) {
  const std::uint32_t sign = 1u << (bits - 1);
  value &= (sign << 1) - 1u;
  return static_cast<std::int32_t>(value ^ sign) - static_cast<std::int32_t>(sign);
}

/// Text of an access class ("R", "WR", "WS", "WH").
constexpr std::string_view to_string(Access a) {
  switch (a) {
    case Access::R: return "R";
    case Access::WR: return "WR";
    case Access::WS: return "WS";
    case Access::WH: return "WH";
  }
  return "?";
}

}  // namespace l6470emu
