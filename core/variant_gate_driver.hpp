// Register map, STATUS layout and ALARM_EN meaning shared by the gate-driver parts
// (L6480, L6482, powerSTEP01); private to the variant tables.
#pragma once

#include <array>

#include "core/registers.hpp"
#include "core/variant.hpp"
#include "core/status_layout.hpp"

namespace l6470emu {

namespace gate_driver_rows {
using enum Access;
using enum Reg;
/// The L6480 register map, which the powerSTEP01 shares in voltage mode.
inline constexpr std::array<RegisterInfo, 27> kVoltageModeGateDriverRegisters{{
    {0x01, ABS_POS, "ABS_POS", 22, 0x000000, WS, kSigned | kLive},
    {0x02, EL_POS, "EL_POS", 9, 0x000, WS, kLive},
    {0x03, MARK, "MARK", 22, 0x000000, WR, kSigned},
    {0x04, SPEED, "SPEED", 20, 0x00000, R, kLive},
    {0x05, ACC, "ACC", 12, 0x08A, WS, kNoFlags},
    {0x06, DEC, "DEC", 12, 0x08A, WS, kNoFlags},
    {0x07, MAX_SPEED, "MAX_SPEED", 10, 0x041, WR, kNoFlags},
    {0x08, MIN_SPEED, "MIN_SPEED", 13, 0x000, WS, kNoFlags},
    {0x09, KVAL_HOLD, "KVAL_HOLD", 8, 0x29, WR, kNoFlags},
    {0x0A, KVAL_RUN, "KVAL_RUN", 8, 0x29, WR, kNoFlags},
    {0x0B, KVAL_ACC, "KVAL_ACC", 8, 0x29, WR, kNoFlags},
    {0x0C, KVAL_DEC, "KVAL_DEC", 8, 0x29, WR, kNoFlags},
    {0x0D, INT_SPEED, "INT_SPEED", 14, 0x0408, WH, kWriteConflict},
    {0x0E, ST_SLP, "ST_SLP", 8, 0x19, WH, kWriteConflict},
    {0x0F, FN_SLP_ACC, "FN_SLP_ACC", 8, 0x29, WH, kWriteConflict},
    {0x10, FN_SLP_DEC, "FN_SLP_DEC", 8, 0x29, WH, kWriteConflict},
    {0x11, K_THERM, "K_THERM", 4, 0x0, WR, kNoFlags},
    {0x12, ADC_OUT, "ADC_OUT", 5, 0x00, R, kLive},
    {0x13, OCD_TH, "OCD_TH", 5, 0x08, WR, kNoFlags},
    {0x14, STALL_TH, "STALL_TH", 5, 0x10, WR, kNoFlags},
    {0x15, FS_SPD, "FS_SPD", 11, 0x027, WR, kNoFlags},
    {0x16, STEP_MODE, "STEP_MODE", 8, 0x07, WH, kNoFlags},
    {0x17, ALARM_EN, "ALARM_EN", 8, 0xFF, WS, kNoFlags},
    {0x18, GATECFG1, "GATECFG1", 12, 0x000, WH, kNoFlags},
    {0x19, GATECFG2, "GATECFG2", 8, 0x00, WH, kNoFlags},
    {0x1A, CONFIG, "CONFIG", 16, 0x2C88, WH, kWriteConflict},
    {0x1B, STATUS, "STATUS", 16, 0x0000, R, kLive},
}};
}  // namespace gate_driver_rows
using gate_driver_rows::kVoltageModeGateDriverRegisters;
static_assert(register_table_is_consistent(kVoltageModeGateDriverRegisters));


/// L6480 / powerSTEP01 STATUS: CMD_ERROR on bit 7, STCK_MOD on 8, UVLO_ADC on 10,
/// TH_STATUS on 12:11, OCD on 13, STALL_A on 14 and STALL_B on 15.
inline constexpr StatusLayout kGateDriverStatus = [] {
  StatusLayout l;
  l.notperf_cmd = 7;
  l.wrong_cmd = 7;
  l.sck_mod = 8;
  l.uvlo = 9;
  l.uvlo_adc = 10;
  l.th_wrn = -1;
  l.th_sd = -1;
  l.th_status = 11;
  l.ocd = 13;
  l.step_loss_a = 14;
  l.step_loss_b = 15;
  l.step_loss_a_name = "STALL_A";
  l.step_loss_b_name = "STALL_B";
  return l;
}();

/// L6480 / powerSTEP01 ALARM_EN: bit 4 ADC undervoltage, bit 5 stall on either bridge.
inline constexpr AlarmLayout kGateDriverAlarms{Alarm::overcurrent, Alarm::thermal_shutdown, Alarm::thermal_warning,
                                               Alarm::uvlo,        Alarm::adc_uvlo,         Alarm::stall_any,
                                               Alarm::switch_turn_on, Alarm::command_error};

}  // namespace l6470emu
