// The bus face of anything behind one chip-select: CS edges and full-duplex
// bytes, on the device's virtual clock. Chips and chains implement it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "core/tick.hpp"
#include "spi/wire.hpp"

namespace l6470emu {

/// A SPI slave (or a daisy chain of them) behind one chip-select. select/exchange/deselect are
/// the byte path: SPI mode 3, MSB first, bytes as the chip expects them. The *_wire functions
/// serve a host with any settings (spi/wire.hpp); use one face or the other for a whole frame.
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

  // ---- hosts with any wire settings (spi/wire.hpp) ----------------------------------------
  /// CS falling edge of a host whose bytes go through exchange_wire(): as select(). A device that
  /// models the wire also applies t_disCS: after a deselect_wire() less than kDeselectMinTicks ago
  /// its chips had no time to load their answers.
  virtual void select_wire() { select(); }
  /// Clocks `tx` as a host with `wire` settings does (mode, bit order): each chip receives, and
  /// `rx` gets, the bits the chip's edge rules give. The default knows only the byte path and
  /// serves every setting as mode 3, MSB first.
  virtual void exchange_wire(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx, const WireSettings& wire) {
    (void)wire;
    exchange(tx, rx);
  }
  /// CS rising edge after exchange_wire(): as deselect(); a device that models the wire keeps
  /// each chip's SDO latch for the next frame.
  virtual void deselect_wire() { deselect(); }

  /// Virtual time of the device.
  virtual Tick now() const = 0;
  /// Runs the device up to `tick`.
  virtual void advance_to(Tick tick) = 0;
};

}  // namespace l6470emu
