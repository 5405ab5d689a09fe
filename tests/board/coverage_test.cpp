// Interface coverage through the OS-free Board (board/coverage*.hpp): a driver that meets a known
// subset of a chip's interface gets exactly that subset, category by category; the universes come
// from the variant tables; the data merges as a union and reads back; the file survives
// concurrent merges and bad neighbours; the reports say what a driver never met.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "board/board.hpp"
#include "board/coverage.hpp"
#include "board/coverage_file.hpp"
#include "board/coverage_report.hpp"
#include "spi/message.hpp"
#include "support/test_support.hpp"
#include "support/trace_test_support.hpp"
#include "support/board_config_support.hpp"

namespace l6470emu::test {
namespace {

using Names = std::set<std::string>;

/// Virtual time reads no host clock after construction; this one never moves.
class StillHostClock final : public HostClock {
 public:
  std::int64_t monotonic_ns() override { return 0; }
  std::int64_t realtime_ns() override { return 0; }
  void sleep_until(std::int64_t) override {}
};

const RegisterInfo& register_named(const Variant& v, std::string_view name) {
  for (const RegisterInfo& r : v.registers)
    if (r.name == name) return r;
  if (v.current_mode)
    for (const RegisterInfo& r : v.current_mode->registers)
      if (r.name == name) return r;
  throw std::logic_error("no register " + std::string(name));
}

/// An opcode and its argument, most significant byte first.
std::vector<std::uint8_t> with_arg(std::uint8_t opcode, std::uint32_t arg, unsigned bytes = 3) {
  std::vector<std::uint8_t> out{opcode};
  for (unsigned i = bytes; i-- > 0;) out.push_back(static_cast<std::uint8_t>(arg >> (8 * i)));
  return out;
}
std::vector<std::uint8_t> set_param(const Variant& v, std::string_view name, std::uint32_t value) {
  const RegisterInfo& r = register_named(v, name);
  return with_arg(static_cast<std::uint8_t>(r.address), value, r.spi_bytes());
}
std::vector<std::uint8_t> get_param(const Variant& v, std::string_view name) {
  const RegisterInfo& r = register_named(v, name);
  return with_arg(static_cast<std::uint8_t>(0x20 | r.address), 0, r.spi_bytes());
}

// L6470 opcodes (datasheet Table 14).
std::vector<std::uint8_t> move(bool fwd, std::uint32_t n) { return with_arg(0x40 | (fwd ? 1 : 0), n); }
std::vector<std::uint8_t> go_to(std::uint32_t pos) { return with_arg(0x60, pos); }
std::vector<std::uint8_t> run(bool fwd, std::uint32_t spd) { return with_arg(0x50 | (fwd ? 1 : 0), spd); }
std::vector<std::uint8_t> go_until(bool act, bool fwd, std::uint32_t spd) {
  return with_arg(static_cast<std::uint8_t>(0x82 | (act ? 8 : 0) | (fwd ? 1 : 0)), spd);
}
std::vector<std::uint8_t> release_sw(bool act, bool fwd) {
  return {static_cast<std::uint8_t>(0x92 | (act ? 8 : 0) | (fwd ? 1 : 0))};
}
const std::vector<std::uint8_t> kHardStop{0xB8}, kHardHiZ{0xA8}, kGetStatus{0xD0, 0x00, 0x00};

/// The first byte `v` decodes as no command at all.
std::uint8_t unknown_opcode(const Variant& v) {
  for (unsigned b = 0xE0; b < 0x100; ++b)
    if (v.opcodes[b].command == Command::Unknown) return static_cast<std::uint8_t>(b);
  throw std::logic_error("no unknown opcode");
}

/// A board in virtual time collecting coverage from its start, and a driver that sends a
/// command to one chip of chain 0, one CS frame per byte position, NOPs to the other chips.
struct Rig {
  explicit Rig(const std::string& description)
      : board(config_of(description + "; time=virtual"), [this](std::string_view line) { log.emplace_back(line); },
              clock) {
    board.enable_coverage();
  }
  StillHostClock clock;
  std::vector<std::string> log;
  Board board;

  /// Sends `cmd` to chip `chip` (a chain index); returns the bytes the chip answered.
  std::vector<std::uint8_t> send(const std::vector<std::uint8_t>& cmd, std::size_t chip = 0) {
    const std::size_t n = board.chip_count(0);
    std::vector<std::vector<std::uint8_t>> tx(cmd.size(), std::vector<std::uint8_t>(n, 0x00));
    std::vector<std::vector<std::uint8_t>> rx(cmd.size(), std::vector<std::uint8_t>(n, 0x00));
    std::vector<SpiTransfer> frames(cmd.size());
    for (std::size_t f = 0; f < cmd.size(); ++f) {
      tx[f][chip] = cmd[f];
      frames[f].tx = tx[f];
      frames[f].rx = rx[f];
      frames[f].len = static_cast<std::uint32_t>(n);
      frames[f].cs_change = f + 1 < cmd.size();
    }
    board.advance_to(board.transfer(0, frames));
    std::vector<std::uint8_t> answer;
    for (const auto& r : rx) answer.push_back(r[chip]);
    return answer;
  }
  std::uint16_t get_status(std::size_t chip = 0) {
    const auto a = send(kGetStatus, chip);
    return static_cast<std::uint16_t>(a[1] << 8 | a[2]);
  }
  void wait_ms(std::uint64_t ms) { ASSERT_TRUE(board.advance(ticks_from_ms(ms))); }

