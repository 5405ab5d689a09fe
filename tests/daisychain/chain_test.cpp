// Daisy chains (spec §7, docs/chip-model.md "Daisy chain"): slot numbering, answers per slot,
// right-aligned commands, frames shorter and longer than the chain worked out by hand from the
// shift-register model, size limits, and a chip in standby breaking the chain (spec §10 item 3).
//
// The hand model used below: MOSI -> chip N-1 -> ... -> chip 0 -> MISO. S_i is chip i's shift
// register. Each byte: MISO = S_0, S_i = S_(i+1), S_(N-1) = MOSI. At the CS rise chip i decodes S_i
// and loads S_i with its next answer byte (0x00 when none is pending).
#include <gtest/gtest.h>

#include <cstdint>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "daisychain/chain.hpp"
#include "support/test_support.hpp"
#include "daisychain/host.hpp"

namespace l6470emu {
namespace {

using namespace test::status_bits;

using Bytes = std::vector<std::uint8_t>;


std::uint8_t value_for(std::size_t k) { return static_cast<std::uint8_t>(k * 37 + 11); }

// ---------------------------------------------------------------- N-byte frames, several sizes

class ChainOfN : public ::testing::TestWithParam<std::size_t> {};

TEST_P(ChainOfN, AnNByteFrameGivesByteKToChipK) {
  const std::size_t n = GetParam();
  Chain chain(n);
  ASSERT_EQ(chain.size(), n);
  Bytes opcodes(n, 0x0A);  // SetParam(KVAL_RUN) to every chip
  Bytes values(n);
  for (std::size_t k = 0; k < n; ++k) values[k] = value_for(k);
  EXPECT_EQ(chain.frame(opcodes), Bytes(n, 0x00));
  EXPECT_EQ(chain.frame(values), Bytes(n, 0x00));
  for (std::size_t k = 0; k < n; ++k) EXPECT_EQ(chain.chip(k).peek(Reg::KVAL_RUN), values[k]) << "chip " << k;
}

TEST_P(ChainOfN, MisoByteKIsChipKsAnswer) {
  const std::size_t n = GetParam();
  Chain chain(n);
  Bytes values(n);
  for (std::size_t k = 0; k < n; ++k) values[k] = value_for(k);
  chain.frame(Bytes(n, 0x0A));
  chain.frame(values);
  EXPECT_EQ(chain.frame(Bytes(n, 0x2A)), Bytes(n, 0x00));  // GetParam(KVAL_RUN) everywhere
  EXPECT_EQ(chain.frame(Bytes(n, 0x00)), values);
  EXPECT_EQ(chain.frame(Bytes(n, 0x00)), Bytes(n, 0x00));
}

TEST_P(ChainOfN, GetStatusGoesToEveryChipInOneTransaction) {
  const std::size_t n = GetParam();
  Chain chain(n);
  Bytes tx(n, 0x00);
  for (std::size_t k = 1; k < n; k += 2) tx[k] = 0xEB;  // WRONG_CMD on the odd chips
  chain.frame(tx);
  EXPECT_EQ(chain.frame(Bytes(n, 0xD0)), Bytes(n, 0x00));
  const Bytes msb = chain.frame(Bytes(n, 0x00));
  const Bytes lsb = chain.frame(Bytes(n, 0x00));
  for (std::size_t k = 0; k < n; ++k) {
    EXPECT_EQ(msb[k], k % 2 ? 0x7D : 0x7C) << "chip " << k;
    EXPECT_EQ(lsb[k], 0x03) << "chip " << k;
  }
  chain.frame(Bytes(n, 0xD0));
  EXPECT_EQ(chain.frame(Bytes(n, 0x00)), Bytes(n, 0x7E)) << "flags cleared by the first GetStatus";
}

TEST_P(ChainOfN, ChainHostTalksToOneChipWithNopsInTheOtherSlots) {
  const std::size_t n = GetParam();
  Chain chain(n);
  ChainHost host(chain);
  const std::set<std::size_t> some{0, n / 2, n - 1};
  for (std::size_t k : some) host.set_param(k, Reg::KVAL_HOLD, value_for(k));
  for (std::size_t k : some) {
    EXPECT_EQ(host.get_param(k, Reg::KVAL_HOLD), value_for(k)) << "chip " << k;
    EXPECT_EQ(host.get_status(k), 0x7C03) << "chip " << k;
  }
  for (std::size_t k = 0; k < n; ++k) {
    const bool touched = some.count(k) != 0;
    EXPECT_EQ(chain.chip(k).peek(Reg::KVAL_HOLD), touched ? value_for(k) : 0x29u) << "chip " << k;
  }
}

INSTANTIATE_TEST_SUITE_P(Sizes, ChainOfN, ::testing::Values(1, 2, 3, 8, 256),
                         [](const auto& info) { return "Of" + std::to_string(info.param) + "Chips"; });

// ---------------------------------------------------------------- send_all

TEST(SendAll, RightAlignsCommandsOfDifferentLengthSoThatTheyEndInTheSameFrame) {
  Chain chain(3);
  ChainHost host(chain);
  const auto frames = host.send_all({{0x01, 0x00, 0x01, 0x00},  // chip 0: SetParam(ABS_POS, 256)
                                     {0xD0},                    // chip 1: GetStatus
                                     {0x0A, 0x66}});            // chip 2: SetParam(KVAL_RUN, 0x66)
  ASSERT_EQ(frames.size(), 4u);
  // Had GetStatus been sent first, its answer would have come out during these frames.
  for (const auto& f : frames) EXPECT_EQ(f, Bytes(3, 0x00));
  EXPECT_EQ(chain.chip(0).peek(Reg::ABS_POS), 256u);
  EXPECT_EQ(chain.chip(2).peek(Reg::KVAL_RUN), 0x66u);
  EXPECT_EQ(chain.frame(Bytes(3, 0x00)), (Bytes{0x00, 0x7C, 0x00}));
  EXPECT_EQ(chain.frame(Bytes(3, 0x00)), (Bytes{0x00, 0x03, 0x00}));
}

TEST(SendAll, ReturnsEveryFramesMisoBytes) {
  Chain chain(3);
  ChainHost host(chain);
  host.send_all({{0xD0}, {0x00}, {0xD0}});
  const auto frames = host.send_all({{0x00, 0x00}, {0x00, 0x00}, {0x00, 0x00}});
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0], (Bytes{0x7C, 0x00, 0x7C}));
  EXPECT_EQ(frames[1], (Bytes{0x03, 0x00, 0x03}));
}

