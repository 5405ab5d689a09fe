// The L6480 (voltage mode, gate driver): the L6470 map with 5-bit OCD_TH/STALL_TH,
// BOOST_MODE in FS_SPD bit 10, GATECFG1/2 at 0x18/0x19 and CONFIG/STATUS moved to 0x1A/0x1B.
#include "core/variant.hpp"
#include "core/variant_gate_driver.hpp"

namespace l6470emu {
namespace {

// A copy with internal linkage: constant evaluation (and UBSan's null checks) only
// accept addresses of this translation unit's own constexpr objects here.
constexpr auto kRegisters = kVoltageModeGateDriverRegisters;


constexpr std::string_view kUnconfirmedChoices[] = {
    "write conditions (WS/WH/WR) mirror the L6470 table plus WH for GATECFG1/2 and CONFIG: one third-party driver",
    "STALL_A on STATUS bit 14 and STALL_B on bit 15 (two ST code bases; two other libraries say the reverse): quirk",
    "ACC = 0xFFF selects infinite acceleration as on the L6470",
    "UVLO_ADC, TH_STATUS and CMD_ERROR latch like the L6470 flags until GetStatus",
};

constexpr ReservedBit kReserved[] = {
    {Reg::STEP_MODE, 3, "L6480 datasheet, STEP_MODE register: bit 3 is written 0 (as on the L6470)"},
    {Reg::CONFIG, 6, "CONFIG bit 6 reserved (as on the L6470; 0 in the reset value 0x2C88)"},
};

constexpr Variant kVariant = [] {
  Variant v = make_variant("L6480", kRegisters, kGateDriverStatus, kGateDriverAlarms, 7, true);
  v.unconfirmed = kUnconfirmedChoices;
  v.reserved_bits = kReserved;
  return v;
}();

static_assert(kVariant.find(Reg::CONFIG)->address == 0x1A && kVariant.find(Reg::STATUS)->address == 0x1B);
static_assert(kVariant.find(Reg::GATECFG1)->spi_bytes() == 2, "GATECFG1 is 12 bits: two bytes (CSPIN's one byte is a bug)");

}  // namespace

const Variant& l6480() { return kVariant; }

}  // namespace l6470emu
