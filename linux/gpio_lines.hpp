// The lines of an emulated gpiochip: five per chip of the chain (BUSY, FLAG, SW, STCK, STBY_RST),
// offset = 5 * chip + pin. Pure naming and layout; levels live in Board.
#pragma once

#include <cstddef>
#include <string>

namespace l6470emu {

/// Character-device major the emulated gpiochips report (dynamic on real systems; 254 is typical).
inline constexpr unsigned kGpiochipMajor = 254;

/// The chip pins a gpiochip exposes, in line order.
enum class Pin : unsigned { BUSY = 0, FLAG = 1, SW = 2, STCK = 3, STBY_RST = 4 };
inline constexpr unsigned kPinsPerChip = 5;

/// Datasheet name of a pin ("BUSY", "FLAG", "SW", "STCK", "STBY_RST").
inline const char* pin_name(Pin p) {
  static const char* const names[] = {"BUSY", "FLAG", "SW", "STCK", "STBY_RST"};
  return names[static_cast<unsigned>(p)];
}

/// Whether the chip drives the pin (BUSY, FLAG) rather than reads it (SW, STCK, STBY_RST).
constexpr bool pin_is_chip_output(Pin p) { return p == Pin::BUSY || p == Pin::FLAG; }

/// Line offset of `pin` of chip `k`.
constexpr unsigned line_offset(std::size_t k, Pin pin) {
  return static_cast<unsigned>(k * kPinsPerChip + static_cast<unsigned>(pin));
}
constexpr std::size_t chip_of_line(unsigned offset) { return offset / kPinsPerChip; }
constexpr Pin pin_of_line(unsigned offset) { return static_cast<Pin>(offset % kPinsPerChip); }

/// Line name: the pin name for a one-chip chain ("BUSY"), the pin name and the chip number
/// otherwise ("BUSY0", "BUSY1", ...), so that names stay unique on the chip.
inline std::string line_name(std::size_t chips_in_chain, unsigned offset) {
  std::string name = pin_name(pin_of_line(offset));
  if (chips_in_chain > 1) name += std::to_string(chip_of_line(offset));
  return name;
}

}  // namespace l6470emu