TEST(SendAll, NeedsOneCommandPerChip) {
  Chain chain(3);
  ChainHost host(chain);
  EXPECT_THROW(host.send_all({{0x00}, {0x00}}), std::invalid_argument);
}

// ---------------------------------------------------------------- frames of the wrong length

/// Three chips with KVAL_HOLD = 0x10, 0x11, 0x12 and nothing pending.
struct ThreeChips {
  Chain chain{3};
  ThreeChips() {
    chain.frame(Bytes{0x09, 0x09, 0x09});
    chain.frame(Bytes{0x10, 0x11, 0x12});
  }
};

TEST(ShortFrame, OnAnIdleChainLetsTheFirstChipDecodeWhatWasInTheLastChipsRegister) {
  // S = [0,0,0]; bytes 0x29, 0x25 -> MISO [S0, S1] = [0, 0]; S = [0 (old S2), 0x29, 0x25].
  ThreeChips c;
  EXPECT_EQ(c.chain.frame(Bytes{0x29, 0x25}), (Bytes{0x00, 0x00}));
  // chip 0 decoded NOP, chip 1 GetParam(KVAL_HOLD), chip 2 GetParam(ACC = 0x008A).
  EXPECT_EQ(c.chain.frame(Bytes{0x00, 0x00, 0x00}), (Bytes{0x00, 0x11, 0x00}));
  EXPECT_EQ(c.chain.frame(Bytes{0x00, 0x00, 0x00}), (Bytes{0x00, 0x00, 0x8A}));
  for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(c.chain.chip(k).status() & kWrongCmd, 0) << k;
}

