// The lines of an emulated gpiochip: five per chip of the chain (BUSY, FLAG, SW, STCK, STBY_RST),
// offset = 5 * chip + pin. Pure naming and layout; levels live in the board (board/board.hpp).
#pragma once

#include <cstddef>
#include <string>

#include "board/pins.hpp"

namespace l6470emu {

/// Character-device major the emulated gpiochips report (dynamic on real systems; 254 is typical).
inline constexpr unsigned kGpiochipMajor = 254;

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
