// The L6470 register table (datasheet Table 9), STATUS layout (Table 34) and
// ALARM_EN bits (Table 21). Other variants live in files of their own.
#include "core/variant.hpp"

namespace l6470emu {
namespace {

using enum Access;
using enum Reg;

constexpr RegisterInfo kL6470Registers[] = {
    // address, id, name, bits, reset, access, flags
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
    {0x13, OCD_TH, "OCD_TH", 4, 0x8, WR, kNoFlags},
    {0x14, STALL_TH, "STALL_TH", 7, 0x40, WR, kNoFlags},
    {0x15, FS_SPD, "FS_SPD", 10, 0x027, WR, kNoFlags},
    {0x16, STEP_MODE, "STEP_MODE", 8, 0x07, WH, kNoFlags},
    {0x17, ALARM_EN, "ALARM_EN", 8, 0xFF, WS, kNoFlags},
    {0x18, CONFIG, "CONFIG", 16, 0x2E88, WH, kWriteConflict},
    {0x19, STATUS, "STATUS", 16, 0x0000, R, kLive},
};

static_assert(register_table_is_consistent(kL6470Registers));
static_assert(std::size(kL6470Registers) == 25, "0x01..0x19, 0x1A/0x1B reserved");

constexpr StatusLayout kL6470Status{};  // the defaults are the L6470 layout

constexpr AlarmLayout kL6470Alarms{
    Alarm::overcurrent, Alarm::thermal_shutdown, Alarm::thermal_warning, Alarm::uvlo,
    Alarm::stall_a,     Alarm::stall_b,          Alarm::switch_turn_on,  Alarm::command_error};

constexpr Variant kL6470 = make_variant("L6470", kL6470Registers, kL6470Status, kL6470Alarms,
                                        /*max_step_sel=*/7, /*infinite_acceleration=*/true);

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
