// The L6472 (current mode, integrated bridges). Its datasheet was only seen in
// excerpts: rows marked kUnconfirmed come from one third-party header (spec §2.2).
#include "core/register_rows.hpp"
#include "core/variant.hpp"

namespace l6470emu {
namespace {

constexpr auto kRegisters = rows::concat(
    rows::kMotion, rows::kCurrentMode, rows::row(rows::kAdcOut),
    rows::row({0x13, Reg::OCD_TH, "OCD_TH", 4, 0x8, Access::WR, kNoFlags}),
    rows::row({0x15, Reg::FS_SPD, "FS_SPD", 10, 0x027, Access::WR, kNoFlags}), rows::row(rows::kStepMode),
    rows::row(rows::kAlarmEn), rows::config_and_status(0x18, 0x2E88, kWriteConflict | kUnconfirmed));

static_assert(register_table_is_consistent(kRegisters));

constexpr StatusLayout kStatus = [] {
  StatusLayout l;  // the L6470 layout without STEP_LOSS_A/B (bits 13 and 14 read 0)
  l.step_loss_a = -1;
  l.step_loss_b = -1;
  return l;
}();

constexpr AlarmLayout kAlarms{Alarm::overcurrent, Alarm::thermal_shutdown, Alarm::thermal_warning, Alarm::uvlo,
                              Alarm::none,        Alarm::none,             Alarm::switch_turn_on,  Alarm::command_error};

constexpr std::string_view kUnconfirmedChoices[] = {
    "register map 0x09-0x10 (TVAL_*, T_FAST, TON_MIN, TOFF_MIN), holes at 0x0D/0x11/0x14 and their widths: one third-party header",
    "reset values of TVAL_* (0x29), T_FAST (0x19), TON_MIN/TOFF_MIN (0x29) and CONFIG (0x2E88): assumed from the L6470/L6482",
    "STATUS bits 13 and 14 (no stall detection) read 0; the rest is the L6470 layout with WRONG_CMD and NOTPERF_CMD",
    "ALARM_EN bits 4 and 5 enable nothing",
    "STEP_SEL 101..111 act as 1/16 (the finest the chip has); the value is stored as written",
    "ACC = 0xFFF is reserved on the L6472: the emulator treats it as an ordinary acceleration",
};

constexpr ReservedBit kReserved[] = {
    {Reg::CONFIG, 6, "CONFIG bit 6 reserved (the one L6472 header's layout; 0 in the reset value 0x2E88)"},
};

constexpr Variant kVariant = [] {
  Variant v = make_variant("L6472", kRegisters, kStatus, kAlarms, /*max_step_sel=*/4, /*infinite_acceleration=*/false);
  v.unconfirmed = kUnconfirmedChoices;
  v.reserved_bits = kReserved;
  return v;
}();

static_assert(kVariant.at_address(0x0D) == nullptr && kVariant.at_address(0x11) == nullptr &&
              kVariant.at_address(0x14) == nullptr);
static_assert(kVariant.opcodes[0x2D].command == Command::Unknown, "GetParam of a hole is an unknown command");

}  // namespace

const Variant& l6472() { return kVariant; }

}  // namespace l6470emu
