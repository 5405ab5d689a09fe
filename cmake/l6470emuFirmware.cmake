# Building firmware programs against l6470emu's fronts (docs/firmware.md), the same in the
# build tree and from the installed package (l6470emuConfig.cmake includes this file):
#
#   l6470emu_add_sketch(NAME SOURCES sketch.ino [more.ino] [lib.cpp ...]
#                       [BOARD "chips=3xL6470 cs_pin=D10 flag_pin=D2" | BOARD_FILE board.conf]
#                       [ARDUINO_BOARD uno | nucleo_f401re] [CHECK error | warn | off]
#                       [INCLUDE_DIRECTORIES dir ...] [LINK_LIBRARIES lib ...])
#     An Arduino sketch and its libraries: .ino files become one C++ file as the Arduino IDE
#     makes it (#include <Arduino.h>, prototypes; the first .ino is the main one, the others
#     follow by name), compiled as GNU C++17 with -fpermissive (as the Arduino IDE compiles);
#     linked with l6470emu::arduino, whose main() runs setup() then loop(). ARDUINO_BOARD is the
#     board whose pin numbers the sketch uses: an Uno by default (D10 is 10); nucleo_f401re
#     numbers them as a NUCLEO-F401RE's Arduino header (D10, 10 and the description's D10 are
#     PB6). The sketch gets the compile definition L6470EMU_ARDUINO_BOARD_<BOARD>.
#   l6470emu_add_hal_program(NAME SOURCES main.c ... [BOARD ... | BOARD_FILE ...] ...)
#     An STM32Cube HAL program with its own main(), linked with l6470emu::stm32hal
#     (stm32f4xx_hal.h and the other families' headers).
#   l6470emu_add_firmware_program(NAME SOURCES ... [BOARD ... | BOARD_FILE ...] ...)
#     A program on the plain C API (<l6470emu/firmware/firmware.h>), linked with l6470emu::firmware.
#
# BOARD / BOARD_FILE is the board the program runs on unless L6470EMU_CHAIN or L6470EMU_CONFIG
# says otherwise at run time; without either, one L6470 with the front's default pins. CHECK is
# the driver sanitizer's level unless the description's check= or L6470EMU_CHECK says: error by
# default, so a program run as a test (add_test) fails on the first broken rule with status 86;
# warn reports each broken rule and runs on. The project must enable C++ (and C for C sources).
include_guard(GLOBAL)