TEST(ShortFrame, PassesAnAnswerByteOfTheLastChipToTheFirstChipAsACommand) {
  // After GetStatus everywhere S = [0x7C,0x7C,0x7C]. Bytes 0, 0 -> MISO [0x7C,0x7C]; S = [0x7C,0,0].
  // Chip 0 decodes 0x7C (no such command: WRONG_CMD); every chip then loads its answer's LSB.
  ThreeChips c;
  c.chain.frame(Bytes{0xD0, 0xD0, 0xD0});
  EXPECT_EQ(c.chain.frame(Bytes{0x00, 0x00}), (Bytes{0x7C, 0x7C}));
  EXPECT_NE(c.chain.chip(0).status() & kWrongCmd, 0);
  EXPECT_EQ(c.chain.chip(1).status() & kWrongCmd, 0);
  EXPECT_EQ(c.chain.chip(2).status() & kWrongCmd, 0);
  EXPECT_EQ(c.chain.frame(Bytes{0x00, 0x00, 0x00}), (Bytes{0x03, 0x03, 0x03}));
  EXPECT_EQ(c.chain.frame(Bytes{0x00, 0x00, 0x00}), (Bytes{0x00, 0x00, 0x00}));
}

TEST(ShortFrame, OfOneByteShiftsTheWholeChainByOneSlot) {
  // S = [0,0,0]; byte 0xD8 -> MISO [0]; S = [0, 0, 0xD8]: only chip 2 (next to MOSI) gets it.
  ThreeChips c;
  c.chain.frame(Bytes{0x01, 0x01, 0x01});
  c.chain.frame(Bytes{0x00, 0x00, 0x00});
  c.chain.frame(Bytes{0x00, 0x00, 0x00});
  c.chain.frame(Bytes{0x05, 0x05, 0x05});  // ABS_POS = 5 everywhere
  EXPECT_EQ(c.chain.frame(Bytes{0xD8}), Bytes{0x00});
  EXPECT_EQ(c.chain.chip(0).position(), 5);
  EXPECT_EQ(c.chain.chip(1).position(), 5);
  EXPECT_EQ(c.chain.chip(2).position(), 0);
}

TEST(LongFrame, PushesTheFirstBytesOutOnMisoAndTheChipsDecodeTheLastN) {
  // S = [0,0,0]; bytes 0x77 0x29 0x00 0x25 -> MISO [0,0,0,0x77]; S = [0x29, 0x00, 0x25].
  ThreeChips c;
  EXPECT_EQ(c.chain.frame(Bytes{0x77, 0x29, 0x00, 0x25}), (Bytes{0x00, 0x00, 0x00, 0x77}));
  for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(c.chain.chip(k).status() & kWrongCmd, 0) << "0x77 never decoded";
  EXPECT_EQ(c.chain.frame(Bytes{0x00, 0x00, 0x00}), (Bytes{0x10, 0x00, 0x00}));  // chip 0: KVAL_HOLD
  EXPECT_EQ(c.chain.frame(Bytes{0x00, 0x00, 0x00}), (Bytes{0x00, 0x00, 0x8A}));  // chip 2: ACC LSB
}

TEST(LongFrame, OfTwoNBytesReturnsTheAnswersThenTheHostsOwnFirstNBytes) {
  ThreeChips c;
  c.chain.frame(Bytes{0x29, 0x29, 0x29});  // S = [0x10, 0x11, 0x12]
  const Bytes tx{0xA1, 0xA2, 0xA3, 0x00, 0xEB, 0x00};
  EXPECT_EQ(c.chain.frame(tx), (Bytes{0x10, 0x11, 0x12, 0xA1, 0xA2, 0xA3}));
  EXPECT_EQ(c.chain.chip(0).status() & kWrongCmd, 0);
  EXPECT_NE(c.chain.chip(1).status() & kWrongCmd, 0);
  EXPECT_EQ(c.chain.chip(2).status() & kWrongCmd, 0);
}

