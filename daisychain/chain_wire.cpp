// Chain's bit-level interface: a host with any SPI mode and bit order, each chip's SDO latch,
// and the answer load a too-short deselect misses. The rules are spi/wire.hpp's; mode 3 MSB
// first stays on the byte path (chain.cpp). Does not model CS polarity (the front's) or clocks
// that stop inside a byte.
#include <algorithm>
#include <cstring>

#include "daisychain/chain.hpp"

namespace l6470emu {

// Where the latches are kept. A chip's SDO latch takes the top bit of its register at every
// falling CK edge. After a byte whose clock idles low (modes 0, 1) the last edge is a falling
// one after the eighth shift, so the latch is the top bit of the byte now in the register.
// After a byte whose clock idles high (modes 2, 3) the last falling edge came after the seventh
// shift, so the latch is bit 0 of the byte the chip shifted out: the byte now in the register
// downstream, or for chip 0 the byte that went to MISO. Inside a frame the registers therefore
// say where the latches are; at the CS rising edge (answers replace the registers) and in
// frames with a chip in standby (whose register is forced to 0) they are stored.

std::uint8_t Chain::latch_at(std::size_t i) const {
  if (!listening(i)) return 0;  // a chip in standby has its logic, latch included, reset (a deaf one: see below)
  switch (latch_at_) {
    case LatchAt::stored: return i < latch_.size() ? latch_[i] : 0;
    case LatchAt::register_msb: return shift_register(i) >> 7;
    case LatchAt::previous_bit0: return (i == 0 ? last_out0_ : shift_register(i - 1)) & 1u;
    case LatchAt::received_msb: return received_[i] >> 7;
    case LatchAt::received_bit0: return (i == 0 ? last_out0_ : received_[i - 1]) & 1u;
  }
  return 0;
}

std::uint8_t Chain::sdo_latch(std::size_t i) const {
  (void)chips_.at(i);
  return latch_at(i);
}

void Chain::store_latches() {
  if (latch_.size() != chips_.size()) latch_.assign(chips_.size(), 0);
  if (latch_at_ == LatchAt::stored) return;
  if (latch_at_ == LatchAt::received_msb || latch_at_ == LatchAt::received_bit0)
    received_.resize(chips_.size());  // (sized by the deselect_wire that chose these)
  // Chip 0 first: previous_bit0 reads the register downstream, which stays as it is.
  for (std::size_t i = 0; i < chips_.size(); ++i) latch_[i] = latch_at(i);
  latch_at_ = LatchAt::stored;
}

void Chain::apply_stale_latches() {
  // A byte whose first edge is a rising one: each chip's first output bit is its latch, not the
  // top bit of its register. Putting the latch there lets the byte shift as usual (the top bit
  // is the only one it changes; previous_bit0 reads bit 0 downstream, which stays).
  const std::size_t n = chips_.size();
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint8_t l = latch_at(i);
    set_shift_register(i, static_cast<std::uint8_t>((shift_register(i) & 0x7Fu) | l << 7));
  }
  latch_at_ = LatchAt::register_msb;
}

std::uint8_t Chain::wire_byte(std::uint8_t host_byte, const WireSettings& wire) {
  const ModeEffects fx = mode_effects(wire.mode & 3u);
  const std::uint8_t w = wire.lsb_first ? reverse_bits(host_byte) : host_byte;  // in the order it goes out
  if (bytes_in_frame_ == 0) {
    mosi_level_ = kMosiIdleLevel;
    // After a deselect_wire the latches are in received_; after a plain deselect() the
    // registers hold answers now, so this is the best that can be said.
    if (latch_at_ == LatchAt::register_msb || latch_at_ == LatchAt::previous_bit0) store_latches();
  }
  if (fx.stale_first_bit && latch_at_ != LatchAt::register_msb) apply_stale_latches();
  const std::uint8_t latch0 = fx.miso_one_bit_late ? latch_at(0) : 0;
  std::uint8_t in = w;
  if (fx.mosi_one_bit_late) in = static_cast<std::uint8_t>(mosi_level_ << 7 | w >> 1);
  mosi_level_ = w & 1u;
  std::uint8_t out0 = 0;
  if (standby_in_frame_ && !fx.stale_first_bit) {
    // A register downstream of a chip in standby is forced to 0, so bit 0 of what each chip
    // shifted out is taken before the shift.
    if (latch_.size() != chips_.size()) latch_.assign(chips_.size(), 0);
    for (std::size_t i = 0; i < chips_.size(); ++i)
      latch_[i] = listening(i) ? static_cast<std::uint8_t>(shift_register(i) & 1u) : 0;
    out0 = shift_byte(in);
    latch_at_ = LatchAt::stored;
  } else {
    out0 = shift_byte(in);
    last_out0_ = out0;
    latch_at_ = fx.stale_first_bit ? LatchAt::register_msb : LatchAt::previous_bit0;
  }
  const std::uint8_t miso = fx.miso_one_bit_late ? static_cast<std::uint8_t>(latch0 << 7 | out0 >> 1) : out0;
  return wire.lsb_first ? reverse_bits(miso) : miso;
}

