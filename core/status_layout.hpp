// Where each STATUS flag sits in a variant's 16-bit STATUS register, and what
// each ALARM_EN bit enables. Pure data; the encoding itself is in status.hpp.
#pragma once

#include <array>
#include <cstdint>
#include <string_view>

namespace l6470emu {

/// Bit positions of the STATUS fields of one variant; -1 when the variant has no such field.
/// Active-low fields (UVLO, TH_*, OCD, STEP_LOSS/STALL) are encoded low when active.
struct StatusLayout {
  std::int8_t hiz = 0;
  std::int8_t busy = 1;          ///< active low
  std::int8_t sw_f = 2;
  std::int8_t sw_evn = 3;
  std::int8_t dir = 4;
  std::int8_t mot_status = 5;    ///< low bit of the 2-bit field
  std::int8_t notperf_cmd = 7;   ///< same bit as wrong_cmd on CMD_ERROR parts
  std::int8_t wrong_cmd = 8;
  std::int8_t uvlo = 9;          ///< active low
  std::int8_t uvlo_adc = -1;     ///< active low
  std::int8_t th_wrn = 10;       ///< active low
  std::int8_t th_sd = 11;        ///< active low
  std::int8_t th_status = -1;    ///< low bit of the 2-bit TH_STATUS field
  std::int8_t ocd = 12;          ///< active low
  std::int8_t step_loss_a = 13;  ///< active low (STALL_A on the gate-driver parts)
  std::int8_t step_loss_b = 14;  ///< active low (STALL_B on the gate-driver parts)
  std::int8_t sck_mod = 15;      ///< SCK_MOD / STCK_MOD
  std::uint16_t unused_ones = 0; ///< bits without a field that read as 1
  std::string_view step_loss_a_name = "STEP_LOSS_A";  ///< datasheet name of the bridge-A stall flag
  std::string_view step_loss_b_name = "STEP_LOSS_B";  ///< datasheet name of the bridge-B stall flag
};

/// The conditions an ALARM_EN bit can enable on the FLAG pin.
enum class Alarm : std::uint8_t {
  none,
  overcurrent,
  thermal_shutdown,
  thermal_warning,
  uvlo,
  adc_uvlo,
  stall_a,
  stall_b,
  stall_any,
  switch_turn_on,
  command_error,  ///< wrong or not-performable command
};

/// What each ALARM_EN bit (0..7) enables.
using AlarmLayout = std::array<Alarm, 8>;

}  // namespace l6470emu
