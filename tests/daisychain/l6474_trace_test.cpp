// An L6474 chain in traces: DIR edges recorded as `pin K DIR` lines beside STCK's, a recording
// that replays byte-exact against a fresh chain with the position the pulses made, and decode
// naming the L6474's commands (Enable, Disable), registers and refusals.
#include <gtest/gtest.h>

#include <sstream>

#include "daisychain/chain_spec.hpp"
#include "daisychain/decode.hpp"
#include "daisychain/explain.hpp"
#include "daisychain/motion_series.hpp"
#include "daisychain/recording_chain.hpp"
#include "daisychain/replay.hpp"
#include "spi/trace_native.hpp"

namespace l6470emu {
namespace {

using Bytes = std::vector<std::uint8_t>;

/// A recording of two L6474s driven as ST's driver drives them: one CS frame per byte position.
struct Session {
  Chain chain{2, l6474()};
  Trace trace;
  RecordingChain rec{chain, trace, RecordOptions{}};

  Bytes frame(const Bytes& tx) {
    rec.advance_to(rec.now() + 8);
    rec.select();
    Bytes rx(tx.size());
    for (std::size_t i = 0; i < tx.size(); ++i) {
      rec.advance_to(rec.now() + 7);
      rx[i] = rec.exchange(tx[i]);
    }
    rec.deselect();
    return rx;
  }
  /// `cmd` to chip `k` (MISO index), NOPs to the other.
  std::vector<Bytes> to(std::size_t k, const Bytes& cmd) {
    std::vector<Bytes> out;
    for (std::uint8_t b : cmd) {
      Bytes tx(2, 0x00);
      tx[k] = b;
      out.push_back(frame(tx));
    }
    return out;
  }
  void pulses(std::size_t k, int n, Tick period = 400) {  // 100 µs apart unless said
    for (int i = 0; i < n; ++i) {
      rec.advance_to(rec.now() + period);
      rec.set_stck_pin(k, true);
      rec.advance_to(rec.now() + 8);
      rec.set_stck_pin(k, false);
    }
  }
  /// The session of the tests: configure, enable chip 1, 40 pulses forward, 15 back, a Move.
  void drive() {
    to(1, {0xD0, 0x00, 0x00});  // GetStatus: clear UVLO
    to(1, {0x16, 0x8C});        // STEP_MODE 1/16
    to(1, {0x09, 0x20});        // TVAL
    to(1, {0xB8});              // Enable
    rec.set_dir_pin(1, true);
    pulses(1, 40);
    rec.set_dir_pin(1, false);
    pulses(1, 15);
    to(1, {0x41, 0x00, 0x00, 0x00});  // Move: no command on an L6474 (and three NOPs)
    to(1, {0x21, 0x00, 0x00, 0x00});  // GetParam(ABS_POS)
    to(1, {0xA8});                    // Disable
  }
};

std::vector<std::string> lines_of(const Trace& trace) {
  std::vector<std::string> lines;
  for (std::size_t i = 0; i < trace.size(); ++i) {
    const std::string l = NativeTraceWriter::format_event(trace[i]);
    lines.push_back(l.substr(l.find(' ') + 1));
  }
  return lines;
}

TEST(L6474Trace, RecordsDirEdgesAndTheChainsVariantsAndReplaysByteExact) {
  Session s;
  s.drive();
  EXPECT_EQ(s.trace.header.chain, "2*L6474");
  const auto lines = lines_of(s.trace);
  EXPECT_NE(std::find(lines.begin(), lines.end(), "pin 1 DIR 1"), lines.end());
  EXPECT_NE(std::find(lines.begin(), lines.end(), "pin 1 DIR 0"), lines.end());
  EXPECT_EQ(s.chain.chip(1).position(), 25);
  EXPECT_EQ(s.chain.chip(0).position(), 0);
  // No BUSY line at all: the L6474 has no BUSY pin to observe. FLAG is observed as on the others.
  EXPECT_EQ(std::count_if(lines.begin(), lines.end(), [](const std::string& l) { return l.find(" BUSY ") != std::string::npos; }), 0);
  EXPECT_NE(std::find(lines.begin(), lines.end(), "pin 1 FLAG 1"), lines.end());

  const std::string text = to_native_text(s.trace);
  NativeTraceReader reader(text, "l6474.trace");
  Chain fresh(2, l6474());
  const ReplayResult r = replay_trace(reader, fresh);
  EXPECT_TRUE(r.matched()) << (r.divergences.empty() ? "" : r.divergences[0].report);
  EXPECT_EQ(fresh.chip(1).position(), 25) << "the DIR and STCK lines replayed";
  EXPECT_EQ(fresh.chip(1).peek(Reg::EL_POS), s.chain.chip(1).peek(Reg::EL_POS));
}

TEST(L6474Trace, ItsPlottedSpeedIsTheStepRateOfItsPulsesWithTheSignOfDir) {
  // The L6474 has no SPEED register: plots and the report page show its step rate instead.
  Session s;
  s.to(1, {0xD0, 0x00, 0x00});
  s.to(1, {0x16, 0x8C});  // 1/16 step
  s.to(1, {0x09, 0x20});
  s.to(1, {0xB8});  // Enable
  s.rec.set_dir_pin(1, true);
  const Tick forward_from = s.rec.now();
  s.pulses(1, 500, 4000);  // 1 kHz for 0.5 s: 62.5 full step/s
  s.rec.set_dir_pin(1, false);
  const Tick back_from = s.rec.now();
  s.pulses(1, 1000, 2000);  // 2 kHz for 0.5 s, back: 125 full step/s
  const Tick stopped_from = s.rec.now();
  s.rec.advance_to(stopped_from + kTicksPerSecond / 10);
  s.to(1, {0xA8});  // Disable: a sample 0.1 s after the last pulse

  Chain fresh(2, l6474());
  auto pass = s.trace.reader();
  const Tick end = trace_end_tick(*pass);
  auto reader = s.trace.reader();
  MotionOptions o;
  o.chips = {1};
  const MotionSeries series = sample_motion(*reader, fresh, end, o);
  ASSERT_EQ(series.chips.size(), 1u);
  const ChipMotion& m = series.chips[0];
  // SPEED's units, 2^-28 full step per 250 ns tick: 62.5 step/s is 4194.3.
  auto step_per_s = [](std::int32_t speed) { return speed * 4e6 / (1 << 28); };
  int forward = 0, back = 0, still = 0;
  for (const MotionSample& x : m.samples) {
    const double v = step_per_s(x.speed);
    if (x.tick >= forward_from + kTicksPerSecond / 20 && x.tick < back_from) {
      EXPECT_NEAR(v, 62.5, 62.5 * 0.12) << "at tick " << x.tick;
      ++forward;
    } else if (x.tick >= back_from + kTicksPerSecond / 20 && x.tick < stopped_from) {
      EXPECT_NEAR(v, -125, 125 * 0.12) << "at tick " << x.tick;
      ++back;
    } else if (x.tick >= stopped_from + kTicksPerSecond / 20) {
      EXPECT_EQ(x.speed, 0) << "at tick " << x.tick;
      ++still;
    }
  }
  EXPECT_GT(forward, 20);
  EXPECT_GT(back, 20);
  EXPECT_GE(still, 1);
  EXPECT_EQ(fresh.chip(1).position(), 500 - 1000);
}

TEST(L6474Trace, ReplayingWithoutTheDirLinesEndsElsewhere) {
  // The DIR lines carry the run: dropped, the 15 reverse pulses go forward too.
  Session s;
  s.drive();
  std::string text = to_native_text(s.trace);
  std::string without;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (line.find(" DIR ") == std::string::npos) without += line + "\n";
  NativeTraceReader reader(without, "l6474.trace");
  Chain fresh(2, l6474());
  const ReplayResult r = replay_trace(reader, fresh);
  EXPECT_FALSE(r.matched());
  EXPECT_EQ(fresh.chip(1).position(), -55) << "DIR low from power-up on: every pulse in reverse";
}

TEST(L6474Trace, DecodeNamesTheL6474sCommandsRegistersAndRefusals) {
  Session s;
  s.drive();
  const std::string text = to_native_text(s.trace);
  NativeTraceReader reader(text, "l6474.trace");
  Chain chain = make_chain(parse_chain_spec("2*L6474"));
  std::ostringstream out;
  DecodeOptions o;
  decode_trace(reader, chain, out, o);
  const std::string log = out.str();
  for (const char* want : {"Enable", "Disable", "SetParam(STEP_MODE, 0x8C = STEP_SEL 4 (1/16 step))",
                           "SetParam(TVAL, 0x20 = 1031.25 mA)", "GetParam(ABS_POS) → 0x000019 = 25 microsteps",
                           "DIR pin high (forward)", "unknown opcode 0x41 (Move(FWD) on the others)"})
    EXPECT_NE(log.find(want), std::string::npos) << want << "\n" << log;
  EXPECT_EQ(log.find("SYNC_EN"), std::string::npos) << "no SYNC pin on the L6474";
  EXPECT_EQ(describe_command(0xB8, 0, l6474(), l6474().status), "Enable");
  EXPECT_EQ(describe_command(0xA8, 0, l6474(), l6474().status), "Disable");
  EXPECT_EQ(describe_command(0x41, 0, l6474(), l6474().status), "unknown opcode 0x41 (Move(FWD) on the others)");
  EXPECT_EQ(describe_answer(0xD0, 0xFE03, l6474(), l6474().status), "GetStatus → 0xFE03 [HiZ REV]");
}

}  // namespace
}  // namespace l6470emu