function(_l6470emu_firmware_program name front_library)
  cmake_parse_arguments(PARSE_ARGV 2 arg "" "BOARD;BOARD_FILE;ARDUINO_BOARD;CHECK" "SOURCES;INCLUDE_DIRECTORIES;LINK_LIBRARIES")
  if(arg_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "l6470emu: ${name}: unknown arguments ${arg_UNPARSED_ARGUMENTS} "
                        "(SOURCES, BOARD, BOARD_FILE, ARDUINO_BOARD, CHECK, INCLUDE_DIRECTORIES, LINK_LIBRARIES)")
  endif()
  set(check error)
  if(DEFINED arg_CHECK)
    string(TOLOWER "${arg_CHECK}" check)
    if(NOT check MATCHES "^(off|warn|error)$")
      message(FATAL_ERROR "l6470emu: ${name}: CHECK \"${arg_CHECK}\" is none of off, warn, error")
    endif()
  endif()
  if(DEFINED arg_ARDUINO_BOARD)
    if(NOT front_library STREQUAL "l6470emu::arduino")
      message(FATAL_ERROR "l6470emu: ${name}: ARDUINO_BOARD is for sketches (l6470emu_add_sketch); "
                          "a HAL or C API program names STM32 port pins itself")
    endif()
    string(TOLOWER "${arg_ARDUINO_BOARD}" arduino_board)
    if(NOT arduino_board MATCHES "^(uno|nucleo_f401re)$")
      message(FATAL_ERROR "l6470emu: ${name}: ARDUINO_BOARD \"${arg_ARDUINO_BOARD}\" is none of uno, nucleo_f401re")
    endif()
  endif()
  if(NOT arg_SOURCES)
    message(FATAL_ERROR "l6470emu: ${name}: no SOURCES")
  endif()
  if(DEFINED arg_BOARD AND DEFINED arg_BOARD_FILE)
    message(FATAL_ERROR "l6470emu: ${name}: BOARD and BOARD_FILE both given (one board per program)")
  endif()
  get_property(languages GLOBAL PROPERTY ENABLED_LANGUAGES)
  if(NOT "CXX" IN_LIST languages)
    message(FATAL_ERROR "l6470emu: ${name}: the project must enable C++ (project(... LANGUAGES C CXX)): "
                        "the emulator is C++")
  endif()

  set(sources "")
  set(ino "")
  set(include_dirs "")
  foreach(s ${arg_SOURCES})
    get_filename_component(path "${s}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
    if(path MATCHES "\\.(ino|pde)$")
      list(APPEND ino "${path}")
    else()
      list(APPEND sources "${path}")
    endif()
    get_filename_component(dir "${path}" DIRECTORY)
    list(APPEND include_dirs "${dir}")  # "file.h" next to a sketch is found from the generated C++
  endforeach()
  if(ino)
    set(out "${CMAKE_CURRENT_BINARY_DIR}/${name}_sketch.cpp")
    add_custom_command(OUTPUT "${out}"
      COMMAND "$<TARGET_FILE:l6470emu::ino>" "${out}" ${ino}
      DEPENDS ${ino} "$<TARGET_FILE:l6470emu::ino>"
      COMMENT "l6470emu: preparing sketch ${name} (${CMAKE_CURRENT_BINARY_DIR}/${name}_sketch.cpp)"
      VERBATIM)
    list(APPEND sources "${out}")
  endif()

  if(DEFINED arg_BOARD OR DEFINED arg_BOARD_FILE)
    if(DEFINED arg_BOARD)
      set(text "${arg_BOARD}")
      set(function l6470emu_fw_default_board)
    else()
      get_filename_component(text "${arg_BOARD_FILE}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
      set(function l6470emu_fw_default_board_file)
    endif()
    string(REPLACE "\\" "\\\\" text "${text}")
    string(REPLACE "\"" "\\\"" text "${text}")
    string(REPLACE "\n" "\\n" text "${text}")
    set(board_source "${CMAKE_CURRENT_BINARY_DIR}/${name}_board.cpp")
    file(CONFIGURE OUTPUT "${board_source}" CONTENT
"// The board ${name} runs on unless L6470EMU_CHAIN or L6470EMU_CONFIG says otherwise (generated).
extern \"C\" const char* ${function}(void) { return \"${text}\"; }
")
    list(APPEND sources "${board_source}")
  endif()

  # The driver sanitizer's level unless the description (check=) or L6470EMU_CHECK says.
  set(check_source "${CMAKE_CURRENT_BINARY_DIR}/${name}_check.cpp")
  file(CONFIGURE OUTPUT "${check_source}" CONTENT
"// The driver sanitizer's level of ${name} unless its description or L6470EMU_CHECK says (generated).
extern \"C\" const char* l6470emu_fw_default_check(void) { return \"${check}\"; }
")
  list(APPEND sources "${check_source}")

  add_executable(${name} ${sources})
  target_link_libraries(${name} PRIVATE ${front_library} ${arg_LINK_LIBRARIES})
  list(REMOVE_DUPLICATES include_dirs)
  target_include_directories(${name} PRIVATE ${include_dirs} ${arg_INCLUDE_DIRECTORIES})
  if(DEFINED arduino_board)
    string(TOUPPER "${arduino_board}" upper)
    target_compile_definitions(${name} PRIVATE L6470EMU_ARDUINO_BOARD_${upper})
  endif()
endfunction()

function(l6470emu_add_sketch name)
  _l6470emu_firmware_program(${name} l6470emu::arduino ${ARGN})
  # As the Arduino IDE compiles: GNU extensions (variable-length arrays, ...) and -fpermissive.
  set_target_properties(${name} PROPERTIES CXX_STANDARD 17 CXX_EXTENSIONS ON)
  target_compile_options(${name} PRIVATE $<$<COMPILE_LANG_AND_ID:CXX,GNU>:-fpermissive>)
endfunction()

function(l6470emu_add_hal_program name)
  _l6470emu_firmware_program(${name} l6470emu::stm32hal ${ARGN})
endfunction()

function(l6470emu_add_firmware_program name)
  _l6470emu_firmware_program(${name} l6470emu::firmware ${ARGN})
endfunction()
