// The OS-free Board on its own, as a single-threaded firmware front would use it in virtual
// time: bytes clocked one at a time under a chip select the front drives, a watched BUSY edge
// at its exact tick, two chains sharing one bus, an L6474 stepped by its STCK and DIR pins.
// Nothing from linux/ is linked.
#include <gtest/gtest.h>

#include <array>
#include <string>
#include <vector>

#include "board/board.hpp"
#include "board/coverage.hpp"
#include "daisychain/host.hpp"
#include "spi/message.hpp"
#include "support/test_support.hpp"
#include "support/board_config_support.hpp"

namespace l6470emu::test {
namespace {

/// Virtual time reads no host clock after construction; this one never moves.
class StillHostClock final : public HostClock {
 public:
  std::int64_t monotonic_ns() override { return 0; }
  std::int64_t realtime_ns() override { return 0; }
  void sleep_until(std::int64_t) override {}
};

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
    v.board.advance(4);  // the host keeps CS high for 1 µs (t_disCS is 800 ns)
  }
  EXPECT_EQ(miso[1], 0x2E);
  EXPECT_EQ(miso[2], 0x88);  // CONFIG's reset value
  // 8 bits at 5 MHz are 1.6 µs: 7 whole ticks a byte; the chip-select edges take no bus time.
  EXPECT_EQ(transfer_ticks(1, 5'000'000), Tick{7});
  EXPECT_EQ(v.board.time().now(), Tick{3 * (7 + 4)});
  EXPECT_EQ(v.board.now(0), Tick{3 * (7 + 4)});
  EXPECT_TRUE(v.log.empty()) << v.log.front();
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
  // CS stays high 1 us between frames (t_disCS is 800 ns: sooner, the chip has not loaded its answer).
  std::array<std::uint8_t, 1> mosi{0x1C}, miso{};
  v.board.drive_chip_select(0, true);
  v.board.advance_to(v.board.clock_bytes(bus, mosi, miso, lsb));
  v.board.drive_chip_select(0, false);
  std::array<std::uint8_t, 2> answer{};
  for (std::uint8_t& b : answer) {
    v.board.advance_to(v.board.time().now() + ticks_from_us(1));
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

// ---------------------------------------------------------------- the L6474 on a board

// Its DIR pin in the board description (dir_pin=) and the pin API, a description giving a chip a
// pin its part lacks refused with one line, STCK and DIR driven through the board moving
// ABS_POS exactly, and the coverage points it has and has not.

std::string error_of(const std::string& text) {
  const ParseResult p = parse_board_config(text, "T");
  EXPECT_FALSE(p.config) << text;
  return p.error.message;
}

McuPin arduino(unsigned n) { return McuPin{McuPin::Kind::arduino, static_cast<std::uint16_t>(n)}; }

void pulses(Board& board, std::size_t chip, int n) {
  for (int i = 0; i < n; ++i) {
    ASSERT_TRUE(board.drive_pin(0, chip, Pin::STCK, true));
    ASSERT_TRUE(board.drive_pin(0, chip, Pin::STCK, false));
  }
}

std::int32_t position(const Board& board, std::size_t chip) { return board.chain(0).peek_chip(chip).position(); }

TEST(L6474Board, TheXNucleoIhm01a1WiringIsADescriptionWithDirPin) {
  const BoardConfig c = config_of("chips=L6474 cs_pin=D10 flag_pin=D2 dir_pin=D7 stby_rst_pin=D8 stck_pin=D9");
  const ChainPins& p = c.chains.at(0).pins;
  EXPECT_EQ(chip_mcu_pin(p, Pin::DIR, 0), arduino(7));
  EXPECT_EQ(chip_mcu_pin(p, Pin::STCK, 0), arduino(9));
  EXPECT_EQ(std::string(pin_key(Pin::DIR)), "dir_pin");
  EXPECT_NE(describe_board_config(c).find("dir_pin=7"), std::string::npos) << describe_board_config(c);
  // One DIR line for two chips, or one each; "dir=" is taken for dir_pin= in the suggestion.
  EXPECT_EQ(chip_mcu_pin(config_of("chips=2xL6474 dir_pin=D7").chains[0].pins, Pin::DIR, 1), arduino(7));
  EXPECT_NE(error_of("chips=L6474 dir=D7").find("did you mean dir_pin=?"), std::string::npos);
  EXPECT_EQ(chip_mcu_pin(config_of("chips=2xL6474 dir_pin=D7,D4").chains[0].pins, Pin::DIR, 1), arduino(4));
}

TEST(L6474Board, APinForAChipThatLacksItIsRefusedWithOneLineNamingIt) {
  EXPECT_EQ(error_of("chips=2xL6470 dir_pin=D7"),
            "l6470emu: config T, clause 1: dir_pin= names a pin for this chain, but none of its chips has a DIR pin "
            "(a pin of L6474)");
  EXPECT_EQ(error_of("chips=L6474 sw_pin=D5"),
            "l6470emu: config T, clause 1: sw_pin= names a pin for this chain, but none of its chips has a SW pin "
            "(a pin of L6470, L6472, L6480, L6482, powerSTEP01)");
  EXPECT_EQ(error_of("chips=L6470,L6474 dir_pin=D7,D4"),
            "l6470emu: config T, clause 1: dir_pin= gives chip 0 a pin, but it is an L6470, which has no DIR pin "
            "(a pin of L6474): write '-' for it");
  EXPECT_EQ(error_of("chips=L6474,L6470 busy_pin=D3,D4"),
            "l6470emu: config T, clause 1: busy_pin= gives chip 0 a pin, but it is an L6474, which has no BUSY pin "
            "(a pin of L6470, L6472, L6480, L6482, powerSTEP01): write '-' for it");
  // numbering=mosi counts the other way: chip 0 is then the L6474.
  EXPECT_TRUE(parse_board_config("chips=L6470,L6474 dir_pin=D4,- numbering=mosi", "T").config);
  EXPECT_TRUE(parse_board_config("chips=L6470,L6474 dir_pin=-,D4", "T").config);
  // One pin for a mixed chain reaches the chips that have the pin.
  EXPECT_TRUE(parse_board_config("chips=L6470,L6474 dir_pin=D4 busy_pin=D3", "T").config);
}

TEST(L6474Board, AChainSummaryCountsRunsOfAVariantAsChipsEqualsWritesThem) {
  VirtualBoard v("bus=0 cs=0 chips=253xL6474,L6470,2xL6480; time=virtual");
  EXPECT_EQ(v.board.chain_summary(0), "/dev/spidev0.0: 256 chips (253xL6474,L6470,2xL6480)");
}

TEST(L6474Board, StckAndDirDrivenThroughTheBoardMoveAbsPosByExactlyThePulses) {
  VirtualBoard v("bus=0 cs=0 chips=L6470,2xL6474; time=virtual");
  v.board.with_chain(0, [](Chain& c) {
    ChainHost h(c);
    h.enable(2);
    h.step_clock(0, true);  // the L6470 in step-clock mode, forward
  });
  ASSERT_TRUE(v.board.drive_pin(0, 2, Pin::DIR, true));
  EXPECT_TRUE(v.board.pin_level(0, 2, Pin::DIR));
  pulses(v.board, 2, 300);
  ASSERT_TRUE(v.board.drive_pin(0, 2, Pin::DIR, false));
  pulses(v.board, 2, 100);
  EXPECT_EQ(position(v.board, 2), 200);
  EXPECT_EQ(position(v.board, 1), 0);
  pulses(v.board, 1, 5);
  EXPECT_EQ(position(v.board, 1), 0) << "in HiZ its STCK moves nothing";
  // The L6470 has no DIR pin: the board refuses the drive, and its steps keep StepClock's direction.
  EXPECT_FALSE(v.board.drive_pin(0, 0, Pin::DIR, false));
  EXPECT_TRUE(v.board.pin_level(0, 0, Pin::DIR)) << "a pin the chip lacks reads high";
  pulses(v.board, 0, 3);
  EXPECT_EQ(position(v.board, 0), 3);
  // Nor does the L6474 have SW or BUSY: no drive, and BUSY stays released.
  EXPECT_FALSE(v.board.drive_pin(0, 2, Pin::SW, false));
  EXPECT_TRUE(v.board.pin_level(0, 2, Pin::BUSY));
}

TEST(L6474Board, AWatchedDirReportsItsEdges) {
  VirtualBoard v("bus=0 cs=0 chips=L6474; time=virtual");
  std::vector<PinEdge> edges;
  v.board.set_edge_sink([&](const PinEdge& e) { edges.push_back(e); });
  v.board.watch_pin(0, 0, Pin::DIR, true);
  ASSERT_TRUE(v.board.advance(100));
  ASSERT_TRUE(v.board.drive_pin(0, 0, Pin::DIR, true));
  ASSERT_EQ(edges.size(), 1u);
  EXPECT_EQ(edges[0].pin, Pin::DIR);
  EXPECT_TRUE(edges[0].level);
  EXPECT_EQ(edges[0].tick, Tick{100});
}

TEST(L6474Coverage, TheUniverseHasEnableDisableAndNoMotionSwitchOrBusyPoint) {
  const CoverageUniverse& u = coverage_universe(l6474());
  EXPECT_GE(u.find(CoverageCategory::commands, "Enable"), 0);
  EXPECT_GE(u.find(CoverageCategory::commands, "Disable"), 0);
  EXPECT_EQ(u.find(CoverageCategory::commands, "Move FWD"), -1);
  EXPECT_EQ(u.find(CoverageCategory::refusals, "Move while the motor runs"), -1);
  EXPECT_EQ(u.find(CoverageCategory::events, "SW closed"), -1);
  EXPECT_EQ(u.find(CoverageCategory::events, "STALL_A"), -1);
  EXPECT_EQ(u.find(CoverageCategory::pin_edges, "BUSY falling"), -1);
  EXPECT_GE(u.find(CoverageCategory::pin_edges, "FLAG falling"), 0);
  EXPECT_GE(u.find(CoverageCategory::step_modes, "1/16"), 0);
  EXPECT_EQ(u.find(CoverageCategory::step_modes, "1/32"), -1);
  EXPECT_GE(u.find(CoverageCategory::registers_written, "TVAL"), 0);
}

}  // namespace
}  // namespace l6470emu::test
