// The powerSTEP01: the L6480 map in voltage mode; with STEP_MODE.CM_VM = 1 the
// addresses 0x09-0x10 read as TVAL_*, T_FAST, TON_MIN and TOFF_MIN (current mode).
#include <algorithm>

#include "core/variant.hpp"
#include "core/variant_gate_driver.hpp"

namespace l6470emu {
namespace {

// A copy with internal linkage: constant evaluation (and UBSan's null checks) only
// accept addresses of this translation unit's own constexpr objects here.
constexpr auto kRegisters = kVoltageModeGateDriverRegisters;

/// The voltage-mode rows with 0x09-0x0C, 0x0E-0x10 read in current mode.
constexpr auto kCurrentModeRegisters = [] {
  auto t = kRegisters;
  for (const auto& a : rows::kCurrentMode)
    for (auto& r : t)
      if (r.address == a.address) r = a;
  return t;
}();
static_assert(register_table_is_consistent(kCurrentModeRegisters));

constexpr std::string_view kUnconfirmedChoices[] = {
    "reset values: assumed equal to the L6480's (the powerSTEP01 table was not retrieved)",
    "voltage and current mode share the storage of 0x09-0x10; reads and writes use the width of the mode in force "
    "(so a TVAL read masks bit 7 of a KVAL written in voltage mode)",
    "ResetDevice while the bridges are enabled is refused with CMD_ERROR (community report); switchable quirk",
    "STALL_A on STATUS bit 14 and STALL_B on bit 15: quirk",
    "1/128 microstepping in both modes",
};

// STEP_MODE bit 3 is CM_VM here (voltage or current mode), not reserved.
constexpr ReservedBit kReserved[] = {
    {Reg::CONFIG, 6, "CONFIG bit 6 reserved (ST's powerSTEP01 code; 0 in the reset value 0x2C88)"},
};

constexpr Variant kCurrentMode = [] {
  Variant v = make_variant("powerSTEP01", kCurrentModeRegisters, kGateDriverStatus, kGateDriverAlarms, 7, true);
  v.reset_device_needs_hiz = true;
  v.unconfirmed = kUnconfirmedChoices;
  v.reserved_bits = kReserved;
  return v;
}();

constexpr Variant kVoltageMode = [] {
  Variant v = make_variant("powerSTEP01", kRegisters, kGateDriverStatus, kGateDriverAlarms, 7, true);
  v.current_mode = &kCurrentMode;
  v.reset_device_needs_hiz = true;
  v.unconfirmed = kUnconfirmedChoices;
  v.reserved_bits = kReserved;
  return v;
}();

static_assert(kCurrentMode.find(Reg::TVAL_HOLD)->address == 0x09 && !kCurrentMode.has(Reg::KVAL_HOLD));
static_assert(kCurrentMode.find(Reg::INT_SPEED) != nullptr, "0x0D keeps its name in current mode");

}  // namespace

const Variant& powerstep01() { return kVoltageMode; }

}  // namespace l6470emu
