// The lines of an emulated gpiochip: five per chip of the chain (BUSY, FLAG, SW, STCK, STBY_RST),
// offset = 5 * chip + pin; on a chain with a DIR input (a chip of it is an L6474), one DIR line
// per chip after them, offset = 5 * chips + chip; on a chain whose SPI is on pins (sck_pin= in
// its description), four more after those: CS, SCK, MOSI, MISO (the host's side of the chain's
// serial interface, for a bit-banging program). Pure naming and layout; levels live in the
// board (board/board.hpp).
#pragma once

#include <cstddef>
#include <optional>
#include <string>

#include "board/pins.hpp"

namespace l6470emu {

/// Character-device major the emulated gpiochips report (dynamic on real systems; 254 is typical).
inline constexpr unsigned kGpiochipMajor = 254;

/// The four lines of a chain's SPI at its pins, in offset order (the host's names: CS is the
/// chips' CS, SCK their CK, MOSI their SDI, MISO chip 0's SDO).
enum class SpiLine : unsigned { cs = 0, sck = 1, mosi = 2, miso = 3 };

/// Line name of an SPI line: "CS", "SCK", "MOSI", "MISO".
inline const char* spi_line_name(SpiLine l) {
  switch (l) {
    case SpiLine::cs: return "CS";
    case SpiLine::sck: return "SCK";
    case SpiLine::mosi: return "MOSI";
    case SpiLine::miso: return "MISO";
  }
  return "?";
}

/// The line layout of one chain's gpiochip.
struct GpioLines {
  /// Lines per chip before the DIR lines: BUSY, FLAG, SW, STCK, STBY_RST.
  static constexpr unsigned kBase = 5;
  /// SPI lines of a chain whose SPI is on pins: CS, SCK, MOSI, MISO.
  static constexpr unsigned kSpiLines = 4;
  std::size_t chips = 0;  ///< chips in the chain
  bool dir = false;       ///< the chain has DIR lines (a chip of it has a DIR input)
  bool spi = false;       ///< the chain has SPI lines (its description has sck_pin=)

  /// How many lines the gpiochip has.
  constexpr unsigned count() const { return spi_first() + (spi ? kSpiLines : 0); }
  /// Offset of the first SPI line (CS) when spi; the count of the chip lines either way.
  constexpr unsigned spi_first() const { return static_cast<unsigned>(chips * kBase + (dir ? chips : 0)); }
  /// Whether the gpiochip has a line for `pin` (DIR only on a chain with DIR lines).
  constexpr bool has(Pin pin) const { return pin != Pin::DIR || dir; }
  /// Line offset of `pin` of chip `k` (has(pin)).
  constexpr unsigned offset(std::size_t k, Pin pin) const {
    if (pin == Pin::DIR) return static_cast<unsigned>(chips * kBase + k);
    return static_cast<unsigned>(k * kBase + static_cast<unsigned>(pin));
  }
  /// Line offset of SPI line `l` (spi).
  constexpr unsigned offset(SpiLine l) const { return spi_first() + static_cast<unsigned>(l); }
  /// The SPI line at `offset`; nullopt for a chip's line (offset < count()).
  constexpr std::optional<SpiLine> spi_line(unsigned offset) const {
    if (!spi || offset < spi_first()) return std::nullopt;
    return static_cast<SpiLine>(offset - spi_first());
  }
  /// The chip of a chip's line (offset < spi_first()).
  constexpr std::size_t chip_of(unsigned offset) const {
    return offset < chips * kBase ? offset / kBase : offset - chips * kBase;
  }
  /// The pin of a chip's line (offset < spi_first()).
  constexpr Pin pin_of(unsigned offset) const {
    return offset < chips * kBase ? static_cast<Pin>(offset % kBase) : Pin::DIR;
  }
  /// Line name: the pin name for a one-chip chain ("BUSY"), the pin name and the chip number
  /// otherwise ("BUSY0", "BUSY1", ...), so that names stay unique on the chip; an SPI line's
  /// own name ("CS", "SCK", "MOSI", "MISO"), one per chain.
  std::string name(unsigned offset) const {
    if (const auto l = spi_line(offset)) return spi_line_name(*l);
    std::string n = pin_name(pin_of(offset));
    if (chips > 1) n += std::to_string(chip_of(offset));
    return n;
  }
};

}  // namespace l6470emu
