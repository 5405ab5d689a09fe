// The HID reports of a Silicon Labs CP2112 (USB HID to SMBus bridge with 8 GPIO pins), as far
// as Linux's hid-cp2112 driver uses them, answered for one emulated chip: the bridge's GPIO
// pins are the chip's BUSY, FLAG, SW, STCK, STBY_RST and DIR lines (pins 0..5 in Pin's order;
// 6 and 7 unused, and like DIR on a chip without one they read high). The driver reads and
// changes pins through feature reports 0x02 (direction), 0x03 (levels) and 0x04 (set outputs);
// probing reads 0x05, 0x06 and 0x20; sysfs reads 0x21..0x24.
// No I/O here: linux/kernel/uhid_cp2112.cpp carries the reports over /dev/uhid.
#pragma once

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "linux/gpio_lines.hpp"

namespace l6470emu {

/// USB ids the hid-cp2112 driver binds to.
inline constexpr std::uint16_t kCp2112Vendor = 0x10c4;
inline constexpr std::uint16_t kCp2112Product = 0xea90;
/// Pins of one bridge.
inline constexpr unsigned kCp2112Pins = 8;

/// The emulated bridge's view of its chip: the level of a chip pin (what the physical line
/// carries) and driving a chip input.
struct Cp2112Pins {
  std::function<bool(Pin)> level;
  std::function<void(Pin, bool)> drive;
};

/// One bridge's GPIO state and report answers.
class Cp2112Reports {
 public:
  /// `product` and `serial` appear in the bridge's sysfs strings.
  Cp2112Reports(Cp2112Pins pins, std::string product, std::string serial);

  /// The report descriptor the bridge declares (vendor page, the report ids and sizes above).
  static std::vector<std::uint8_t> descriptor();

  /// GET_REPORT of feature report `id`: the bytes (report id first), or empty for an unknown
  /// report (answered with EIO).
  std::vector<std::uint8_t> get(std::uint8_t id);
  /// SET_REPORT of feature report `data[0]`: 0 or a positive errno.
  int set(std::span<const std::uint8_t> data);
  /// An output report (the SMBus side): the input report to send back, if any. Every SMBus
  /// transfer fails at once (no SMBus devices behind this bridge).
  std::vector<std::uint8_t> output(std::span<const std::uint8_t> data);

  /// Direction bits (1 = output, as the host configured them).
  std::uint8_t direction() const { return direction_; }
  /// The levels a GET 0x03 reports now.
  std::uint8_t levels() const;

 private:
  Cp2112Pins pins_;
  std::string product_, serial_;
  std::uint8_t direction_ = 0;     // all inputs at power-up
  std::uint8_t push_pull_ = 0;
  std::uint8_t special_ = 0;
  std::uint8_t clock_divider_ = 0;
  std::uint8_t latch_ = 0xFF;      // output latches (high at power-up)
  std::vector<std::uint8_t> smbus_config_;
};

}  // namespace l6470emu
