// Chain: the shared shift register of a daisy chain, kept as a ring buffer so a
// byte costs O(1) whatever the chain length. Chips in standby break the chain
// (their SDO floats; modelled as 0x00 and the bytes they receive are lost).
#include "daisychain/chain.hpp"

#include <algorithm>
#include <cstring>
#include <stdexcept>
#include <string>

namespace l6470emu {

Chain::Chain(std::vector<Chip> chips) : chips_(std::move(chips)), ring_(chips_.size(), 0) {
  if (chips_.empty() || chips_.size() > kMaxChips)
    throw std::invalid_argument("a chain has 1 to 256 chips, not " + std::to_string(chips_.size()));
}

Chain::Chain(std::size_t n, const Variant& variant, Quirks quirks)
    : Chain(std::vector<Chip>(n, Chip(variant, quirks))) {}

void Chain::select() {
  if (selected_) return;
  selected_ = true;
  bytes_in_frame_ = 0;
  if (chips_touched_) {
    // Someone may have moved a STBY pin through chip(); look again.
    any_standby_ = any_in_standby();
    chips_touched_ = false;
  }
  standby_in_frame_ = any_standby_;
  // A chip in standby drives 0x00 and holds nothing it could pass on.
  if (standby_in_frame_)
    for (std::size_t i = 0; i < chips_.size(); ++i)
      if (!chips_[i].spi_enabled()) set_shift_register(i, 0x00);
}

bool Chain::any_in_standby() const {
  for (const auto& c : chips_)
    if (!c.spi_enabled()) return true;
  return false;
}

std::uint8_t Chain::exchange(std::uint8_t mosi) {
  if (!selected_) return 0x00;  // SDO is high impedance while CS is high
  ++bytes_in_frame_;
  const std::size_t n = ring_.size();
  const std::uint8_t miso = ring_[head_];
  ring_[head_] = mosi;
  head_ = head_ + 1 == n ? 0 : head_ + 1;
  if (standby_in_frame_) {
    for (std::size_t i = 0; i < n; ++i)
      if (!chips_[i].spi_enabled()) set_shift_register(i, 0x00);
    if (!chips_[0].spi_enabled()) return 0x00;
  }
  return miso;
}

void Chain::exchange(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx) {
  const std::size_t n = ring_.size();
  if (!selected_ || (standby_in_frame_ && tx.size() < n)) {
    for (std::size_t i = 0; i < tx.size(); ++i) rx[i] = exchange(tx[i]);
    return;
  }
  if (standby_in_frame_ && exchange_through_standby(tx, rx)) return;
  // The common case: a plain shift of the ring buffer, a run of bytes at a time
  // (what leaves the ring goes to MISO, what enters it comes from MOSI).
  std::uint8_t* ring = ring_.data();
  std::size_t head = head_;
  if (tx.size() >= n) {
    // At least a whole chain's worth: MISO is the ring's bytes then tx delayed by n, and the
    // ring keeps tx's last n bytes, wherever the head ends up.
    const std::size_t size = tx.size();
    for (std::size_t i = 0; i < n; ++i) rx[i] = ring[(head + i) % n];
    std::memcpy(rx.data() + n, tx.data(), size - n);
    const std::size_t new_head = (head + size) % n;
    for (std::size_t i = 0; i < n; ++i) ring[(new_head + i) % n] = tx[size - n + i];
    head_ = new_head;
    bytes_in_frame_ += size;
    return;
  }
  for (std::size_t i = 0; i < tx.size();) {
    const std::size_t run = std::min(tx.size() - i, n - head);
    std::memcpy(rx.data() + i, ring + head, run);
    std::memcpy(ring + head, tx.data() + i, run);
    i += run;
    head += run;
    if (head == n) head = 0;
  }
  head_ = head;
  bytes_in_frame_ += tx.size();
}

bool Chain::exchange_through_standby(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx) {
  // At least a whole chain's worth of bytes while chips in standby break the chain. A byte
  // reaches MISO only if it never sits in a standby chip's register on its way, so only what
  // the chips in front of the first standby chip held comes out; everything after is 0x00.
  // Every byte in the ring at the end came from tx (tx.size() >= n); those that passed through
  // the last standby chip were lost, the ones behind it are tx's last bytes. This equals n or
  // more single-byte exchanges, in O(tx.size()) memory traffic rather than O(n) per byte.
  const std::size_t n = ring_.size();
  std::size_t first = n, last = 0;
  for (std::size_t i = 0; i < n; ++i)
    if (!chips_[i].spi_enabled()) {
      first = std::min(first, i);
      last = i;
    }
  if (first == n) return false;  // STBY rose since the frame began: a plain shift
  const std::size_t size = tx.size();
  for (std::size_t i = 0; i < first; ++i) rx[i] = ring_[(head_ + i) % n];
  std::memset(rx.data() + first, 0, size - first);
  const std::size_t new_head = (head_ + size) % n;
  head_ = new_head;
  for (std::size_t i = 0; i < n; ++i) set_shift_register(i, i > last ? tx[size - n + i] : 0x00);
  bytes_in_frame_ += size;
  return true;
}

void Chain::deselect() {
  if (!selected_) return;
  selected_ = false;
  // A CS pulse without clocks leaves the shift registers as they are: nothing is decoded.
  if (bytes_in_frame_ == 0) return;
  ++frames_;
  const std::size_t n = chips_.size();
  std::size_t slot = head_;
  for (std::size_t i = 0; i < n; ++i) {
    Chip& c = chips_[i];
    const std::uint8_t byte = ring_[slot];
    // A NOP outside a command only clocks an answer on; it needs no up-to-date state.
    if (byte != 0x00 || c.collecting_arguments()) c.advance_to(now_);
    ring_[slot] = c.on_byte(byte);
    slot = slot + 1 == n ? 0 : slot + 1;
  }
}

void Chain::advance_to(Tick tick) {
  if (tick > now_) now_ = tick;
}

void Chain::frame(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx) {
  select();
  exchange(tx, rx);
  deselect();
}

std::vector<std::uint8_t> Chain::frame(std::span<const std::uint8_t> tx) {
  std::vector<std::uint8_t> rx(tx.size());
  frame(tx, rx);
  return rx;
}

Tick Chain::next_event_tick() const {
  Tick t = kNever;
  for (std::size_t i = 0; i < chips_.size(); ++i) t = std::min(t, chip(i).next_event_tick());
  return t;
}

}  // namespace l6470emu
