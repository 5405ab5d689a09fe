// sample_motion (daisychain/motion_series.hpp): samples are the chip's exact state at their
// ticks, MOT_STATUS and BUSY edges are sampled at the tick they happen, commands become
// marks, the window and the chip list are honoured, and long runs stay within max_points.
#include <gtest/gtest.h>

#include <algorithm>

#include "daisychain/chain_spec.hpp"
#include "daisychain/host.hpp"
#include "daisychain/motion_series.hpp"
#include "spi/trace_native.hpp"
#include "support/trace_test_support.hpp"

namespace l6470emu {
namespace {

/// A recorded session: one chip (of `n`) makes a Move and the trace goes on polling.
struct MovedChain {
  Chain chain;
  Trace trace;
  RecordingChain rec;
  ChainHost host;
  explicit MovedChain(std::size_t n) : chain(n), rec(chain, trace), host(chain, rec) {}
};

MotionSeries sample(const Trace& trace, const MotionOptions& o = {}) {
  Chain fresh = make_chain(parse_chain_spec(trace.header.chain));
  auto pass = trace.reader();
  const Tick end = trace_end_tick(*pass);
  auto reader = trace.reader();
  return sample_motion(*reader, fresh, end, o);
}

TEST(MotionSeries, EverySampleIsTheChipsExactStateAtItsTick) {
  MovedChain s(1);
  s.host.move(0, true, 3200);
  s.host.wait_ms(600);
  s.host.get_status(0);
  const MotionSeries m = sample(s.trace);
  ASSERT_EQ(m.chips.size(), 1u);
  const auto& v = m.chips[0].samples;
  ASSERT_GT(v.size(), 10u);
  // A second chain driven by the same trace, stopped at each sample's tick, agrees.
  for (std::size_t i = 0; i < v.size(); i += std::max<std::size_t>(1, v.size() / 25)) {
    Chain probe(1);
    auto reader = s.trace.reader();
    TraceEvent e;
    std::vector<std::uint8_t> rx;
    while (reader->next(e) && (e.kind == TraceEventKind::frame ? e.end() : e.tick) <= v[i].tick) {
      if (e.kind != TraceEventKind::frame) continue;
      probe.advance_to(e.tick);
      rx.resize(e.mosi.size());
      probe.select();
      probe.exchange(e.mosi, rx);
      probe.advance_to(e.end());
      probe.deselect();
    }
    probe.advance_to(v[i].tick);
    EXPECT_EQ(v[i].abs_pos, probe.chip(0).position()) << "sample " << i;
    EXPECT_EQ(std::abs(v[i].speed), static_cast<std::int32_t>(probe.chip(0).peek(Reg::SPEED))) << "sample " << i;
  }
  EXPECT_EQ(v.back().abs_pos, 3200);
  EXPECT_EQ(v.back().speed, 0);
  EXPECT_TRUE(v.back().busy);
}

TEST(MotionSeries, BusyRisesAtTheTickTheMoveEnds) {
  MovedChain s(1);
  s.host.move(0, true, 128000);  // 1000 full steps: long enough to reach MAX_SPEED
  const Tick start = s.chain.now();
  s.host.wait_ms(2000);
  s.host.get_status(0);  // the trace goes on past the move's end
  const MotionSeries m = sample(s.trace);
  const auto& v = m.chips[0].samples;
  const auto rise = std::find_if(v.begin(), v.end(), [&](const MotionSample& x) { return x.tick > start && x.busy; });
  ASSERT_NE(rise, v.end());
  ASSERT_NE(rise, v.begin());
  // The tick before the edge the chip was still busy.
  Chain probe(1);
  ChainHost h(probe);
  h.move(0, true, 128000);
  probe.advance_to(rise->tick - 1);
  EXPECT_FALSE(probe.chip(0).busy_sync_pin());
  probe.advance_to(rise->tick);
  EXPECT_TRUE(probe.chip(0).busy_sync_pin());
  // and every phase change (MOT_STATUS) is a sample of its own: accelerate, decelerate, stop.
  std::vector<int> phases;
  for (const MotionSample& x : v)
    if (phases.empty() || phases.back() != x.mot_status) phases.push_back(x.mot_status);
  EXPECT_EQ(phases, (std::vector<int>{0, 1, 3, 2, 0}));
}

TEST(MotionSeries, ReverseMotionHasNegativeSpeed) {
  MovedChain s(1);
  s.host.run(0, false, 0x4189);  // 250 step/s in reverse
  s.host.wait_ms(300);
  const MotionSeries m = sample(s.trace);
  const auto& v = m.chips[0].samples;
  EXPECT_LT(v.back().speed, 0);
  EXPECT_LT(v.back().abs_pos, 0);
}

TEST(MotionSeries, CommandsBecomeMarksAtTheirFramesEnd) {
  MovedChain s(2);
  s.host.set_param(1, Reg::ACC, 0x100);
  s.host.move(1, true, 3200);
  s.host.get_status(1);
  s.host.wait_ms(50);
  s.host.soft_stop(1);
  s.host.wait_ms(300);
  const MotionSeries m = sample(s.trace);
  ASSERT_EQ(m.chips.size(), 2u);
  EXPECT_TRUE(m.chips[0].commands.empty());
  const auto& c = m.chips[1].commands;
  ASSERT_EQ(c.size(), 3u);  // GetStatus, GetParam and NOP are not marks
  EXPECT_EQ(c[0].name, "SetParam(ACC)");
  EXPECT_EQ(c[1].name, "Move(FWD)");
  EXPECT_EQ(c[1].text, "Move(FWD, 3200 microsteps)");
  EXPECT_EQ(c[2].name, "SoftStop");
  EXPECT_LT(c[1].tick, c[2].tick);
  EXPECT_EQ(m.chips[1].microsteps_per_step, 128u);
}

TEST(MotionSeries, OnlyTheChosenChipsInTheChosenWindow) {
  MovedChain s(3);
  s.host.move(2, true, 6400);
  s.host.wait_ms(800);
  MotionOptions o;
  o.chips = {2};
  o.from = ticks_from_ms(100);
  o.to = ticks_from_ms(200);
  const MotionSeries m = sample(s.trace, o);
  ASSERT_EQ(m.chips.size(), 1u);
  EXPECT_EQ(m.chips[0].chip, 2u);
  const auto& v = m.chips[0].samples;
  ASSERT_FALSE(v.empty());
  EXPECT_EQ(v.front().tick, o.from);
  EXPECT_EQ(v.back().tick, o.to);
  EXPECT_GT(v.front().abs_pos, 0);  // the move began before the window
  EXPECT_TRUE(m.chips[0].commands.empty());
}

TEST(MotionSeries, ARunLeftGoingIsFollowedForTheTailOnly) {
  MovedChain s(1);
  s.host.run(0, true, 0x4189);
  s.host.wait_ms(10);
  const MotionSeries m = sample(s.trace);
  EXPECT_EQ(m.to, m.trace_end + kTicksPerSecond);
  EXPECT_EQ(m.chips[0].samples.back().tick, m.to);
}

TEST(MotionSeries, ALongRunStaysWithinMaxPoints) {
  MovedChain s(1);
  for (int i = 0; i < 200; ++i) {
    s.host.move(0, i % 2 == 0, 3200);
    s.host.wait_ms(400);
    s.host.get_status(0);
  }
  MotionOptions o;
  o.max_points = 500;
  const MotionSeries m = sample(s.trace, o);
  EXPECT_LE(m.chips[0].samples.size(), 500u);
  EXPECT_GT(m.chips[0].samples.size(), 200u);
  EXPECT_EQ(m.chips[0].commands.size(), 200u);
  // The extremes survive thinning.
  int hi = 0;
  for (const MotionSample& x : m.chips[0].samples) hi = std::max(hi, x.abs_pos);
  EXPECT_EQ(hi, 3200);
}

TEST(MotionSeries, BadChipsAndEmptyWindowsAreRefused) {
  MovedChain s(2);
  s.host.move(0, true, 100);
  MotionOptions chip;
  chip.chips = {5};
  EXPECT_THROW(sample(s.trace, chip), std::invalid_argument);
  MotionOptions window;
  window.from = ticks_from_ms(10);
  window.to = ticks_from_ms(5);
  EXPECT_THROW(sample(s.trace, window), std::invalid_argument);
  MotionOptions late;
  late.from = ticks_from_ms(100000);
  EXPECT_THROW(sample(s.trace, late), std::invalid_argument);
}

/// Every report a PassProgress got.
struct Reports {
  std::vector<ReadProgress> seen;
  PassProgress callback() {
    return [this](const ReadProgress& p) { seen.push_back(p); };
  }
  /// done never goes back, never passes total, and the last report is done == total.
  void expect_rising_to_the_end(const char* pass, std::size_t at_least) const {
    ASSERT_GE(seen.size(), at_least) << pass;
    for (std::size_t i = 1; i < seen.size(); ++i) {
      EXPECT_GE(seen[i].done, seen[i - 1].done) << pass << ", report " << i;
      EXPECT_LE(seen[i].done, seen[i].total) << pass << ", report " << i;
    }
    EXPECT_EQ(seen.back().done, seen.back().total) << pass;
    EXPECT_GT(seen.back().total, 0u) << pass;
  }
};

/// One chip moving while the host polls 6000 times: more events than one report's worth.
void polled_run(MovedChain& s) {
  s.host.move(0, true, 3200);
  for (int i = 0; i < 6000; ++i) s.host.get_status(0);
}

TEST(MotionSeries, BothPassesOverAFileReportBytesRisingToDoneEqualsTotal) {
  MovedChain s(2);
  polled_run(s);
  test::TempDir dir;
  const std::string path = dir.write("long.trace", to_native_text(s.trace));
  const auto size = static_cast<std::uint64_t>(test::read_text(path).size());

  Reports reading, replaying;
  NativeTraceReader pass(path);
  const Tick end = trace_end_tick(pass, reading.callback());
  MotionOptions o;
  o.progress = replaying.callback();
  NativeTraceReader again(path);
  Chain fresh(2);
  sample_motion(again, fresh, end, o);

  reading.expect_rising_to_the_end("reading", 3);  // the start, every 4096 events, the end
  replaying.expect_rising_to_the_end("replaying", 3);
  EXPECT_TRUE(replaying.seen.back().bytes);
  EXPECT_EQ(reading.seen.back().total, size);
  EXPECT_EQ(replaying.seen.back().total, size);
}

TEST(MotionSeries, ATraceInMemoryReportsEventsAlongTheWay) {
  MovedChain s(1);
  polled_run(s);
  Reports replaying;
  MotionOptions o;
  o.progress = replaying.callback();
  sample(s.trace, o);
  replaying.expect_rising_to_the_end("replaying", 3);
  EXPECT_FALSE(replaying.seen.back().bytes);
  EXPECT_EQ(replaying.seen.back().total, s.trace.size());
  EXPECT_EQ(replaying.seen[1].done, 4096u);  // every 4096 events
}

TEST(MotionSeries, AWindowEndingBeforeTheTraceStillReportsDoneEqualsTotal) {
  MovedChain s(1);
  polled_run(s);
  Reports replaying;
  MotionOptions o;
  o.to = 1000;  // long before the trace ends: the pass stops early
  o.progress = replaying.callback();
  sample(s.trace, o);
  replaying.expect_rising_to_the_end("replaying", 2);
  EXPECT_EQ(replaying.seen.back().total, s.trace.size());
}

TEST(MotionSeries, TheThreeChipFixtureShowsItsSwitchAndItsMoves) {
  const Trace t = read_native_trace(test::fixture("three_chips.trace"), "three_chips.trace");
  const MotionSeries m = sample(t);
  ASSERT_EQ(m.chips.size(), 3u);
  bool sw_closed = false;
  for (const MotionSample& x : m.chips[0].samples) sw_closed = sw_closed || !x.sw;
  EXPECT_TRUE(sw_closed);
  for (const ChipMotion& c : m.chips) EXPECT_FALSE(c.commands.empty());
}

}  // namespace
}  // namespace l6470emu
