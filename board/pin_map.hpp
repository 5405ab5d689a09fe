// Which microcontroller pin each wire of a chain goes to, for the firmware fronts: the chain's
// chip select and each chip's BUSY, FLAG, SW, STCK, STBY_RST and DIR, and the SPI controller it
// hangs on. Names and parsing only; levels and edges live in Board and firmware/.
#pragma once

#include <array>
#include <compare>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "board/pins.hpp"

namespace l6470emu {

/// A pin of the microcontroller a firmware program runs on: an Arduino pin number (`10`, `D10`,
/// `A0` = 14 as on an Uno, `GPIO5` = 5) or an STM32 port pin (`PA4`, ports A to K).
struct McuPin {
  enum class Kind : std::uint8_t { arduino, stm32 };
  Kind kind = Kind::arduino;
  /// arduino: the pin number, 0 to kMaxArduinoPin; stm32: port × 16 + pin (port 0 = A, 10 = K).
  std::uint16_t number = 0;
  auto operator<=>(const McuPin&) const = default;
};

/// The highest Arduino pin number a description may name (A0 = 14 ... A7 = 21 as on an Uno).
inline constexpr unsigned kMaxArduinoPin = 127;
/// The number of STM32 ports (A to K).
inline constexpr unsigned kStm32Ports = 11;
/// Arduino pin number of A0 (the analog pins A0..A7 follow it, as on an Uno or a Nano).
inline constexpr unsigned kArduinoA0 = 14;

/// Parses a pin name (any case): `10`, `D10`, `A0`..`A7`, `GPIO5`, `PA0`..`PK15`; nullopt if it is none.
std::optional<McuPin> parse_mcu_pin(std::string_view text);
/// The pin as the description writes it back: "10" or "PA4".
std::string to_string(const McuPin& pin);

/// Where one chip wire (a chip pin, or the chain's chip select) goes, per chip.
using ChipPinList = std::vector<std::optional<McuPin>>;

/// The microcontroller side of one chain (the description's cs_pin=, busy_pin=, flag_pin=,
/// sw_pin=, stck_pin=, stby_rst_pin=, dir_pin=, sck_pin=, mosi_pin=, miso_pin= and spi= keys).
struct ChainPins {
  /// The pin driving the chain's chip select (cs_pin=); none: nothing selects it.
  std::optional<McuPin> cs;
  /// SPI at the pins (sck_pin=, mosi_pin=, miso_pin=): the program drives CK and SDI and reads
  /// SDO on these pins itself (bit-banged SPI); none: only an SPI controller reaches the chain.
  std::optional<McuPin> sck, mosi, miso;
  /// Per chip pin (indexed by Pin): empty = not given; one entry = every chip of the chain on
  /// that pin (open-drain BUSY/FLAG wired together, one line driving every SW/STCK/STBY_RST);
  /// else one entry per chip in the order numbering= counts them (nullopt: that chip's pin is
  /// not connected).
  std::array<ChipPinList, kPinsPerChip> chip;
  /// The SPI controller's name as firmware names it (spi=: "SPI", "SPI1".."SPI9", "HSPI",
  /// "VSPI", "FSPI"); "" = named after bus= (docs/firmware.md).
  std::string spi;

  /// Whether any pin is given.
  bool any() const {
    if (cs || sck || mosi || miso) return true;
    for (const auto& l : chip)
      if (!l.empty()) return true;
    return false;
  }
  bool operator==(const ChainPins&) const = default;
};

/// The description key of a chip pin: "busy_pin", "flag_pin", "sw_pin", "stck_pin", "stby_rst_pin", "dir_pin".
const char* pin_key(Pin p);

/// Canonical name of an SPI controller (spi=): "SPI", "SPI1".."SPI9", "HSPI", "VSPI", "FSPI",
/// with `hspi1` meaning "SPI1" (an STM32 HAL handle's name); nullopt if it is none.
std::optional<std::string> parse_spi_controller(std::string_view text);

/// The MCU pin chip `user_chip` (counted as numbering= says) has for `pin`, or nullopt.
std::optional<McuPin> chip_mcu_pin(const ChainPins& pins, Pin pin, std::size_t user_chip);

}  // namespace l6470emu
