// A spidev message clocked a piece at a time (the daemon's way with a long message whose caller
// may die) reaches the chips exactly as when clocked at once: the same CS edges at the same ticks,
// the same bytes inside each frame, the same MISO; and a message given up midway leaves CS high at once.
#include <gtest/gtest.h>

#include <random>
#include <string>
#include <vector>

#include "core/variant.hpp"
#include "daisychain/chain.hpp"
#include "linux/spidev_rules.hpp"

namespace l6470emu {
namespace {

/// A real chain whose CS edges (with their ticks) and bytes are written down.
class Logged final : public SpiDevice {
 public:
  explicit Logged(std::size_t chips) : chain_(chips) {}
  void select() override {
    log_ += "S@" + std::to_string(chain_.now()) + " ";
    chain_.select();
  }
  std::uint8_t exchange(std::uint8_t mosi) override {
    const std::uint8_t miso = chain_.exchange(mosi);
    // Inside a frame a byte carries no time of its own (the chips decode at CS's rising edge, and
    // run_message passes a block's time before its bytes), so only the CS edges are timed.
    log_ += std::to_string(mosi) + ">" + std::to_string(miso) + " ";
    return miso;
  }
  void deselect() override {
    log_ += "D@" + std::to_string(chain_.now()) + " ";
    chain_.deselect();
  }
  bool selected() const override { return chain_.selected(); }
  Tick now() const override { return chain_.now(); }
  void advance_to(Tick tick) override { chain_.advance_to(tick); }
  const std::string& log() const { return log_; }

 private:
  Chain chain_;
  std::string log_;
};

struct Message {
  std::vector<spi_ioc_transfer> xfers;
  std::vector<std::uint8_t> tx;
  std::size_t rx_bytes = 0;
};

Message random_message(std::mt19937& rng) {
  Message m;
  const int n = std::uniform_int_distribution<int>(1, 6)(rng);
  for (int i = 0; i < n; ++i) {
    spi_ioc_transfer x{};
    const int kind = std::uniform_int_distribution<int>(0, 9)(rng);
    x.len = static_cast<std::uint32_t>(kind == 0 ? std::uniform_int_distribution<int>(4096, 20000)(rng)
                                                 : std::uniform_int_distribution<int>(1, 12)(rng));
    x.tx_buf = kind == 0 || kind == 1 ? 0 : 1;  // bufferless (0) or rx-only (1) now and then
    x.rx_buf = kind == 0 || kind == 2 ? 0 : 1;
    x.cs_change = std::uniform_int_distribution<int>(0, 2)(rng) == 0;
    x.delay_usecs = static_cast<std::uint16_t>(std::uniform_int_distribution<int>(0, 3)(rng) == 0 ? 7 : 0);
    x.word_delay_usecs = static_cast<std::uint8_t>(std::uniform_int_distribution<int>(0, 4)(rng) == 0 ? 2 : 0);
    x.speed_hz = std::uniform_int_distribution<int>(0, 1)(rng) ? 0 : 1'000'000;
    if (x.tx_buf)
      for (std::uint32_t k = 0; k < x.len; ++k) m.tx.push_back(static_cast<std::uint8_t>(rng()));
    if (x.rx_buf) m.rx_bytes += x.len;
    m.xfers.push_back(x);
  }
  return m;
}

SpidevSettings settings() {
  SpidevSettings s;
  s.mode = SPI_MODE_3;
  s.max_speed_hz = s.speed_hz = 5'000'000;
  s.bufsiz = 1 << 20;
  return s;
}

TEST(SpidevWireMessage, ClockedInPiecesTheChipsSeeWhatTheySeeClockedAtOnce) {
  std::mt19937 rng(26);
  for (int round = 0; round < 300; ++round) {
    const Message m = random_message(rng);
    const SpidevSettings s = settings();
    ASSERT_GE(validate_spidev_message(s, m.xfers), 0);
    Logged whole(2), pieces(2);
    std::vector<std::uint8_t> rx_whole(m.rx_bytes), rx_pieces(m.rx_bytes);
    // Two messages each: the second starts from where the first left CS.
    for (int k = 0; k < 2; ++k) {
      run_spidev_message(whole, s, m.xfers, m.tx, rx_whole);
      SpidevWireMessage w;
      w.prepare(s, m.xfers, m.tx);
      const Tick budget = std::uniform_int_distribution<Tick>(1, 400)(rng);
      int calls = 0;
      while (!w.run(pieces, budget)) ASSERT_LT(++calls, 1'000'000);
      w.finish(rx_pieces);
      ASSERT_EQ(pieces.log(), whole.log()) << "round " << round << ", budget " << budget;
      ASSERT_EQ(rx_pieces, rx_whole) << "round " << round;
      ASSERT_EQ(pieces.now(), whole.now()) << "round " << round;
    }
  }
}

TEST(SpidevWireMessage, AMessageGivenUpMidwayRaisesCsAtOnceAndClocksNothingMore) {
  const SpidevSettings s = settings();
  spi_ioc_transfer x{};
  x.len = 1000;
  x.tx_buf = 1;
  std::vector<std::uint8_t> tx(1000, 0x00);  // NOPs
  SpidevWireMessage w;
  w.prepare(s, std::span<const spi_ioc_transfer>(&x, 1), tx);
  EXPECT_EQ(w.bus_ticks(), 1000 * transfer_ticks(1, 5'000'000) + ticks_from_us(10));
  Logged dev(1);
  EXPECT_FALSE(w.run(dev, 70));  // ten bytes at 7 ticks each
  EXPECT_TRUE(dev.selected());
  const Tick at = dev.now();
  EXPECT_EQ(at, 70u);
  w.abandon(dev);
  EXPECT_FALSE(dev.selected());
  EXPECT_EQ(dev.now(), at);
  EXPECT_TRUE(w.run(dev, kNever));  // nothing left
  EXPECT_EQ(dev.now(), at);
}

}  // namespace
}  // namespace l6470emu
