// The L6482 (current mode, gate driver): TVAL_*/T_FAST/TON_MIN/TOFF_MIN at 0x09-0x10,
// holes at 0x0D, 0x11 and 0x14, no stall detection, at most 1/16 microstepping.
#include "core/register_rows.hpp"
#include "core/variant.hpp"
#include "core/variant_gate_driver.hpp"

namespace l6470emu {
namespace {

constexpr auto kRegisters = rows::concat(
    rows::kMotion, rows::kCurrentMode, rows::row(rows::kAdcOut),
    rows::row({0x13, Reg::OCD_TH, "OCD_TH", 5, 0x08, Access::WR, kNoFlags}),
    rows::row({0x15, Reg::FS_SPD, "FS_SPD", 11, 0x027, Access::WR, kNoFlags}),
    rows::row({0x16, Reg::STEP_MODE, "STEP_MODE", 8, 0x07, Access::WH, kUnconfirmed}), rows::row(rows::kAlarmEn),
    rows::kGateConfig, rows::config_and_status(0x1A, 0x2C88, kWriteConflict | kUnconfirmed));

static_assert(register_table_is_consistent(kRegisters));

constexpr StatusLayout kStatus = [] {
  StatusLayout l = kGateDriverStatus;  // no stall detection: bits 15 and 14 read 0
  l.step_loss_a = -1;
  l.step_loss_b = -1;
  return l;
}();

constexpr AlarmLayout kAlarms{Alarm::overcurrent, Alarm::thermal_shutdown, Alarm::thermal_warning, Alarm::uvlo,
                              Alarm::adc_uvlo,    Alarm::none,             Alarm::switch_turn_on,  Alarm::command_error};

constexpr std::string_view kUnconfirmedChoices[] = {
    "reset values of TVAL_*, T_FAST, TON_MIN, TOFF_MIN, STEP_MODE (0x07) and CONFIG (0x2C88): ST's cSPIN defaults, which look copied from the L6480",
    "STATUS bits 15 and 14 (no stall flags) read 0",
    "STEP_MODE bit 3 must be written 1 (ST cSPIN); the emulator stores what is written and gives it no meaning",
    "STEP_SEL 101..111 act as 1/16 (the finest the chip has); the value is stored as written",
    "an access to a hole (0x0D, 0x11, 0x14) is an unknown command, like any missing address",
};

// STEP_MODE bit 3 is not here: ST's cSPIN says write 1, its own defaults write 0 (CONFLICT).
constexpr ReservedBit kReserved[] = {
    {Reg::CONFIG, 6, "CONFIG bit 6 reserved (ST cSPIN's L6482 layout; 0 in the reset value 0x2C88)"},
};

constexpr Variant kVariant = [] {
  Variant v = make_variant("L6482", kRegisters, kStatus, kAlarms, /*max_step_sel=*/4, /*infinite_acceleration=*/true);
  v.unconfirmed = kUnconfirmedChoices;
  v.reserved_bits = kReserved;
  return v;
}();

static_assert(kVariant.at_address(0x0D) == nullptr && kVariant.at_address(0x11) == nullptr &&
              kVariant.at_address(0x14) == nullptr);

}  // namespace

const Variant& l6482() { return kVariant; }

}  // namespace l6470emu
