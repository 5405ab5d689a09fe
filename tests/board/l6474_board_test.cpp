// The L6474 on a board: its DIR pin in the board description (dir_pin=) and the board's pin API,
// a description giving a chip a pin its part lacks refused with one line, STCK and DIR driven
// through the board moving ABS_POS exactly, and the coverage points it has and has not.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "board/board.hpp"
#include "board/coverage.hpp"
#include "daisychain/host.hpp"

namespace l6470emu::test {
namespace {

class StillHostClock final : public HostClock {
 public:
  std::int64_t monotonic_ns() override { return 0; }
  std::int64_t realtime_ns() override { return 0; }
  void sleep_until(std::int64_t) override {}
};

BoardConfig config_of(const std::string& text) {
  ParseResult p = parse_board_config(text, "test");
  EXPECT_TRUE(p.config) << p.error.message;
  return p.config ? *p.config : BoardConfig{};
}

std::string error_of(const std::string& text) {
  const ParseResult p = parse_board_config(text, "T");
  EXPECT_FALSE(p.config) << text;
  return p.error.message;
}

McuPin arduino(unsigned n) { return McuPin{McuPin::Kind::arduino, static_cast<std::uint16_t>(n)}; }

struct VirtualBoard {
  explicit VirtualBoard(const std::string& description)
      : board(config_of(description), [this](std::string_view line) { log.emplace_back(line); }, clock) {}
  StillHostClock clock;
  std::vector<std::string> log;
  Board board;

  void pulses(std::size_t chip, int n) {
    for (int i = 0; i < n; ++i) {
      ASSERT_TRUE(board.drive_pin(0, chip, Pin::STCK, true));
      ASSERT_TRUE(board.drive_pin(0, chip, Pin::STCK, false));
    }
  }
  std::int32_t position(std::size_t chip) const { return board.chain(0).peek_chip(chip).position(); }
};

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

TEST(L6474Board, StckAndDirDrivenThroughTheBoardMoveAbsPosByExactlyThePulses) {
  VirtualBoard v("bus=0 cs=0 chips=L6470,2xL6474; time=virtual");
  v.board.with_chain(0, [](Chain& c) {
    ChainHost h(c);
    h.enable(2);
    h.step_clock(0, true);  // the L6470 in step-clock mode, forward
  });
  ASSERT_TRUE(v.board.drive_pin(0, 2, Pin::DIR, true));
  EXPECT_TRUE(v.board.pin_level(0, 2, Pin::DIR));
  v.pulses(2, 300);
  ASSERT_TRUE(v.board.drive_pin(0, 2, Pin::DIR, false));
  v.pulses(2, 100);
  EXPECT_EQ(v.position(2), 200);
  EXPECT_EQ(v.position(1), 0);
  v.pulses(1, 5);
  EXPECT_EQ(v.position(1), 0) << "in HiZ its STCK moves nothing";
  // The L6470 has no DIR pin: the board refuses the drive, and its steps keep StepClock's direction.
  EXPECT_FALSE(v.board.drive_pin(0, 0, Pin::DIR, false));
  EXPECT_TRUE(v.board.pin_level(0, 0, Pin::DIR)) << "a pin the chip lacks reads high";
  v.pulses(0, 3);
  EXPECT_EQ(v.position(0), 3);
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
