// RecordingChain (daisychain/recording_chain.hpp): frames with their times, backdoor pins
// and faults, BUSY/FLAG changes, events made while CS is low, spidev messages, and a
// recording that replays against a fresh chain without a single divergence.
#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <sstream>

#include "daisychain/replay.hpp"
#include "spi/message.hpp"
#include "spi/trace_native.hpp"
#include "support/trace_test_support.hpp"

namespace l6470emu {
namespace {

using Bytes = std::vector<std::uint8_t>;
using test::RecordedSession;

Bytes bytes(std::span<const std::uint8_t> s) { return Bytes(s.begin(), s.end()); }

TEST(RecordingChain, WritesTheChainAndTheInitialOutputLevelsFirst) {
  RecordedSession s(2);
  EXPECT_EQ(s.trace.header.chain, "2*L6470");
  ASSERT_EQ(s.trace.size(), 4u);
  EXPECT_EQ(NativeTraceWriter::format_event(s.trace[0]), "0.00000000 pin 0 BUSY 1");
  EXPECT_EQ(NativeTraceWriter::format_event(s.trace[1]), "0.00000000 pin 0 FLAG 0");  // UVLO at power-up
}

TEST(RecordingChain, RecordsEachFrameAtItsCsEdgesWithBothDirections) {
  RecordedSession s(1, RecordOptions{.observe_outputs = false, .board = {}});
  s.frame({0xD0});
  const Bytes rx = s.frame({0x00});
  const TraceEvent e = s.trace[1];
  EXPECT_EQ(e.kind, TraceEventKind::frame);
  EXPECT_EQ(e.tick, 8u + 7u + 8u);
  EXPECT_EQ(e.duration, 7u);
  EXPECT_EQ(bytes(e.mosi), Bytes{0x00});
  EXPECT_EQ(bytes(e.miso), rx);
  EXPECT_EQ(rx, Bytes{0x7C});
}

TEST(RecordingChain, RecordsPinsFaultsAndTheOutputsTheyChange) {
  RecordedSession s(1);
  s.each({0xD0, 0x00, 0x00});  // clears UVLO: FLAG goes high
  const std::size_t before = s.trace.size();
  s.rec.set_overcurrent(0, true);
  s.rec.set_thermal(0, Thermal::warning);
  s.rec.set_adc_input(0, 40);
  s.rec.set_stall(0, Bridge::B, true);
  std::vector<std::string> lines;
  for (std::size_t i = before; i < s.trace.size(); ++i) {
    const std::string l = NativeTraceWriter::format_event(s.trace[i]);
    lines.push_back(l.substr(l.find(' ') + 1));
  }
  EXPECT_EQ(lines, (std::vector<std::string>{"fault 0 OCD on", "pin 0 FLAG 0", "fault 0 THERMAL warning",
                                             "fault 0 ADCIN 31", "fault 0 STALL_B on"}));
}

TEST(RecordingChain, WritesEventsMadeWhileCsIsLowAfterTheFrame) {
  RecordedSession s(1, RecordOptions{.observe_outputs = false, .board = {}});
  s.rec.advance_to(100);
  s.rec.select();
  s.rec.exchange(0xD0);
  s.rec.advance_to(110);
  s.rec.set_sw_pin(0, false);
  s.rec.advance_to(120);
  s.rec.deselect();
  ASSERT_EQ(s.trace.size(), 2u);
  EXPECT_EQ(s.trace[0].kind, TraceEventKind::frame);
  EXPECT_EQ(s.trace[0].tick, 100u);
  EXPECT_EQ(s.trace[1].kind, TraceEventKind::pin);
  EXPECT_EQ(s.trace[1].tick, 110u);
  // The written file reads back: no time goes backwards.
  EXPECT_NO_THROW(read_native_trace(to_native_text(s.trace), "x"));
}

TEST(RecordingChain, RecordsSpidevMessagesFrameByFrame) {
  Chain chain(2);
  Trace trace;
  RecordingChain rec(chain, trace, RecordOptions{.observe_outputs = false, .board = {}});
  const Bytes tx0{0xD0, 0xD0}, tx1{0x00, 0x00};
  Bytes rx0(2), rx1(2);
  const SpiTransfer t[] = {{tx0, rx0, 2, 4'000'000, 0, true}, {tx1, rx1, 2, 4'000'000, 0, false}};
  run_message(rec, t);
  ASSERT_EQ(trace.frame_count(), 2u);
  EXPECT_EQ(bytes(trace[1].miso), (Bytes{0x7C, 0x7C}));
  EXPECT_EQ(trace[0].duration, 16u);  // 2 bytes at 4 MHz: 8 ticks each
  EXPECT_EQ(trace[1].tick, trace[0].end() + BusTiming{}.cs_high_ticks);
}

/// The native text of `trace`, each line without its time.
std::vector<std::string> lines_without_time(const Trace& trace, std::size_t from = 0) {
  std::vector<std::string> lines;
  for (std::size_t i = from; i < trace.size(); ++i) {
    const std::string l = NativeTraceWriter::format_event(trace[i]);
    lines.push_back(l.substr(l.find(' ') + 1));
  }
  return lines;
}

bool has_line(const std::vector<std::string>& lines, const std::string& line) {
  return std::find(lines.begin(), lines.end(), line) != lines.end();
}

/// Replays the native text of a recording against a fresh chain of `chips` L6470s.
ReplayResult replay_text(const std::string& text, std::size_t chips = 1) {
  NativeTraceReader reader(text, "axis.trace");
  Chain fresh(chips);
  return replay_trace(reader, fresh);
}

TEST(RecordingChain, AnAxisAttachedMidRecordingIsAnEventAndTheSwitchItClosesIsObservedAtItsOwnTick) {
  RecordedSession s(1);
  s.each({0xD0, 0x00, 0x00});
  AxisSpec axis;
  axis.start_position = 12'800;
  axis.switches.push_back(SwitchSpec{.name = "home", .position = 0});
  s.rec.attach_axis(0, axis);
  s.frame({0x82});  // GoUntil(reset, reverse) at SPD 0x2000: onto the home switch
  s.frame({0x00});
  s.frame({0x20});
  s.frame({0x00});
  s.wait_ms(3000);
  const std::vector<std::string> lines = lines_without_time(s.trace);
  EXPECT_TRUE(has_line(lines, "axis 0 start=12800,switch=home@0:below:no")) << ::testing::PrintToString(lines);
  EXPECT_TRUE(has_line(lines, "pin 0 SW 1 axis"));  // its level once attached
  EXPECT_TRUE(has_line(lines, "pin 0 SW 0 axis"));  // the switch closing under GoUntil
  EXPECT_TRUE(s.chain.chip(0).busy_sync_pin());     // GoUntil ended on the switch

  // The switch closes at the tick the axis reaches it, and the replay's axis does the same.
  const std::string text = to_native_text(s.trace);
  const ReplayResult r = replay_text(text);
  EXPECT_TRUE(r.matched()) << (r.divergences.empty() ? "" : r.divergences[0].report);

  // Without the axis event the replayed carriage never reaches a switch: the observation says so.
  std::string without = text;
  const std::size_t at = without.find(" axis 0 ");
  without.erase(without.rfind('\n', at) + 1, without.find('\n', at) - without.rfind('\n', at));
  const ReplayResult bare = replay_text(without);
  ASSERT_FALSE(bare.matched());
  EXPECT_NE(bare.divergences[0].summary.find("SW (driven by its axis) expected low"), std::string::npos) << bare.divergences[0].summary;
}

TEST(RecordingChain, AHostDrivenSwitchIsAnInputEvenOnAChipWithAnAxis) {
  RecordedSession s(1);
  s.rec.attach_axis(0, AxisSpec{});
  const std::size_t before = s.trace.size();
  s.rec.set_sw_pin(0, false);
  EXPECT_EQ(lines_without_time(s.trace, before), (std::vector<std::string>{"pin 0 SW 0"}));  // no "SW 0 axis"
}

TEST(RecordingChain, AxisStopsSupplyAndRemovalAreRecordedAndReplayed) {
  RecordedSession s(1);
  s.each({0xD0, 0x00, 0x00});
  s.rec.attach_axis(0, AxisSpec{});
  s.frame({0x50});  // Run forward at SPD 0x4000
  s.frame({0x00});
  s.frame({0x40});
  s.frame({0x00});
  s.wait_ms(200);
  s.rec.set_axis_stops(0, true, -6400, true, 25'600);  // a hard stop ahead: the rotor stalls on it
  s.rec.set_axis_supply(0, 9'000);
  s.wait_ms(1500);
  s.rec.detach_axis(0);
  s.wait_ms(10);
  const std::vector<std::string> lines = lines_without_time(s.trace);
  EXPECT_TRUE(has_line(lines, "axis 0 default"));
  EXPECT_TRUE(has_line(lines, "stops 0 -6400..25600"));
  EXPECT_TRUE(has_line(lines, "supply 0 9000"));
  EXPECT_TRUE(has_line(lines, "axis 0 none"));
  const ReplayResult r = replay_text(to_native_text(s.trace));
  EXPECT_TRUE(r.matched()) << (r.divergences.empty() ? "" : r.divergences[0].report);
  EXPECT_GT(r.pin_checks, 3u);
}

TEST(RecordingChain, ARecordingOfRandomTrafficReplaysWithoutDivergence) {
  // Random commands (valid or not), random waits, pins and faults on a 3-chip chain: the
  // recording, written as text and read back, must replay byte for byte and pin for pin.
  std::mt19937 rng(6470);
  RecordedSession s(3);
  for (int step = 0; step < 400; ++step) {
    const int what = std::uniform_int_distribution<int>(0, 9)(rng);
    if (what < 6) {
      Bytes tx(3);
      for (auto& b : tx) b = static_cast<std::uint8_t>(std::uniform_int_distribution<int>(0, 255)(rng));
      if (what < 2) tx.assign(3, 0xD0);
      s.frame(tx, std::uniform_int_distribution<Tick>(4, 400)(rng));
    } else if (what == 6) {
      s.wait_ms(std::uniform_int_distribution<std::uint64_t>(1, 30)(rng));
    } else if (what == 7) {
      s.rec.set_sw_pin(std::uniform_int_distribution<std::size_t>(0, 2)(rng), rng() & 1);
    } else if (what == 8) {
      s.rec.set_stall(std::uniform_int_distribution<std::size_t>(0, 2)(rng), Bridge::A, rng() & 1);
    } else {
      s.rec.set_stck_pin(std::uniform_int_distribution<std::size_t>(0, 2)(rng), rng() & 1);
    }
  }
  const std::string text = to_native_text(s.trace);
  NativeTraceReader reader(text, "random.trace");
  Chain fresh(3);
  const ReplayResult r = replay_trace(reader, fresh);
  EXPECT_TRUE(r.matched()) << (r.divergences.empty() ? "" : r.divergences[0].report);
  EXPECT_GT(r.frames, 200u);
  EXPECT_GT(r.pin_checks, 10u);
}

}  // namespace
}  // namespace l6470emu
