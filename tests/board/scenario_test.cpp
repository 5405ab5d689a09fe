// Scenarios on the OS-free Board: actions at their exact ticks and events, expectations judged
// with what/when/which chip/expected/seen, the exchange form read back, mistakes named by step.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "board/board.hpp"
#include "board/scenario.hpp"
#include "board/scenario_runner.hpp"
#include "daisychain/replay.hpp"
#include "spi/trace_native.hpp"
#include "spi/message.hpp"
#include "support/board_config_support.hpp"

namespace l6470emu::test {
namespace {

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

// One-byte frames (a chain of one chip), as a driver sends a command.
Tick send(Board& board, std::initializer_list<std::uint8_t> bytes) {
  std::vector<std::uint8_t> tx(bytes);
  std::vector<SpiTransfer> frames;
  for (std::size_t i = 0; i < tx.size(); ++i) {
    SpiTransfer t;
    t.tx = std::span<const std::uint8_t>(&tx[i], 1);
    t.len = 1;
    t.cs_change = i + 1 != tx.size();
    frames.push_back(t);
  }
  return board.transfer(0, frames);
}

ScenarioStep at_time(Tick tick, ScenarioAction a, std::string where = "s.yaml:1") {
  ScenarioStep s;
  s.where = std::move(where);
  s.when.kind = ScenarioTrigger::Kind::time;
  s.when.tick = tick;
  s.action = a;
  return s;
}

ScenarioStep expect_at(ScenarioTrigger when, ScenarioExpectation e, std::string where = "s.yaml:2") {
  ScenarioStep s;
  s.where = std::move(where);
  s.when = std::move(when);
  s.expect = std::move(e);
  return s;
}

ScenarioExpectation reg(std::string name, std::int64_t value, std::int64_t tolerance = 0) {
  ScenarioExpectation e;
  e.kind = ScenarioExpectation::Kind::reg;
  e.name = std::move(name);
  e.value = value;
  e.tolerance = tolerance;
  return e;
}

TEST(ScenarioRunner, TheOutcomeSaysWhenTheHostLastLookedAtEachChipsBusyAndFlagPins) {
  VirtualBoard v("chips=2xL6470 time=virtual");
  ScenarioRunner runner(v.board, Scenario{});
  EXPECT_TRUE(runner.outcome().pin_reads.empty());
  runner.advance_to(1000);
  v.board.note_output_read(0, 1, Pin::FLAG);
  runner.advance_to(2500);
  v.board.note_output_read(0, 1, Pin::FLAG);
  v.board.note_output_read(0, 0, Pin::BUSY);
  v.board.note_output_read(0, 0, Pin::SW);  // an input: the host drives it, nothing to say
  const auto reads = runner.outcome().pin_reads;
  ASSERT_EQ(reads.size(), 2u);
  EXPECT_EQ(reads[0].chain, "spidev0.0");
  EXPECT_EQ(reads[0].chip, 0u);
  EXPECT_EQ(reads[0].pin, "BUSY");
  EXPECT_EQ(reads[0].tick, 2500u);
  EXPECT_EQ(reads[1].chip, 1u);
  EXPECT_EQ(reads[1].pin, "FLAG");
  EXPECT_EQ(reads[1].tick, 2500u);
  EXPECT_EQ(v.board.last_output_read(0, 1, Pin::BUSY), kNever);
}

TEST(ScenarioRunner, SerialTextReachesTheProgramsSerialAtItsTick) {
  VirtualBoard v("chips=L6470 time=virtual");
  ScenarioAction typed;
  typed.kind = ScenarioAction::Kind::serial;
  typed.text = "MOVE 12800\n";
  Scenario s;
  s.steps.push_back(at_time(ticks_from_ms(500), typed));
  std::string arrived;
  ScenarioRunner runner(v.board, s, [&](std::string_view bytes) { arrived += bytes; });
  EXPECT_EQ(runner.next_tick(), ticks_from_ms(500));
  runner.advance_to(ticks_from_ms(499));
  EXPECT_EQ(arrived, "");
  runner.advance_to(ticks_from_ms(1000));
  EXPECT_EQ(arrived, "MOVE 12800\n");
  ASSERT_EQ(runner.log().size(), 1u);
  EXPECT_EQ(runner.log()[0], "0.500000 s: s.yaml:1: Serial: typed \"MOVE 12800\\n\"");
  runner.finish();
  EXPECT_TRUE(runner.failures().empty());
}

TEST(ScenarioRunner, SerialTextForAProgramWithNoSerialFailsNamedWhenItFires) {
  VirtualBoard v("chips=L6470 time=virtual");
  ScenarioAction typed;
  typed.kind = ScenarioAction::Kind::serial;
  typed.text = "G\n";
  Scenario s;
  s.steps.push_back(at_time(ticks_from_ms(10), typed));
  ScenarioRunner runner(v.board, s);  // the preload's: no Serial
  runner.advance_to(ticks_from_ms(20));
  runner.finish();
  ASSERT_EQ(runner.failures().size(), 1u);
  const ScenarioFailure& f = runner.failures()[0];
  EXPECT_EQ(f.where, "s.yaml:1");
  EXPECT_EQ(f.what, "serial input");
  EXPECT_EQ(f.chip, "Serial");
  EXPECT_EQ(f.tick, ticks_from_ms(10));
  EXPECT_EQ(f.expected, "a program whose Serial reads it (a firmware sketch)");
  EXPECT_EQ(f.seen, "a program with no Serial (under the preload): \"G\\n\" went nowhere");
  EXPECT_EQ(runner.judged(), 1u);
}

TEST(ScenarioRunner, ATimedSwitchClosureReachesTheChipAtItsTickWhateverTheHostWaitsFor) {
  VirtualBoard v("chips=L6470; time=virtual");
  ScenarioAction close;
  close.kind = ScenarioAction::Kind::sw;
  close.level = false;
  Scenario s;
  s.steps.push_back(at_time(ticks_from_ms(100), close));
  ScenarioTrigger end;
  end.kind = ScenarioTrigger::Kind::end;
  ScenarioExpectation st;
  st.kind = ScenarioExpectation::Kind::status;
  st.flags = {{"SW_F", true}, {"SW_EVN", true}};
  s.steps.push_back(expect_at(end, st));
  ScenarioRunner runner(v.board, s);
  EXPECT_EQ(runner.next_tick(), ticks_from_ms(100));
  runner.advance_to(ticks_from_ms(1000));  // one jump, as a host sleeping a second makes
  EXPECT_EQ(runner.next_tick(), kNever);
  EXPECT_FALSE(v.board.pin_level(0, 0, Pin::SW));
  ASSERT_FALSE(runner.log().empty());
  EXPECT_EQ(runner.log()[0].rfind("0.100000 s: s.yaml:1: spidev0.0 chip 0: SW closed", 0), 0u) << runner.log()[0];
  runner.finish();
  EXPECT_TRUE(runner.failures().empty());
  EXPECT_EQ(runner.judged(), 1u);
}

TEST(ScenarioRunner, StepsAddedWhileItRunsFireAtTheirTicksAndAreJudgedAtTheEnd) {
  // As a campaign's rerun forked from a snapshot adds its fault and its oracle.
  VirtualBoard v("chips=L6470; time=virtual");
  ScenarioRunner runner(v.board, Scenario{});
  runner.advance_to(ticks_from_ms(50));
  ScenarioAction close;
  close.kind = ScenarioAction::Kind::sw;
  close.level = false;
  ScenarioTrigger end;
  end.kind = ScenarioTrigger::Kind::end;
  ScenarioExpectation st;
  st.kind = ScenarioExpectation::Kind::status;
  st.flags = {{"SW_F", true}};
  runner.add_steps({at_time(ticks_from_ms(50), close, "the fault"), expect_at(end, st, "the oracle")});
  EXPECT_FALSE(v.board.pin_level(0, 0, Pin::SW));  // due now: fired at once
  runner.finish();
  EXPECT_TRUE(runner.failures().empty());
  EXPECT_EQ(runner.judged(), 1u);
}

TEST(ScenarioRunner, OnlyStepsAtATimeOrAtTheEndCanJoinARunningScenarioAndABadOneAddsNothing) {
  VirtualBoard v("chips=L6470; time=virtual");
  ScenarioRunner runner(v.board, Scenario{});
  ScenarioTrigger busy;
  busy.kind = ScenarioTrigger::Kind::busy_fall;
  EXPECT_THROW(runner.add_steps({expect_at(busy, reg("ABS_POS", 0))}), std::invalid_argument);
  ScenarioTrigger end;
  end.kind = ScenarioTrigger::Kind::end;
  try {
    runner.add_steps({expect_at(end, reg("ABS_POS", 0)), expect_at(end, reg("NO_SUCH", 0), "s.yaml:9")});
    ADD_FAILURE() << "a register the chip lacks was taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("s.yaml:9"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(runner.scenario().steps.empty());
  runner.finish();
  EXPECT_EQ(runner.judged(), 0u);
}

TEST(ScenarioRunner, APositionTriggerFiresAtTheExactTickTheRegisterReachesIt) {
  VirtualBoard v("chips=L6470; time=virtual");
  Scenario s;
  ScenarioTrigger at_pos;
  at_pos.kind = ScenarioTrigger::Kind::position;
  at_pos.position = 5000;
  s.steps.push_back(expect_at(at_pos, reg("ABS_POS", 5000), "s.yaml:3"));
  ScenarioTrigger end;
  end.kind = ScenarioTrigger::Kind::end;
  s.steps.push_back(expect_at(end, reg("ABS_POS", 10001), "s.yaml:4"));  // one off: must fail
  ScenarioRunner runner(v.board, s);
  const Tick t = send(v.board, {0x41, 0x00, 0x27, 0x10});  // Move(forward, 10000 microsteps)
  runner.after_transfer();
  runner.advance_to(t + ticks_from_ms(2000));
  runner.finish();
  ASSERT_EQ(runner.failures().size(), 1u);
  const ScenarioFailure& f = runner.failures()[0];
  EXPECT_EQ(f.where, "s.yaml:4");
  EXPECT_EQ(f.what, "ABS_POS");
  EXPECT_EQ(f.chip, "spidev0.0 chip 0");
  EXPECT_EQ(f.expected, "10001");
  EXPECT_EQ(f.seen, "10000");
  EXPECT_EQ(f.tick, t + ticks_from_ms(2000));
  EXPECT_EQ(runner.judged(), 2u);
}

TEST(ScenarioRunner, BusyPulsesCommandsAndFramesAreCountedAndJudgedAtTheEnd) {
  VirtualBoard v("chips=L6470; time=virtual");
  Scenario s;
  ScenarioTrigger end;
  end.kind = ScenarioTrigger::Kind::end;
  ScenarioExpectation pulse;
  pulse.kind = ScenarioExpectation::Kind::busy_pulse;
  pulse.pulse = 1;
  pulse.min_ticks = ticks_from_ms(1);
  pulse.max_ticks = ticks_from_ms(5);  // the move takes longer: fails with the length seen
  s.steps.push_back(expect_at(end, pulse, "s.yaml:5"));
  ScenarioExpectation sent;
  sent.kind = ScenarioExpectation::Kind::command;
  sent.name = "Move";
  s.steps.push_back(expect_at(end, sent, "s.yaml:6"));
  ScenarioExpectation not_sent = sent;
  not_sent.name = "SoftStop";
  not_sent.count = 0;
  s.steps.push_back(expect_at(end, not_sent, "s.yaml:7"));
  ScenarioExpectation frames;
  frames.kind = ScenarioExpectation::Kind::frames;
  frames.min_count = frames.max_count = 4;
  s.steps.push_back(expect_at(end, frames, "s.yaml:8"));
  ScenarioRunner runner(v.board, s);
  const Tick t = send(v.board, {0x41, 0x00, 0x27, 0x10});
  runner.after_transfer();
  runner.advance_to(t + ticks_from_ms(2000));
  runner.finish();
  ASSERT_EQ(runner.failures().size(), 1u);
  EXPECT_EQ(runner.failures()[0].what.rfind("BUSY pulse 1", 0), 0u);
  EXPECT_EQ(runner.failures()[0].expected, "0.001000 s .. 0.005000 s");
  EXPECT_NE(runner.failures()[0].seen, "still low at the end");
  EXPECT_EQ(runner.judged(), 4u);
}

ScenarioExpectation status_is(std::vector<std::pair<std::string, bool>> flags) {
  ScenarioExpectation e;
  e.kind = ScenarioExpectation::Kind::status;
  e.flags = std::move(flags);
  return e;
}

ScenarioTrigger at(Tick tick) {
  ScenarioTrigger t;
  t.kind = ScenarioTrigger::Kind::time;
  t.tick = tick;
  return t;
}

TEST(ScenarioRunner, TheTemperatureTheAdcTheSupplyAndStandbyReachTheChipAtTheirTicks) {
  VirtualBoard v("chips=L6470 axis.0=stops=-1000000..1000000; time=virtual");
  Scenario s;
  ScenarioAction hot;
  hot.kind = ScenarioAction::Kind::fault;
  hot.fault = TraceFault::THERMAL;
  hot.value = static_cast<std::uint8_t>(Thermal::warning);
  s.steps.push_back(at_time(ticks_from_ms(1), hot, "s.yaml:1"));
  s.steps.push_back(expect_at(at(ticks_from_ms(2)), status_is({{"TH_WRN", false}}), "s.yaml:2"));
  ScenarioAction adc;
  adc.kind = ScenarioAction::Kind::fault;
  adc.fault = TraceFault::ADCIN;
  adc.value = 17;
  s.steps.push_back(at_time(ticks_from_ms(3), adc, "s.yaml:3"));
  s.steps.push_back(expect_at(at(ticks_from_ms(4)), reg("ADC_OUT", 17), "s.yaml:4"));
  ScenarioAction low_supply;
  low_supply.kind = ScenarioAction::Kind::supply;
  low_supply.supply_mV = 6000;  // below the 7.2 V UVLO threshold
  s.steps.push_back(at_time(ticks_from_ms(5), low_supply, "s.yaml:5"));
  s.steps.push_back(expect_at(at(ticks_from_ms(6)), status_is({{"UVLO", false}}), "s.yaml:6"));
  ScenarioAction standby;
  standby.kind = ScenarioAction::Kind::stby_rst;
  standby.level = false;
  s.steps.push_back(at_time(ticks_from_ms(7), standby, "s.yaml:7"));
  ScenarioAction wake = standby;
  wake.level = true;
  s.steps.push_back(at_time(ticks_from_ms(8), wake, "s.yaml:8"));
  // The reset put MAX_SPEED back to its power-up value, 0x041, after the host wrote 0x020.
  s.steps.push_back(expect_at(at(ticks_from_ms(9)), reg("MAX_SPEED", 0x041), "s.yaml:9"));
  ScenarioRunner runner(v.board, s);
  send(v.board, {0x07, 0x00, 0x20});  // SetParam(MAX_SPEED, 0x020)
  runner.after_transfer();
  runner.advance_to(ticks_from_ms(10));
  runner.finish();
  for (const ScenarioFailure& f : runner.failures())
    ADD_FAILURE() << f.where << ": " << f.what << ": expected " << f.expected << ", seen " << f.seen;
  EXPECT_EQ(runner.judged(), 4u);
  EXPECT_EQ(runner.log().size(), 5u);
}

TEST(ScenarioRunner, BusyFallTruePositionTriggersAndAHardStopActAtTheirTicks) {
  VirtualBoard v("chips=L6470 axis.0=stops=-1000000..1000000; time=virtual");
  Scenario s;
  ScenarioTrigger fall;
  fall.kind = ScenarioTrigger::Kind::busy_fall;
  s.steps.push_back(expect_at(fall, status_is({{"BUSY", false}}), "s.yaml:1"));
  // When the rotor reaches 20 full steps, a block appears 10 full steps further on.
  ScenarioTrigger rotor;
  rotor.kind = ScenarioTrigger::Kind::true_position;
  rotor.position = 20 * 128;
  s.steps.push_back(expect_at(rotor, reg("ABS_POS", 20 * 128, 1), "s.yaml:2"));
  ScenarioStep block;
  block.where = "s.yaml:3";
  block.when = rotor;
  block.action = ScenarioAction{};
  block.action->kind = ScenarioAction::Kind::block;
  block.action->position = 30 * 128;
  s.steps.push_back(block);
  ScenarioTrigger end;
  end.kind = ScenarioTrigger::Kind::end;
  ScenarioExpectation rotor_at;
  rotor_at.kind = ScenarioExpectation::Kind::true_position;
  rotor_at.value = 30 * 128;
  rotor_at.tolerance = 4 * 128;  // it stalls at the stop, within the rotor's pull-out of a few steps
  s.steps.push_back(expect_at(end, rotor_at, "s.yaml:4"));
  ScenarioRunner runner(v.board, s);
  const Tick t = send(v.board, {0x41, 0x00, 0x64, 0x00});  // Move(forward, 200 full steps)
  runner.after_transfer();
  runner.advance_to(t + ticks_from_ms(3000));
  runner.finish();
  for (const ScenarioFailure& f : runner.failures())
    ADD_FAILURE() << f.where << ": " << f.what << ": expected " << f.expected << ", seen " << f.seen;
  EXPECT_EQ(runner.judged(), 3u);
  // ABS_POS counted the whole move: the rotor did not follow past the stop.
  EXPECT_EQ(v.board.chain(0).chip(0).position(), 200 * 128);
}

TEST(ScenarioRunner, AnActionOnACommandSeenIsAppliedWhenTheBusUseEnds) {
  VirtualBoard v("chips=L6470; time=virtual");
  Scenario s;
  ScenarioStep st;
  st.where = "s.yaml:9";
  st.when.kind = ScenarioTrigger::Kind::command;
  st.when.command = "run";  // names are matched ignoring case
  ScenarioAction ocd;
  ocd.kind = ScenarioAction::Kind::fault;
  ocd.fault = TraceFault::OCD;
  ocd.value = 1;
  st.action = ocd;
  s.steps.push_back(st);
  ScenarioTrigger end;
  end.kind = ScenarioTrigger::Kind::end;
  ScenarioExpectation flags;
  flags.kind = ScenarioExpectation::Kind::status;
  flags.flags = {{"OCD", false}};  // active low: 0 = overcurrent seen
  s.steps.push_back(expect_at(end, flags));
  ScenarioRunner runner(v.board, s);
  send(v.board, {0xD0, 0x00, 0x00});  // GetStatus: the power-up UVLO latch released
  EXPECT_TRUE(v.board.pin_level(0, 0, Pin::FLAG));
  send(v.board, {0x51, 0x00, 0x10, 0x00});  // Run(forward)
  runner.after_transfer();
  EXPECT_FALSE(v.board.pin_level(0, 0, Pin::FLAG));
  runner.finish();
  EXPECT_TRUE(runner.failures().empty()) << runner.failures()[0].seen;
}

TEST(ScenarioRunner, AStepNamingWhatTheBoardLacksIsRefusedWithItsPlace) {
  VirtualBoard v("chips=L6470,L6470; numbering=mosi");
  Scenario s;
  ScenarioTrigger end;
  end.kind = ScenarioTrigger::Kind::end;
  ScenarioExpectation e = reg("ABS_PS", 0);
  s.steps.push_back(expect_at(end, e, "s.yaml:12"));
  try {
    ScenarioRunner runner(v.board, s);
    FAIL();
  } catch (const std::invalid_argument& ex) {
    EXPECT_EQ(std::string(ex.what()), "s.yaml:12: the L6470 has no register 'ABS_PS'");
  }
  s.steps[0].expect = reg("ABS_POS", 0);
  s.steps[0].expect->chip.number = 2;
  try {
    ScenarioRunner runner(v.board, s);
    FAIL();
  } catch (const std::invalid_argument& ex) {
    EXPECT_NE(std::string(ex.what()).find("s.yaml:12: no chip 2 on spidev0.0 (chips 0..1"), std::string::npos) << ex.what();
  }
}

TEST(ScenarioRunner, ChipNumbersAreTheUsersNumbering) {
  VirtualBoard v("chips=L6470,L6480; numbering=mosi; time=virtual");
  Scenario s;
  ScenarioTrigger end;
  end.kind = ScenarioTrigger::Kind::end;
  ScenarioExpectation e = reg("GATECFG1", 0);  // only the L6480 (chain index 1 = user chip 0) has it
  s.steps.push_back(expect_at(end, e));
  ScenarioRunner runner(v.board, s);
  runner.finish();
  EXPECT_TRUE(runner.failures().empty());
}

ScenarioAction one_shot(TraceFault fault, std::size_t chip, std::uint8_t value = 0) {
  ScenarioAction a;
  a.kind = ScenarioAction::Kind::fault;
  a.fault = fault;
  a.value = value;
  a.chip.number = chip;
  return a;
}

TEST(ScenarioRunner, TheOneShotFaultsActAtTheirTicksAndTheRecordingReplaysThemExactly) {
  VirtualBoard v("chips=L6470,L6470,L6470; time=virtual");
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("l6470emu-one-shot-" + std::to_string(std::random_device{}()) + ".trace")).string();
  ASSERT_EQ(v.board.start_recording(0, path), "");
  Scenario s;
  s.steps.push_back(at_time(ticks_from_ms(10), one_shot(TraceFault::POWER_CYCLE, 0), "s.yaml:1"));
  s.steps.push_back(at_time(ticks_from_ms(20), one_shot(TraceFault::MISO_FLIP, 1, 7), "s.yaml:2"));
  s.steps.push_back(at_time(ticks_from_ms(30), one_shot(TraceFault::LOST_FRAME, 0), "s.yaml:3"));
  ScenarioRunner runner(v.board, s);
  std::array<std::uint8_t, 3> rx{};
  auto frame = [&](std::array<std::uint8_t, 3> tx) {
    SpiTransfer t;
    t.tx = tx;
    t.rx = rx;
    t.len = 3;
    v.board.transfer(0, std::span<const SpiTransfer>(&t, 1));
    runner.after_transfer();
    return rx;
  };
  using Three = std::array<std::uint8_t, 3>;
  frame({0xD0, 0xD0, 0xD0});
  frame({0x00, 0x00, 0x00});
  frame({0x00, 0x00, 0x00});  // the power-up UVLO latches released
  frame({0x2A, 0x2A, 0x2A});  // GetParam(KVAL_RUN): the answers wait in the registers
  runner.advance_to(ticks_from_ms(15));
  EXPECT_FALSE(v.board.pin_level(0, 0, Pin::FLAG)) << "chip 0 is back with UVLO latched";
  EXPECT_EQ(frame({0x00, 0x00, 0x00}), (Three{0x00, 0x29, 0x29})) << "chip 0's answer went with the power";
  frame({0x2A, 0x2A, 0x2A});
  runner.advance_to(ticks_from_ms(25));
  EXPECT_EQ(frame({0x00, 0x00, 0x00}), (Three{0x29, 0x29 ^ 0x80, 0x29})) << "chip 1's MSB inverted on the wire";
  runner.advance_to(ticks_from_ms(35));
  frame({0x0A, 0x0A, 0x0A});  // SetParam(KVAL_RUN): chip 0 misses it
  frame({0x00, 0x22, 0x33});
  v.board.with_chain(0, [](Chain& c) {
    EXPECT_EQ(c.chip(0).peek(Reg::KVAL_RUN), 0x29u);
    EXPECT_EQ(c.chip(1).peek(Reg::KVAL_RUN), 0x22u);
    EXPECT_EQ(c.chip(2).peek(Reg::KVAL_RUN), 0x33u);
  });
  runner.finish();
  EXPECT_TRUE(runner.failures().empty());
  ASSERT_GE(runner.log().size(), 3u);
  ASSERT_TRUE(v.board.stop_recording(0));

  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  std::remove(path.c_str());
  EXPECT_NE(text.str().find(" fault 0 POWER_CYCLE\n"), std::string::npos) << text.str();
  EXPECT_NE(text.str().find(" fault 1 MISO_FLIP 7\n"), std::string::npos);
  EXPECT_NE(text.str().find(" fault 0 LOST_FRAME\n"), std::string::npos);
  const std::string recorded = text.str();  // the reader keeps a view of it
  NativeTraceReader reader(recorded, "one-shot.trace");
  Chain fresh(3);
  const ReplayResult r = replay_trace(reader, fresh);
  EXPECT_TRUE(r.matched()) << (r.divergences.empty() ? "" : r.divergences[0].report);
  EXPECT_EQ(r.divergent_frames, 0u);
  EXPECT_EQ(r.frames, 9u);
}

TEST(ScenarioExchange, AScenarioReadsBackAsItWasWritten) {
  Scenario s;
  s.name = "homing";
  s.timeout_ticks = ticks_from_ms(30'000);
  ScenarioAction load;
  load.kind = ScenarioAction::Kind::load;
  load.chip = ScenarioChip{"spidev0.1", 2};
  load.load.force_uNm = -5000;
  s.steps.push_back(at_time(7, load));
  ScenarioExpectation st;
  st.kind = ScenarioExpectation::Kind::status;
  st.flags = {{"UVLO", true}};
  ScenarioTrigger cmd;
  cmd.kind = ScenarioTrigger::Kind::command;
  cmd.command = "GoUntil";
  cmd.count = 3;
  s.steps.push_back(expect_at(cmd, st));
  s.steps.push_back(at_time(9, one_shot(TraceFault::LOST_FRAME, 1)));
  s.steps.push_back(at_time(10, one_shot(TraceFault::MISO_FLIP, 0, 5)));
  ScenarioAction typed;
  typed.kind = ScenarioAction::Kind::serial;
  typed.text = "G 100\r\n\xff";  // bytes, as they are
  s.steps.push_back(at_time(11, typed));
  std::string error;
  const auto back = deserialize_scenario(serialize_scenario(s), error);
  ASSERT_TRUE(back) << error;
  EXPECT_EQ(*back, s);
  EXPECT_FALSE(deserialize_scenario("{\"l6470emu_scenario\":1,\"name\":\"78\",\"steps\":[{}]}", error));
  s.name = "\xff\xfe not UTF-8";  // names are bytes
  ASSERT_TRUE(deserialize_scenario(serialize_scenario(s), error));
  EXPECT_EQ(deserialize_scenario(serialize_scenario(s), error)->name, s.name);
  EXPECT_NE(error.find("not a scenario"), std::string::npos);
}

}  // namespace
}  // namespace l6470emu::test

namespace l6470emu::test {
namespace {

TEST(ScenarioRunner, ADirStepTurnsTheWayAnL6474StepsAndIsRefusedForAChipWithoutTheDirPin) {
  VirtualBoard v("chips=L6474; time=virtual");
  send(v.board, {0xB8});  // Enable: the bridges on, STCK moves the motor
  Scenario s;
  ScenarioAction reverse;
  reverse.kind = ScenarioAction::Kind::dir;
  reverse.level = false;
  s.steps.push_back(at_time(ticks_from_ms(1), reverse, "s.yaml:1"));
  s.steps.push_back(expect_at(at(ticks_from_ms(3)), reg("ABS_POS", -10), "s.yaml:2"));  // signed, as ABS_POS reads
  ScenarioRunner runner(v.board, s);
  auto pulses = [&](int n, Tick from) {
    for (int k = 0; k < n; ++k) {
      runner.advance_to(from + 8 * k);
      v.board.drive_pin(0, 0, Pin::STCK, true);
      runner.advance_to(from + 8 * k + 4);
      v.board.drive_pin(0, 0, Pin::STCK, false);
    }
  };
  v.board.drive_pin(0, 0, Pin::DIR, true);
  pulses(10, ticks_from_us(10));   // forward: +10
  pulses(20, ticks_from_ms(2));    // after the step: -20
  runner.advance_to(ticks_from_ms(4));
  runner.finish();
  for (const ScenarioFailure& f : runner.failures())
    ADD_FAILURE() << f.where << ": " << f.what << ": expected " << f.expected << ", seen " << f.seen;
  EXPECT_EQ(runner.judged(), 1u);
  EXPECT_NE(runner.log().at(0).find("DIR low (reverse)"), std::string::npos) << runner.log().at(0);
  // run's exchange form carries the step (the fuzzer found it refused as "bad kind").
  std::string error;
  const std::optional<Scenario> back = deserialize_scenario(serialize_scenario(s), error);
  ASSERT_TRUE(back) << error;
  EXPECT_EQ(*back, s);

  VirtualBoard l6470("chips=L6470; time=virtual");
  try {
    ScenarioRunner refused(l6470.board, s);
    ADD_FAILURE() << "a dir: step for an L6470 was taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("(L6470) has no DIR pin for dir: (an L6474 has)"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace l6470emu::test
