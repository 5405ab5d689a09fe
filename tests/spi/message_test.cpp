// spidev message semantics (spi/message.hpp; Linux spi_ioc_transfer rules): transfers of one
// message share CS unless cs_change says otherwise, cs_change on the last transfer keeps CS low,
// tx-only and rx-only transfers, and virtual time from speed_hz and delay_usecs.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "daisychain/chain.hpp"
#include "support/test_support.hpp"
#include "spi/message.hpp"

namespace l6470emu {
namespace {

using namespace test::status_bits;

using Bytes = std::vector<std::uint8_t>;


/// A transfer whose buffers live in the test: tx bytes and an rx buffer of the same length.
struct Xfer {
  Bytes tx;
  Bytes rx;
  bool has_tx = true;
  bool has_rx = true;
  std::uint32_t len = 0;
  std::uint32_t speed_hz = 0;
  std::uint16_t delay_usecs = 0;
  bool cs_change = false;
};

Xfer tx_rx(Bytes tx, bool cs_change = false) {
  Xfer x;
  x.len = static_cast<std::uint32_t>(tx.size());
  x.tx = std::move(tx);
  x.rx.assign(x.len, 0xEE);
  x.cs_change = cs_change;
  return x;
}

Xfer tx_only(Bytes tx, bool cs_change = false) {
  Xfer x = tx_rx(std::move(tx), cs_change);
  x.has_rx = false;
  return x;
}

Xfer rx_only(std::uint32_t len, bool cs_change = false) {
  Xfer x;
  x.len = len;
  x.rx.assign(len, 0xEE);
  x.has_tx = false;
  x.cs_change = cs_change;
  return x;
}

/// Runs one message built from `xfers`; their rx buffers receive the MISO bytes.
void run(SpiDevice& dev, std::vector<Xfer>& xfers, const BusTiming& timing = {}) {
  std::vector<SpiTransfer> t;
  for (auto& x : xfers) {
    SpiTransfer s;
    if (x.has_tx) s.tx = x.tx;
    if (x.has_rx) s.rx = x.rx;
    s.len = x.len;
    s.speed_hz = x.speed_hz;
    s.delay_usecs = x.delay_usecs;
    s.cs_change = x.cs_change;
    t.push_back(s);
  }
  run_message(dev, t, timing);
}

// ---------------------------------------------------------------- CS handling

TEST(RunMessage, PutsAllTransfersWithoutCsChangeInOneCsFrame) {
  Chain chain(1);
  std::vector<Xfer> m{tx_rx({0xD0}), tx_rx({0x00})};
  run(chain, m);
  EXPECT_EQ(m[0].rx, Bytes{0x00});
  EXPECT_EQ(m[1].rx, Bytes{0xD0}) << "CS stayed low: the chip echoes the first byte";
  EXPECT_FALSE(chain.selected());
  // Only the NOP was decoded: no GetStatus answer follows.
  std::vector<Xfer> next{tx_rx({0x00})};
  run(chain, next);
  EXPECT_EQ(next[0].rx, Bytes{0x00});
}

TEST(RunMessage, CsChangeInTheMiddleRaisesCsAfterThatTransfer) {
  Chain chain(1);
  std::vector<Xfer> m{tx_rx({0xD0}, true), tx_rx({0x00}, true), tx_rx({0x00})};
  run(chain, m);
  EXPECT_EQ(m[0].rx, Bytes{0x00});
  EXPECT_EQ(m[1].rx, Bytes{0x7C});
  EXPECT_EQ(m[2].rx, Bytes{0x03});
  EXPECT_FALSE(chain.selected());
}

TEST(RunMessage, OneTransferPerByteWithCsChangeReadsAGetParamAnswer) {
  Chain chain(1);
  std::vector<Xfer> m{tx_rx({0x38}, true), tx_rx({0x00}, true), tx_rx({0x00})};  // GetParam(CONFIG)
  run(chain, m);
  EXPECT_EQ((Bytes{m[0].rx[0], m[1].rx[0], m[2].rx[0]}), (Bytes{0x00, 0x2E, 0x88}));
}

TEST(RunMessage, CsChangeOnTheLastTransferKeepsCsLowAfterTheMessage) {
  Chain chain(1);
  std::vector<Xfer> first{tx_rx({0xEB}, true)};
  run(chain, first);
  EXPECT_TRUE(chain.selected());
  EXPECT_EQ(chain.chip(0).status() & kWrongCmd, 0) << "nothing decoded while CS is low";
  // The next message continues the same CS frame; a zero-length transfer just ends it.
  std::vector<Xfer> second{tx_rx({})};
  run(chain, second);
  EXPECT_FALSE(chain.selected());
  EXPECT_NE(chain.chip(0).status() & kWrongCmd, 0) << "0xEB decoded at the CS rise";
}

TEST(RunMessage, AFrameContinuedByTheNextMessageDecodesOnlyItsLastByte) {
  Chain chain(1);
  std::vector<Xfer> first{tx_rx({0xEB}, true)};
  run(chain, first);
  std::vector<Xfer> second{tx_rx({0x00})};
  run(chain, second);
  EXPECT_EQ(second[0].rx, Bytes{0xEB}) << "echo: still the same CS frame";
  EXPECT_EQ(chain.chip(0).status() & kWrongCmd, 0);
}

TEST(RunMessage, TxOnlyTransfersSendTheirBytesAndDiscardMiso) {
  Chain chain(1);
  std::vector<Xfer> m{tx_only({0x0A}, true), tx_only({0x77})};
  run(chain, m);
  EXPECT_EQ(chain.chip(0).peek(Reg::KVAL_RUN), 0x77u);
  EXPECT_EQ(m[0].rx, Bytes{0xEE}) << "rx buffer untouched";
}

TEST(RunMessage, RxOnlyTransfersSendZerosAndReceiveTheAnswer) {
  Chain chain(1);
  std::vector<Xfer> cmd{tx_only({0xD0})};
  run(chain, cmd);
  std::vector<Xfer> m{rx_only(1, true), rx_only(1)};
  run(chain, m);
  EXPECT_EQ(m[0].rx, Bytes{0x7C});
  EXPECT_EQ(m[1].rx, Bytes{0x03});
  EXPECT_EQ(chain.chip(0).status() & kWrongCmd, 0);
  EXPECT_EQ(chain.chip(0).peek(Reg::KVAL_RUN), 0x29u);
}

TEST(RunMessage, AnRxOnlyTransferOfTwoBytesIsOneFrameAndEchoesItsOwnZero) {
  Chain chain(1);
  std::vector<Xfer> cmd{tx_only({0xD0})};
  run(chain, cmd);
  std::vector<Xfer> m{rx_only(2)};
  run(chain, m);
  EXPECT_EQ(m[0].rx, (Bytes{0x7C, 0x00}));
  std::vector<Xfer> rest{rx_only(1)};
  run(chain, rest);
  EXPECT_EQ(rest[0].rx, Bytes{0x03});
}

TEST(RunMessage, ReachesEveryChipOfAChainWithOneFramePerTransfer) {
  Chain chain(3);
  std::vector<Xfer> m{tx_rx({0xD0, 0x00, 0xD0}, true), tx_rx({0, 0, 0}, true), tx_rx({0, 0, 0})};
  run(chain, m);
  EXPECT_EQ(m[1].rx, (Bytes{0x7C, 0x00, 0x7C}));
  EXPECT_EQ(m[2].rx, (Bytes{0x03, 0x00, 0x03}));
}

// ---------------------------------------------------------------- virtual time

TEST(TransferTicks, IsTheClockingTimeRoundedUpToWholeTicks) {
  EXPECT_EQ(transfer_ticks(0, 5'000'000), 0u);
  EXPECT_EQ(transfer_ticks(1, 4'000'000), 8u);   // 2 µs
  EXPECT_EQ(transfer_ticks(1, 1'000'000), 32u);  // 8 µs
  EXPECT_EQ(transfer_ticks(4, 1'000'000), 128u);
  EXPECT_EQ(transfer_ticks(1, 5'000'000), 7u);   // 1.6 µs = 6.4 ticks
  EXPECT_EQ(transfer_ticks(5, 5'000'000), 32u);  // 8 µs exactly
  EXPECT_EQ(transfer_ticks(1, 32'000'000), 1u);
}

TEST(TransferTicks, IsAtLeastOneTickPerByte) {
  EXPECT_EQ(transfer_ticks(10, 100'000'000), 10u);
  EXPECT_EQ(transfer_ticks(1, 1'000'000'000), 1u);
}

TEST(RunMessage, AdvancesTimeByTheBytesAtTheDefaultSpeedAndTheCsHighTime) {
  Chain chain(1);
  BusTiming timing;
  timing.default_speed_hz = 4'000'000;  // 8 ticks per byte
  timing.cs_high_ticks = 4;
  std::vector<Xfer> m{tx_rx({0x00, 0x00, 0x00})};
  run(chain, m, timing);
  EXPECT_EQ(chain.now(), 3u * 8 + 4);
}

TEST(RunMessage, UsesTheTransfersOwnSpeed) {
  Chain chain(1);
  BusTiming timing;
  timing.default_speed_hz = 4'000'000;
  timing.cs_high_ticks = 4;
  std::vector<Xfer> m{tx_rx({0x00, 0x00})};
  m[0].speed_hz = 1'000'000;  // 32 ticks per byte
  run(chain, m, timing);
  EXPECT_EQ(chain.now(), 2u * 32 + 4);
}

TEST(RunMessage, DelayUsecsAddsTimeBeforeCsRises) {
  Chain chain(1);
  BusTiming timing;
  timing.default_speed_hz = 4'000'000;
  timing.cs_high_ticks = 4;
  std::vector<Tick> seen;
  chain.chip(0).set_diagnostic_sink([&](const Diagnostic& d) { seen.push_back(d.tick); });
  std::vector<Xfer> m{tx_rx({0xEB})};
  m[0].delay_usecs = 10;
  run(chain, m, timing);
  EXPECT_EQ(chain.now(), 8u + 40 + 4);
  ASSERT_EQ(seen.size(), 1u);
  EXPECT_EQ(seen[0], 8u + 40) << "the byte is decoded at the CS rise, after the delay";
}

TEST(RunMessage, CsChangeInTheMiddleAlsoSpendsTheCsHighTime) {
  Chain chain(1);
  BusTiming timing;
  timing.default_speed_hz = 4'000'000;
  timing.cs_high_ticks = 4;
  std::vector<Xfer> m{tx_rx({0x00}, true), tx_rx({0x00}, true), tx_rx({0x00})};
  run(chain, m, timing);
  EXPECT_EQ(chain.now(), 3u * (8 + 4));
}

TEST(RunMessage, KeepingCsLowSpendsNoCsHighTime) {
  Chain chain(1);
  BusTiming timing;
  timing.default_speed_hz = 4'000'000;
  timing.cs_high_ticks = 4;
  std::vector<Xfer> m{tx_rx({0x00}, true)};
  run(chain, m, timing);
  EXPECT_EQ(chain.now(), 8u);
  EXPECT_TRUE(chain.selected());
}

TEST(RunMessage, LetsTheMotorMoveWhileTheBytesAreClocked) {
  Chain chain(1);
  BusTiming timing;
  timing.default_speed_hz = 4'000'000;
  // Run forward with infinite acceleration: ACC = 0xFFF, then Run at MAX_SPEED.
  std::vector<Xfer> setup{tx_rx({0x05}, true), tx_rx({0x0F}, true), tx_rx({0xFF}, true),
                          tx_rx({0x51}, true), tx_rx({0x0F}, true), tx_rx({0xFF}, true), tx_rx({0xFF})};
  run(chain, setup, timing);
  const auto before = chain.chip(0).position();
  std::vector<Xfer> wait{tx_rx({0x00})};
  wait[0].delay_usecs = 10'000;  // 10 ms at ≈992 step/s, 1/128 microsteps: ≈1270 microsteps
  run(chain, wait, timing);
  EXPECT_NEAR(chain.chip(0).position() - before, 1270, 5);
}

}  // namespace
}  // namespace l6470emu
