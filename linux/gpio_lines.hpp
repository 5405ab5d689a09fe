// The lines of an emulated gpiochip: five per chip of the chain (BUSY, FLAG, SW, STCK, STBY_RST),
// offset = 5 * chip + pin; on a chain with a DIR input (a chip of it is an L6474), one DIR line
// per chip after them, offset = 5 * chips + chip. Pure naming and layout; levels live in the
// board (board/board.hpp).
#pragma once

#include <cstddef>
#include <string>

#include "board/pins.hpp"

namespace l6470emu {

/// Character-device major the emulated gpiochips report (dynamic on real systems; 254 is typical).
inline constexpr unsigned kGpiochipMajor = 254;

/// The line layout of one chain's gpiochip.
struct GpioLines {
  /// Lines per chip before the DIR lines: BUSY, FLAG, SW, STCK, STBY_RST.
  static constexpr unsigned kBase = 5;
  std::size_t chips = 0;  ///< chips in the chain
  bool dir = false;       ///< the chain has DIR lines (a chip of it has a DIR input)

  /// How many lines the gpiochip has.
  constexpr unsigned count() const { return static_cast<unsigned>(chips * kBase + (dir ? chips : 0)); }
  /// Whether the gpiochip has a line for `pin` (DIR only on a chain with DIR lines).
  constexpr bool has(Pin pin) const { return pin != Pin::DIR || dir; }
  /// Line offset of `pin` of chip `k` (has(pin)).
  constexpr unsigned offset(std::size_t k, Pin pin) const {
    if (pin == Pin::DIR) return static_cast<unsigned>(chips * kBase + k);
    return static_cast<unsigned>(k * kBase + static_cast<unsigned>(pin));
  }
  /// The chip of a line (offset < count()).
  constexpr std::size_t chip_of(unsigned offset) const {
    return offset < chips * kBase ? offset / kBase : offset - chips * kBase;
  }
  /// The pin of a line (offset < count()).
  constexpr Pin pin_of(unsigned offset) const {
    return offset < chips * kBase ? static_cast<Pin>(offset % kBase) : Pin::DIR;
  }
  /// Line name: the pin name for a one-chip chain ("BUSY"), the pin name and the chip number
  /// otherwise ("BUSY0", "BUSY1", ...), so that names stay unique on the chip.
  std::string name(unsigned offset) const {
    std::string n = pin_name(pin_of(offset));
    if (chips > 1) n += std::to_string(chip_of(offset));
    return n;
  }
};

}  // namespace l6470emu
