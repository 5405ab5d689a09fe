// The chain's serial interface at its pins (daisychain/pin_level_bus.hpp): a host that bit-bangs
// CS, CK and SDI and reads SDO between edges gets what a host with an SPI controller gets, bit
// for bit, through the same chain; and where it reads between edges it reads what the edge
// rules say chip 0 drives.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "daisychain/pin_level_bus.hpp"
#include "support/test_support.hpp"

namespace l6470emu {
namespace {

using Bytes = std::vector<std::uint8_t>;

/// A host bit-banging one chain: each edge a tick after the last, as a program's pin writes are.
struct BitBanger {
  Chain& chain;
  PinLevelBus pins;
  bool idle_high;  // the clock's level between bytes: high for mode 3's shape, low for mode 0's

  BitBanger(Chain& c, bool clock_idles_high) : chain(c), idle_high(clock_idles_high) { set_ck(idle_high); }

  void tick() { chain.advance_to(chain.now() + 1); }
  void set_ck(bool level) {
    tick();
    pins.set_ck(level, chain, chain);
  }
  void cs_low() {
    tick();
    chain.select_wire();
    pins.cs_fell(chain);
  }
  void cs_high() {
    tick();
    pins.cs_rising();
    chain.deselect_wire();
    chain.advance_to(chain.now() + kDeselectMinTicks);
  }
  /// One byte, MSB first: mode 3's shape (CK low, SDI, CK high, read) or mode 0's (SDI, CK
  /// high, read, CK low), reading SDO where each host reads it.
  std::uint8_t byte(std::uint8_t out) {
    std::uint8_t in = 0;
    for (int b = 7; b >= 0; --b) {
      if (idle_high) set_ck(false);
      pins.set_sdi(((out >> b) & 1u) != 0);
      set_ck(true);
      in = static_cast<std::uint8_t>(in | (pins.sdo(chain) ? 1u : 0u) << b);
      if (!idle_high) set_ck(false);
    }
    return in;
  }
  Bytes frame(const Bytes& tx) {
    cs_low();
    Bytes rx;
    for (const std::uint8_t b : tx) rx.push_back(byte(b));
    cs_high();
    return rx;
  }
};

WireSettings mode(std::uint8_t m) {
  WireSettings w;
  w.mode = m;
  return w;
}

TEST(PinLevelBus, AMode3ShapedHostReadsConfig0x2E88FromEachChipOfAThreeChipChain) {
  Chain chain(3);
  BitBanger host(chain, true);
  host.frame({0x38, 0x38, 0x38});  // GetParam(CONFIG) to every chip
  EXPECT_EQ(host.frame({0x00, 0x00, 0x00}), (Bytes{0x2E, 0x2E, 0x2E}));
  EXPECT_EQ(host.frame({0x00, 0x00, 0x00}), (Bytes{0x88, 0x88, 0x88}));
  EXPECT_EQ(chain.frames(), 3u);
}

TEST(PinLevelBus, AMode0ShapedHostReadsConfigAs0x2E08AsSiliconDoes) {
  Chain chain(1);
  BitBanger host(chain, false);
  host.frame({0x00});
  host.frame({0x38});
  EXPECT_EQ(host.frame({0x00}), Bytes{0x2E});
  EXPECT_EQ(host.frame({0x00}), Bytes{0x08});  // the first bit is the latch the NOP left: 0
}

TEST(PinLevelBus, BitBangedFramesMoveTheChipsAsBytesFromAController) {
  Chain a(3), b(3);
  BitBanger host(a, true);
  // Run forward, reverse, forward at SPD 0x01000 (one frame per byte, a byte per chip).
  for (const Bytes& tx : {Bytes{0x51, 0x50, 0x51}, Bytes{0x00, 0x00, 0x00}, Bytes{0x10, 0x10, 0x10}, Bytes{0x00, 0x00, 0x00}}) {
    Bytes rx(3);
    b.frame(tx, rx, mode(3));
    EXPECT_EQ(host.frame(tx), rx);
    const Tick t = std::max(a.now(), b.now()) + 40;
    a.advance_to(t);
    b.advance_to(t);
  }
  a.advance_to(ticks_from_ms(50));
  b.advance_to(ticks_from_ms(50));
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(a.chip(i).peek(Reg::SPEED), b.chip(i).peek(Reg::SPEED)) << "chip " << i;
    EXPECT_EQ(a.chip(i).peek(Reg::ABS_POS), b.chip(i).peek(Reg::ABS_POS)) << "chip " << i;
    EXPECT_NE(a.chip(i).peek(Reg::ABS_POS), 0u) << "chip " << i;
  }
}

TEST(PinLevelBus, RandomFramesReadWhatAControllerInTheSameModeReads) {
  std::mt19937 rng(7);
  for (const bool idle_high : {true, false}) {
    for (std::size_t n : {1u, 2u, 5u}) {
      Chain a(n), b(n);
      BitBanger host(a, idle_high);
      for (int f = 0; f < 200; ++f) {
        if (n > 1 && f % 50 == 20) {  // a chip in standby for a while: it drives 0 and loses what reaches it
          const bool level = f % 100 != 20;
          a.chip(1).set_stby_rst_pin(level);
          b.chip(1).set_stby_rst_pin(level);
        }
        Bytes tx(1 + rng() % (2 * n + 1));
        for (auto& x : tx) x = static_cast<std::uint8_t>(rng() % 3 == 0 ? 0x00 : rng());
        Bytes rx(tx.size());
        b.frame(tx, rx, mode(idle_high ? 3 : 0));
        ASSERT_EQ(host.frame(tx), rx) << "frame " << f << ", " << n << " chips, idle " << (idle_high ? "high" : "low");
        const Tick t = std::max(a.now(), b.now()) + 10;
        a.advance_to(t);
        b.advance_to(t);
        for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(a.shift_register(i), b.shift_register(i));
      }
      for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(a.chip(i).status(), b.chip(i).status());
    }
  }
}

TEST(PinLevelBus, SdoShowsEachBitFromTheFallingEdgeThatLatchesIt) {
  Chain chain(1);
  chain.frame(Bytes{0x38});  // GetParam(CONFIG)
  chain.advance_to(chain.now() + 10);
  PinLevelBus pins;
  pins.set_ck(true, chain, chain);
  chain.select_wire();
  pins.cs_fell(chain);
  // 0x2E = 0010 1110: before each rising edge, after the falling one, SDO shows the next bit.
  std::uint8_t seen = 0;
  for (int b = 7; b >= 0; --b) {
    pins.set_ck(false, chain, chain);
    seen = static_cast<std::uint8_t>(seen | (pins.sdo(chain) ? 1u : 0u) << b);
    pins.set_sdi(false);
    pins.set_ck(true, chain, chain);
  }
  EXPECT_EQ(seen, 0x2E);
}

TEST(PinLevelBus, AFrameEndingInsideAByteDropsItsBitsAndSaysHowMany) {
  Chain chain(1);
  BitBanger host(chain, true);
  host.cs_low();
  host.byte(0x38);
  for (int b = 0; b < 3; ++b) {
    host.set_ck(false);
    host.set_ck(true);
  }
  EXPECT_EQ(host.pins.bits_pending(), 3u);
  EXPECT_EQ(host.pins.bytes_in_frame(), 1u);
  EXPECT_EQ(host.pins.cs_rising(), 3u);
  chain.deselect_wire();
  EXPECT_TRUE(chain.chip(0).answer_bytes_pending() != 0) << "the whole byte was decoded: GetParam(CONFIG)";
}

TEST(PinLevelBus, ClockEdgesWithCsHighShiftNothingAndAreCounted) {
  Chain chain(1);
  PinLevelBus pins;
  for (int k = 0; k < 8; ++k) {
    pins.set_ck(true, chain, chain);
    pins.set_ck(false, chain, chain);
  }
  EXPECT_EQ(pins.rising_edges_deselected(), 8u);
  EXPECT_EQ(chain.frames(), 0u);
  EXPECT_EQ(chain.chip(0).decoded_bytes(), 0u);
}

TEST(PinLevelBus, AMisoFlipFaultInvertsTheBitTheHostReads) {
  Chain chain(1);
  BitBanger host(chain, true);
  host.frame({0x38});
  chain.arm_miso_flip(0, 5);  // bit 5 of byte 0: 0x2E reads 0x0E
  EXPECT_EQ(host.frame({0x00}), Bytes{0x0E});
  EXPECT_EQ(host.frame({0x00}), Bytes{0x88});
}

}  // namespace
}  // namespace l6470emu