TEST(LongFrame, WithAnswersPendingShiftsThemAllOutThenDecodesTheTail) {
  // S = [0x7C,0x7C,0x7C]; four NOPs -> MISO [0x7C,0x7C,0x7C,0x00]; all decode NOP and load 0x03.
  ThreeChips c;
  c.chain.frame(Bytes{0xD0, 0xD0, 0xD0});
  EXPECT_EQ(c.chain.frame(Bytes{0x00, 0x00, 0x00, 0x00}), (Bytes{0x7C, 0x7C, 0x7C, 0x00}));
  EXPECT_EQ(c.chain.frame(Bytes{0x00, 0x00, 0x00}), (Bytes{0x03, 0x03, 0x03}));
}

TEST(ShortFrame, OfTwoChipsChainMatchesTheCommunityExampleOnlyWithCsRaisedEveryTwoBytes) {
  // Spec §7 last row: GetStatus to the MISO-side chip of two, "D0 00 00 00 00 00".
  Chain chain(2);
  const Bytes one_cs = chain.frame(Bytes{0xD0, 0x00, 0x00, 0x00, 0x00, 0x00});
  // In one CS frame the opcode just passes through both chips and comes back on MISO;
  // only the last two bytes (NOPs) are decoded.
  EXPECT_EQ(one_cs, (Bytes{0x00, 0x00, 0xD0, 0x00, 0x00, 0x00}));
  EXPECT_EQ(chain.frame(Bytes{0x00, 0x00}), (Bytes{0x00, 0x00})) << "no GetStatus answer";
  Chain framed(2);
  Bytes rx;
  for (auto pair : {Bytes{0xD0, 0x00}, Bytes{0x00, 0x00}, Bytes{0x00, 0x00}}) {
    const auto r = framed.frame(pair);
    rx.insert(rx.end(), r.begin(), r.end());
  }
  EXPECT_EQ(rx, (Bytes{0x00, 0x00, 0x7C, 0x00, 0x03, 0x00}));  // MSB at byte 2, LSB at byte 4
}

// ---------------------------------------------------------------- size limits

TEST(Chain, RejectsZeroAnd257Chips) {
  EXPECT_THROW(Chain(0), std::invalid_argument);
  EXPECT_THROW(Chain(257), std::invalid_argument);
  EXPECT_THROW(Chain(std::vector<Chip>{}), std::invalid_argument);
  EXPECT_THROW(Chain(std::vector<Chip>(257)), std::invalid_argument);
  EXPECT_NO_THROW(Chain(256));
  EXPECT_EQ(Chain::kMaxChips, 256u);
}

TEST(Chain, AdvancesEveryChipsClock) {
  Chain chain(3);
  chain.advance_to(1000);
  EXPECT_EQ(chain.now(), 1000u);
  for (std::size_t k = 0; k < 3; ++k) EXPECT_EQ(chain.chip(k).now(), 1000u);
  chain.advance_to(10);  // never backwards
  EXPECT_EQ(chain.now(), 1000u);
}

// ---------------------------------------------------------------- standby

TEST(Standby, AChipInStandbyBreaksTheChainForItsSlotAndTheSlotsBehindIt) {
  // docs/chip-model.md "A chip in standby breaks the chain: it passes nothing on and drives 0x00"
  // (spec §1 last row / §10 item 3: SPI disabled while STBY is low). Found as a model bug (MISO
  // read {0x10, 0x11, 0x00}: chip 1's stale answer leaked out), fixed in 3bc7068; regression test.
  ThreeChips c;
  for (auto f : {Bytes{0x01, 0x01, 0x01}, Bytes{0, 0, 0}, Bytes{0, 0, 0}, Bytes{100, 100, 100}}) c.chain.frame(f);
  c.chain.frame(Bytes{0x29, 0x29, 0x29});  // S = [0x10, 0x11, 0x12]
  c.chain.chip(1).set_stby_rst_pin(false);
  // MISO slot 0 is chip 0's own answer; slot 1 (chip 1) and slot 2 (through chip 1) read 0x00.
  EXPECT_EQ(c.chain.frame(Bytes{0xD8, 0x00, 0xD8}), (Bytes{0x10, 0x00, 0x00}));
  EXPECT_EQ(c.chain.chip(0).position(), 100) << "chip 0 only received 0x00 from the broken link";
  EXPECT_EQ(c.chain.chip(2).position(), 0) << "chip 2, before the break, got its ResetPos";
  EXPECT_EQ(c.chain.chip(0).status() & kWrongCmd, 0);
}

