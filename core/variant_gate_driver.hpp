// Register map, STATUS layout and ALARM_EN meaning shared by the gate-driver parts
// (L6480, L6482, powerSTEP01); private to the variant tables.
#pragma once

#include <array>

#include "core/register_rows.hpp"
#include "core/registers.hpp"
#include "core/variant.hpp"
#include "core/status_layout.hpp"

namespace l6470emu {

/// The L6480 register map, which the powerSTEP01 shares in voltage mode.
inline constexpr auto kVoltageModeGateDriverRegisters = rows::concat(
    rows::kMotion, rows::kVoltageMode, rows::row(rows::kAdcOut),
    rows::row({0x13, Reg::OCD_TH, "OCD_TH", 5, 0x08, Access::WR, kNoFlags}),
    rows::row({0x14, Reg::STALL_TH, "STALL_TH", 5, 0x10, Access::WR, kNoFlags}),
    rows::row({0x15, Reg::FS_SPD, "FS_SPD", 11, 0x027, Access::WR, kNoFlags}), rows::row(rows::kStepMode),
    rows::row(rows::kAlarmEn), rows::kGateConfig, rows::config_and_status(0x1A, 0x2C88, kWriteConflict));
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
