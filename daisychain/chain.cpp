// Chain: the shared shift register of a daisy chain, kept as a ring buffer so a
// byte costs O(1) whatever the chain length. Chips in standby break the chain
// (their SDO floats; modelled as 0x00 and the bytes they receive are lost). A chip missing a
// frame (a lost_frame fault) is one for that frame; a MISO flip touches only what the host reads.
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
  odd_frame_ = standby_in_frame_;
  if (faults_armed_) take_armed_faults();
  // A chip in standby drives 0x00 and holds nothing it could pass on.
  if (standby_in_frame_)
    for (std::size_t i = 0; i < chips_.size(); ++i)
      if (!listening(i)) set_shift_register(i, 0x00);
}

void Chain::take_armed_faults() {
  faults_armed_ = false;
  flips_.swap(flips_armed_);  // flips_ is empty between frames
  flips_armed_.clear();
  if (!deaf_armed_.empty()) {
    const std::size_t n = chips_.size();
    if (deaf_.size() != n) {
      deaf_.assign(n, 0);
      deaf_held_.assign(n, 0);
    }
    for (const std::size_t k : deaf_armed_) {
      deaf_[k] = 1;
      deaf_held_[k] = shift_register(k);  // what it holds on to while it hears nothing
    }
    deaf_armed_.clear();
    deaf_in_frame_ = true;
    standby_in_frame_ = true;  // the standby model, for this frame, for the deaf chips
  }
  odd_frame_ = standby_in_frame_ || !flips_.empty();
  end_of_frame_work_ = end_of_frame_work_ || deaf_in_frame_ || !flips_.empty();
}

void Chain::arm_miso_flip(std::size_t i, std::uint8_t bit) {
  (void)chips_.at(i);
  arm_flips(i, static_cast<std::uint8_t>(1u << (bit & 7u)));
}

void Chain::arm_flips(std::size_t i, std::uint8_t mask) {
  faults_armed_ = true;
  for (auto& f : flips_armed_)
    if (f.first == i) {
      f.second = static_cast<std::uint8_t>(f.second | mask);
      return;
    }
  flips_armed_.emplace_back(i, mask);
}

void Chain::arm_lost_frame(std::size_t i) {
  (void)chips_.at(i);
  faults_armed_ = true;
  if (std::find(deaf_armed_.begin(), deaf_armed_.end(), i) == deaf_armed_.end()) deaf_armed_.push_back(i);
}

void Chain::power_cycle(std::size_t i) {
  (void)chips_.at(i);
  if (selected_) {
    power_cycles_.push_back(i);
    end_of_frame_work_ = true;
    return;
  }
  power_cycle_now(i);
}

void Chain::power_cycle_now(std::size_t i) {
  chip(i).power_cycle();  // (chip() brings it up to now and forgets that the chain was quiet)
  chips_touched_ = true;
  // Its shift register and SDO latch lost their contents with the power.
  store_latches();
  latch_[i] = 0;
  set_shift_register(i, 0x00);
  if (i < received_.size()) received_[i] = 0x00;
}

void Chain::apply_flips(std::uint64_t at, std::span<std::uint8_t> rx) const {
  for (const auto& [k, mask] : flips_)
    if (k >= at && k - at < rx.size()) rx[k - at] = static_cast<std::uint8_t>(rx[k - at] ^ mask);
}

bool Chain::any_in_standby() const {
  for (const auto& c : chips_)
    if (!c.spi_enabled()) return true;
  return false;
}

std::uint8_t Chain::exchange(std::uint8_t mosi) {
  const std::uint64_t at = bytes_in_frame_;
  std::uint8_t miso = shift_byte(mosi);
  if (odd_frame_ && selected_ && !flips_.empty()) apply_flips(at, {&miso, 1});
  return miso;
}

std::uint8_t Chain::shift_byte(std::uint8_t mosi) {
  if (!selected_) return 0x00;  // SDO is high impedance while CS is high
  ++bytes_in_frame_;
  const std::size_t n = ring_.size();
  const std::uint8_t miso = ring_[head_];
  ring_[head_] = mosi;
  head_ = head_ + 1 == n ? 0 : head_ + 1;
  if (standby_in_frame_) {
    for (std::size_t i = 0; i < n; ++i)
      if (!listening(i)) set_shift_register(i, 0x00);
    if (!listening(0)) return 0x00;
  }
  return miso;
}

void Chain::exchange_odd(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx) {
  const std::uint64_t at = bytes_in_frame_;
  exchange_slow(tx, rx);
  if (selected_ && !flips_.empty()) apply_flips(at, rx.first(tx.size()));
}

void Chain::exchange_slow(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx) {
  if (!selected_ || (standby_in_frame_ && tx.size() < ring_.size())) {
    for (std::size_t i = 0; i < tx.size(); ++i) rx[i] = shift_byte(tx[i]);
    return;
  }
  if (standby_in_frame_ && exchange_through_standby(tx, rx)) return;
  shift_bytes(tx, rx);  // no chip in standby (STBY rose since the frame began): a plain shift
}

namespace {

/// Copies `count` bytes between distinct buffers; a few chips' worth without a library call.
inline void copy_bytes(std::uint8_t* dst, const std::uint8_t* src, std::size_t count) {
  const auto two = [&](auto word) {  // two possibly overlapping words cover 1-2 words' worth
    constexpr std::size_t w = sizeof word;
    decltype(word) a, b;
    std::memcpy(&a, src, w);
    std::memcpy(&b, src + count - w, w);
    std::memcpy(dst, &a, w);
    std::memcpy(dst + count - w, &b, w);
  };
  if (count > 16) std::memcpy(dst, src, count);
  else if (count >= 8) two(std::uint64_t{});
  else if (count >= 4) two(std::uint32_t{});
  else if (count >= 2) two(std::uint16_t{});
  else if (count == 1) *dst = *src;
}

}  // namespace