TEST(Standby, AChipInStandbyPassesNothingOnEvenWhatWasInItsRegisterWhenStbyFell) {
  // Same rule as above (docs/chip-model.md "Daisy chain"). Chip 1 holds its answer 0xEB when STBY
  // falls; chip 0 must receive 0x00 (NOP) from the broken link, not 0xEB (which would raise
  // WRONG_CMD). Found as a model bug, fixed in 3bc7068; regression test.
  ThreeChips c;
  c.chain.frame(Bytes{0x00, 0x09, 0x00});
  c.chain.frame(Bytes{0x00, 0xEB, 0x00});  // chip 1: KVAL_HOLD = 0xEB
  c.chain.frame(Bytes{0x00, 0x29, 0x00});  // chip 1 now holds 0xEB, its answer
  c.chain.chip(1).set_stby_rst_pin(false);
  EXPECT_EQ(c.chain.frame(Bytes{0x00}), Bytes{0x00});
  EXPECT_EQ(c.chain.chip(0).status() & kWrongCmd, 0) << "chip 0 decoded a byte from a chip in standby";
}

TEST(Standby, AChipInStandbyAtTheMisoEndSilencesTheWholeChain) {
  ThreeChips c;
  c.chain.frame(Bytes{0x29, 0x29, 0x29});
  c.chain.chip(0).set_stby_rst_pin(false);
  EXPECT_EQ(c.chain.frame(Bytes{0xD0, 0xD0, 0xD0}), (Bytes{0x00, 0x00, 0x00}));
  EXPECT_EQ(c.chain.frame(Bytes{0x00, 0x00, 0x00}), (Bytes{0x00, 0x00, 0x00}));
}

TEST(Standby, StatusReadsZeroWhileStbyIsLow) {
  // Spec §10 item 3 (MotorDriver/L6474#4): STATUS read before releasing reset returns 0.
  Chain chain(1);
  ChainHost host(chain);
  chain.chip(0).set_stby_rst_pin(false);
  EXPECT_FALSE(chain.chip(0).spi_enabled());
  EXPECT_EQ(chain.chip(0).status(), 0);
  EXPECT_EQ(host.send(0, Bytes{0xD0, 0x00, 0x00}), (Bytes{0x00, 0x00, 0x00}));
  EXPECT_EQ(host.send(0, Bytes{0x39, 0x00, 0x00}), (Bytes{0x00, 0x00, 0x00}));
}

TEST(Standby, ReleaseReturnsTheChipToThePowerUpStateAndMendsTheChain) {
  ThreeChips c;
  c.chain.frame(Bytes{0xD0, 0xD0, 0xD0});
  c.chain.frame(Bytes{0, 0, 0});
  c.chain.frame(Bytes{0, 0, 0});  // flags cleared everywhere
  c.chain.chip(1).set_stby_rst_pin(false);
  c.chain.frame(Bytes{0x00, 0xB8, 0x00});  // a HardStop sent to chip 1 during standby is lost
  c.chain.chip(1).set_stby_rst_pin(true);
  c.chain.advance_to(c.chain.now() + ticks_from_us(45));
  c.chain.frame(Bytes{0xD0, 0xD0, 0xD0});
  EXPECT_EQ(c.chain.frame(Bytes{0, 0, 0}), (Bytes{0x7E, 0x7C, 0x7E})) << "chip 1 shows the power-up UVLO";
  EXPECT_EQ(c.chain.frame(Bytes{0, 0, 0}), (Bytes{0x03, 0x03, 0x03}));
  EXPECT_EQ(c.chain.chip(1).peek(Reg::KVAL_HOLD), 0x29u) << "registers back at reset";
  EXPECT_EQ(c.chain.chip(0).peek(Reg::KVAL_HOLD), 0x10u);
}

