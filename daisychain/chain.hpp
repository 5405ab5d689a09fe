// N chips behind one chip-select as one long shift register (1 <= N <= 256).
// Numbering: chip 0 drives MISO and is farthest from the host's MOSI, so byte k
// of an N-byte frame is for chip k and MISO byte k is chip k's answer.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/chip.hpp"
#include "spi/spi_device.hpp"

namespace l6470emu {

/// A daisy chain of chips sharing CS and SCK; MOSI → chip N-1 → ... → chip 0 → MISO.
/// It adds no framing of its own: each byte shifts the whole chain by eight bits, and at
/// the CS rising edge every chip decodes the byte its own shift register holds.
class Chain final : public SpiDevice {
 public:
  /// Longest chain supported.
  static constexpr std::size_t kMaxChips = 256;

  /// A chain of `chips` (1..256). Throws std::invalid_argument otherwise.
  explicit Chain(std::vector<Chip> chips);
  /// A chain of `n` chips of one variant.
  Chain(std::size_t n, const Variant& variant = l6470(), Quirks quirks = {});

  std::size_t size() const { return chips_.size(); }
  /// Chip `i`, brought up to the chain's time first (chips advance lazily). The reference
  /// shows the chip as of this call: after the chain's time moves on, call chip(i) again.
  Chip& chip(std::size_t i) const {
    Chip& c = chips_.at(i);
    chips_touched_ = true;
    c.advance_to(now_);
    return c;
  }

  // SpiDevice
  void select() override;
  std::uint8_t exchange(std::uint8_t mosi) override;
  void exchange(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx) override;
  void deselect() override;
  bool selected() const override { return selected_; }
  Tick now() const override { return now_; }
  void advance_to(Tick tick) override;

  /// One CS frame: select, exchange every byte of `tx` into `rx`, deselect.
  void frame(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx);
  /// One CS frame returning the MISO bytes.
  std::vector<std::uint8_t> frame(std::span<const std::uint8_t> tx);

  /// Chooses the motion engine of every chip (the event-driven one is the default).
  void set_motion_engine(MotionEngine e) {
    for (std::size_t i = 0; i < chips_.size(); ++i) chip(i).set_motion_engine(e);
  }

  /// The earliest next_event_tick() of the chips.
  Tick next_event_tick() const;

  /// CS frames that clocked at least one byte, since the chain was made.
  std::uint64_t frames() const { return frames_; }
  /// Bytes clocked since the last CS falling edge.
  std::uint64_t bytes_in_frame() const { return bytes_in_frame_; }

  /// The byte in chip `i`'s shift register, without side effects: inside a frame, the byte the
  /// chip will decode at the CS rising edge; between frames, the byte it will shift out next.
  std::uint8_t shift_register(std::size_t i) const { return ring_[(head_ + i) % ring_.size()]; }

 private:
  void set_shift_register(std::size_t i, std::uint8_t v) { ring_[(head_ + i) % ring_.size()] = v; }
  bool any_in_standby() const;
  /// false (nothing done) when no chip is in standby any more.
  bool exchange_through_standby(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx);

  // Chips are advanced lazily: when they decode a byte that needs their state,
  // or when someone looks at them through chip(). Hence mutable.
  mutable std::vector<Chip> chips_;
  std::vector<std::uint8_t> ring_;  // shift registers; logical register i is ring_[(head_ + i) % N]
  std::size_t head_ = 0;
  bool selected_ = false;
  bool standby_in_frame_ = false;  // some chip was in standby at the CS falling edge
  mutable bool chips_touched_ = true;  // chip() handed out a chip since the last look at STBY pins
  bool any_standby_ = false;
  std::uint64_t bytes_in_frame_ = 0;
  std::uint64_t frames_ = 0;
  Tick now_ = 0;
};

}  // namespace l6470emu
