// The SPI wire as the chip sees it: the host's settings (SPI mode, bit order, chip-select
// polarity, word size, clock) and the edge rules of the chip's serial interface that decide
// which bits reach it and which bits the host reads. Pure rules; the shift registers live in
// daisychain/ (Chain::exchange_wire) and the checks in board/ (the sanitizer).
#pragma once

#include <cstdint>
#include <string>

#include "core/tick.hpp"

namespace l6470emu {

/// How a host drives the bus, as the host's SPI controller is set up.
struct WireSettings {
  std::uint8_t mode = 3;            ///< SPI mode: CPOL << 1 | CPHA (0..3); the chip needs 3
  bool lsb_first = false;           ///< the host shifts each byte least significant bit first
  bool cs_active_high = false;      ///< the host's chip-select is asserted high
  std::uint8_t bits_per_word = 8;   ///< the host's word size (words reach the bus as bytes, see below)
  std::uint32_t speed_hz = 0;       ///< SCK in Hz (0 = not known, not checked)
  /// Whether the time between a CS falling edge and the first SCK edge is what the front's
  /// ticks say (a front that drives CS itself). spidev's controller's own CS-to-clock delay is
  /// not known, so its fronts leave this false and t_setCS is not checked.
  bool cs_setup_timed = false;

  /// Whether a host with these settings clocks bytes exactly as the chip expects (mode 3, MSB
  /// first, CS active low): the byte fast path.
  bool plain() const { return mode == 3 && !lsb_first && !cs_active_high; }
  friend bool operator==(const WireSettings&, const WireSettings&) = default;
};

// ---- the chip's serial interface (datasheet §8, Table 5 "SPI") ------------------------------

/// f_CK,MAX: the fastest SCK the chip accepts (Table 5).
inline constexpr std::uint32_t kChipMaxSpeedHz = 5'000'000;
/// t_hCK, t_lCK: shortest SCK high and low time, ns (Table 5). At a 50 % duty cycle any SCK up to
/// 6.67 MHz meets it; f_CK,MAX is the tighter bound.
inline constexpr std::uint32_t kClockHighLowMinNs = 75;
/// t_setCS: shortest time from the CS falling edge to the first SCK edge, ns (Table 5).
inline constexpr std::uint32_t kCsSetupMinNs = 350;
/// t_disCS: shortest time CS stays high between frames, ns (Table 5; §8: the chip needs it to
/// decode the byte and load its answer).
inline constexpr std::uint32_t kDeselectMinNs = 800;
/// The same in whole ticks: CS high for fewer ticks than this is too short (3 ticks = 750 ns).
inline constexpr Tick kDeselectMinTicks = 4;
/// t_setCS in whole ticks: a first clock edge fewer ticks than this after CS fell is too early.
inline constexpr Tick kCsSetupMinTicks = 2;

/// CPOL: the clock idles high. Then the first edge of each byte is a falling one.
constexpr bool clock_idles_high(std::uint8_t mode) { return (mode & 2) != 0; }
/// CPHA: the host samples MISO on the trailing (second) edge of each clock and changes MOSI on
/// the leading one; without it, it samples on the leading edge and changes on the trailing one.
constexpr bool samples_on_trailing_edge(std::uint8_t mode) { return (mode & 1) != 0; }
/// Whether the host samples MISO on falling edges (mode 1: trailing, clock idle low; mode 2:
/// leading, clock idle high).
constexpr bool host_samples_on_falling(std::uint8_t mode) {
  return clock_idles_high(mode) != samples_on_trailing_edge(mode);
}
/// Whether the host changes MOSI on rising edges (modes 1 and 2: the opposite edge to the one it samples on).
constexpr bool host_changes_mosi_on_rising(std::uint8_t mode) { return host_samples_on_falling(mode); }

/// What one byte looks like in a mode, derived from the chip's edge rules: the chip samples SDI
/// on rising CK edges and changes its SDO latch on falling edges (§8); where the host acts on
/// the same edge as the chip, the sampler sees the level from before the edge (the chip's SDO
/// hold time t_holSDO >= 37 ns after a falling edge; the host's MOSI changing later than
/// t_holSDI = 20 ns after its edge; both readings UNCONFIRMED on silicon).
struct ModeEffects {
  /// The byte's first edge is a rising one, before any falling edge has moved the SDO latch:
  /// every chip's first output bit is its stale latch (modes 0 and 1).
  bool stale_first_bit = false;
  /// The host changes MOSI on the rising edge the chip samples on, so the chip sees the level
  /// from before: the MOSI stream reaches the chain one bit late (mode 1).
  bool mosi_one_bit_late = false;
  /// The host samples MISO on the falling edge the chip changes SDO on, so it sees the level
  /// from before: the MISO stream reaches the host one bit late (mode 2).
  bool miso_one_bit_late = false;
};

/// The effects of SPI mode `mode` (0..3); mode 3 has none.
constexpr ModeEffects mode_effects(std::uint8_t mode) {
  ModeEffects e;
  e.stale_first_bit = !clock_idles_high(mode);
  // Mode 2 changes MOSI on rising edges too, but after a leading falling edge that already
  // put the bit out: the chip samples the right level. Only in mode 1 is the rising edge the
  // one that puts the bit out.
  e.mosi_one_bit_late = host_changes_mosi_on_rising(mode) && samples_on_trailing_edge(mode);
  // Mode 1 samples on falling edges too, but each falling edge comes after the rising edge
  // the chip's neighbour sampled on, with the same latch: the host reads what a chip would.
  e.miso_one_bit_late = host_samples_on_falling(mode) && !samples_on_trailing_edge(mode);
  return e;
}

/// The level the host leaves MOSI at before the first clock edge of a frame, which a mode-1
/// chip samples as its first bit (UNCONFIRMED: controllers differ; low is the common idle).
inline constexpr std::uint8_t kMosiIdleLevel = 0;

/// `b` with its bit order reversed (bit 0 becomes bit 7).
constexpr std::uint8_t reverse_bits(std::uint8_t b) {
  b = static_cast<std::uint8_t>((b & 0xF0) >> 4 | (b & 0x0F) << 4);
  b = static_cast<std::uint8_t>((b & 0xCC) >> 2 | (b & 0x33) << 2);
  b = static_cast<std::uint8_t>((b & 0xAA) >> 1 | (b & 0x55) << 1);
  return b;
}

/// "8 MHz", "400 kHz", "3815 Hz".
std::string describe_speed(std::uint32_t hz);

/// "mode 0 (CPOL=0, CPHA=0)", and ", LSB first", ", CS active high", ", 16-bit words", ", 8 MHz"
/// where they apply.
std::string describe_wire(const WireSettings& wire);

}  // namespace l6470emu
