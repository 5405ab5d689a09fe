// The bit-level interface (docs/spi-interface.md): what chips receive and hosts read in every SPI
// mode, bit order and framing. A reference model that simulates every clock edge of every chip
// (shift register, SDO latch, MOSI, MISO) is the oracle for Chain::exchange_wire; public reports
// of wrong-mode reads (L6474, L6480, SparkFun) are checked value for value.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>
#include <vector>

#include "daisychain/chain.hpp"
#include "support/test_support.hpp"

namespace l6470emu {
namespace {

using Bytes = std::vector<std::uint8_t>;

WireSettings mode(std::uint8_t m, bool lsb_first = false) {
  WireSettings w;
  w.mode = m;
  w.lsb_first = lsb_first;
  return w;
}

// ---------------------------------------------------------------- the edge-level oracle

/// A daisy chain simulated edge by edge from the datasheet's rules alone: each chip samples
/// SDI on rising CK edges (register := register << 1 | SDI) and sets its SDO latch to the top of
/// its register on falling edges; chip i's SDI is chip i+1's latch, chip N-1's is MOSI, MISO is
/// chip 0's latch. Where the host acts on the same edge as a chip, each sees the other's level
/// from before the edge. The host puts its bits out and samples MISO as SPI mode (CPOL, CPHA)
/// says. At the CS rising edge each chip decodes its register (Chip::on_byte) and loads its
/// answer there, unless the next CS falling edge comes sooner than t_disCS. Chips in standby
/// hold 0 in register and latch.
class EdgeChain {
 public:
  explicit EdgeChain(std::vector<Chip> chips) : chips_(std::move(chips)), reg_(chips_.size(), 0), latch_(chips_.size(), 0) {}

  Chip& chip(std::size_t i) { return chips_[i]; }
  std::uint8_t reg(std::size_t i) const { return reg_[i]; }
  std::uint8_t latch(std::size_t i) const { return latch_[i]; }
  void advance_to(Tick t) { now_ = std::max(now_, t); }
  Tick now() const { return now_; }

  void select() {
    if (loaded_ && now_ - deselect_tick_ < kDeselectMinTicks) reg_ = received_;
    loaded_ = false;
    selected_ = true;
    clocked_ = false;
    mosi_ = 0;  // the idle level a mode-1 chip samples first
    standby_.assign(chips_.size(), false);
    for (std::size_t i = 0; i < chips_.size(); ++i)
      if (!chips_[i].spi_enabled()) {
        standby_[i] = true;
        reg_[i] = 0;
        latch_[i] = 0;
      }
  }

  std::uint8_t byte(std::uint8_t host_byte, const WireSettings& w) {
    if (!selected_) return 0;
    clocked_ = true;
    const bool cpol = (w.mode & 2) != 0, cpha = (w.mode & 1) != 0;
    auto bit = [&](int k) -> std::uint8_t {  // the host's k-th bit on the wire
      return w.lsb_first ? (host_byte >> k) & 1u : (host_byte >> (7 - k)) & 1u;
    };
    std::uint8_t read = 0;
    int read_count = 0;
    auto sample = [&](std::uint8_t miso) {
      const int k = read_count++;
      if (w.lsb_first)
        read = static_cast<std::uint8_t>(read | miso << k);
      else
        read = static_cast<std::uint8_t>(read | miso << (7 - k));
    };
    if (!cpha) mosi_ = bit(0);  // valid before the leading edge
    for (int k = 0; k < 8; ++k) {
      // leading edge
      const bool leading_rising = !cpol;
      edge(leading_rising, /*host samples*/ !cpha, /*host changes to*/ cpha ? bit(k) : -1, sample);
      // trailing edge
      edge(!leading_rising, /*host samples*/ cpha, /*host changes to*/ !cpha && k < 7 ? bit(k + 1) : -1, sample);
    }
    return read;
  }

  void deselect() {
    if (!selected_) return;
    selected_ = false;
    deselect_tick_ = now_;
    loaded_ = clocked_;
    if (!clocked_) return;
    received_ = reg_;
    for (std::size_t i = 0; i < chips_.size(); ++i) {
      chips_[i].advance_to(now_);
      reg_[i] = chips_[i].on_byte(reg_[i]);
    }
  }

