// The L6470 register table (datasheet Table 9), STATUS layout (Table 34) and
// ALARM_EN bits (Table 21). Other variants live in files of their own.
#include "core/register_rows.hpp"
#include "core/variant.hpp"

namespace l6470emu {
namespace {

constexpr auto kL6470Registers = rows::concat(
    rows::kMotion, rows::kVoltageMode, rows::row(rows::kAdcOut),
    rows::row({0x13, Reg::OCD_TH, "OCD_TH", 4, 0x8, Access::WR, kNoFlags}),
    rows::row({0x14, Reg::STALL_TH, "STALL_TH", 7, 0x40, Access::WR, kNoFlags}),
    rows::row({0x15, Reg::FS_SPD, "FS_SPD", 10, 0x027, Access::WR, kNoFlags}), rows::row(rows::kStepMode),
    rows::row(rows::kAlarmEn), rows::config_and_status(0x18, 0x2E88, kWriteConflict));

static_assert(register_table_is_consistent(kL6470Registers));
static_assert(std::size(kL6470Registers) == 25, "0x01..0x19, 0x1A/0x1B reserved");

constexpr StatusLayout kL6470Status{};  // the defaults are the L6470 layout

constexpr AlarmLayout kL6470Alarms{
    Alarm::overcurrent, Alarm::thermal_shutdown, Alarm::thermal_warning, Alarm::uvlo,
    Alarm::stall_a,     Alarm::stall_b,          Alarm::switch_turn_on,  Alarm::command_error};

constexpr ReservedBit kL6470Reserved[] = {
    {Reg::STEP_MODE, 3, "§9.1.19 Table 17, note 1: bit 3 is written 0"},
    {Reg::CONFIG, 6, "§9.1.21 Table 22: bit 6 RESERVED (0 in the reset value 0x2E88)"},
};

constexpr Variant kL6470 = [] {
  Variant v = make_variant("L6470", kL6470Registers, kL6470Status, kL6470Alarms,
                           /*max_step_sel=*/7, /*infinite_acceleration=*/true);
  v.reserved_bits = kL6470Reserved;
  return v;
}();

static_assert(kL6470.find(Reg::ABS_POS)->spi_bytes() == 3);
static_assert(kL6470.find(Reg::EL_POS)->spi_bytes() == 2);
static_assert(kL6470.find(Reg::MIN_SPEED)->spi_bytes() == 2);
static_assert(kL6470.find(Reg::CONFIG)->spi_bytes() == 2 && kL6470.find(Reg::CONFIG)->address == 0x18);
static_assert(kL6470.find(Reg::STATUS)->address == 0x19);
static_assert(kL6470.at_address(0x1A) == nullptr && kL6470.at_address(0x00) == nullptr);
static_assert(sign_extend(0x3FFFFF, 22) == -1 && sign_extend(0x200000, 22) == -(1 << 21));

}  // namespace

const Variant& l6470() { return kL6470; }

}  // namespace l6470emu
