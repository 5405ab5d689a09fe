// Property test of the chain's CS-rising-edge pass (Chain::decode_shift_registers): random
// frames of a chain's length — runs of NOP frames, GetStatus polls, GetParam answers, motion
// commands whose argument bytes span frames, pins and time moved through chip() — must leave
// every chip, and every MISO byte, as the same bytes fed one by one to lone chips do. This is
// what the chain's shortcuts (GetStatus from cached STATUS, NOP frames to a quiet chain) rest on.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "daisychain/chain.hpp"

namespace l6470emu {
namespace {

using Bytes = std::vector<std::uint8_t>;
using Rng = std::mt19937;

unsigned pick(Rng& rng, unsigned lo, unsigned hi) { return std::uniform_int_distribution<unsigned>(lo, hi)(rng); }

/// N lone chips with a shift register each: for an N-byte frame, MISO byte k is what chip k's
/// register held, and at the CS rise chip k decodes byte k (the chain's hand model, no standby).
struct LoneChips {
  std::vector<Chip> chips;
  Bytes regs;
  explicit LoneChips(std::size_t n) : chips(n), regs(n, 0) {}
  Bytes frame(const Bytes& tx, Tick now) {
    Bytes miso = regs;
    for (std::size_t k = 0; k < chips.size(); ++k) {
      chips[k].advance_to(now);
      regs[k] = chips[k].on_byte(tx[k]);
    }
    return miso;
  }
};

/// The next byte chip k's host sends: a NOP, or the next byte of a random command it has begun.
struct HostPlan {
  std::vector<Bytes> pending;  // per chip, bytes still to send
  explicit HostPlan(std::size_t n) : pending(n) {}
  std::uint8_t next(Rng& rng, std::size_t k, unsigned busy_percent) {
    Bytes& p = pending[k];
    if (p.empty() && pick(rng, 0, 99) < busy_percent) {
      switch (pick(rng, 0, 7)) {
        case 0: p = {0xD0, 0x00, 0x00}; break;                                          // GetStatus
        case 1: p = {0x21, 0x00, 0x00, 0x00}; break;                                    // GetParam ABS_POS
        case 2: p = {0x39, 0x00, 0x00}; break;                                          // GetParam STATUS (no clearing)
        case 3: p = {static_cast<std::uint8_t>(0x40 | pick(rng, 0, 1)), 0x00, static_cast<std::uint8_t>(pick(rng, 0, 255)), 0x40}; break;  // Move
        case 4: p = {static_cast<std::uint8_t>(0x50 | pick(rng, 0, 1)), 0x00, static_cast<std::uint8_t>(pick(rng, 1, 255)), 0x00}; break;  // Run
        case 5: p = {0xB0}; break;                                                      // SoftStop
        case 6: p = {0x05, 0x00, static_cast<std::uint8_t>(pick(rng, 1, 255))}; break;  // SetParam ACC (refused while running)
        default: p = {0xD0}; break;                                                     // GetStatus, answer never read
      }
    }
    if (p.empty()) return 0x00;
    const std::uint8_t b = p.front();
    p.erase(p.begin());
    return b;
  }
};

TEST(ChainDecode, FramesOfNopsAndCommandsLeaveEveryChipAsTheSameBytesFedToLoneChipsDo) {
  for (std::size_t n : {1u, 2u, 5u, 17u, 64u}) {
    Rng rng(static_cast<unsigned>(1000 + n));
    Chain chain(n);
    LoneChips lone(n);
    HostPlan plan(n);
    Tick now = 0;
    for (int frame = 0; frame < 3000; ++frame) {
      // Stretches of quiet polling and stretches of commands; runs of NOP-only frames in between.
      const unsigned busy = (frame / 200) % 3 == 0 ? 0 : (frame / 200) % 3 == 1 ? 5 : 40;
      Bytes tx(n);
      for (std::size_t k = 0; k < n; ++k) tx[k] = plan.next(rng, k, busy);
      now += pick(rng, 1, 4) == 1 ? pick(rng, 1, 40'000) : pick(rng, 1, 200);
      chain.advance_to(now);
      Bytes rx(n);
      chain.select();
      chain.exchange(tx, rx);
      chain.deselect();
      ASSERT_EQ(rx, lone.frame(tx, now)) << n << " chips, frame " << frame;
      if (pick(rng, 0, 99) == 0) {  // the physical world, through chip(): a switch or a fault
        const std::size_t k = pick(rng, 0, static_cast<unsigned>(n) - 1);
        const bool level = pick(rng, 0, 1) == 1;
        if (pick(rng, 0, 1) == 0) {
          chain.chip(k).set_sw_pin(level);
          lone.chips[k].advance_to(now);
          lone.chips[k].set_sw_pin(level);
        } else {
          chain.chip(k).set_thermal(level ? Thermal::warning : Thermal::normal);
          lone.chips[k].advance_to(now);
          lone.chips[k].set_thermal(level ? Thermal::warning : Thermal::normal);
        }
      }
    }
    for (std::size_t k = 0; k < n; ++k) {
      lone.chips[k].advance_to(now);
      EXPECT_EQ(chain.chip(k).motion(), lone.chips[k].motion()) << n << " chips, chip " << k;
      EXPECT_EQ(chain.chip(k).status(), lone.chips[k].status()) << n << " chips, chip " << k;
      EXPECT_EQ(chain.chip(k).collecting_arguments(), lone.chips[k].collecting_arguments());
      EXPECT_EQ(chain.shift_register(k), lone.regs[k]) << n << " chips, chip " << k;
    }
  }
}

}  // namespace
}  // namespace l6470emu