TEST(Standby, DiscardsCommandsAddressedToTheChip) {
  Chain chain(1);
  ChainHost host(chain);
  chain.chip(0).set_stby_rst_pin(false);
  host.send(0, Bytes{0xEB, 0x0A, 0x55});
  chain.chip(0).set_stby_rst_pin(true);
  EXPECT_EQ(host.get_status(0), 0x7C03);
  EXPECT_EQ(chain.chip(0).peek(Reg::KVAL_RUN), 0x29u);
}

TEST(ChainShift, ABlockOfBytesShiftsExactlyAsTheSameBytesOneByOne) {
  std::uint32_t seed = 12345;
  auto next = [&] { return static_cast<std::uint8_t>((seed = seed * 1103515245u + 12345u) >> 16); };
  for (std::size_t chips : {1u, 2u, 3u, 8u}) {
    for (std::size_t len = 0; len <= 40; ++len) {
      for (std::size_t lead = 0; lead < chips + 2; ++lead) {  // bytes already in the frame: any head
        Chain block(chips), single(chips);
        block.select();
        single.select();
        for (std::size_t i = 0; i < lead; ++i) {
          const std::uint8_t b = next();
          block.exchange(b);
          single.exchange(b);
        }
        std::vector<std::uint8_t> tx(len), rx_block(len), rx_single(len);
        for (auto& b : tx) b = next();
        block.exchange(tx, rx_block);
        for (std::size_t i = 0; i < len; ++i) rx_single[i] = single.exchange(tx[i]);
        EXPECT_EQ(rx_block, rx_single) << chips << " chips, " << len << " bytes after " << lead;
        for (std::size_t k = 0; k < chips; ++k)
          EXPECT_EQ(block.shift_register(k), single.shift_register(k)) << chips << " chips, chip " << k;
        EXPECT_EQ(block.bytes_in_frame(), single.bytes_in_frame());
      }
    }
  }
}

TEST(ChainShift, ABlockThroughChipsInStandbyShiftsExactlyAsTheSameBytesOneByOne) {
  std::uint32_t seed = 777;
  auto next = [&] { return static_cast<std::uint8_t>((seed = seed * 1103515245u + 12345u) >> 16); };
  for (std::size_t chips : {1u, 2u, 3u, 5u}) {
    for (unsigned standby = 1; standby < (1u << chips); ++standby) {  // every non-empty set
      for (std::size_t len : {chips, chips + 1, 2 * chips + 3, std::size_t{40}}) {
        for (std::size_t lead = 0; lead < chips + 1; ++lead) {
          Chain block(chips), single(chips);
          for (std::size_t k = 0; k < chips; ++k) {  // registers full of something before STBY falls
            block.select();
            single.select();
            const std::uint8_t b = next();
            block.exchange(b);
            single.exchange(b);
          }
          for (std::size_t k = 0; k < chips; ++k)
            if (standby & (1u << k)) {
              block.chip(k).set_stby_rst_pin(false);
              single.chip(k).set_stby_rst_pin(false);
            }
          block.deselect();
          single.deselect();
          block.select();
          single.select();
          for (std::size_t i = 0; i < lead; ++i) {
            const std::uint8_t b = next();
            block.exchange(b);
            single.exchange(b);
          }
          std::vector<std::uint8_t> tx(len), rx_block(len), rx_single(len);
          for (auto& b : tx) b = next();
          block.exchange(tx, rx_block);
          for (std::size_t i = 0; i < len; ++i) rx_single[i] = single.exchange(tx[i]);
          const auto what = std::to_string(chips) + " chips, standby set " + std::to_string(standby) + ", " +
                            std::to_string(len) + " bytes after " + std::to_string(lead);
          EXPECT_EQ(rx_block, rx_single) << what;
          for (std::size_t k = 0; k < chips; ++k)
            EXPECT_EQ(block.shift_register(k), single.shift_register(k)) << what << ", chip " << k;
          EXPECT_EQ(block.bytes_in_frame(), single.bytes_in_frame()) << what;
        }
      }
    }
  }
}

}  // namespace
}  // namespace l6470emu
