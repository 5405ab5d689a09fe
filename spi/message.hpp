// spidev message semantics (struct spi_ioc_transfer): a message is a list of
// transfers under one chip-select; cs_change and delays follow the Linux spidev
// rules, and transfer time is turned into virtual ticks here, in one place. The host's wire
// settings (SPI mode, bit order, ...) travel with the message (spi/wire.hpp).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/tick.hpp"
#include "spi/spi_device.hpp"
#include "spi/wire.hpp"

namespace l6470emu {

/// One transfer of a spidev message, as in struct spi_ioc_transfer.
struct SpiTransfer {
  std::span<const std::uint8_t> tx;  ///< bytes to send; empty = send zeros (rx-only transfer)
  std::span<std::uint8_t> rx;        ///< where to put received bytes; empty = discard (tx-only)
  std::uint32_t len = 0;             ///< bytes in the transfer
  std::uint32_t speed_hz = 0;        ///< 0 = the device default
  std::uint16_t delay_usecs = 0;     ///< wait after the transfer, before CS changes
  bool cs_change = false;            ///< deselect after this transfer (or stay selected after the last)
  Tick gap_ticks = 0;                ///< extra time inside the transfer, after its bytes (word delays)
  /// The host's word size for this transfer (0 = BusTiming::wire's). Words reach the bus as
  /// bytes, in the order the host shifts them: the front turns words into bytes, the bus only
  /// checks the size (board/'s sanitizer).
  std::uint8_t bits_per_word = 0;
};

/// Bus timing used to turn bytes into ticks, and the host's wire settings.
struct BusTiming {
  std::uint32_t default_speed_hz = 5'000'000;  ///< SCK when a transfer does not say
  Tick cs_high_ticks = 4;                       ///< CS high between frames (1 µs)
  /// How the host drives the wire (mode, bit order, ...); each transfer's speed_hz and
  /// bits_per_word replace its speed and word size.
  WireSettings wire;
};

/// Ticks needed to clock `bytes` bytes at `speed_hz` (rounded up, at least one tick per byte).
Tick transfer_ticks(std::uint32_t bytes, std::uint32_t speed_hz);

/// Runs one spidev message against `dev`, advancing its clock as the bytes take time
/// (each byte takes transfer_ticks(1, speed) whole ticks — 7 ticks at 5 MHz rather than 6.4 —
/// so that the timing, and with it the chip state, does not depend on how the bytes are grouped):
/// CS drops at the start (unless already low from a previous cs_change on the last transfer),
/// `cs_change` on a transfer other than the last raises CS after it (and drops it again),
/// and on the last transfer keeps CS low after the message. Bytes go through the device's
/// bit-level face (select_wire, exchange_wire, deselect_wire) with `timing.wire`.
void run_message(SpiDevice& dev, std::span<const SpiTransfer> transfers, const BusTiming& timing = {});

}  // namespace l6470emu
