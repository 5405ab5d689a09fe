// A small reference host: encodes dSPIN commands the way careful drivers do
// (one CS frame per byte position, NOP in every other chip's slot) and reads
// the answers back. Used by the tests, the demo and the README example.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/registers.hpp"
#include "daisychain/chain.hpp"
#include "daisychain/chip_status.hpp"
#include "spi/spi_device.hpp"

namespace l6470emu {

/// Encodes command bytes for one chip of a chain and sends them frame by frame.
class ChainHost {
 public:
  /// `frame_gap` ticks pass between frames (CS high time plus the frame itself).
  explicit ChainHost(Chain& chain, Tick frame_gap = 8) : ChainHost(chain, chain, frame_gap) {}
  /// Frames go through `bus` (e.g. a RecordingChain over `chain`); `chain` answers register
  /// look-ups. Both must outlive the host.
  ChainHost(Chain& chain, SpiDevice& bus, Tick frame_gap = 8) : chain_(chain), bus_(bus), frame_gap_(frame_gap) {}

  /// Sends `bytes` to chip `k`, one frame per byte (others get NOP), and returns
  /// what chip k's slot of MISO carried in each frame.
  std::vector<std::uint8_t> send(std::size_t k, std::span<const std::uint8_t> bytes);
  /// Sends one command per chip in the same frames, right-aligned so that all end together
  /// (shorter ones padded with NOPs in front); returns every frame's MISO.
  std::vector<std::vector<std::uint8_t>> send_all(const std::vector<std::vector<std::uint8_t>>& per_chip);

  void nop(std::size_t k);
  void set_param(std::size_t k, Reg reg, std::uint32_t value);
  std::uint32_t get_param(std::size_t k, Reg reg);
  std::uint16_t get_status(std::size_t k);
  void run(std::size_t k, bool forward, std::uint32_t spd);
  void step_clock(std::size_t k, bool forward);
  void move(std::size_t k, bool forward, std::uint32_t n_step);
  void go_to(std::size_t k, std::int32_t abs_pos);
  void go_to_dir(std::size_t k, bool forward, std::int32_t abs_pos);
  void go_until(std::size_t k, bool copy_to_mark, bool forward, std::uint32_t spd);
  void release_sw(std::size_t k, bool copy_to_mark, bool forward);
  void go_home(std::size_t k);
  void go_mark(std::size_t k);
  void reset_pos(std::size_t k);
  void reset_device(std::size_t k);
  void soft_stop(std::size_t k);
  void hard_stop(std::size_t k);
  void soft_hiz(std::size_t k);
  void hard_hiz(std::size_t k);
  /// The L6474's Enable (bridges on) and Disable (high impedance): HardStop's and HardHiZ's opcodes.
  void enable(std::size_t k) { hard_stop(k); }
  void disable(std::size_t k) { hard_hiz(k); }

  // ---- typed forms (Direction, SwitchAction, ChipStatus) -----------------------------------

  void run(std::size_t k, Direction dir, std::uint32_t spd) { run(k, dir == Direction::forward, spd); }
  void step_clock(std::size_t k, Direction dir) { step_clock(k, dir == Direction::forward); }
  void move(std::size_t k, Direction dir, std::uint32_t n_step) { move(k, dir == Direction::forward, n_step); }
  void go_to_dir(std::size_t k, Direction dir, std::int32_t abs_pos) { go_to_dir(k, dir == Direction::forward, abs_pos); }
  void go_until(std::size_t k, SwitchAction act, Direction dir, std::uint32_t spd) {
    go_until(k, act == SwitchAction::copy_to_mark, dir == Direction::forward, spd);
  }
  void release_sw(std::size_t k, SwitchAction act, Direction dir) {
    release_sw(k, act == SwitchAction::copy_to_mark, dir == Direction::forward);
  }
  /// GetStatus, decoded with chip k's layout (the chip clears its latched flags).
  ChipStatus status(std::size_t k) { return ChipStatus(get_status(k), chain_.chip(k).status_layout()); }
  /// GetParam(STATUS), decoded: the same bits, nothing cleared.
  ChipStatus peek_status(std::size_t k) {
    return ChipStatus(static_cast<std::uint16_t>(get_param(k, Reg::STATUS)), chain_.chip(k).status_layout());
  }
  /// Lets time pass until chip k's BUSY pin is high (its command done), at most `timeout`
  /// ticks, without a frame on the bus: time jumps from one of the chip's events to the next
  /// and stops at the tick BUSY rises. Returns whether it did (false: still busy at the timeout).
  bool wait_until_idle(std::size_t k, Tick timeout);
  /// The same with the timeout in milliseconds.
  bool wait_until_idle_ms(std::size_t k, std::uint64_t timeout_ms) { return wait_until_idle(k, ticks_from_ms(timeout_ms)); }

  /// Lets `ticks` of virtual time pass.
  void wait(Tick ticks) { bus_.advance_to(bus_.now() + ticks); }
  /// Lets `ms` milliseconds of virtual time pass.
  void wait_ms(std::uint64_t ms) { wait(ticks_from_ms(ms)); }

  Chain& chain() { return chain_; }

 private:
  void frame(std::span<const std::uint8_t> tx, std::span<std::uint8_t> rx);
  std::uint8_t frame_byte(std::size_t k, std::uint8_t byte);
  void send_value(std::size_t k, std::uint8_t opcode, std::uint32_t value, unsigned bytes);
  std::uint32_t read_answer(std::size_t k, std::uint8_t opcode, unsigned bytes);

  Chain& chain_;
  SpiDevice& bus_;
  Tick frame_gap_;
  std::vector<std::uint8_t> tx_, rx_;
};

}  // namespace l6470emu
