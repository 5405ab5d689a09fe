// The OS-free Board on its own, as a single-threaded firmware front would use it in virtual
// time: bytes clocked one at a time under a chip select the front drives, a watched BUSY edge
// at its exact tick, two chains sharing one bus. Nothing from linux/ is linked.
#include <gtest/gtest.h>

#include <array>
#include <vector>

#include "board/board.hpp"
#include "spi/message.hpp"
#include "support/test_support.hpp"

namespace l6470emu::test {
namespace {

/// Virtual time reads no host clock after construction; this one never moves.
class StillHostClock final : public HostClock {
 public:
  std::int64_t monotonic_ns() override { return 0; }
  std::int64_t realtime_ns() override { return 0; }
  void sleep_until(std::int64_t) override {}
};

BoardConfig config_of(const std::string& text) {
  ParseResult p = parse_board_config(text, "test");
  EXPECT_TRUE(p.config) << p.error.message;
  return *p.config;
}

struct VirtualBoard {
  explicit VirtualBoard(const std::string& description)
      : board(config_of(description), [this](std::string_view line) { log.emplace_back(line); }, clock) {}
  StillHostClock clock;
  std::vector<std::string> log;
  Board board;
};

/// A front in the Arduino style: CS is a pin it writes, bytes go one SPI.transfer at a time,
/// and the host's time is the bus time its calls take.
struct ByteAtATimeFront {
  Board& board;
  std::size_t chain;
  std::uint32_t speed_hz = 5'000'000;

