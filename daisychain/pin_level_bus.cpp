// PinLevelBus: edges in, whole bytes out to the chain's bit-level face; SDO from chip 0's register.
#include "daisychain/pin_level_bus.hpp"

namespace l6470emu {

void PinLevelBus::cs_fell(const Chain& chain) {
  selected_ = true;
  frame_clocked_ = false;
  byte_started_ = false;
  rising_ = 0;
  bits_ = 0;
  byte_index_ = 0;
  // Until a falling edge moves it, SDO shows the latch the last frame left: a clock that idles
  // low makes it the first bit the host reads.
  sdo_ = chain.sdo_latch(0) != 0;
  shown_byte_ = 0;
  shown_bit_ = 0;
}

unsigned PinLevelBus::cs_rising() {
  if (!selected_) return 0;
  const unsigned dropped = rising_;
  selected_ = false;
  byte_started_ = false;
  rising_ = 0;
  bits_ = 0;
  return dropped;
}

bool PinLevelBus::set_ck(bool level, SpiDevice& device, Chain& chain) {
  if (level == ck_) return false;
  ck_ = level;
  if (!selected_) {
    if (level) ++rising_deselected_;
    return false;
  }
  const bool first = !frame_clocked_;
  frame_clocked_ = true;
  if (!byte_started_) {
    byte_started_ = true;
    stale_first_ = level;
    reg0_ = chain.hears_frame(0) ? chain.shift_register(0) : std::uint8_t{0};  // a chip in standby drives 0
    if (!level) chain.falling_clock_edge();
  }
  if (!level) {
    // The latch takes the top bit of the register, which has shifted once per rising edge so
    // far: bit 7 - n of what it held. (After a stale first bit, bit 7 never reaches SDO.)
    sdo_ = ((reg0_ >> (7 - rising_)) & 1u) != 0;
    shown_byte_ = byte_index_;
    shown_bit_ = rising_;
    return first;
  }
  bits_ = static_cast<std::uint8_t>(bits_ << 1 | (sdi_ ? 1u : 0u));
  if (++rising_ == 8) {
    // The byte as the chain's wire face takes it: a clock that rose first is mode 0's stale
    // first bit, one that fell first is mode 3's plain byte. SCK is not known (the edges' times
    // are the host's; every edge is at least a tick apart, so it never exceeds f_CK,MAX).
    WireSettings wire;
    wire.mode = stale_first_ ? 0 : 3;
    const std::uint8_t tx = bits_;
    std::uint8_t rx = 0;
    device.exchange_wire({&tx, 1}, {&rx, 1}, wire);
    ++byte_index_;
    rising_ = 0;
    bits_ = 0;
    byte_started_ = false;
  }
  return first;
}

bool PinLevelBus::sdo(const Chain& chain) const {
  if (!selected_) return false;
  const std::uint8_t mask = chain.miso_flip_mask(shown_byte_);
  return sdo_ != (((mask >> (7 - shown_bit_)) & 1u) != 0);
}

}  // namespace l6470emu
