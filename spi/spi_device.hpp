// The bus face of anything behind one chip-select: CS edges and full-duplex
// bytes, on the device's virtual clock. Chips and chains implement it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "core/tick.hpp"

namespace l6470emu {

/// A SPI slave (or a daisy chain of them) behind one chip-select, SPI mode 3, MSB first.
class SpiDevice {
 public:
  virtual ~SpiDevice() = default;

  /// CS falling edge.
  virtual void select() = 0;
  /// Clocks one byte in on MOSI and returns the byte shifted out on MISO.
  virtual std::uint8_t exchange(std::uint8_t mosi) = 0;
  /// CS rising edge: the devices decode what their shift registers hold.
  virtual void deselect() = 0;
  /// Whether CS is currently low.
  virtual bool selected() const = 0;

  /// Clocks `tx` out and fills `rx` (same length) byte by byte; override to go faster.
  virtual void exchange(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx) {
    for (std::size_t i = 0; i < tx.size(); ++i) rx[i] = exchange(tx[i]);
  }

  /// Virtual time of the device.
  virtual Tick now() const = 0;
  /// Runs the device up to `tick`.
  virtual void advance_to(Tick tick) = 0;
};

}  // namespace l6470emu
