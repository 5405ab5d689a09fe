// The Arduino boards the firmware front imitates (docs/firmware.md, "Arduino boards"): an Uno,
// whose pin numbers are its own, and a NUCLEO-F401RE, whose Arduino header pins D0..D15 are
// STM32 port pins (D3 is PB3). Only the pin numbering: no board's peripherals or clocks.
#pragma once

#include <optional>
#include <string_view>

#include "board/board_config.hpp"

namespace l6470emu {

enum class ArduinoBoard { uno, nucleo_f401re };

/// "uno", "nucleo_f401re" (any case); nullopt for any other name.
std::optional<ArduinoBoard> parse_arduino_board(std::string_view name);
std::string_view to_string(ArduinoBoard board);

/// The pin an Arduino pin number is on `board`, as a FirmwareRuntime key: on a NUCLEO-F401RE
/// 0..15 are its header's D0..D15 (PA3, PA2, PA10, PB3, ...), every other number (PA0 = 128 ...)
/// is itself; on an Uno every number is itself.
int arduino_pin_key(ArduinoBoard board, int pin);

/// The description's Arduino pin numbers as `board` wires them: on a NUCLEO-F401RE `cs_pin=D10`
/// becomes PB6, the pin the sketch's D10 (and 10) drives. An Uno's description is left alone.
void map_arduino_header(BoardConfig& config, ArduinoBoard board);

}  // namespace l6470emu
