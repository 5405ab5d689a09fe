// The named pins of one chip as the board wires them: BUSY\SYNC and FLAG (the chip drives
// them), SW, STCK and STBY\RST (the world or a host drives them). Names only; levels live in Board.
#pragma once

namespace l6470emu {

/// The pins of a chip a board brings out, in a fixed order (a gpiochip's line order).
enum class Pin : unsigned { BUSY = 0, FLAG = 1, SW = 2, STCK = 3, STBY_RST = 4 };
/// How many named pins each chip has.
inline constexpr unsigned kPinsPerChip = 5;

/// Datasheet name of a pin ("BUSY", "FLAG", "SW", "STCK", "STBY_RST").
inline const char* pin_name(Pin p) {
  static const char* const names[] = {"BUSY", "FLAG", "SW", "STCK", "STBY_RST"};
  return names[static_cast<unsigned>(p)];
}

/// Whether the chip drives the pin (BUSY, FLAG) rather than reads it (SW, STCK, STBY_RST).
constexpr bool pin_is_chip_output(Pin p) { return p == Pin::BUSY || p == Pin::FLAG; }

}  // namespace l6470emu
