// The L6482 (current mode, gate driver): TVAL_*/T_FAST/TON_MIN/TOFF_MIN at 0x09-0x10,
// holes at 0x0D, 0x11 and 0x14, no stall detection, at most 1/16 microstepping.
#include "core/variant.hpp"
#include "core/variant_gate_driver.hpp"

namespace l6470emu {
namespace {

using enum Access;
using enum Reg;

constexpr RegisterInfo kRegisters[] = {
    {0x01, ABS_POS, "ABS_POS", 22, 0x000000, WS, kSigned | kLive},
    {0x02, EL_POS, "EL_POS", 9, 0x000, WS, kLive},
    {0x03, MARK, "MARK", 22, 0x000000, WR, kSigned},
    {0x04, SPEED, "SPEED", 20, 0x00000, R, kLive},
    {0x05, ACC, "ACC", 12, 0x08A, WS, kNoFlags},
    {0x06, DEC, "DEC", 12, 0x08A, WS, kNoFlags},
    {0x07, MAX_SPEED, "MAX_SPEED", 10, 0x041, WR, kNoFlags},
    {0x08, MIN_SPEED, "MIN_SPEED", 13, 0x000, WS, kNoFlags},
    {0x09, TVAL_HOLD, "TVAL_HOLD", 7, 0x29, WR, kUnconfirmed},
    {0x0A, TVAL_RUN, "TVAL_RUN", 7, 0x29, WR, kUnconfirmed},
    {0x0B, TVAL_ACC, "TVAL_ACC", 7, 0x29, WR, kUnconfirmed},
    {0x0C, TVAL_DEC, "TVAL_DEC", 7, 0x29, WR, kUnconfirmed},
    {0x0E, T_FAST, "T_FAST", 8, 0x19, WH, kUnconfirmed},
    {0x0F, TON_MIN, "TON_MIN", 7, 0x29, WH, kUnconfirmed},
    {0x10, TOFF_MIN, "TOFF_MIN", 7, 0x29, WH, kUnconfirmed},
    {0x12, ADC_OUT, "ADC_OUT", 5, 0x00, R, kLive},
    {0x13, OCD_TH, "OCD_TH", 5, 0x08, WR, kNoFlags},
    {0x15, FS_SPD, "FS_SPD", 11, 0x027, WR, kNoFlags},
    {0x16, STEP_MODE, "STEP_MODE", 8, 0x07, WH, kUnconfirmed},
    {0x17, ALARM_EN, "ALARM_EN", 8, 0xFF, WS, kNoFlags},
    {0x18, GATECFG1, "GATECFG1", 12, 0x000, WH, kNoFlags},
    {0x19, GATECFG2, "GATECFG2", 8, 0x00, WH, kNoFlags},
    {0x1A, CONFIG, "CONFIG", 16, 0x2C88, WH, kUnconfirmed},
    {0x1B, STATUS, "STATUS", 16, 0x0000, R, kLive},
};
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

constexpr Variant kVariant = [] {
  Variant v = make_variant("L6482", kRegisters, kStatus, kAlarms, /*max_step_sel=*/4, /*infinite_acceleration=*/true);
  v.unconfirmed = kUnconfirmedChoices;
  return v;
}();

static_assert(kVariant.at_address(0x0D) == nullptr && kVariant.at_address(0x11) == nullptr &&
              kVariant.at_address(0x14) == nullptr);

}  // namespace

const Variant& l6482() { return kVariant; }

}  // namespace l6470emu
