// A chain's serial interface at its pins, for a host that bit-bangs it: CS, CK and SDI levels
// set one at a time, SDO read at any moment. It keeps only the edges of the byte under way; the
// shifting is the chain's (each byte goes through SpiDevice::exchange_wire once its eighth
// rising CK edge comes), so recordings, checks and every wire rule see whole bytes as always.
// It does not model a frame that ends inside a byte (those bits are dropped and counted).
#pragma once

#include <cstdint>

#include "daisychain/chain.hpp"
#include "spi/spi_device.hpp"
#include "spi/wire.hpp"

namespace l6470emu {

/// The edge rules of datasheet §8 at the pins: every chip samples SDI on a rising CK edge and
/// moves its SDO latch on a falling one, only while CS is low. A byte whose first edge is a
/// falling one (the clock idled high) is a mode-3 byte; one whose first edge is a rising one
/// (the clock idled low) reaches the chain as a mode-0 byte: each chip's first output bit is
/// its stale latch (spi/wire.hpp ModeEffects::stale_first_bit). SDO between edges is chip 0's
/// latch as the edges so far left it, computed from the chain's registers as they stood at the
/// byte's first edge (what chip 0 shifts out does not depend on what comes in). One per chain.
class PinLevelBus {
 public:
  /// CS fell: `device` (the chain, its recording or a bus over them) has just been selected;
  /// `chain` is the chain behind it, looked at for SDO.
  void cs_fell(const Chain& chain);
  /// CS is about to rise: the bits of an unfinished byte are dropped. Returns how many (0..7).
  unsigned cs_rising();
  /// CK goes to `level`. While CS is low a rising edge samples SDI; the eighth of a
  /// byte clocks the byte on `device` (whose chain is `chain`). Returns true when this edge was
  /// the first clock edge of the frame (the t_setCS check). No effect when the level is unchanged.
  bool set_ck(bool level, SpiDevice& device, Chain& chain);
  /// SDI (MOSI) goes to `level`; sampled at the next rising CK edge.
  void set_sdi(bool level) { sdi_ = level; }
  /// The level chip 0 drives on SDO now (its latch, with a MISO flip fault of the frame
  /// applied); nothing meaningful while CS is high (the pin floats: the caller decides).
  bool sdo(const Chain& chain) const;

  bool ck() const { return ck_; }
  bool selected() const { return selected_; }
  /// Rising CK edges since the last whole byte of this frame (0..7).
  unsigned bits_pending() const { return rising_; }
  /// Whether a CK edge came since CS fell.
  bool frame_clocked() const { return frame_clocked_; }
  /// Whole bytes clocked since CS fell.
  std::uint64_t bytes_in_frame() const { return byte_index_; }
  /// Rising CK edges while CS was high, since the chain was made (they shift nothing).
  std::uint64_t rising_edges_deselected() const { return rising_deselected_; }

 private:
  bool selected_ = false;
  bool ck_ = false;
  bool sdi_ = false;
  bool frame_clocked_ = false;
  bool byte_started_ = false;   // an edge of the byte under way came
  bool stale_first_ = false;    // the byte's first edge was a rising one
  unsigned rising_ = 0;         // rising edges of the byte under way
  std::uint8_t bits_ = 0;       // SDI as sampled, MSB first
  std::uint8_t reg0_ = 0;       // chip 0's register at the byte's first edge
  bool sdo_ = false;            // chip 0's latch as the edges left it
  std::uint64_t shown_byte_ = 0;  // which output bit the latch shows: byte of the frame ...
  unsigned shown_bit_ = 0;        // ... and bit, 0 = the first (most significant) one
  std::uint64_t byte_index_ = 0;
  std::uint64_t rising_deselected_ = 0;
};

}  // namespace l6470emu
