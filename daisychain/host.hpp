// A small reference host: encodes dSPIN commands the way careful drivers do
// (one CS frame per byte position, NOP in every other chip's slot) and reads
// the answers back. Used by the tests, the demo and the README example.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/registers.hpp"
#include "daisychain/chain.hpp"
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
