// DeviceBoard's private state, shared by device_board.cpp (files, SPI, time), device_board_gpio.cpp
// (gpio ioctls) and device_board_pump.cpp (the edge-delivery thread). Not part of the public API.
#pragma once

#include <linux/gpio.h>

#include "linux/device_board.hpp"
#include "linux/gpio_uapi.hpp"

namespace l6470emu {

/// The spidev node in front of one chain of the board.
struct DeviceBoard::ChainDev {
  std::string name;               // "spidev0.0"
  SpidevSettings spi;
  unsigned users = 0;             // open files (spidev resets speed_hz at the last close)
  int gpio = -1;                  // index into gpios_, -1 = no gpiochip
};

/// One line of a gpiochip.
struct DeviceBoard::LineDev {
  std::string name;
  Handle* owner = nullptr;       // the line request holding it
  unsigned index = 0;            // its position in the owner's offsets
  std::uint64_t flags = 0;       // v2 flags of the current (or last) configuration
  std::uint32_t debounce_us = 0;
  bool out_value = false;        // chip outputs: the level the host drives while it is an output
};

/// One gpiochip: the pins of one chain (their levels and edges are the Board's).
struct DeviceBoard::GpioDev {
  std::string name;   // "gpiochip0"
  std::string label;  // "l6470emu spidev0.0"
  std::size_t chain = 0;
  GpioLines layout;  // which line is which chip's which pin (and the SPI lines)
  std::vector<LineDev> lines;
  // SPI lines (device_board_spi_pins.cpp)
  std::uint64_t unselected_rising = 0;  // rising SCK edges while CS was high
  bool cs_low_from_request = false;     // CS went low when its line was requested as an output low
  bool clockless_said = false;          // the log said a frame with no clock edge
  bool miso_driven_said = false;        // the log said the host drives MISO
};

/// An open file or line request.
struct DeviceBoard::Handle {
  std::uint64_t id = 0;
  HandleKind kind = HandleKind::spidev;
  int fd = -1;             // the board's end of the socketpair
  std::size_t dev = 0;     // chain index (spidev) or gpio index (everything else)
  // gpiochip open file: lineinfo watches
  std::vector<bool> watched;
  int watch_abi = 0;       // 0 none yet, 1 or 2: the uAPI of the first watch
  // line requests
  std::vector<unsigned> offsets;
  std::string consumer;
  std::uint64_t seqno = 0;
  std::vector<std::uint32_t> line_seqno;
  std::uint64_t dropped = 0;
};

}  // namespace l6470emu
