// Register-table rows that several variants share, as named constants, and a
// constexpr concatenation to build each variant's table from them. Private to core/.
#pragma once

#include <array>
#include <cstddef>

#include "core/registers.hpp"

namespace l6470emu::rows {

using enum Access;
using enum Reg;

/// Concatenates row groups into one table (groups must be given in address order).
template <std::size_t... N>
constexpr auto concat(const std::array<RegisterInfo, N>&... groups) {
  std::array<RegisterInfo, (N + ...)> out{};
  std::size_t i = 0;
  ((std::copy(groups.begin(), groups.end(), out.begin() + static_cast<std::ptrdiff_t>(i)), i += N), ...);
  return out;
}

/// One row as a group of one.
constexpr std::array<RegisterInfo, 1> row(RegisterInfo r) { return {r}; }

/// 0x01-0x03: the position registers, identical on every family member.
inline constexpr std::array<RegisterInfo, 3> kPosition{{
    // address, id, name, bits, reset, access, flags
    {0x01, ABS_POS, "ABS_POS", 22, 0x000000, WS, kSigned | kLive},
    {0x02, EL_POS, "EL_POS", 9, 0x000, WS, kLive},
    {0x03, MARK, "MARK", 22, 0x000000, WR, kSigned},
}};

/// 0x01-0x08: position and speed profile, identical on every part with a motion engine.
inline constexpr auto kMotion = concat(kPosition, std::array<RegisterInfo, 5>{{
    {0x04, SPEED, "SPEED", 20, 0x00000, R, kLive},
    {0x05, ACC, "ACC", 12, 0x08A, WS, kNoFlags},
    {0x06, DEC, "DEC", 12, 0x08A, WS, kNoFlags},
    {0x07, MAX_SPEED, "MAX_SPEED", 10, 0x041, WR, kNoFlags},
    {0x08, MIN_SPEED, "MIN_SPEED", 13, 0x000, WS, kNoFlags},
}});

/// 0x09-0x11 of the voltage-mode parts: KVAL_*, BEMF compensation, K_THERM.
inline constexpr std::array<RegisterInfo, 9> kVoltageMode{{
    {0x09, KVAL_HOLD, "KVAL_HOLD", 8, 0x29, WR, kNoFlags},
    {0x0A, KVAL_RUN, "KVAL_RUN", 8, 0x29, WR, kNoFlags},
    {0x0B, KVAL_ACC, "KVAL_ACC", 8, 0x29, WR, kNoFlags},
    {0x0C, KVAL_DEC, "KVAL_DEC", 8, 0x29, WR, kNoFlags},
    {0x0D, INT_SPEED, "INT_SPEED", 14, 0x0408, WH, kWriteConflict},
    {0x0E, ST_SLP, "ST_SLP", 8, 0x19, WH, kWriteConflict},
    {0x0F, FN_SLP_ACC, "FN_SLP_ACC", 8, 0x29, WH, kWriteConflict},
    {0x10, FN_SLP_DEC, "FN_SLP_DEC", 8, 0x29, WH, kWriteConflict},
    {0x11, K_THERM, "K_THERM", 4, 0x0, WR, kNoFlags},
}};

/// 0x09-0x0C of the current-mode parts with a motion engine (and the powerSTEP01 in current
/// mode): a TVAL per phase of the profile. Reset values are UNCONFIRMED.
inline constexpr std::array<RegisterInfo, 4> kTvals{{
    {0x09, TVAL_HOLD, "TVAL_HOLD", 7, 0x29, WR, kUnconfirmed},
    {0x0A, TVAL_RUN, "TVAL_RUN", 7, 0x29, WR, kUnconfirmed},
    {0x0B, TVAL_ACC, "TVAL_ACC", 7, 0x29, WR, kUnconfirmed},
    {0x0C, TVAL_DEC, "TVAL_DEC", 7, 0x29, WR, kUnconfirmed},
}};

/// 0x0E-0x10 of the current-mode parts: the current-control timings (0x0D has no register).
/// Reset values are UNCONFIRMED.
inline constexpr std::array<RegisterInfo, 3> kCurrentTimes{{
    {0x0E, T_FAST, "T_FAST", 8, 0x19, WH, kUnconfirmed},
    {0x0F, TON_MIN, "TON_MIN", 7, 0x29, WH, kUnconfirmed},
    {0x10, TOFF_MIN, "TOFF_MIN", 7, 0x29, WH, kUnconfirmed},
}};

/// 0x09-0x10 of the current-mode parts with a motion engine: TVAL_* and the timings.
inline constexpr auto kCurrentMode = concat(kTvals, kCurrentTimes);

inline constexpr RegisterInfo kAdcOut{0x12, ADC_OUT, "ADC_OUT", 5, 0x00, R, kLive};
inline constexpr RegisterInfo kStepMode{0x16, STEP_MODE, "STEP_MODE", 8, 0x07, WH, kNoFlags};
inline constexpr RegisterInfo kAlarmEn{0x17, ALARM_EN, "ALARM_EN", 8, 0xFF, WS, kNoFlags};

/// 0x18-0x19 of the gate-driver parts.
inline constexpr std::array<RegisterInfo, 2> kGateConfig{{
    {0x18, GATECFG1, "GATECFG1", 12, 0x000, WH, kNoFlags},
    {0x19, GATECFG2, "GATECFG2", 8, 0x00, WH, kNoFlags},
}};

/// CONFIG and STATUS at `address` and `address + 1`.
constexpr std::array<RegisterInfo, 2> config_and_status(std::uint8_t address, std::uint32_t config_reset,
                                                        std::uint8_t config_flags) {
  return {{{address, CONFIG, "CONFIG", 16, config_reset, WH, config_flags},
           {static_cast<std::uint8_t>(address + 1), STATUS, "STATUS", 16, 0x0000, R, kLive}}};
}

}  // namespace l6470emu::rows
