// The L6472 (current mode, integrated bridges). Its datasheet was only seen in
// excerpts: rows marked kUnconfirmed come from one third-party header (spec §2.2).
#include "core/variant.hpp"

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
    {0x13, OCD_TH, "OCD_TH", 4, 0x8, WR, kNoFlags},
    {0x15, FS_SPD, "FS_SPD", 10, 0x027, WR, kNoFlags},
    {0x16, STEP_MODE, "STEP_MODE", 8, 0x07, WH, kNoFlags},
    {0x17, ALARM_EN, "ALARM_EN", 8, 0xFF, WS, kNoFlags},
    {0x18, CONFIG, "CONFIG", 16, 0x2E88, WH, kUnconfirmed},
    {0x19, STATUS, "STATUS", 16, 0x0000, R, kLive},
};
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

constexpr Variant kVariant = [] {
  Variant v = make_variant("L6472", kRegisters, kStatus, kAlarms, /*max_step_sel=*/4, /*infinite_acceleration=*/false);
  v.unconfirmed = kUnconfirmedChoices;
  return v;
}();

static_assert(kVariant.at_address(0x0D) == nullptr && kVariant.at_address(0x11) == nullptr &&
              kVariant.at_address(0x14) == nullptr);
static_assert(kVariant.opcodes[0x2D].command == Command::Unknown, "GetParam of a hole is an unknown command");

}  // namespace

const Variant& l6472() { return kVariant; }

}  // namespace l6470emu
