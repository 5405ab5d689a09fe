// The L6474 (easySPIN: current mode, integrated bridges, no motion engine): its register table,
// STATUS layout and ALARM_EN bits. Every fact and its source is in docs/l6474.md.
#include "core/register_rows.hpp"
#include "core/variant.hpp"

namespace l6470emu {
namespace {

using enum Access;
using enum Reg;

// Only the position registers of 0x01-0x08, one TVAL at 0x09, the current-control timings of
// the L6472 at 0x0E-0x10; 0x04-0x08, 0x0A-0x0D, 0x11, 0x14, 0x15 and 0x1A-0x1F are holes.
constexpr auto kRegisters = rows::concat(
    rows::kPosition, rows::row({0x09, TVAL, "TVAL", 7, 0x29, WR, kUnconfirmed}), rows::kCurrentTimes,
    rows::row(rows::kAdcOut), rows::row({0x13, OCD_TH, "OCD_TH", 4, 0x8, WR, kUnconfirmed}),
    rows::row({0x16, STEP_MODE, "STEP_MODE", 8, 0x07, WH, kUnconfirmed}),
    rows::row({0x17, ALARM_EN, "ALARM_EN", 8, 0xFF, WS, kUnconfirmed}),
    rows::config_and_status(0x18, 0x2E88, kWriteConflict | kUnconfirmed));

static_assert(register_table_is_consistent(kRegisters));
static_assert(std::size(kRegisters) == 13, "ABS_POS, EL_POS, MARK, TVAL, T_FAST, TON_MIN, TOFF_MIN, ADC_OUT, OCD_TH, "
                                           "STEP_MODE, ALARM_EN, CONFIG, STATUS");

// The L6470's places for the flags it has; no BUSY, SW_F, SW_EVN, MOT_STATUS, stall or SCK_MOD
// field. Bits 15, 14, 13 and 1 read 1 (public reports of real chips: 0xFE03 after start-up).
constexpr StatusLayout kStatus = [] {
  StatusLayout l;
  l.busy = -1;
  l.sw_f = -1;
  l.sw_evn = -1;
  l.mot_status = -1;
  l.step_loss_a = -1;
  l.step_loss_b = -1;
  l.sck_mod = -1;
  l.unused_ones = 0xE002;
  return l;
}();

// Bits 4 and 5 enable nothing (no stall detection); bit 6, the others' switch turn-on event,
// has nothing to enable either: the L6474 has no SW input.
constexpr AlarmLayout kAlarms{Alarm::overcurrent, Alarm::thermal_shutdown, Alarm::thermal_warning, Alarm::uvlo,
                              Alarm::none,        Alarm::none,             Alarm::none,            Alarm::command_error};

constexpr std::string_view kUnconfirmedChoices[] = {
    "reset values of TVAL (0x29), T_FAST (0x19), TON_MIN/TOFF_MIN (0x29), OCD_TH (0x8), STEP_MODE (0x07), ALARM_EN "
    "(0xFF) and CONFIG (0x2E88): one open-source driver's test model, the same values as the L6472's",
    "STATUS bits 15, 14, 13 and 1 read 1, bits 6, 5, 3 and 2 read 0 (public reports of real chips read 0xFE03 after "
    "start-up)",
    "STCK rising edges move the position only while the bridges are enabled (Enable); in HiZ they are ignored",
    "DIR high steps forward (ABS_POS up, STATUS DIR 1), as ST's drivers drive it",
    "Enable while a fault holds the bridges in HiZ (thermal shutdown, OCD with OC_SD, UVLO) leaves them in HiZ and "
    "raises no flag, as HardStop does on the others",
    "STEP_SEL 101..111 act as 1/16 (the finest the chip has); the value is stored as written",
    "ALARM_EN bits 4, 5 and 6 enable nothing",
};

constexpr ReservedBit kReserved[] = {
    {Reg::CONFIG, 6, "CONFIG bit 6 has no field on the L6474 (ST's driver header; 0 in the reset value 0x2E88)"},
};

constexpr Variant kVariant = [] {
  Variant v = make_variant("L6474", kRegisters, kStatus, kAlarms, /*max_step_sel=*/4, /*infinite_acceleration=*/false);
  drop_motion_engine(v);
  v.unconfirmed = kUnconfirmedChoices;
  v.reserved_bits = kReserved;
  return v;
}();

static_assert(kVariant.at_address(0x04) == nullptr && kVariant.at_address(0x0A) == nullptr &&
              kVariant.at_address(0x15) == nullptr && kVariant.at_address(0x1A) == nullptr);
static_assert(kVariant.opcodes[0x39].command == Command::GetParam, "GetParam(STATUS)");
static_assert(kVariant.opcodes[0x24].command == Command::Unknown, "GetParam of a hole (SPEED's address)");
static_assert(kVariant.opcodes[0xB8].command == Command::Enable && kVariant.opcodes[0xA8].command == Command::Disable);
static_assert(kVariant.opcodes[0xD0].command == Command::GetStatus);
static_assert(kVariant.opcodes[0x40].command == Command::Unknown && kVariant.opcodes[0x40].arg_bytes == 0,
              "Move is no command: its argument bytes are decoded as commands");
static_assert(kVariant.opcodes[0xB0].command == Command::Unknown && kVariant.opcodes[0xC0].command == Command::Unknown &&
              kVariant.opcodes[0xD8].command == Command::Unknown, "SoftStop, ResetDevice, ResetPos");
static_assert(kVariant.opcodes[0xEB].command == Command::Reserved);

}  // namespace

const Variant& l6474() { return kVariant; }

}  // namespace l6470emu