void Chain::shift_bytes(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx) {
  const std::size_t n = ring_.size();
  if (tx.size() == n && head_ == 0) {
    // A frame of the chain's length from slot 0 (the usual frame): the registers' bytes out,
    // tx's in; a short chain's byte by byte, a long one's in two copies.
    std::uint8_t* const ring = ring_.data();
    if (n <= 16) {
      for (std::size_t i = 0; i < n; ++i) {
        const std::uint8_t out = ring[i];
        ring[i] = tx[i];
        rx[i] = out;
      }
    } else {
      std::memcpy(rx.data(), ring, n);
      std::memcpy(ring, tx.data(), n);
    }
    bytes_in_frame_ += n;
    return;
  }
  shift_runs(tx, rx);
}

void Chain::shift_runs(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx) {
  // What leaves the ring goes to MISO, what enters it comes from MOSI, a run of bytes at a time.
  const std::size_t n = ring_.size();
  const std::size_t size = tx.size();
  std::uint8_t* const ring = ring_.data();
  std::size_t head = head_;
  bytes_in_frame_ += size;
  if (size >= n) {
    // At least a whole chain's worth: MISO is the ring's bytes then tx delayed by n, and the
    // ring keeps tx's last n bytes. Only the logical order of the ring matters, so it restarts
    // at slot 0: two copies out, one copy in, no division per byte.
    copy_bytes(rx.data(), ring + head, n - head);
    copy_bytes(rx.data() + (n - head), ring, head);
    copy_bytes(rx.data() + n, tx.data(), size - n);
    copy_bytes(ring, tx.data() + (size - n), n);
    head_ = 0;
    return;
  }
  for (std::size_t i = 0; i < size;) {
    const std::size_t run = std::min(size - i, n - head);
    copy_bytes(rx.data() + i, ring + head, run);
    copy_bytes(ring + head, tx.data() + i, run);
    i += run;
    head += run;
    if (head == n) head = 0;
  }
  head_ = head;
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
    if (!listening(i)) {
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
  if (end_of_frame_work_) return end_odd_frame(bytes_in_frame_ != 0);
  // A CS pulse without clocks leaves the shift registers as they are: nothing is decoded.
  if (bytes_in_frame_ == 0) return;
  decode_shift_registers();
}

void Chain::end_odd_frame(bool clocked) {
  end_of_frame_work_ = false;
  if (clocked) {
    if (deaf_in_frame_)
      decode_around_deaf_chips();
    else
      decode_shift_registers();
  } else {
    // A CS pulse without clocks: the wire faults wait for a frame that clocks a byte.
    for (const auto& [k, mask] : flips_) arm_flips(k, mask);
    if (deaf_in_frame_)
      for (std::size_t k = 0; k < deaf_.size(); ++k)
        if (deaf_[k]) {
          set_shift_register(k, deaf_held_[k]);
          arm_lost_frame(k);
        }
  }
  flips_.clear();
  if (deaf_in_frame_) {
    std::fill(deaf_.begin(), deaf_.end(), std::uint8_t{0});
    deaf_in_frame_ = false;
  }
  for (const std::size_t k : power_cycles_) power_cycle_now(k);
  power_cycles_.clear();
}

void Chain::decode_around_deaf_chips() {
  // The frame's end for the chips that heard it; a deaf chip's register gets back the byte it
  // held, which it shifts out in the next frame.
  ++frames_;
  quiet_ = false;
  const std::size_t n = chips_.size();
  for (std::size_t i = 0, slot = head_; i < n; ++i, slot = slot + 1 == n ? 0 : slot + 1)
    ring_[slot] = deaf_[i] ? deaf_held_[i] : chips_[i].on_byte_at(now_, ring_[slot]);
}

// The loop every polled byte of a chain goes through. Its start is pinned to a 64-byte boundary:
// left where the linker happens to put it, an unrelated change elsewhere moved it by 16 bytes and
// the motion benchmark by 12 % with the very same instructions (callgrind: equal counts).
[[gnu::aligned(64)]] void Chain::decode_shift_registers() {
  // Chip i decodes logical register i, ring_[(head_ + i) % n]: chips 0 .. n-head-1 read the
  // ring from head_ on, the others from slot 0. Each chip's answer byte replaces its register.
  ++frames_;  // every frame the chips decode (scenario expectations count them)
  Chip* const chips = chips_.data();
  std::uint8_t* const ring = ring_.data();
  const std::size_t n = chips_.size();
  const std::size_t head = head_;
  const Tick now = now_;
  std::uint8_t any = 0;
  for (std::size_t i = 0; i < n; ++i) any |= ring[i];
  if (any == 0) {
    // A frame of NOPs. On a quiet chain it changes nothing: every chip shifts out 0x00, which
    // is what its register holds already. Otherwise each chip clocks an answer byte on.
    if (quiet_) return;
    std::uint32_t noise = 0;
    const auto nops = [now, &noise](Chip* chip, std::uint8_t* slot, std::size_t count) {
      for (std::size_t i = 0; i < count; ++i) slot[i] = chip[i].on_nop_at(now, noise);
    };
    nops(chips, ring + head, n - head);
    if (head != 0) nops(chips + (n - head), ring, head);
    quiet_ = noise == 0;
    return;
  }
  quiet_ = false;
  const auto decode = [now](Chip* chip, std::uint8_t* slot, std::size_t count) {
    for (std::size_t i = 0; i < count; ++i) slot[i] = chip[i].on_byte_at(now, slot[i]);
  };
  decode(chips, ring + head, n - head);
  if (head != 0) decode(chips + (n - head), ring, head);
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