  void chip_select(bool low) {
    SpiDevice& dev = board.begin_transfer(chain);
    if (low)
      dev.select();
    else
      dev.deselect();
    board.advance_to(board.end_transfer(chain));
  }
  std::uint8_t transfer(std::uint8_t mosi) {
    SpiDevice& dev = board.begin_transfer(chain);
    dev.advance_to(dev.now() + transfer_ticks(1, speed_hz));  // the byte's bus time, as run_message counts it
    const std::uint8_t miso = dev.exchange(mosi);
    board.advance_to(board.end_transfer(chain));
    return miso;
  }
};

TEST(BoardSpi, AFrontDrivingItsOwnChipSelectClocksOneByteAtATimeAndEachByteTakesItsBusTime) {
  VirtualBoard v("bus=0 cs=0 chips=L6470; time=virtual");
  ByteAtATimeFront front{v.board, 0};
  // GetParam(CONFIG) on a single chip: each byte is its own CS frame, as the chip needs.
  std::array<std::uint8_t, 3> miso{};
  const std::array<std::uint8_t, 3> mosi{0x38, 0x00, 0x00};
  for (std::size_t i = 0; i < mosi.size(); ++i) {
    front.chip_select(true);
    miso[i] = front.transfer(mosi[i]);
    front.chip_select(false);
  }
  EXPECT_EQ(miso[1], 0x2E);
  EXPECT_EQ(miso[2], 0x88);  // CONFIG's reset value
  // 8 bits at 5 MHz are 1.6 µs: 7 whole ticks a byte; the chip-select edges take no bus time.
  EXPECT_EQ(transfer_ticks(1, 5'000'000), Tick{7});
  EXPECT_EQ(v.board.time().now(), Tick{3 * 7});
  EXPECT_EQ(v.board.now(0), Tick{3 * 7});
  EXPECT_FALSE(v.board.chain(0).selected());
}

TEST(BoardEdges, AWatchedBusyFallsWhenTheMoveIsDecodedAndRisesAtTheExactTickItEnds) {
  VirtualBoard v("bus=0 cs=0 chips=L6470; time=virtual");
  std::vector<PinEdge> edges;
  v.board.set_edge_sink([&](const PinEdge& e) { edges.push_back(e); });
  v.board.watch_pin(0, 0, Pin::BUSY, true);
  ASSERT_TRUE(v.board.pin_level(0, 0, Pin::BUSY));

  // Move(forward, 3200): four one-byte frames in one message.
  const std::uint32_t n_step = 3200;
  const std::array<std::uint8_t, 4> bytes{0x41, 0x00, 0x0C, 0x80};
  std::vector<SpiTransfer> frames;
  for (const std::uint8_t& b : bytes) {
    SpiTransfer t;
    t.tx = std::span<const std::uint8_t>(&b, 1);
    t.len = 1;
    t.cs_change = &b != &bytes.back();  // CS rises after every byte (the last: at the message's end)
    frames.push_back(t);
  }
  BusTiming timing;
  const Tick end = v.board.transfer(0, frames, timing);
  // Four bytes of 7 ticks and a CS-high time after each: the last CS rise (the decode) is 4 ticks before the end.
  const Tick decoded = 4 * 7 + 3 * timing.cs_high_ticks;
  ASSERT_EQ(end, decoded + timing.cs_high_ticks);
  ASSERT_EQ(edges.size(), 1u);
  EXPECT_EQ(edges[0].pin, Pin::BUSY);
  EXPECT_FALSE(edges[0].level);
  EXPECT_EQ(edges[0].tick, end);  // reported when the bus use ends

  // Time passes in virtual time: BUSY rises by itself, reported at the tick the profile ends.
  const Tick rise = decoded + move_profile_ticks(true, n_step);
  EXPECT_EQ(v.board.next_edge_tick(), rise);
  ASSERT_TRUE(v.board.advance_to(rise + ticks_from_ms(100)));
  ASSERT_EQ(edges.size(), 2u);
  EXPECT_TRUE(edges[1].level);
  EXPECT_EQ(edges[1].tick, rise);
  EXPECT_EQ(edges[1].chain, 0u);
  EXPECT_EQ(edges[1].chip, 0u);
  EXPECT_EQ(v.board.next_edge_tick(), kNever);
}

TEST(BoardEdges, AWatchedInputReportsTheWorldsDriveAndAnUnwatchedPinReportsNothing) {
  VirtualBoard v("bus=0 cs=0 chips=2xL6470; time=virtual");
  std::vector<PinEdge> edges;
  v.board.set_edge_sink([&](const PinEdge& e) { edges.push_back(e); });
  v.board.watch_pin(0, 1, Pin::SW, true);
  ASSERT_TRUE(v.board.advance(1000));
  ASSERT_TRUE(v.board.drive_pin(0, 1, Pin::SW, false));
  ASSERT_TRUE(v.board.drive_pin(0, 0, Pin::SW, false));  // not watched
  EXPECT_FALSE(v.board.drive_pin(0, 0, Pin::BUSY, false));  // the chip drives BUSY
  ASSERT_EQ(edges.size(), 1u);
  EXPECT_EQ(edges[0].chip, 1u);
  EXPECT_EQ(edges[0].pin, Pin::SW);
  EXPECT_FALSE(edges[0].level);
  EXPECT_EQ(edges[0].tick, Tick{1000});
  EXPECT_FALSE(v.board.pin_level(0, 1, Pin::SW));
}

TEST(BoardSpi, TwoChainsOnOneBusTakeTurnsAndAChipSelectLeftLowIsReleasedWhileAnotherBusRunsAtOnce) {
  VirtualBoard v("bus=0 cs=0 chips=L6470; bus=0 cs=1 chips=L6470; bus=1 cs=0 chips=L6470; time=virtual");
  const std::array<std::uint8_t, 4> nops{};
  SpiTransfer t;
  t.tx = nops;
  t.len = nops.size();
  t.cs_change = true;  // the last transfer keeps CS low after the message
  const Tick bytes = 4 * transfer_ticks(1, 5'000'000);

  // Nobody waits between the calls: each use starts when its bus is free, not at the board's time.
  const Tick first = v.board.transfer(0, std::span(&t, 1));
  EXPECT_EQ(first, bytes);
  EXPECT_TRUE(v.board.chain(0).selected());
  const Tick second = v.board.transfer(1, std::span(&t, 1));
  EXPECT_EQ(second, first + bytes);
  EXPECT_FALSE(v.board.chain(0).selected()) << "one controller per bus: chain 0 is deselected first";
  const Tick other_bus = v.board.transfer(2, std::span(&t, 1));
  EXPECT_EQ(other_bus, bytes);
  EXPECT_TRUE(v.board.chain(1).selected());
  EXPECT_EQ(v.board.time().now(), Tick{0});
}


TEST(BoardPinChipSelect, BytesReachOnlyTheChainsWhoseChipSelectIsLowAndTakeTheirBusTime) {
  VirtualBoard v("bus=0 cs=0 chips=L6470; bus=0 cs=1 chips=L6480; time=virtual");
  const std::array<std::size_t, 2> bus{0, 1};
  BusSettings settings;
  settings.speed_hz = 4'000'000;  // 2 us a byte: 8 ticks
  auto get_config = [&](std::size_t chain, std::uint8_t opcode) {
    std::array<std::uint8_t, 3> mosi{opcode, 0, 0}, miso{};
    for (std::size_t i = 0; i < 3; ++i) {
      v.board.drive_chip_select(chain, true);
      v.board.advance_to(v.board.clock_bytes(bus, std::span(&mosi[i], 1), std::span(&miso[i], 1), settings));
      v.board.drive_chip_select(chain, false);
      v.board.advance(4);  // CS high for 1 us
    }
    return miso[1] << 8 | miso[2];
  };
  EXPECT_EQ(get_config(0, 0x38), 0x2E88);  // GetParam(CONFIG) of the L6470 (0x18)
  EXPECT_EQ(get_config(1, 0x3A), 0x2C88);  // the L6480's CONFIG is at 0x1A
  EXPECT_EQ(v.board.time().now(), Tick{6 * (8 + 4)});
  // Nothing selected: the bytes take their time, MISO reads 0x00 and no chip sees them.
  std::array<std::uint8_t, 2> mosi{0xD0, 0xD0}, miso{0xAA, 0xAA};
  EXPECT_EQ(v.board.clock_bytes(bus, mosi, miso, settings), v.board.time().now() + 16);
  EXPECT_EQ(miso, (std::array<std::uint8_t, 2>{0, 0}));
  EXPECT_FALSE(v.board.chip_selected(0));
}

TEST(BoardPinChipSelect, LsbFirstReachesTheChipBitReversedAndTwoSelectedChainsShareMiso) {
  VirtualBoard v("bus=0 cs=0 chips=L6470; bus=0 cs=1 chips=L6470; time=virtual");
  const std::array<std::size_t, 2> bus{0, 1};
  BusSettings lsb;
  lsb.lsb_first = true;
  // 0x1C sent LSB first is 0x38 on the wire: GetParam(CONFIG). The answer comes back reversed too.
  std::array<std::uint8_t, 1> mosi{0x1C}, miso{};
  v.board.drive_chip_select(0, true);
  v.board.clock_bytes(bus, mosi, miso, lsb);
  v.board.drive_chip_select(0, false);
  std::array<std::uint8_t, 2> answer{};
  for (std::uint8_t& b : answer) {
    v.board.drive_chip_select(0, true);
    const std::uint8_t nop = 0;
    v.board.advance_to(v.board.clock_bytes(bus, std::span(&nop, 1), std::span(&b, 1), lsb));
    v.board.drive_chip_select(0, false);
  }
  EXPECT_EQ(answer, (std::array<std::uint8_t, 2>{0x74, 0x11}));  // 0x2E, 0x88 bit-reversed
  // Both chip selects low: both chains take the byte; MISO is what both drive together.
  v.board.drive_chip_select(0, true);
  v.board.drive_chip_select(1, true);
  std::array<std::uint8_t, 1> status{0xD0};
  v.board.advance_to(v.board.clock_bytes(bus, status, miso, BusSettings{}));
  v.board.drive_chip_select(0, false);
  v.board.drive_chip_select(1, false);
  EXPECT_EQ(v.board.chain(0).chip(0).peek(Reg::STATUS) & 0x0200, 0x0200) << "GetStatus cleared UVLO on chain 0";
  EXPECT_EQ(v.board.chain(1).chip(0).peek(Reg::STATUS) & 0x0200, 0x0200) << "and on chain 1";
}

TEST(BoardEdges, APredictedEdgeStaysExactWhileTimeMovesInSmallStepsAndANewCommandIsSeen) {
  VirtualBoard v("bus=0 cs=0 chips=L6470; time=virtual");
  std::vector<PinEdge> edges;
  v.board.set_edge_sink([&](const PinEdge& e) { edges.push_back(e); });
  v.board.watch_pin(0, 0, Pin::BUSY, true);
  auto frame = [&](std::uint8_t b) {
    v.board.drive_chip_select(0, true);
    std::uint8_t in = 0;
    v.board.advance_to(v.board.clock_bytes(std::array<std::size_t, 1>{0}, std::span(&b, 1), std::span(&in, 1), {}));
    v.board.drive_chip_select(0, false);
  };
  for (std::uint8_t b : {0x41, 0x00, 0x0C, 0x80}) frame(b);  // Move(FWD, 3200)
  const Tick decoded = v.board.time().now();
  ASSERT_EQ(edges.size(), 1u);
  const Tick rise = decoded + move_profile_ticks(true, 3200);
  EXPECT_EQ(v.board.next_edge_tick(), rise);
  while (v.board.time().now() < rise + 100) v.board.advance(997);  // steps that straddle the edge
  ASSERT_EQ(edges.size(), 2u);
  EXPECT_EQ(edges[1].tick, rise);
  // A new move invalidates the prediction: its own end is found.
  for (std::uint8_t b : {0x41, 0x00, 0x0C, 0x80}) frame(b);
  const Tick second = v.board.time().now() + move_profile_ticks(true, 3200);
  EXPECT_EQ(v.board.next_edge_tick(), second);
  v.board.advance_to(second + 1);
  ASSERT_EQ(edges.size(), 4u);
  EXPECT_EQ(edges[3].tick, second);
}

}  // namespace
}  // namespace l6470emu::test
