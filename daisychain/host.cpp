// ChainHost: command encoding for the reference host (opcodes from the datasheet's command table).
#include "daisychain/host.hpp"

#include <algorithm>
#include <stdexcept>

namespace l6470emu {

void ChainHost::frame(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx) {
  bus_.advance_to(bus_.now() + frame_gap_);
  bus_.select();
  bus_.exchange(tx, rx);
  bus_.deselect();
}

std::uint8_t ChainHost::frame_byte(std::size_t k, std::uint8_t byte) {
  const std::size_t n = chain_.size();
  tx_.assign(n, 0x00);
  rx_.assign(n, 0x00);
  tx_.at(k) = byte;
  frame(tx_, rx_);
  return rx_[k];
}

std::vector<std::uint8_t> ChainHost::send(std::size_t k, std::span<const std::uint8_t> bytes) {
  std::vector<std::uint8_t> out;
  out.reserve(bytes.size());
  for (auto b : bytes) out.push_back(frame_byte(k, b));
  return out;
}

std::vector<std::vector<std::uint8_t>> ChainHost::send_all(const std::vector<std::vector<std::uint8_t>>& per_chip) {
  if (per_chip.size() != chain_.size()) throw std::invalid_argument("send_all needs one command per chip");
  std::size_t len = 0;
  for (const auto& c : per_chip) len = std::max(len, c.size());
  std::vector<std::vector<std::uint8_t>> frames;
  for (std::size_t f = 0; f < len; ++f) {
    tx_.assign(chain_.size(), 0x00);
    rx_.assign(chain_.size(), 0x00);
    for (std::size_t k = 0; k < per_chip.size(); ++k) {
      const std::size_t pad = len - per_chip[k].size();
      if (f >= pad) tx_[k] = per_chip[k][f - pad];
    }
    frame(tx_, rx_);
    frames.push_back(rx_);
  }
  return frames;
}

void ChainHost::send_value(std::size_t k, std::uint8_t opcode, std::uint32_t value, unsigned bytes) {
  frame_byte(k, opcode);
  for (unsigned i = bytes; i-- > 0;) frame_byte(k, static_cast<std::uint8_t>(value >> (8 * i)));
}

std::uint32_t ChainHost::read_answer(std::size_t k, std::uint8_t opcode, unsigned bytes) {
  frame_byte(k, opcode);
  std::uint32_t v = 0;
  for (unsigned i = 0; i < bytes; ++i) v = (v << 8) | frame_byte(k, 0x00);
  return v;
}

void ChainHost::nop(std::size_t k) { frame_byte(k, 0x00); }

void ChainHost::set_param(std::size_t k, Reg reg, std::uint32_t value) {
  const RegisterInfo* r = chain_.chip(k).registers().find(reg);
  if (!r) throw std::invalid_argument("the chip has no such register");
  send_value(k, r->address, value, r->spi_bytes());
}

std::uint32_t ChainHost::get_param(std::size_t k, Reg reg) {
  const RegisterInfo* r = chain_.chip(k).registers().find(reg);
  if (!r) throw std::invalid_argument("the chip has no such register");
  return read_answer(k, static_cast<std::uint8_t>(0x20 | r->address), r->spi_bytes());
}

std::uint16_t ChainHost::get_status(std::size_t k) { return static_cast<std::uint16_t>(read_answer(k, 0xD0, 2)); }

void ChainHost::run(std::size_t k, bool forward, std::uint32_t spd) { send_value(k, 0x50 | forward, spd, 3); }
void ChainHost::step_clock(std::size_t k, bool forward) { frame_byte(k, 0x58 | forward); }
void ChainHost::move(std::size_t k, bool forward, std::uint32_t n) { send_value(k, 0x40 | forward, n, 3); }
void ChainHost::go_to(std::size_t k, std::int32_t pos) {
  send_value(k, 0x60, static_cast<std::uint32_t>(pos) & 0x3FFFFF, 3);
}
void ChainHost::go_to_dir(std::size_t k, bool forward, std::int32_t pos) {
  send_value(k, 0x68 | forward, static_cast<std::uint32_t>(pos) & 0x3FFFFF, 3);
}
void ChainHost::go_until(std::size_t k, bool copy_to_mark, bool forward, std::uint32_t spd) {
  send_value(k, static_cast<std::uint8_t>(0x82 | (copy_to_mark ? 0x08 : 0) | forward), spd, 3);
}
void ChainHost::release_sw(std::size_t k, bool copy_to_mark, bool forward) {
  frame_byte(k, static_cast<std::uint8_t>(0x92 | (copy_to_mark ? 0x08 : 0) | forward));
}
void ChainHost::go_home(std::size_t k) { frame_byte(k, 0x70); }
void ChainHost::go_mark(std::size_t k) { frame_byte(k, 0x78); }
void ChainHost::reset_pos(std::size_t k) { frame_byte(k, 0xD8); }
void ChainHost::reset_device(std::size_t k) { frame_byte(k, 0xC0); }
void ChainHost::soft_stop(std::size_t k) { frame_byte(k, 0xB0); }
void ChainHost::hard_stop(std::size_t k) { frame_byte(k, 0xB8); }
void ChainHost::soft_hiz(std::size_t k) { frame_byte(k, 0xA0); }
void ChainHost::hard_hiz(std::size_t k) { frame_byte(k, 0xA8); }

bool ChainHost::wait_until_idle(std::size_t k, Tick timeout) {
  const Tick deadline = bus_.now() + timeout;
  for (;;) {
    if (chain_.chip(k).busy_sync_pin()) return true;
    const Tick now = bus_.now();
    if (now >= deadline) return false;
    const Tick next = chain_.chip(k).next_event_tick();
    bus_.advance_to(next == kNever || next > deadline ? deadline : std::max(next, now + 1));
  }
}

}  // namespace l6470emu
