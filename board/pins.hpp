// The named pins of one chip as the board wires them: BUSY\SYNC and FLAG (the chip drives
// them), SW, STCK, STBY\RST and DIR (the world or a host drives them). Names only; levels live
// in Board. Which pins a chip really has is its variant's (Variant::pins): the L6474 has DIR
// and neither BUSY\SYNC nor SW; the others have BUSY\SYNC and SW and no DIR.
#pragma once

#include "core/variant.hpp"

namespace l6470emu {

/// The pins of a chip a board brings out, in a fixed order (a gpiochip's line order; DIR,
/// added last, has its lines after the others').
enum class Pin : unsigned { BUSY = 0, FLAG = 1, SW = 2, STCK = 3, STBY_RST = 4, DIR = 5 };
/// How many named pins each chip has.
inline constexpr unsigned kPinsPerChip = 6;

/// Datasheet name of a pin ("BUSY", "FLAG", "SW", "STCK", "STBY_RST", "DIR").
inline const char* pin_name(Pin p) {
  static const char* const names[] = {"BUSY", "FLAG", "SW", "STCK", "STBY_RST", "DIR"};
  return names[static_cast<unsigned>(p)];
}

/// Whether the chip drives the pin (BUSY, FLAG) rather than reads it (SW, STCK, STBY_RST, DIR).
constexpr bool pin_is_chip_output(Pin p) { return p == Pin::BUSY || p == Pin::FLAG; }

/// Whether a chip of `variant` has pin `p` (FLAG, STCK and STBY_RST: all of them).
constexpr bool variant_has_pin(const Variant& variant, Pin p) {
  switch (p) {
    case Pin::BUSY: return variant.pins.busy_sync;
    case Pin::SW: return variant.pins.sw;
    case Pin::DIR: return variant.pins.dir;
    default: return true;
  }
}

}  // namespace l6470emu