 private:
  template <typename Sample>
  void edge(bool rising, bool host_samples, int host_sets, Sample& sample) {
    const std::size_t n = chips_.size();
    // Levels before the edge.
    const std::uint8_t miso = standby_[0] ? 0 : latch_[0];
    std::vector<std::uint8_t> sdi(n);
    for (std::size_t i = 0; i < n; ++i) sdi[i] = i + 1 < n ? (standby_[i + 1] ? 0 : latch_[i + 1]) : mosi_;
    if (rising) {
      for (std::size_t i = 0; i < n; ++i)
        if (!standby_[i]) reg_[i] = static_cast<std::uint8_t>(reg_[i] << 1 | sdi[i]);
    } else {
      for (std::size_t i = 0; i < n; ++i)
        if (!standby_[i]) latch_[i] = reg_[i] >> 7;
    }
    if (host_samples) sample(miso);
    if (host_sets >= 0) mosi_ = static_cast<std::uint8_t>(host_sets);
  }

  std::vector<Chip> chips_;
  std::vector<std::uint8_t> reg_, latch_, received_;
  std::vector<bool> standby_;
  std::uint8_t mosi_ = 0;
  bool selected_ = false, clocked_ = false, loaded_ = false;
  Tick now_ = 0, deselect_tick_ = 0;
};

// ---------------------------------------------------------------- worked checks

/// One L6470 driven one byte per CS frame, as the datasheet asks, with a host in `wire`.
struct OneChip {
  Chain chain{1};
  WireSettings wire;
  explicit OneChip(WireSettings w) : wire(w) {}
  Bytes per_byte(const Bytes& tx) {
    Bytes rx;
    for (std::uint8_t b : tx) {
      std::uint8_t in = 0;
      chain.advance_to(chain.now() + 8);
      chain.frame(std::span<const std::uint8_t>(&b, 1), std::span<std::uint8_t>(&in, 1), wire);
      chain.advance_to(chain.now() + 4);
      rx.push_back(in);
    }
    return rx;
  }
};

TEST(WireModes, Mode0ReadsConfigAfterANopAs0x2E08) {
  // The answer's second byte follows a NOP frame: the latch holds the NOP's top bit, 0.
  OneChip h(mode(0));
  h.per_byte({0x00});
  EXPECT_EQ(h.per_byte({0x38, 0x00, 0x00}), (Bytes{0x00, 0x2E, 0x08}));
  OneChip m3(mode(3));
  m3.per_byte({0x00});
  EXPECT_EQ(m3.per_byte({0x38, 0x00, 0x00}), (Bytes{0x00, 0x2E, 0x88}));
}

TEST(WireModes, Mode0ReadsStepModeWrittenAs0xCCAs0x4CAsTheL6474ReportSays) {
  // GitHub report on the L6474 (the same SPI block): STEP_MODE written 0xCC read back 0x4C.
  // The chip receives intact bytes in mode 0; the answer's top bit is the latch left by the
  // GetParam opcode 0x36, whose top bit is 0.
  OneChip h(mode(0));
  h.per_byte({0x16, 0xCC});  // SetParam(STEP_MODE) (WH: the bridges are in HiZ at power-up)
  EXPECT_EQ(h.chain.chip(0).peek(Reg::STEP_MODE), 0xCCu);
  // (The opcode's own frame reads 0x80: the latch still holds the top bit of 0xCC.)
  EXPECT_EQ(h.per_byte({0x36, 0x00}), (Bytes{0x80, 0x4C}));
}

TEST(WireModes, Mode0ReadsStatusAs0x7F03ByGetParamAnd0xFF03ByGetStatusAsTheL6474ReportSays) {
  // An L6470 whose STATUS is 0xFF03: step-clock mode (SCK_MOD), bridges held in HiZ by an
  // undervoltage that has gone, its flag cleared, WRONG_CMD latched. In mode 0 the top bit of
  // each answer is the latch of the opcode's top bit: 0 for GetParam(STATUS) 0x39, 1 for
  // GetStatus 0xD0 (GitHub report on the L6474: 0x7F03 and 0xFF03).
  OneChip h(mode(0));
  h.per_byte({0x58});  // StepClock(reverse)
  h.chain.chip(0).set_undervoltage(true);
  h.chain.chip(0).set_undervoltage(false);
  h.per_byte({0xD0, 0x00, 0x00});  // GetStatus clears UVLO
  h.per_byte({0xE5});              // no command: WRONG_CMD
  ASSERT_EQ(h.chain.chip(0).status(), 0xFF03) << std::hex << h.chain.chip(0).status();
  EXPECT_EQ(h.per_byte({0x39, 0x00, 0x00}), (Bytes{0x80, 0x7F, 0x03}));  // 0x80: the top bit of 0xE5
  EXPECT_EQ(h.per_byte({0xD0, 0x00, 0x00}), (Bytes{0x00, 0xFF, 0x03}));
}

TEST(WireModes, Mode0ReadsL6480ConfigAs0x2C08AsTheForumThreadSays) {
  Chain chain(1, l6480());
  auto frame = [&](std::uint8_t b) {
    std::uint8_t in = 0;
    chain.frame(std::span<const std::uint8_t>(&b, 1), std::span<std::uint8_t>(&in, 1), mode(0));
    chain.advance_to(chain.now() + 8);
    return in;
  };
  frame(0x3A);  // GetParam(CONFIG) at 0x1A
  EXPECT_EQ(frame(0x00), 0x2C);
  EXPECT_EQ(frame(0x00), 0x08);
}

TEST(WireModes, Mode0LosesBit7OfEveryAnswerByteAsSparkFunIssue29Says) {
  // getPos 128..200 read as 0..72: with CS raised after every byte, every answer byte is the
  // first of its frame, and the latch holds the NOP's 0.
  OneChip h(mode(0));
  h.per_byte({0x01, 0x00, 0x00, 0xC8});  // SetParam(ABS_POS, 200)
  EXPECT_EQ(h.per_byte({0x21, 0x00, 0x00, 0x00}), (Bytes{0x80, 0x00, 0x00, 0x48}));  // 0x80: the top bit of 0xC8
}

TEST(WireModes, Mode2ReadsEveryByteShiftedRightByOneBit) {
  OneChip h(mode(2));
  h.per_byte({0x00});
  // CONFIG 0x2E88: the host sees the latch before each byte, then bits 7..1.
  EXPECT_EQ(h.per_byte({0x38, 0x00, 0x00}), (Bytes{0x00, 0x17, 0x44}));
}

TEST(WireModes, Mode1ShiftsMosiByOneBitSoTheChipDecodesAnotherCommand) {
  // The chip receives the idle 0 and bits 7..1: GetStatus 0xD0 arrives as 0x68 = GoTo.
  OneChip h(mode(1));
  h.per_byte({0xD0});
  EXPECT_TRUE(h.chain.chip(0).collecting_arguments());
  EXPECT_EQ(h.chain.chip(0).collecting_command(), Command::GoTo_DIR);
}

TEST(WireModes, LsbFirstBytesArriveBitReversed) {
  // A host sending 0x1C least significant bit first puts 0x38 (GetParam(CONFIG)) on the wire,
  // and reads the answer bytes 0x2E 0x88 reversed.
  OneChip h(mode(3, true));
  EXPECT_EQ(h.per_byte({reverse_bits(0x38), 0x00, 0x00}), (Bytes{0x00, reverse_bits(0x2E), reverse_bits(0x88)}));
}

TEST(WireModes, InAChainTheStaleBitShowsOnlyInTheFirstByteOfEachFrame) {
  // Three chips polled with GetStatus in mode 0: each chip's answer goes down the chain with its
  // top bit replaced by that chip's latch (the top bit of 0xD0: 1); later bytes are intact.
  Chain chain(3);
  auto frame = [&](Bytes tx) {
    Bytes rx(tx.size());
    chain.frame(tx, rx, mode(0));
    chain.advance_to(chain.now() + 20);
    return rx;
  };
  frame({0xD0, 0xD0, 0xD0});
  EXPECT_EQ(frame({0x00, 0x00, 0x00}), (Bytes{0xFC, 0xFC, 0xFC}));  // 0x7C with the latch's 1
  EXPECT_EQ(frame({0x00, 0x00, 0x00}), (Bytes{0x03, 0x03, 0x03}));  // latches: the top bit of the NOPs
}

TEST(WireModes, ADeselectShorterThanTDisCSLeavesTheReceivedByteToBeClockedOut) {
  Chain chain(1);
  auto frame = [&](std::uint8_t b, Tick gap) {
    std::uint8_t in = 0;
    chain.advance_to(chain.now() + gap);
    chain.frame(std::span<const std::uint8_t>(&b, 1), std::span<std::uint8_t>(&in, 1), mode(3));
    return in;
  };
  frame(0x38, 0);
  EXPECT_EQ(frame(0x00, 3), 0x38);  // 750 ns: the answer was not loaded; the opcode echoes
  EXPECT_EQ(frame(0x00, 4), 0x88);  // the answer's first byte was used up by the missed load
  frame(0x38, 4);
  EXPECT_EQ(frame(0x00, 4), 0x2E);  // 1 µs: fine
}

// ---------------------------------------------------------------- the oracle, and mode 3

struct Rng {
  std::mt19937_64 g;
  explicit Rng(std::uint64_t seed) : g(seed) {}
  std::uint64_t below(std::uint64_t n) { return std::uniform_int_distribution<std::uint64_t>(0, n - 1)(g); }
  bool chance(unsigned percent) { return below(100) < percent; }
};

/// Bytes a driver would send, and some it would not.
std::uint8_t some_byte(Rng& r) {
  static constexpr std::uint8_t kUseful[] = {0x00, 0x00, 0x00, 0xD0, 0x38, 0x39, 0x36, 0x21, 0x24, 0x29, 0x16,
                                             0x05, 0x07, 0x0A, 0x40, 0x41, 0x50, 0x51, 0x60, 0x68, 0xB0, 0xB8,
                                             0xA0, 0xA8, 0xD8, 0x70, 0x78, 0x58, 0x82, 0x92, 0xEB, 0xC0};
  if (r.chance(30)) return static_cast<std::uint8_t>(r.below(256));
  return kUseful[r.below(sizeof kUseful)];
}

std::vector<Chip> some_chips(std::size_t n, Rng& r) {
  std::vector<Chip> chips;
  for (std::size_t i = 0; i < n; ++i) chips.emplace_back(r.chance(30) ? l6480() : l6470());
  return chips;
}

void expect_same_chips(Chain& chain, EdgeChain& edges, const std::string& where) {
  for (std::size_t i = 0; i < chain.size(); ++i) {
    ASSERT_EQ(chain.shift_register(i), edges.reg(i)) << where << " chip " << i << " register";
    ASSERT_EQ(chain.sdo_latch(i), edges.latch(i)) << where << " chip " << i << " latch";
    edges.chip(i).advance_to(chain.now());
    ASSERT_EQ(chain.chip(i).dump(), edges.chip(i).dump()) << where << " chip " << i;
    ASSERT_EQ(chain.chip(i).collecting_arguments(), edges.chip(i).collecting_arguments()) << where << " chip " << i;
  }
}

TEST(WireOracle, EveryModeBitOrderAndFramingMatchesTheEdgeByEdgeModel) {
  for (std::uint64_t seed = 1; seed <= 60; ++seed) {
    Rng r(seed);
    const std::size_t n = 1 + r.below(5);
    std::vector<Chip> chips = some_chips(n, r);
    Chain chain(chips);
    EdgeChain edges(chips);
    Tick t = 0;
    WireSettings w = mode(static_cast<std::uint8_t>(r.below(4)), r.chance(20));
    for (int f = 0; f < 150; ++f) {
      if (r.chance(25)) w = mode(static_cast<std::uint8_t>(r.below(4)), r.chance(20));
      // The gap before the frame: sometimes shorter than t_disCS.
      static constexpr Tick kGaps[] = {0, 1, 2, 3, 4, 5, 40, 4000, 400000};
      t += kGaps[r.below(std::size(kGaps))];
      if (r.chance(3)) {  // STBY\RST pulses between frames
        const std::size_t k = r.below(n);
        const bool level = !chain.chip(k).spi_enabled();
        chain.chip(k).set_stby_rst_pin(level);
        edges.chip(k).advance_to(chain.now());
        edges.chip(k).set_stby_rst_pin(level);
      }
      chain.advance_to(t);
      edges.advance_to(t);
      chain.select_wire();
      edges.select();
      const std::size_t len = r.chance(70) ? n : r.below(2 * n + 2);
      const std::string where = "seed " + std::to_string(seed) + " frame " + std::to_string(f);
      for (std::size_t b = 0; b < len;) {
        // Transfers of a few bytes; now and then the settings change inside a frame.
        const std::size_t run = std::min<std::size_t>(len - b, 1 + r.below(3));
        if (r.chance(5)) w = mode(static_cast<std::uint8_t>(r.below(4)), r.chance(20));
        Bytes tx(run), rx(run);
        for (auto& x : tx) x = some_byte(r);
        t += 7 * run;
        chain.advance_to(t);
        edges.advance_to(t);
        chain.exchange_wire(tx, rx, w);
        for (std::size_t i = 0; i < run; ++i)
          ASSERT_EQ(rx[i], edges.byte(tx[i], w)) << where << " byte " << b + i << " mode " << int(w.mode) << " lsb " << w.lsb_first;
        b += run;
      }
      chain.deselect_wire();
      edges.deselect();
      expect_same_chips(chain, edges, where);
    }
  }
}

TEST(WireOracle, Mode3OnTheBitLevelFaceEqualsTheBytePath) {
  // The same random stream, framing and timing into two chains: one through exchange_wire in
  // mode 3, one through the plain byte path (exchange), and the edge-level model; CS high for at
  // least t_disCS between frames (a byte-path host knows no shorter deselect).
  for (std::uint64_t seed = 100; seed < 140; ++seed) {
    Rng r(seed);
    const std::size_t n = 1 + r.below(5);
    std::vector<Chip> chips = some_chips(n, r);
    Chain wire(chips), plain(chips);
    EdgeChain edges(chips);
    Tick t = 0;
    for (int f = 0; f < 200; ++f) {
      t += 4 + r.below(3) * 2000;
      wire.advance_to(t);
      plain.advance_to(t);
      edges.advance_to(t);
      wire.select_wire();
      plain.select();
      edges.select();
      const std::size_t len = r.chance(70) ? n : r.below(3 * n + 1);
      const std::string where = "seed " + std::to_string(seed) + " frame " + std::to_string(f);
      for (std::size_t b = 0; b < len;) {
        const std::size_t run = std::min<std::size_t>(len - b, 1 + r.below(2 * n));
        Bytes tx(run), a(run), c(run);
        for (auto& x : tx) x = some_byte(r);
        t += 7 * run;
        wire.advance_to(t);
        plain.advance_to(t);
        edges.advance_to(t);
        wire.exchange_wire(tx, a, mode(3));
        plain.exchange(tx, c);
        ASSERT_EQ(a, c) << where;
        for (std::size_t i = 0; i < run; ++i) ASSERT_EQ(a[i], edges.byte(tx[i], mode(3))) << where;
        b += run;
      }
      wire.deselect_wire();
      plain.deselect();
      edges.deselect();
      for (std::size_t i = 0; i < n; ++i) {
        ASSERT_EQ(wire.shift_register(i), plain.shift_register(i)) << where;
        ASSERT_EQ(wire.chip(i).dump(), plain.chip(i).dump()) << where;
      }
      expect_same_chips(wire, edges, where);
    }
  }
}

}  // namespace
}  // namespace l6470emu
