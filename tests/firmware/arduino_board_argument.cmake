# l6470emu_add_sketch's ARDUINO_BOARD checked before anything is built: a board the front does
# not imitate, or the argument given to a HAL program, is one error naming what it takes.
# Usage: cmake -DFUNCTIONS=.../cmake/l6470emuFirmware.cmake -DCASE=unknown_board|hal_program -P arduino_board_argument.cmake
include(${FUNCTIONS})
if(CASE STREQUAL "unknown_board")
  l6470emu_add_sketch(demo SOURCES demo.ino ARDUINO_BOARD nucleo_f411re)
else()
  l6470emu_add_hal_program(demo SOURCES main.c ARDUINO_BOARD uno)
endif()
