// Arduino pin numbers as the imitated board wires them: the NUCLEO-F401RE's Arduino header
// (STM32duino's variant_NUCLEO_F401RE.h: D0 = PA3 ... D15 = PB8).
#include "firmware/arduino_board.hpp"

#include <array>
#include <cctype>
#include <string>

namespace l6470emu {
namespace {

constexpr int port_pin(char port, int n) { return 128 + (port - 'A') * 16 + n; }

// D0..D15 of a Nucleo-64's Arduino header on the F401RE.
constexpr std::array<int, 16> kNucleoF401reHeader = {
    port_pin('A', 3), port_pin('A', 2), port_pin('A', 10), port_pin('B', 3), port_pin('B', 5), port_pin('B', 4),
    port_pin('B', 10), port_pin('A', 8), port_pin('A', 9), port_pin('C', 7), port_pin('B', 6), port_pin('A', 7),
    port_pin('A', 6), port_pin('A', 5), port_pin('B', 9), port_pin('B', 8)};

McuPin mapped(ArduinoBoard board, const McuPin& pin) {
  if (pin.kind != McuPin::Kind::arduino) return pin;
  const int key = arduino_pin_key(board, pin.number);
  if (key < 128) return pin;
  return McuPin{McuPin::Kind::stm32, static_cast<std::uint16_t>(key - 128)};
}

}  // namespace

std::optional<ArduinoBoard> parse_arduino_board(std::string_view name) {
  std::string lower;
  for (const char c : name) lower += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (lower == "uno") return ArduinoBoard::uno;
  if (lower == "nucleo_f401re") return ArduinoBoard::nucleo_f401re;
  return std::nullopt;
}

std::string_view to_string(ArduinoBoard board) {
  return board == ArduinoBoard::uno ? "uno" : "nucleo_f401re";
}

int arduino_pin_key(ArduinoBoard board, int pin) {
  if (board == ArduinoBoard::nucleo_f401re && pin >= 0 && pin < static_cast<int>(kNucleoF401reHeader.size()))
    return kNucleoF401reHeader[static_cast<std::size_t>(pin)];
  return pin;
}

void map_arduino_header(BoardConfig& config, ArduinoBoard board) {
  if (board == ArduinoBoard::uno) return;
  for (ChainConfig& c : config.chains) {
    if (c.pins.cs) c.pins.cs = mapped(board, *c.pins.cs);
    for (ChipPinList& list : c.pins.chip)
      for (std::optional<McuPin>& p : list)
        if (p) p = mapped(board, *p);
  }
}

}  // namespace l6470emu
