// N chips behind one chip-select as one long shift register (1 <= N <= 256).
// Numbering: chip 0 drives MISO and is farthest from the host's MOSI, so byte k
// of an N-byte frame is for chip k and MISO byte k is chip k's answer.
#pragma once

#include <cstdint>
#include <span>
#include <utility>
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
  /// The bytes the chips' decoders have taken so far (Chip::decoded_bytes, summed), read
  /// without bringing a chip up to time or handing one out (a recording asks at every frame).
  std::uint64_t decoded_bytes() const {
    std::uint64_t n = 0;
    for (const Chip& c : chips_) n += c.decoded_bytes();
    return n;
  }
  /// Chip `i`, brought up to the chain's time first (chips advance lazily). The reference
  /// shows the chip as of this call: after the chain's time moves on, call chip(i) again.
  Chip& chip(std::size_t i) const {
    Chip& c = chips_.at(i);
    chips_touched_ = true;
    quiet_ = false;
    c.advance_to(now_);
    return c;
  }

  // SpiDevice
  void select() override;
  std::uint8_t exchange(std::uint8_t mosi) override;
  void exchange(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx) override {
    if (!selected_ || odd_frame_) return exchange_odd(tx, rx);
    shift_bytes(tx, rx);
  }
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

  // ---- the wire's faults and a chip's brown-out (the backdoor; board/ records them) ----------
  // The two wire faults are one-shot: armed now, they act on the next CS frame that clocks at
  // least one byte (one armed while CS is low waits for the frame after this one) and are gone.

  /// The next frame: bit `bit` (0..7) of MISO byte `i` as the host reads it (the byte chip `i`
  /// drives, at its position in the chain) is inverted. The chips are not affected: it is the wire.
  void arm_miso_flip(std::size_t i, std::uint8_t bit);
  /// The next frame: chip `i` misses it, as if its CS stayed high. It shifts nothing (like a
  /// chip in standby it drives 0x00 and what reaches it is lost), decodes nothing, and its
  /// register keeps the byte it held; its state and motion are untouched.
  void arm_lost_frame(std::size_t i);
  /// Chip `i` loses power and is back at once (Chip::power_cycle): its shift register and SDO
  /// latch are empty. With CS low it happens at the CS rising edge, after the chips decode (a
  /// recording writes it after the frame: a replay does the same).
  void power_cycle(std::size_t i);
  /// Whether chip `i` takes part in the frame under way (or the next one): not in standby, and
  /// not missing it for a lost frame.
  bool hears_frame(std::size_t i) const { return listening(i); }
  /// The bits a MISO flip fault inverts in byte `byte` of the frame under way (as the host reads
  /// it, most significant bit first), 0 when none: for a host that reads MISO a bit at a time.
  std::uint8_t miso_flip_mask(std::uint64_t byte) const {
    std::uint8_t mask = 0;
    apply_flips(byte, {&mask, 1});  // the byte path's rule
    return mask;
  }

  /// CS frames that clocked at least one byte, since the chain was made.
  std::uint64_t frames() const { return frames_; }
  /// Bytes clocked since the last CS falling edge.
  std::uint64_t bytes_in_frame() const { return bytes_in_frame_; }

  /// The byte in chip `i`'s shift register, without side effects: inside a frame, the byte the
  /// chip will decode at the CS rising edge; between frames, the byte it will shift out next.
  std::uint8_t shift_register(std::size_t i) const { return ring_[(head_ + i) % ring_.size()]; }

  // ---- the bit-level interface: hosts with any SPI settings (daisychain/chain_wire.cpp) -------
  // Each chip also has an SDO latch: the bit its SDO drives, set from the top of its shift
  // register at every falling CK edge and kept across CS edges. Mode 3, MSB first, takes the
  // byte path above; other settings go bit-exact through the edge rules of spi/wire.hpp.
  // (WireSettings::cs_active_high is the front's business: the chain sees CS only through
  // select and deselect.)

  /// CS falling edge (SpiDevice::select_wire): after a deselect_wire() less than t_disCS ago the
  /// chips had no time to load their answers, so each register still holds the byte it received.
  void select_wire() override;
  /// Clocks `tx` as a host with `wire` settings does; rx gets what the host reads.
  void exchange_wire(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx, const WireSettings& wire) override {
    if (tx.size() == 1 && selected_ && wire.mode == 3 && !wire.lsb_first && !odd_frame_) {
      // One byte on the byte path (a clock-idle-high byte: the latches are where previous_bit0 says).
      rx[0] = last_out0_ = shift_byte(tx[0]);
      mosi_level_ = tx[0] & 1u;
      latch_at_ = LatchAt::previous_bit0;
      return;
    }
    exchange_wire_bytes(tx, rx, wire);
  }
  /// CS rising edge: as deselect(), keeping each chip's SDO latch for the next frame.
  void deselect_wire() override;
  /// One CS frame of a host with `wire` settings: select_wire, exchange_wire, deselect_wire.
  void frame(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx, const WireSettings& wire);
  /// A falling CK edge between two bytes of a frame (a host clocking at the pins, whose byte
  /// starts there): each listening chip's SDO latch takes the top bit of its register. Bytes of
  /// exchange_wire take their own edges; this is the one a mode-0-shaped host makes after a byte.
  void falling_clock_edge();
  /// Chip `i`'s SDO latch (0 or 1) as of now: the bit its SDO shows until the next falling CK edge.
  std::uint8_t sdo_latch(std::size_t i) const;
  /// Whether some chip was in standby at the last CS falling edge (its bytes are lost).
  bool standby_in_frame() const { return standby_in_frame_; }
  /// Calls f(i, chip i, the byte in its register) for every chip, chip 0 first, as they stand:
  /// no side effects (the sanitizer looks at what the chips are about to decode).
  template <typename F>
  void for_each_register(F&& f) const {
    const std::size_t n = ring_.size();
    for (std::size_t i = 0, slot = head_; i < n; ++i, slot = slot + 1 == n ? 0 : slot + 1) f(i, chips_[i], ring_[slot]);
  }
  /// Chip `i` as it stands, without bringing it up to the chain's time or any other side effect
  /// (for looking at what does not depend on time: its decoder, its STBY level).
  const Chip& peek_chip(std::size_t i) const { return chips_.at(i); }

 private:
  void set_shift_register(std::size_t i, std::uint8_t v) { ring_[(head_ + i) % ring_.size()] = v; }
  bool any_in_standby() const;
  /// Whether chip `i` shifts and decodes in this frame: SPI enabled and not deaf (a lost frame).
  bool listening(std::size_t i) const { return chips_[i].spi_enabled() && (!deaf_in_frame_ || !deaf_[i]); }
  /// exchange() of one byte as the chips see it (no wire fault applied).
  std::uint8_t shift_byte(std::uint8_t mosi);
  /// exchange() of a span when odd_frame_ (or CS high): the chips' way, then the wire's flips.
  void exchange_odd(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx);
  /// The armed wire faults become this frame's (at the CS falling edge).
  void take_armed_faults();
  /// Arms the bits of `mask` to be inverted in chip `i`'s MISO byte of the next frame.
  void arm_flips(std::size_t i, std::uint8_t mask);
  /// Inverts the bits of this frame's MISO flips that fall in `rx`, the frame's bytes from `at` on.
  void apply_flips(std::uint64_t at, std::span<std::uint8_t> rx) const;
  /// The CS rising edge of a frame with a deaf chip or a power cycle waiting: the chips decode
  /// (the deaf ones not), the wire faults end, the power cycles happen.
  void end_odd_frame(bool clocked);
  /// decode_shift_registers() leaving out the deaf chips, whose registers get their bytes back.
  void decode_around_deaf_chips();
  void power_cycle_now(std::size_t i);
  /// The CS rising edge of a frame that clocked bytes: every chip decodes its register (SPI
  /// mode 3, whole bytes) and loads its answer byte into it. A frame of NOPs to a quiet chain
  /// (see quiet_) is known to change nothing.
  void decode_shift_registers();
  /// The byte fast path (SPI mode 3, whole bytes, CS low, no chip in standby): the ring shifts
  /// by tx.size() bytes. A frame of the chain's length from slot 0 is swapped whole; anything
  /// else goes through shift_runs(), a run of bytes at a time.
  void shift_bytes(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx);
  void shift_runs(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx);
  /// exchange() with CS high or chips in standby.
  void exchange_slow(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx);
  /// false (nothing done) when no chip is in standby any more.
  bool exchange_through_standby(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx);

  // Chips are advanced lazily: when they decode a byte that needs their state,
  // or when someone looks at them through chip(). Hence mutable.
  mutable std::vector<Chip> chips_;
  std::vector<std::uint8_t> ring_;  // shift registers; logical register i is ring_[(head_ + i) % N]
  std::size_t head_ = 0;
  bool selected_ = false;
  bool standby_in_frame_ = false;  // some chip was in standby (or deaf) at the CS falling edge
  bool odd_frame_ = false;         // standby_in_frame_, or a MISO flip in this frame: not the plain byte path
  bool faults_armed_ = false;      // a wire fault is armed for the next frame
  bool end_of_frame_work_ = false;  // a deaf chip or a power cycle waiting: deselect takes the long way
  mutable bool chips_touched_ = true;  // chip() handed out a chip since the last look at STBY pins
  // Every chip is ready for an opcode with no answer byte left (Chip::on_nop_at), as the last
  // frame of NOPs left them and nothing reached them since: the next frame of NOPs changes nothing.
  mutable bool quiet_ = false;
  bool any_standby_ = false;
  std::uint64_t bytes_in_frame_ = 0;
  std::uint64_t frames_ = 0;
  Tick now_ = 0;

  // ---- the bit-level interface's state (chain_wire.cpp) ----
  /// Where each chip's SDO latch is to be found: stored in latch_, or (no chip in standby) as the
  /// top bit of its register after a clock-idle-low byte, or as bit 0 of the register downstream
  /// (of the byte chip 0 sent last, for chip 0) after a clock-idle-high one; after the CS rising
  /// edge the same in received_, the registers as they were before the chips decoded them.
  enum class LatchAt : std::uint8_t { stored, register_msb, previous_bit0, received_msb, received_bit0 };
  void exchange_wire_bytes(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx, const WireSettings& wire);
  std::uint8_t wire_byte(std::uint8_t host_byte, const WireSettings& wire);
  void apply_stale_latches();
  void store_latches();
  std::uint8_t latch_at(std::size_t i) const;
  std::vector<std::uint8_t> latch_;     // per chip, while latch_at_ == stored (sized on first use)
  std::vector<std::uint8_t> received_;  // the registers before the last deselect_wire decoded them
  LatchAt latch_at_ = LatchAt::stored;
  std::uint8_t last_out0_ = 0;   // the byte chip 0 shifted out last
  std::uint8_t mosi_level_ = 0;  // MOSI as the last byte left it (a mode-1 chip samples it first)
  bool answers_loaded_ = false;  // the last deselect_wire decoded bytes and loaded answers
  Tick deselect_tick_ = 0;       // when it did

  // ---- the wire faults (arm_miso_flip, arm_lost_frame) and power cycles waiting for a CS
  // rising edge; last, so that the fields every byte touches keep their offsets ----
  bool deaf_in_frame_ = false;     // a chip misses this frame (deaf_)
  std::vector<std::pair<std::size_t, std::uint8_t>> flips_armed_, flips_;  // (chip, mask): next frame's, this frame's
  std::vector<std::size_t> deaf_armed_;     // chips to miss the next frame
  std::vector<std::uint8_t> deaf_;          // per chip: misses this frame (sized on first use)
  std::vector<std::uint8_t> deaf_held_;     // per chip: the byte its register held at the CS falling edge
  std::vector<std::size_t> power_cycles_;   // chips to power-cycle at the CS rising edge
};

}  // namespace l6470emu