  Names hits(CoverageCategory c, const std::string& variant = "L6470") const {
    const CoverageData d = board.coverage();
    const auto it = d.variants().find(variant);
    if (it == d.variants().end()) return {};
    return it->second.hit[static_cast<std::size_t>(c)];
  }
};

/// The names of a universe's points of one category.
Names points_of(const CoverageUniverse& u, CoverageCategory c) {
  Names out;
  for (const CoveragePoint& p : u.points())
    if (p.category == c) out.insert(p.name);
  return out;
}
Names points_of(const Variant& v, CoverageCategory c) { return points_of(coverage_universe(v), c); }

std::string one_line_error(std::string_view text) {
  try {
    CoverageData::from_json(text);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "(accepted)";
}

// ================================================================ collection through a Board

TEST(CoverageCollection, NothingIsCollectedUntilCoverageIsEnabled) {
  StillHostClock clock;
  Board board(config_of("chips=L6470; time=virtual"), {}, clock);
  EXPECT_FALSE(board.coverage_enabled());
  EXPECT_TRUE(board.coverage().empty());
  board.enable_coverage();
  EXPECT_TRUE(board.coverage_enabled());
  const CoverageData d = board.coverage();
  ASSERT_EQ(d.variants().size(), 1u);
  EXPECT_EQ(d.variants().begin()->first, "L6470");
  EXPECT_EQ(d.variants().begin()->second.positions, (Names{"chip 0 of 1"}));
}

TEST(CoverageCollection, EachCommandIsCountedWithTheArgumentClassesItWasSentWith) {
  Rig r("chips=L6470");
  r.send(move(true, 100));
  r.wait_ms(500);
  r.send(move(false, 0));  // Move of 0 steps
  r.wait_ms(10);
  r.send(go_to(100));  // ABS_POS is 100 again: GoTo to the current position
  r.wait_ms(10);
  r.send(run(true, 0xFFFFF));  // far above MAX_SPEED's 0x41 (66 560 in SPD units)
  r.send(kHardStop);
  r.send(run(false, 1000));  // below MAX_SPEED: only Run REV
  r.send(kHardStop);
  r.send(go_until(true, false, 1000));
  r.send(kHardStop);
  r.send(release_sw(false, true));
  r.send(kHardHiZ);
  EXPECT_EQ(r.hits(CoverageCategory::commands),
            (Names{"Move FWD", "Move REV", "Move of 0 steps", "GoTo", "GoTo to the current position", "Run FWD", "Run REV",
                   "Run above MAX_SPEED", "HardStop", "GoUntil REV", "GoUntil ACT=1", "ReleaseSW FWD", "ReleaseSW ACT=0",
                   "HardHiZ"}));
  EXPECT_EQ(r.hits(CoverageCategory::refusals), Names{});
  EXPECT_EQ(r.hits(CoverageCategory::registers_read), Names{});
  EXPECT_EQ(r.hits(CoverageCategory::registers_written), Names{});
  EXPECT_EQ(r.hits(CoverageCategory::step_modes), Names{"1/128"});
  EXPECT_EQ(r.hits(CoverageCategory::events), Names{});
  EXPECT_EQ(r.hits(CoverageCategory::rules_broken), Names{}) << (r.log.empty() ? "" : r.log.front());
}

TEST(CoverageCollection, RunAtExactlyMaxSpeedIsNotAboveIt) {
  Rig r("chips=L6470");
  const std::uint32_t max_speed_in_spd = 0x41u << 10;  // MAX_SPEED 2^-18 step/tick, SPD 2^-28 step/tick
  r.send(run(true, max_speed_in_spd));
  r.send(kHardStop);
  EXPECT_EQ(r.hits(CoverageCategory::commands), (Names{"Run FWD", "HardStop"}));
  r.send(run(true, max_speed_in_spd + 1));
  EXPECT_EQ(r.hits(CoverageCategory::commands), (Names{"Run FWD", "HardStop", "Run above MAX_SPEED"}));
}

TEST(CoverageCollection, GoToDirToTheCurrentPositionIsItsOwnClass) {
  Rig r("chips=L6470");
  r.send(with_arg(0x68, 0));  // GoTo_DIR REV to 0, where the motor is
  r.wait_ms(10);
  r.send(with_arg(0x69, 50));  // GoTo_DIR FWD elsewhere
  EXPECT_EQ(r.hits(CoverageCategory::commands), (Names{"GoTo_DIR REV", "GoTo_DIR FWD", "GoTo_DIR to the current position"}));
}

TEST(CoverageCollection, RegistersReadAndWrittenAreTheOnesTheDriverNamedAndARefusedWriteIsNoWrite) {
  Rig r("chips=L6470");
  const Variant& v = l6470();
  r.send(get_param(v, "ABS_POS"));
  r.send(get_param(v, "CONFIG"));
  r.send(set_param(v, "MAX_SPEED", 0x41));
  r.send(set_param(v, "KVAL_RUN", 0x29));
  r.send(run(true, 1000));
  r.send(set_param(v, "ACC", 0x8A));  // WS while the motor runs: refused
  r.send(kHardStop);
  r.send(set_param(v, "STEP_MODE", 0x07));  // WH with the bridges on: refused
  EXPECT_EQ(r.hits(CoverageCategory::registers_read), (Names{"ABS_POS", "CONFIG"}));
  EXPECT_EQ(r.hits(CoverageCategory::registers_written), (Names{"MAX_SPEED", "KVAL_RUN"}));
  EXPECT_EQ(r.hits(CoverageCategory::refusals), (Names{"SetParam(ACC)", "SetParam(STEP_MODE)"}));
}

TEST(CoverageCollection, AWritePendingAtTheEndOfTheRunCountsAsWritten) {
  Rig r("chips=L6470");
  r.send(set_param(l6470(), "MARK", 5));  // nothing follows it: not settled by a later command
  EXPECT_EQ(r.hits(CoverageCategory::registers_written), Names{"MARK"});
}

TEST(CoverageCollection, EachRefusalTheChipMadeIsCountedAndNothingElse) {
  Rig r("chips=L6470");
  const Variant& v = l6470();
  r.send(run(true, 1000));
  r.send(set_param(v, "ACC", 0x8A));  // a WS register while the motor runs
  r.send(kHardStop);
  r.wait_ms(10);
  r.send(move(true, 20000));
  r.send(go_to(0));  // a GoTo while BUSY
  r.send(kHardStop);
  r.send({unknown_opcode(v)});  // no command at all
  r.send(set_param(v, "SPEED", 0));  // a read-only register (WRONG_CMD at its command byte)
  EXPECT_EQ(r.hits(CoverageCategory::refusals), (Names{"SetParam(ACC)", "GoTo while BUSY", "an opcode that is no command",
                                                       "SetParam of a read-only register"}));
  EXPECT_EQ(r.hits(CoverageCategory::registers_written), Names{});
  // A refused motion command ran in no step mode; the Run and the Move did.
  EXPECT_EQ(r.hits(CoverageCategory::step_modes), Names{"1/128"});
}

TEST(CoverageCollection, AMoveWhileTheMotorRunsAndAMotionCommandDuringAFaultAreRefusals) {
  Rig r("chips=L6470");
  r.send(run(true, 1000));
  r.send(move(true, 10));
  r.send(kHardStop);
  r.board.inject_fault(0, 0, TraceFault::OCD, 1);  // the bridges go off and stay off while it lasts
  r.send(move(true, 10));
  EXPECT_EQ(r.hits(CoverageCategory::refusals), (Names{"Move while the motor runs", "motion command while a fault holds HiZ"}));
}

TEST(CoverageCollection, AFlagRaisedButNeverReadIsNotObservedUntilTheDriverReadsStatus) {
  Rig r("chips=L6470");
  r.get_status();  // the power-up UVLO is seen and cleared
  r.board.inject_fault(0, 0, TraceFault::OCD, 1);
  EXPECT_TRUE(r.hits(CoverageCategory::flags_raised).count("OCD"));
  EXPECT_FALSE(r.hits(CoverageCategory::flags_observed).count("OCD"));
  {
    const auto s = summarize(r.board.coverage());
    ASSERT_EQ(s.size(), 1u);
    EXPECT_EQ(s[0].raised_not_observed, std::vector<std::string>{"OCD"});
    EXPECT_NE(coverage_text(r.board.coverage(), false).find("raised but never observed: OCD\n"), std::string::npos)
        << coverage_text(r.board.coverage(), false);
  }
  r.get_status();
  EXPECT_TRUE(r.hits(CoverageCategory::flags_observed).count("OCD"));
  EXPECT_TRUE(summarize(r.board.coverage())[0].raised_not_observed.empty());
  EXPECT_NE(coverage_text(r.board.coverage(), false).find("raised but never observed: none\n"), std::string::npos);
}

TEST(CoverageCollection, GetParamOfStatusObservesTheFlagsAndTheFlagPinReadLowObservesTheAlarms) {
  {
    Rig r("chips=L6470");
    r.get_status();
    r.board.inject_fault(0, 0, TraceFault::STALL_A, 1);
    r.send(get_param(l6470(), "STATUS"));
    EXPECT_TRUE(r.hits(CoverageCategory::flags_observed).count("STEP_LOSS_A"));
  }
  {
    Rig r("chips=L6470");
    r.get_status();
    r.board.inject_fault(0, 0, TraceFault::OCD, 1);
    ASSERT_FALSE(r.board.pin_level(0, 0, Pin::FLAG));
    const Names before = r.hits(CoverageCategory::flags_observed);
    EXPECT_FALSE(before.count("OCD"));
    r.board.note_output_read(0, 0, Pin::FLAG);
    Names added;
    for (const std::string& f : r.hits(CoverageCategory::flags_observed))
      if (!before.count(f)) added.insert(f);
    EXPECT_EQ(added, Names{"OCD"});  // the alarm; HiZ, also set now, is no alarm: FLAG does not show it
  }
  {
    Rig r("chips=L6470");
    r.board.inject_fault(0, 0, TraceFault::OCD, 1);
    r.board.note_output_read(0, 0, Pin::FLAG);
    EXPECT_FALSE(r.hits(CoverageCategory::flags_observed).count("HiZ"));
  }
}

TEST(CoverageCollection, EveryBackdoorEventTheSwitchAndAStandbyResetAreEvents) {
  Rig r("chips=L6470");
  for (const TraceFault f : {TraceFault::UVLO, TraceFault::OCD, TraceFault::STALL_A, TraceFault::STALL_B}) {
    ASSERT_TRUE(r.board.inject_fault(0, 0, f, 1));
    ASSERT_TRUE(r.board.inject_fault(0, 0, f, 0));
  }
  for (std::uint8_t t = 1; t <= 3; ++t) ASSERT_TRUE(r.board.inject_fault(0, 0, TraceFault::THERMAL, t));
  ASSERT_TRUE(r.board.inject_fault(0, 0, TraceFault::THERMAL, 0));
  ASSERT_TRUE(r.board.inject_fault(0, 0, TraceFault::ADCIN, 12));
  ASSERT_TRUE(r.board.inject_fault(0, 0, TraceFault::POWER_CYCLE, 0));
  ASSERT_TRUE(r.board.inject_fault(0, 0, TraceFault::MISO_FLIP, 3));
  ASSERT_TRUE(r.board.inject_fault(0, 0, TraceFault::LOST_FRAME, 0));
  ASSERT_TRUE(r.board.drive_pin(0, 0, Pin::SW, false));
  ASSERT_TRUE(r.board.drive_pin(0, 0, Pin::SW, true));
  ASSERT_TRUE(r.board.drive_pin(0, 0, Pin::STBY_RST, false));
  ASSERT_TRUE(r.board.drive_pin(0, 0, Pin::STBY_RST, true));
  const Names events = r.hits(CoverageCategory::events);
  EXPECT_EQ(events, points_of(l6470(), CoverageCategory::events));
  EXPECT_EQ(events, (Names{"UVLO", "OCD", "STALL_A", "STALL_B", "THERMAL warning", "THERMAL bridge_shutdown",
                           "THERMAL device_shutdown", "ADCIN", "POWER_CYCLE", "MISO_FLIP", "LOST_FRAME", "SW closed",
                           "SW opened", "STBY_RST reset"}));
}

TEST(CoverageCollection, AnEventThatEndsAConditionOrAHalfDoneSwitchIsNoEvent) {
  Rig r("chips=L6470");
  r.board.inject_fault(0, 0, TraceFault::OCD, 0);
  r.board.inject_fault(0, 0, TraceFault::THERMAL, 0);
  r.board.drive_pin(0, 0, Pin::SW, true);  // already open
  r.board.drive_pin(0, 0, Pin::STBY_RST, false);  // held in standby, never released
  EXPECT_EQ(r.hits(CoverageCategory::events), Names{});
  r.board.drive_pin(0, 0, Pin::SW, false);
  EXPECT_EQ(r.hits(CoverageCategory::events), Names{"SW closed"});
}

TEST(CoverageCollection, EachStepModeAMotionCommandRanInIsCounted) {
  Rig r("chips=L6470");
  const Variant& v = l6470();
  r.send(set_param(v, "STEP_MODE", 0x00));  // full step (the bridges are off at power-up)
  r.send(move(true, 4));
  r.wait_ms(500);
  r.send(kHardHiZ);
  r.send(set_param(v, "STEP_MODE", 0x04));  // 1/16
  r.send(move(true, 4));
  r.wait_ms(500);
  r.send(kHardHiZ);
  EXPECT_EQ(r.hits(CoverageCategory::step_modes), (Names{"full step", "1/16"}));
  EXPECT_EQ(r.hits(CoverageCategory::registers_written), Names{"STEP_MODE"});
}

TEST(CoverageCollection, OnlyTheChipTheDriverAddressedIsAChainPositionHitOnAThreeChipChain) {
  Rig r("chips=3xL6470");
  r.get_status(1);  // chips 0 and 2 get NOP bytes
  r.send(move(true, 10), 1);
  const CoverageData d = r.board.coverage();
  ASSERT_EQ(d.variants().size(), 1u);
  const auto& v = d.variants().at("L6470");
  EXPECT_EQ(v.positions, (Names{"chip 0 of 3", "chip 1 of 3", "chip 2 of 3"}));
  EXPECT_EQ(v.hit[static_cast<std::size_t>(CoverageCategory::chain_positions)], Names{"chip 1 of 3"});
  EXPECT_EQ(r.hits(CoverageCategory::commands), (Names{"GetStatus", "Move FWD"}));
}

TEST(CoverageCollection, ChainPositionsFollowTheBoardsNumbering) {
  Rig r("chips=3xL6470 numbering=mosi");
  r.send(move(true, 10), 0);  // chain index 0 is chip 2 from the MOSI end
  EXPECT_EQ(r.hits(CoverageCategory::chain_positions), Names{"chip 2 of 3"});
}

TEST(CoverageCollection, PinEdgesComeFromEdgeEventsAndFromReadsThatSeeANewLevel) {
  {
    Rig r("chips=L6470");  // edge events handed to the host
    r.board.note_output_edge(0, 0, Pin::BUSY, false);
    r.board.note_output_edge(0, 0, Pin::FLAG, true);
    EXPECT_EQ(r.hits(CoverageCategory::pin_edges), (Names{"BUSY falling", "FLAG rising"}));
  }
  {
    Rig r("chips=L6470");  // FLAG read before and after a fault
    r.get_status();  // the power-up UVLO cleared: FLAG high
    r.board.note_output_read(0, 0, Pin::FLAG);
    r.board.note_output_read(0, 0, Pin::FLAG);  // the same level: no edge
    EXPECT_EQ(r.hits(CoverageCategory::pin_edges), Names{});
    r.board.inject_fault(0, 0, TraceFault::OCD, 1);
    r.board.note_output_read(0, 0, Pin::FLAG);  // low now
    EXPECT_EQ(r.hits(CoverageCategory::pin_edges), Names{"FLAG falling"});
  }
  {
    Rig r("chips=L6470");  // a read loop on BUSY through a Move: high, low, high
    r.board.note_output_read(0, 0, Pin::BUSY);
    r.send(move(true, 100));
    r.board.note_output_read(0, 0, Pin::BUSY);
    EXPECT_EQ(r.hits(CoverageCategory::pin_edges), Names{"BUSY falling"});
    r.wait_ms(500);
    r.board.note_output_read(0, 0, Pin::BUSY);
    EXPECT_EQ(r.hits(CoverageCategory::pin_edges), (Names{"BUSY falling", "BUSY rising"}));
    EXPECT_TRUE(r.hits(CoverageCategory::flags_observed).count("BUSY"));  // read low while the Move ran
    // Reads of an input, or of a chip that is not there, count for nothing.
    r.board.note_output_read(0, 0, Pin::SW);
    r.board.note_output_read(0, 7, Pin::FLAG);
    r.board.note_output_edge(0, 0, Pin::SW, true);
    r.board.note_output_edge(3, 0, Pin::FLAG, true);
    EXPECT_EQ(r.hits(CoverageCategory::pin_edges), (Names{"BUSY falling", "BUSY rising"}));
  }
}

TEST(CoverageCollection, AWrongOpcodeUnderCheckWarnIsListedUnderRulesBroken) {
  Rig r("chips=L6470 check=warn");
  r.send({unknown_opcode(l6470())});
  EXPECT_EQ(r.hits(CoverageCategory::rules_broken), Names{"WRONG_CMD"});
  const std::string text = coverage_text(r.board.coverage(), false);
  EXPECT_NE(text.find("rules broken: WRONG_CMD\n"), std::string::npos) << text;
  // Rules broken are listed, never counted: the total leaves them out.
  const auto s = summarize(r.board.coverage());
  ASSERT_EQ(s.size(), 1u);
  CoverageCount counted;
  for (std::size_t c = 0; c < kCoverageCategoryCount; ++c)
    if (!counts_against(static_cast<CoverageCategory>(c))) {
      counted.hit += s[0].category[c].hit;
      counted.total += s[0].category[c].total;
    }
  EXPECT_EQ(s[0].total.hit, counted.hit);
  EXPECT_EQ(s[0].total.total, counted.total);

  Rig off("chips=L6470 check=off");
  off.send({unknown_opcode(l6470())});
  EXPECT_EQ(off.hits(CoverageCategory::rules_broken), Names{});
  EXPECT_EQ(off.hits(CoverageCategory::refusals), Names{"an opcode that is no command"});
}

TEST(CoverageCollection, AGateDriverCountsCmdErrorItsThermalClassesAndItsStallNames) {
  Rig r("chips=L6480");
  r.get_status();
  r.send({unknown_opcode(l6480())});
  r.board.inject_fault(0, 0, TraceFault::THERMAL, 1);
  r.board.inject_fault(0, 0, TraceFault::THERMAL, 2);
  r.board.inject_fault(0, 0, TraceFault::THERMAL, 3);
  r.board.inject_fault(0, 0, TraceFault::STALL_A, 1);
  r.board.inject_fault(0, 0, TraceFault::UVLO_ADC, 1);
  const Names raised = r.hits(CoverageCategory::flags_raised, "L6480");
  for (const char* f : {"CMD_ERROR", "TH_STATUS warning", "TH_STATUS bridge shutdown", "TH_STATUS device shutdown", "STALL_A",
                        "UVLO_ADC"})
    EXPECT_TRUE(raised.count(f)) << f;
  for (const char* f : {"WRONG_CMD", "NOTPERF_CMD", "TH_WRN", "TH_SD", "STEP_LOSS_A"}) EXPECT_FALSE(raised.count(f)) << f;
  EXPECT_TRUE(r.hits(CoverageCategory::events, "L6480").count("STALL_A"));
  EXPECT_TRUE(r.hits(CoverageCategory::events, "L6480").count("UVLO_ADC"));
  EXPECT_FALSE(r.hits(CoverageCategory::flags_observed, "L6480").count("STALL_A"));
  r.get_status();
  EXPECT_TRUE(r.hits(CoverageCategory::flags_observed, "L6480").count("STALL_A"));
  EXPECT_TRUE(r.hits(CoverageCategory::flags_observed, "L6480").count("TH_STATUS device shutdown"));
}

TEST(CoverageCollection, APowerstep01CountsARegisterUnderTheNameOfTheModeInForce) {
  Rig r("chips=powerSTEP01");
  const Variant& v = powerstep01();
  r.send(get_param(v, "KVAL_HOLD"));  // voltage mode at power-up
  r.send(set_param(v, "STEP_MODE", 0x08 | 0x07));  // CM_VM = 1: current mode (the bridges are off)
  r.send(get_param(v, "KVAL_HOLD"));  // the same address, now TVAL_HOLD
  EXPECT_EQ(r.hits(CoverageCategory::registers_read, "powerSTEP01"), (Names{"KVAL_HOLD", "TVAL_HOLD"}));
  EXPECT_EQ(r.hits(CoverageCategory::registers_written, "powerSTEP01"), Names{"STEP_MODE"});
}

TEST(CoverageCollection, ABoardOfTwoVariantsKeepsThemApart) {
  Rig r("chips=L6470,L6480");
  r.send(move(true, 10), 0);
  r.send(kHardHiZ, 1);
  EXPECT_EQ(r.hits(CoverageCategory::commands, "L6470"), Names{"Move FWD"});
  EXPECT_EQ(r.hits(CoverageCategory::commands, "L6480"), Names{"HardHiZ"});
  EXPECT_EQ(r.hits(CoverageCategory::chain_positions, "L6470"), Names{"chip 0 of 2"});
  EXPECT_EQ(r.hits(CoverageCategory::chain_positions, "L6480"), Names{"chip 1 of 2"});
}

// With STEP_MODE.SYNC_EN = 1 the BUSY pin is the SYNC output: a read of it low observes BUSY only
// when STATUS shows BUSY set.
TEST(CoverageCollection, ASyncOutputReadLowIsNoBusyObserved) {
  Rig r("chips=L6470");
  r.send(set_param(l6470(), "STEP_MODE", 0x80 | 0x07));  // SYNC_EN = 1, SYNC_SEL = 0, 1/128 step
  int tries = 0;
  std::uint16_t status = 0;
  for (; tries < 64; ++tries) {
    r.send(move(true, 1));
    r.wait_ms(50);
    status = r.get_status();
    if (!r.board.pin_level(0, 0, Pin::BUSY) && (status & status_bits::kBusyN) != 0) break;
  }
  if (tries == 64) GTEST_SKIP() << "no stopped state with the SYNC output low was reached";
  ASSERT_FALSE(r.hits(CoverageCategory::flags_observed).count("BUSY"));
  r.board.note_output_read(0, 0, Pin::BUSY);
  EXPECT_FALSE(r.hits(CoverageCategory::flags_observed).count("BUSY"))
      << "the SYNC output read low after " << tries + 1 << " Move(1) counted as BUSY observed; STATUS 0x" << std::hex
      << status << " says not busy";
}

// ================================================================ universes from the tables

TEST(CoverageUniverse, EveryRegisterOfTheL6470IsAPointToReadAndEachWritableOneAPointToWrite) {
  const Variant& v = l6470();
  Names all, writable, refusable;
  for (const RegisterInfo& r : v.registers) {
    all.insert(std::string(r.name));
    if (r.access != Access::R) writable.insert(std::string(r.name));
    if (r.access == Access::WS || r.access == Access::WH) refusable.insert("SetParam(" + std::string(r.name) + ")");
  }
  EXPECT_EQ(points_of(v, CoverageCategory::registers_read), all);
  EXPECT_EQ(points_of(v, CoverageCategory::registers_written), writable);
  const Names refusals = points_of(v, CoverageCategory::refusals);
  for (const std::string& r : refusable) EXPECT_TRUE(refusals.count(r)) << r;
  EXPECT_TRUE(refusals.count("SetParam(ACC)"));
  EXPECT_TRUE(refusals.count("SetParam(STEP_MODE)"));
  EXPECT_FALSE(refusals.count("SetParam(MAX_SPEED)"));  // WR: always writable
  EXPECT_TRUE(refusals.count("SetParam of a read-only register"));
}

TEST(CoverageUniverse, EveryCommandTheOpcodeTableDecodesIsAPointOfEveryVariant) {
  for (const Variant* v : all_variants()) {
    const Names commands = points_of(*v, CoverageCategory::commands);
    for (unsigned b = 0; b < 256; ++b) {
      const Opcode& op = v->opcodes[b];
      switch (op.command) {
        case Command::NOP: case Command::SetParam: case Command::GetParam: case Command::Reserved: case Command::Unknown:
          continue;
        default: break;
      }
      const std::string name(to_string(op.command));
      const bool found = commands.count(name) || commands.count(name + (op.dir ? " FWD" : " REV"));
      EXPECT_TRUE(found) << v->name << ": opcode 0x" << std::hex << b << " (" << name << ")";
    }
    if (!v->motion_engine) {  // the L6474: Enable, Disable and GetStatus, nothing that moves
      EXPECT_EQ(commands, (Names{"Disable", "Enable", "GetStatus"})) << v->name;
      continue;
    }
    for (const char* c : {"Move of 0 steps", "GoTo to the current position", "Run above MAX_SPEED", "GoUntil ACT=0",
                          "GoUntil ACT=1", "ReleaseSW ACT=0", "ReleaseSW ACT=1", "Move FWD", "Move REV", "StepClock FWD"})
      EXPECT_TRUE(commands.count(c)) << v->name << ": " << c;
  }
}

TEST(CoverageUniverse, EveryStatusFlagIsAPointRaisedAndAPointObserved) {
  for (const Variant* v : all_variants()) {
    Names flags;
    for (const StatusFlagPoint& f : status_flag_points(v->status)) flags.insert(f.name);
    EXPECT_EQ(points_of(*v, CoverageCategory::flags_raised), flags) << v->name;
    EXPECT_EQ(points_of(*v, CoverageCategory::flags_observed), flags) << v->name;
  }
}

TEST(CoverageUniverse, TheL6472HasNoStallEventNorStepLossFlagsAndNoStepFinerThanASixteenth) {
  const Variant& v = l6472();
  const Names events = points_of(v, CoverageCategory::events);
  EXPECT_FALSE(events.count("STALL_A"));
  EXPECT_FALSE(events.count("STALL_B"));
  EXPECT_TRUE(events.count("OCD"));
  for (const CoverageCategory c : {CoverageCategory::flags_raised, CoverageCategory::flags_observed}) {
    const Names flags = points_of(v, c);
    EXPECT_FALSE(flags.count("STEP_LOSS_A"));
    EXPECT_FALSE(flags.count("STEP_LOSS_B"));
    EXPECT_TRUE(flags.count("OCD"));
  }
  EXPECT_EQ(points_of(v, CoverageCategory::step_modes), (Names{"full step", "1/2", "1/4", "1/8", "1/16"}));
  EXPECT_EQ(coverage_universe(v).find(CoverageCategory::events, "STALL_A"), -1);
}

TEST(CoverageUniverse, TheGateDriversNameCmdErrorTheThermalClassesAndTheirStallFlags) {
  const Variant& v = l6480();
  const Names flags = points_of(v, CoverageCategory::flags_raised);
  for (const char* f : {"CMD_ERROR", "TH_STATUS warning", "TH_STATUS bridge shutdown", "TH_STATUS device shutdown", "STALL_A",
                        "STALL_B", "UVLO_ADC"})
    EXPECT_TRUE(flags.count(f)) << f;
  for (const char* f : {"WRONG_CMD", "NOTPERF_CMD", "TH_WRN", "TH_SD", "STEP_LOSS_A", "STEP_LOSS_B"})
    EXPECT_FALSE(flags.count(f)) << f;
  EXPECT_TRUE(points_of(v, CoverageCategory::events).count("UVLO_ADC"));
  EXPECT_FALSE(points_of(l6470(), CoverageCategory::events).count("UVLO_ADC"));
  const Names l6470_flags = points_of(l6470(), CoverageCategory::flags_raised);
  for (const char* f : {"WRONG_CMD", "NOTPERF_CMD", "TH_WRN", "TH_SD", "STEP_LOSS_A", "STEP_LOSS_B"})
    EXPECT_TRUE(l6470_flags.count(f)) << f;
  EXPECT_FALSE(l6470_flags.count("CMD_ERROR"));
}

TEST(CoverageUniverse, ThePowerstep01HoldsTheRegistersOfBothItsModes) {
  const Variant& v = powerstep01();
  ASSERT_NE(v.current_mode, nullptr);
  const Names read = points_of(v, CoverageCategory::registers_read);
  for (const Variant* t : {&v, v.current_mode})
    for (const RegisterInfo& r : t->registers) EXPECT_TRUE(read.count(std::string(r.name))) << r.name;
  EXPECT_TRUE(read.count("KVAL_HOLD"));
  EXPECT_TRUE(read.count("TVAL_HOLD"));
  EXPECT_FALSE(points_of(l6480(), CoverageCategory::registers_read).count("TVAL_HOLD"));
}

TEST(CoverageUniverse, EachVariantHasOneAndNoOtherNameHasAny) {
  for (const Variant* v : all_variants()) {
    const CoverageUniverse* u = coverage_universe(v->name);
    ASSERT_NE(u, nullptr) << v->name;
    EXPECT_EQ(u, &coverage_universe(*v));
    EXPECT_EQ(u->variant(), v->name);
    // Names are unique within a category, and find() finds each.
    for (std::size_t i = 0; i < u->points().size(); ++i)
      EXPECT_EQ(u->find(u->points()[i].category, u->points()[i].name), static_cast<int>(i)) << u->points()[i].name;
  }
  EXPECT_EQ(coverage_universe("L6471"), nullptr);
  EXPECT_EQ(coverage_universe(""), nullptr);
  EXPECT_EQ(coverage_universe(l6470()).find(CoverageCategory::commands, "Frobnicate"), -1);
}

// ================================================================ CoverageData

CoverageData run_a() {
  CoverageData d;
  d.use("L6470").positions = {"chip 0 of 1"};
  d.hit("L6470", CoverageCategory::commands, "Move FWD");
  d.hit("L6470", CoverageCategory::registers_read, "ABS_POS");
  d.hit("L6470", CoverageCategory::chain_positions, "chip 0 of 1");
  return d;
}
CoverageData run_b() {
  CoverageData d;
  d.use("L6470").positions = {"chip 0 of 3", "chip 2 of 3"};
  d.hit("L6470", CoverageCategory::commands, "GoUntil ACT=1");
  d.hit("L6470", CoverageCategory::flags_raised, "OCD");
  d.hit("L6470", CoverageCategory::chain_positions, "chip 2 of 3");
  d.use("L6480").positions = {"chip 1 of 3"};
  d.hit("L6480", CoverageCategory::flags_raised, "CMD_ERROR");
  return d;
}
CoverageData run_c() {
  CoverageData d;
  d.use("powerSTEP01").positions = {"chip 0 of 1"};
  d.hit("powerSTEP01", CoverageCategory::registers_read, "TVAL_HOLD");
  d.hit("L6470", CoverageCategory::rules_broken, "WRONG_CMD");
  return d;
}

TEST(CoverageData, MergingTwoDisjointRunsGivesTheirUnion) {
  CoverageData m = run_a();
  m.merge(run_b());
  const auto& v = m.variants().at("L6470");
  EXPECT_EQ(v.hit[static_cast<std::size_t>(CoverageCategory::commands)], (Names{"Move FWD", "GoUntil ACT=1"}));
  EXPECT_EQ(v.hit[static_cast<std::size_t>(CoverageCategory::registers_read)], Names{"ABS_POS"});
  EXPECT_EQ(v.hit[static_cast<std::size_t>(CoverageCategory::flags_raised)], Names{"OCD"});
  EXPECT_EQ(v.hit[static_cast<std::size_t>(CoverageCategory::chain_positions)], (Names{"chip 0 of 1", "chip 2 of 3"}));
  EXPECT_EQ(v.positions, (Names{"chip 0 of 1", "chip 0 of 3", "chip 2 of 3"}));
  EXPECT_EQ(m.variants().at("L6480").hit[static_cast<std::size_t>(CoverageCategory::flags_raised)], Names{"CMD_ERROR"});
  EXPECT_EQ(m.variants().size(), 2u);
  // Merging a run into itself changes nothing.
  CoverageData again = m;
  again.merge(m);
  EXPECT_EQ(again, m);
}

TEST(CoverageData, MergingInAnyOrderGivesTheSameBytes) {
  const std::vector<CoverageData> runs{run_a(), run_b(), run_c()};
  std::vector<int> order{0, 1, 2};
  std::string first;
  do {
    CoverageData m;
    for (const int i : order) m.merge(runs[static_cast<std::size_t>(i)]);
    const std::string json = m.to_json();
    if (first.empty()) first = json;
    EXPECT_EQ(json, first);
  } while (std::next_permutation(order.begin(), order.end()));
  // Merging merged pairs: the same.
  CoverageData ab = runs[0], c_then_ab = runs[2];
  ab.merge(runs[1]);
  c_then_ab.merge(ab);
  EXPECT_EQ(c_then_ab.to_json(), first);
}

TEST(CoverageData, AFileReadsBackToTheSameData) {
  CoverageData d = run_a();
  d.merge(run_b());
  d.merge(run_c());
  d.use("L6472");  // in use, nothing hit
  const CoverageData back = CoverageData::from_json(d.to_json());
  EXPECT_EQ(back, d);
  EXPECT_EQ(back.to_json(), d.to_json());
  EXPECT_EQ(CoverageData::from_json(CoverageData{}.to_json()), CoverageData{});
  // A board's own run reads back too.
  Rig r("chips=L6470,L6480,powerSTEP01");
  r.send(move(true, 3), 0);
  r.get_status(1);
  r.board.inject_fault(0, 2, TraceFault::OCD, 1);
  r.board.note_output_edge(0, 2, Pin::FLAG, false);
  EXPECT_EQ(CoverageData::from_json(r.board.coverage().to_json()), r.board.coverage());
}

TEST(CoverageData, ANonCoverageTextIsRefusedInOneLine) {
  const std::string good = run_a().to_json();
  auto replaced = [&](const std::string& from, const std::string& to) {
    std::string t = good;
    const auto at = t.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return t.replace(at, from.size(), to);
  };
  const std::map<std::string, std::string> cases{
      {"not JSON", "this is not { json"},
      {"empty", ""},
      {"a foreign JSON", R"({"name": "package.json", "version": 1})"},
      {"a JSON list", "[1, 2, 3]"},
      {"another version", replaced("\"version\": 1", "\"version\": 2")},
      {"a version as text", replaced("\"version\": 1", "\"version\": \"1\"")},
      {"no version", replaced("\"version\": 1,", "")},
      {"an unknown variant", replaced("\"L6470\"", "\"L6471\"")},
      {"an unknown category", replaced("\"commands\"", "\"comands\"")},
      {"an unknown point", replaced("\"Move FWD\"", "\"Move sideways\"")},
      {"a point of another category", replaced("\"Move FWD\"", "\"ABS_POS\"")},
      {"a chain position hit but not present", [] {
         CoverageData d;
         d.use("L6470").positions = {"chip 0 of 1"};
         d.hit("L6470", CoverageCategory::chain_positions, "chip 9 of 1");
         return d.to_json();
       }()},
      {"a point that is no name", replaced("\"Move FWD\"", "42")},
      {"variants as a list", R"({"format": "l6470emu-coverage", "version": 1, "variants": []})"},
      {"a variant as a list", R"({"format": "l6470emu-coverage", "version": 1, "variants": {"L6470": []}})"},
      {"hit as a list", R"({"format": "l6470emu-coverage", "version": 1, "variants": {"L6470": {"hit": []}}})"},
  };
  for (const auto& [what, text] : cases) {
    const std::string e = one_line_error(text);
    EXPECT_NE(e, "(accepted)") << what << ":\n" << text;
    EXPECT_EQ(e.find('\n'), std::string::npos) << what << ": " << e;
    EXPECT_FALSE(e.empty()) << what;
  }
  EXPECT_NE(one_line_error(replaced("\"version\": 1", "\"version\": 2")).find("version 2"), std::string::npos);
  EXPECT_NE(one_line_error(replaced("\"L6470\"", "\"L6471\"")).find("L6471"), std::string::npos);
  EXPECT_NE(one_line_error(replaced("\"commands\"", "\"comands\"")).find("comands"), std::string::npos);
  EXPECT_NE(one_line_error(replaced("\"Move FWD\"", "\"Move sideways\"")).find("Move sideways"), std::string::npos);
}

// A refusal quotes the file's own names (found by fuzz_coverage, input in
// tests/fuzz/regressions/coverage/): a name holding "\n" or "\u001b" stays one line and puts no
// escape sequence on a terminal.
TEST(CoverageData, ARefusalQuotesTheFilesNamesOnOneLineWithoutControlCharacters) {
  for (const std::string& text :
       {std::string(R"({"format":"l6470emu-coverage","version":1,"variants":{"L6470":{"hit":{"\n":[]}}}})"),
        std::string(R"({"format":"l6470emu-coverage","version":1,"variants":{"L64\u001b[2J70":{}}})"),
        std::string(R"({"format":"l6470emu-coverage","version":1,"variants":{"L6470":{"hit":{"commands":["Move\nFWD"]}}}})")}) {
    const std::string e = one_line_error(text);
    ASSERT_NE(e, "(accepted)") << text;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
    EXPECT_EQ(e.find('\x1b'), std::string::npos) << e;
  }
}

TEST(CoverageData, CategoriesAreNamedBothWays) {
  for (std::size_t c = 0; c < kCoverageCategoryCount; ++c) {
    const auto cat = static_cast<CoverageCategory>(c);
    EXPECT_EQ(coverage_category_named(to_string(cat)), cat);
  }
  EXPECT_EQ(coverage_category_named("Commands"), CoverageCategory::count);
  EXPECT_TRUE(counts_against(CoverageCategory::rules_broken));
  EXPECT_FALSE(counts_against(CoverageCategory::refusals));
}

// ================================================================ the coverage file

TEST(CoverageFile, EightProcessesMergingAtOnceLoseNoPoint) {
  TempDir dir;
  const std::string path = dir.file("coverage.json");
  const std::vector<std::string> names{"ABS_POS", "EL_POS", "MARK", "SPEED", "ACC", "DEC", "MAX_SPEED", "MIN_SPEED"};
  for (int round = 0; round < 3; ++round) {
    std::vector<pid_t> children;
    for (std::size_t i = 0; i < names.size(); ++i) {
      const pid_t pid = fork();
      ASSERT_GE(pid, 0);
      if (pid == 0) {
        CoverageData d;
        d.hit("L6470", CoverageCategory::registers_read, names[i]);
        d.hit("L6480", CoverageCategory::registers_read, names[(i + static_cast<std::size_t>(round)) % names.size()]);
        _exit(merge_into_coverage_file(path, d).empty() ? 0 : 1);
      }
      children.push_back(pid);
    }
    for (const pid_t pid : children) {
      int status = 0;
      ASSERT_EQ(waitpid(pid, &status, 0), pid);
      EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "round " << round;
    }
    const CoverageData d = read_coverage_file(path);
    EXPECT_EQ(d.variants().at("L6470").hit[static_cast<std::size_t>(CoverageCategory::registers_read)],
              Names(names.begin(), names.end()))
        << "round " << round;
    EXPECT_EQ(d.variants().at("L6480").hit[static_cast<std::size_t>(CoverageCategory::registers_read)],
              Names(names.begin(), names.end()));
  }
  // No temporary file is left beside it.
  const RunResult ls = run_command("ls -A '" + dir.file("") + "'");
  EXPECT_EQ(ls.out, "coverage.json\n");
}

TEST(CoverageFile, AMergeIntoAMissingOrEmptyFileStartsIt) {
  TempDir dir;
  const std::string path = dir.file("new.json");
  EXPECT_EQ(merge_into_coverage_file(path, run_a()), "");
  EXPECT_EQ(read_coverage_file(path), run_a());
  const std::string empty = dir.write("empty.json", "");
  EXPECT_EQ(merge_into_coverage_file(empty, run_b()), "");
  EXPECT_EQ(read_coverage_file(empty), run_b());
  EXPECT_EQ(merge_into_coverage_file(path, run_b()), "");
  CoverageData ab = run_a();
  ab.merge(run_b());
  EXPECT_EQ(read_coverage_file(path).to_json(), ab.to_json());
}

TEST(CoverageFile, ACorruptOrForeignFileIsLeftAsItIsAndTheMergeSaysWhy) {
  TempDir dir;
  for (const std::string& text : {std::string("{\"format\": \"l6470emu-coverage\", \"version\": 1, \"vari"),
                                 std::string("{\"name\": \"something else\"}\n"), std::string("\x1f\x8b\x08 binary")}) {
    const std::string path = dir.write("bad.json", text);
    const std::string why = merge_into_coverage_file(path, run_a());
    EXPECT_FALSE(why.empty());
    EXPECT_EQ(why.find('\n'), std::string::npos) << why;
    EXPECT_EQ(why.rfind(path, 0), 0u) << why;
    EXPECT_EQ(read_text(path), text);
    EXPECT_EQ(run_command("ls -A '" + dir.file("") + "'").out, "bad.json\n");
  }
}

TEST(CoverageFile, ReadingNamesTheFileInOneLine) {
  TempDir dir;
  auto error_of = [](const std::string& path) {
    try {
      read_coverage_file(path);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("(read)");
  };
  for (const std::string& path : {dir.file("missing.json"), dir.write("empty.json", ""), dir.write("bad.json", "{]"),
                                  dir.file("")}) {
    const std::string e = error_of(path);
    EXPECT_EQ(e.rfind(path, 0), 0u) << e;
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
  EXPECT_EQ(read_coverage_file(dir.write("good.json", run_c().to_json())), run_c());
}

TEST(CoverageFile, CheckCoverageOutputRefusesADirectoryAMissingFolderAndAForeignFile) {
  TempDir dir;
  const std::map<std::string, std::string> refused{
      {"a directory", dir.file("")},
      {"a missing folder", dir.file("no/such/folder/coverage.json")},
      {"a foreign file", dir.write("foreign.json", "{\"name\": \"not coverage\"}\n")},
      {"a corrupt file", dir.write("corrupt.json", "{\"format\": \"l6470emu-cov")},
      {"another version", dir.write("v2.json", "{\"format\": \"l6470emu-coverage\", \"version\": 2, \"variants\": {}}\n")},
      {"no name", ""},
      {"a device", "/dev/null"},
  };
  for (const auto& [what, path] : refused) {
    const std::string why = check_coverage_output(path);
    EXPECT_FALSE(why.empty()) << what;
    EXPECT_EQ(why.find('\n'), std::string::npos) << what << ": " << why;
  }
  EXPECT_EQ(check_coverage_output(dir.file("new.json")), "");
  EXPECT_EQ(check_coverage_output(dir.write("empty.json", "")), "");
  EXPECT_EQ(check_coverage_output(dir.write("old.json", run_b().to_json())), "");
  EXPECT_EQ(check_coverage_output(dir.file("") + "/./new.json"), "");
}

TEST(CoverageFile, CheckCoverageOutputRefusesAReadOnlyFileAndFolder) {
  if (geteuid() == 0) GTEST_SKIP() << "running as root: access(2) grants root any write, so nothing is read-only here";
  TempDir dir;
  const std::string file = dir.write("ro.json", run_a().to_json());
  ASSERT_EQ(chmod(file.c_str(), 0444), 0);
  EXPECT_NE(check_coverage_output(file), "");
  ASSERT_EQ(mkdir(dir.file("ro").c_str(), 0555), 0);
  EXPECT_NE(check_coverage_output(dir.file("ro/new.json")), "");
}

// A coverage file reached through a symbolic link (one file shared by several build trees) is
// merged into where the link points; the link stays a link.
TEST(CoverageFile, AMergeThroughASymbolicLinkUpdatesTheFileItPointsAt) {
  TempDir dir;
  const std::string target = dir.write("shared.json", run_a().to_json());
  ASSERT_EQ(symlink(target.c_str(), dir.file("link.json").c_str()), 0);
  EXPECT_EQ(check_coverage_output(dir.file("link.json")), "");
  EXPECT_EQ(merge_into_coverage_file(dir.file("link.json"), run_b()), "");
  CoverageData ab = run_a();
  ab.merge(run_b());
  EXPECT_EQ(read_coverage_file(target).to_json(), ab.to_json()) << "the file the link points at did not get the merge";
  struct stat st {};
  ASSERT_EQ(lstat(dir.file("link.json").c_str(), &st), 0);
  EXPECT_TRUE(S_ISLNK(st.st_mode)) << "the link was replaced by a file";
}

// ================================================================ reports

TEST(CoverageReport, FailUnderIsExactAtTheBoundary) {
  EXPECT_TRUE((CoverageCount{1, 4}.at_least(25.0)));
  EXPECT_FALSE((CoverageCount{1, 4}.at_least(25.000001)));
  EXPECT_TRUE((CoverageCount{3, 8}.at_least(37.5)));
  EXPECT_FALSE((CoverageCount{3, 8}.at_least(37.50000000001)));
  EXPECT_TRUE((CoverageCount{1, 3}.at_least(33.3)));
  EXPECT_FALSE((CoverageCount{1, 3}.at_least(33.4)));
  EXPECT_TRUE((CoverageCount{0, 0}.at_least(100.0)));
  EXPECT_TRUE((CoverageCount{7, 7}.at_least(100.0)));
  EXPECT_FALSE((CoverageCount{6, 7}.at_least(100.0)));
  EXPECT_TRUE((CoverageCount{0, 7}.at_least(0.0)));
  EXPECT_EQ((CoverageCount{1, 4}.percent()), 25.0);
  EXPECT_EQ((CoverageCount{0, 0}.percent()), 100.0);
  // Large counts: no overflow, still exact.
  EXPECT_TRUE((CoverageCount{1'000'000'001, 2'000'000'002}.at_least(50.0)));
  EXPECT_FALSE((CoverageCount{1'000'000'000, 2'000'000'001}.at_least(50.0)));
}

TEST(CoverageReport, ATotalCountsEveryPointOfEveryVariantInUseButTheRulesBroken) {
  CoverageData d = run_a();
  d.merge(run_b());
  std::uint64_t expected_total = 0;
  for (const auto& [name, v] : d.variants()) {
    const CoverageUniverse& u = *coverage_universe(name);
    for (const CoveragePoint& p : u.points())
      if (!counts_against(p.category)) ++expected_total;
    expected_total += v.positions.size();  // chain positions come from the chains in use
  }
  const CoverageCount t = coverage_total(d);
  EXPECT_EQ(t.total, expected_total);
  EXPECT_EQ(t.hit, 7u);  // Move FWD, ABS_POS, 2 positions, GoUntil ACT=1, OCD (L6470); CMD_ERROR (L6480)
  CoverageData with_rules = d;
  with_rules.hit("L6470", CoverageCategory::rules_broken, "WRONG_CMD");
  EXPECT_EQ(coverage_total(with_rules).hit, t.hit);
  EXPECT_EQ(coverage_total(with_rules).total, t.total);
}

TEST(CoverageReport, TheTextReportListsTheMissingPointsByCategoryWhenAsked) {
  CoverageData d = run_a();
  const std::string plain = coverage_text(d, false);
  const std::string missing = coverage_text(d, true);
  EXPECT_EQ(plain.find("never hit:"), std::string::npos);
  EXPECT_NE(missing.find("never hit:"), std::string::npos);
  EXPECT_NE(missing.find("    commands: "), std::string::npos) << missing;
  EXPECT_EQ(missing.find("Move FWD,"), std::string::npos) << "a hit point listed as missing";
  EXPECT_NE(plain.find("L6470 (chip 0 of 1)\n"), std::string::npos) << plain;
  EXPECT_NE(plain.find("TOTAL 3 / "), std::string::npos) << plain;
  EXPECT_EQ(coverage_text(CoverageData{}, true), "interface coverage: no chip in use\n");
}

TEST(CoverageReport, TheJsonReportCarriesTheSameNumbers) {
  CoverageData d = run_a();
  d.merge(run_b());
  const std::string text = coverage_json_report(d);
  const nlohmann::json j = nlohmann::json::parse(text);
  const CoverageCount t = coverage_total(d);
  EXPECT_EQ(j["format"], "l6470emu-coverage-report");
  EXPECT_EQ(j["hit"], t.hit);
  EXPECT_EQ(j["total"], t.total);
  const auto& l6470 = j["variants"]["L6470"];
  EXPECT_EQ(l6470["raised but never observed"], nlohmann::json::array({"OCD"}));
  EXPECT_EQ(l6470["categories"]["commands"]["hit points"], nlohmann::json::array({"Move FWD", "GoUntil ACT=1"}));
  EXPECT_EQ(l6470["categories"]["chain positions"]["hit"], 2);
  EXPECT_EQ(l6470["categories"]["chain positions"]["total"], 3);
  EXPECT_EQ(l6470["categories"]["chain positions"]["missing"], nlohmann::json::array({"chip 0 of 3"}));
  const auto s = summarize(d);
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(l6470["hit"], s[0].total.hit);
  EXPECT_EQ(l6470["total"], s[0].total.total);
  // A merge in the other order reports the same bytes.
  CoverageData ba = run_b();
  ba.merge(run_a());
  EXPECT_EQ(coverage_json_report(ba), text);
}

/// The lines of a text, numbered from 1.
std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) out.push_back(line);
  return out;
}

TEST(CoverageReport, EachLcovLineRecordPointsAtTheListingLineOfItsPoint) {
  CoverageData d = run_a();
  d.merge(run_b());
  d.merge(run_c());
  const CoverageLcov lcov = coverage_lcov(d, "/listings");
  ASSERT_EQ(lcov.listings.size(), 3u);
  std::map<std::string, std::vector<std::string>> listing;
  for (const auto& [path, text] : lcov.listings) listing[path] = lines_of(text);

  std::string file;
  std::size_t records = 0, functions = 0;
  std::uint64_t lines_hit = 0;
  std::map<std::string, std::uint64_t> hit_in_file;
  for (const std::string& line : lines_of(lcov.tracefile)) {
    if (line.rfind("SF:", 0) == 0) {
      file = line.substr(3);
      ASSERT_TRUE(listing.count(file)) << file;
      continue;
    }
    if (line.rfind("FN:", 0) == 0) {
      const auto comma = line.find(',');
      const std::size_t n = std::stoul(line.substr(3, comma - 3));
      std::string category = line.substr(comma + 1);
      std::replace(category.begin(), category.end(), '_', ' ');
      ASSERT_LE(n, listing[file].size());
      EXPECT_EQ(listing[file][n - 1].rfind("[" + category + "]", 0), 0u) << file << ":" << n << " " << listing[file][n - 1];
      ++functions;
      continue;
    }
    if (line.rfind("DA:", 0) != 0) continue;
    const auto comma = line.find(',');
    const std::size_t n = std::stoul(line.substr(3, comma - 3));
    const bool hit = line.substr(comma + 1) == "1";
    ASSERT_GE(n, 1u);
    ASSERT_LE(n, listing[file].size()) << line;
    const std::string& text = listing[file][n - 1];
    // The listing line starts with the point's name; the variant's data says whether it was hit.
    const std::string variant = file.substr(file.rfind('/') + 1, file.rfind('.') - file.rfind('/') - 1);
    const auto& v = d.variants().at(variant);
    bool named_hit = false, named = false;
    for (std::size_t c = 0; c < kCoverageCategoryCount; ++c)
      for (const CoveragePoint& p : coverage_universe(variant)->points())
        if (static_cast<std::size_t>(p.category) == c && text.rfind(p.name + "  ", 0) == 0) named = true;
    for (const auto& pos : v.positions)
      if (text.rfind(pos + "  ", 0) == 0) named = true;
    for (const auto& set : v.hit)
      for (const auto& name : set)
        if (text.rfind(name + "  ", 0) == 0) named_hit = true;
    EXPECT_TRUE(named) << file << ":" << n << ": " << text;
    if (hit) {
      EXPECT_TRUE(named_hit) << file << ":" << n << ": " << text;
      ++lines_hit;
      ++hit_in_file[variant];
    }
    ++records;
  }
  EXPECT_EQ(functions, 3u * (kCoverageCategoryCount));
  EXPECT_EQ(records, coverage_total(d).total);
  EXPECT_EQ(lines_hit, coverage_total(d).hit);
  // The hit points land exactly on the lines of their names (in the L6470's record).
  const auto& l6470_listing = listing.at("/listings/L6470.interface");
  const std::size_t from = lcov.tracefile.find("SF:/listings/L6470.interface\n");
  ASSERT_NE(from, std::string::npos);
  const std::string record = lcov.tracefile.substr(from, lcov.tracefile.find("end_of_record\n", from) - from);
  for (const std::string name : {"Move FWD", "ABS_POS", "GoUntil ACT=1", "chip 2 of 3"}) {
    const auto at = std::find_if(l6470_listing.begin(), l6470_listing.end(),
                                 [&](const std::string& l) { return l.rfind(name + " ", 0) == 0; });
    ASSERT_NE(at, l6470_listing.end()) << name;
    const std::size_t n = static_cast<std::size_t>(at - l6470_listing.begin()) + 1;
    EXPECT_NE(record.find("\nDA:" + std::to_string(n) + ",1\n"), std::string::npos) << name << " at line " << n;
  }
  EXPECT_EQ(hit_in_file["L6470"], 6u);
  // A broken rule is listed, marked, and has no DA record.
  const auto rules = std::find(l6470_listing.begin(), l6470_listing.end(),
                               "[rules broken]  (a hit here is a rule broken: listed, never counted)");
  ASSERT_NE(rules, l6470_listing.end());
  const auto broken =
      std::find_if(rules, l6470_listing.end(), [](const std::string& l) { return l.rfind("WRONG_CMD ", 0) == 0; });
  ASSERT_NE(broken, l6470_listing.end());
  EXPECT_NE(broken->find("** BROKEN **"), std::string::npos);
  const std::size_t broken_line = static_cast<std::size_t>(broken - l6470_listing.begin()) + 1;
  EXPECT_EQ(record.find("\nDA:" + std::to_string(broken_line) + ","), std::string::npos);
}

// Chain positions are checked as every other name: a position that is no "chip K of N" (a newline
// in it would shift every later DA record of the LCOV listing) is refused.
TEST(CoverageReport, AChainPositionWithANewlineCannotShiftTheLcovLines) {
  const std::string text = R"({"format": "l6470emu-coverage", "version": 1, "variants": {"L6470": {)"
                           R"("chain positions present": ["chip 0 of 1\nx", "chip 0 of 2"], )"
                           R"("hit": {"commands": ["HardHiZ"], "pin edges": ["BUSY rising"]}}}})";
  CoverageData d;
  try {
    d = CoverageData::from_json(text);
  } catch (const std::runtime_error&) {
    return;  // refused: fine
  }
  const CoverageLcov lcov = coverage_lcov(d, "/listings");
  ASSERT_EQ(lcov.listings.size(), 1u);
  const auto listing = lines_of(lcov.listings[0].second);
  for (const std::string name : {"HardHiZ", "BUSY rising"}) {
    const auto at = std::find_if(listing.begin(), listing.end(), [&](const std::string& l) { return l.rfind(name + " ", 0) == 0; });
    ASSERT_NE(at, listing.end()) << name;
    const std::size_t n = static_cast<std::size_t>(at - listing.begin()) + 1;
    EXPECT_NE(lcov.tracefile.find("\nDA:" + std::to_string(n) + ",1\n"), std::string::npos) << name << " at line " << n;
  }
}

}  // namespace
}  // namespace l6470emu::test