void Chain::exchange_wire_bytes(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx, const WireSettings& wire) {
  if (!selected_) {
    // CS high: SDO is high impedance and the chips ignore the clock (their latches included).
    std::fill(rx.begin(), rx.begin() + static_cast<std::ptrdiff_t>(tx.size()), std::uint8_t{0});
    return;
  }
  if (tx.empty()) return;
  const std::uint64_t at = bytes_in_frame_;
  if (wire.mode == 3 && !wire.lsb_first && !standby_in_frame_) {
    // The byte path. A clock-idle-high byte leaves every latch where previous_bit0 finds it,
    // whatever the frame's earlier bytes left.
    if (tx.size() == 1)
      rx[0] = shift_byte(tx[0]);
    else
      shift_bytes(tx, rx);
    last_out0_ = rx[tx.size() - 1];
    mosi_level_ = tx[tx.size() - 1] & 1u;
    latch_at_ = LatchAt::previous_bit0;
  } else {
    for (std::size_t i = 0; i < tx.size(); ++i) rx[i] = wire_byte(tx[i], wire);
  }
  // A MISO flip is on the wire to the host: the bytes as the host reads them.
  if (!flips_.empty()) apply_flips(at, rx.first(tx.size()));
}

void Chain::falling_clock_edge() {
  if (!selected_) return;  // CS high: the chips ignore the clock
  latch_at_ = LatchAt::register_msb;
  if (standby_in_frame_) store_latches();  // with a chip in standby in the frame: kept as they are now
}

void Chain::deselect_wire() {
  if (!selected_) return;
  answers_loaded_ = bytes_in_frame_ > 0;
  if (answers_loaded_) {
    // The registers before the chips decode them: where the latches are, and what a deselect
    // shorter than t_disCS leaves in them. One copy, in chip order.
    const std::size_t n = ring_.size();
    if (received_.size() != n) {
      if (latch_at_ == LatchAt::received_msb || latch_at_ == LatchAt::received_bit0) store_latches();
      received_.resize(n);
    }
    if (n <= 16) {
      for (std::size_t i = 0, slot = head_; i < n; ++i, slot = slot + 1 == n ? 0 : slot + 1) received_[i] = ring_[slot];
    } else {
      std::memcpy(received_.data(), ring_.data() + head_, n - head_);
      std::memcpy(received_.data() + (n - head_), ring_.data(), head_);
    }
    // A chip that missed the frame received nothing: its register keeps the byte it held.
    if (deaf_in_frame_)
      for (std::size_t i = 0; i < n; ++i)
        if (deaf_[i]) received_[i] = deaf_held_[i];
    if (latch_at_ == LatchAt::register_msb)
      latch_at_ = LatchAt::received_msb;
    else if (latch_at_ == LatchAt::previous_bit0)
      latch_at_ = LatchAt::received_bit0;
  }
  deselect_tick_ = now_;
  deselect();
}

void Chain::select_wire() {
  if (selected_) return;
  if (answers_loaded_ && now_ - deselect_tick_ < kDeselectMinTicks) {
    // CS was high for less than t_disCS: the chips decoded their bytes but had no time to put
    // their answers into their registers (UNCONFIRMED reading of datasheet §8): each register
    // still holds the byte it received, which the next byte clocks out as an echo.
    for (std::size_t i = 0; i < chips_.size(); ++i) set_shift_register(i, received_[i]);
  }
  answers_loaded_ = false;
  select();
}

void Chain::frame(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx, const WireSettings& wire) {
  select_wire();
  exchange_wire(tx, rx, wire);
  deselect_wire();
}

}  // namespace l6470emu
