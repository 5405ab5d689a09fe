// Compacted traces replay and decode exactly as their expanded form: a polling host recorded
// through a RecordingChain (fixtures/traces/polling_host.trace), written with and without
// `repeat` lines, gives the same replay result, the same divergences and the same decode log.
#include <gtest/gtest.h>

#include <cstdlib>
#include <fstream>
#include <regex>
#include <sstream>

#include "daisychain/chain_spec.hpp"
#include "daisychain/decode.hpp"
#include "daisychain/replay.hpp"
#include "spi/trace_native.hpp"
#include "support/trace_test_support.hpp"

namespace l6470emu {
namespace {

/// Two L6470s, a frame per byte position: chip 0 moves 200 full steps while the host polls
/// GetStatus on both every millisecond, and keeps polling for half a second after.
Trace polling_host_session() {
  test::RecordedSession s(2);
  s.each({0xD0, 0x00, 0x00});  // GetStatus: clears UVLO after power-up
  s.all({{0x41, 0x00, 0x64, 0x00}, {0x00}});  // chip 0: Move(FWD, 25600 microsteps); chip 1: NOP
  const Tick start = s.rec.now();
  for (int poll = 1; poll <= 1200; ++poll) {
    s.rec.advance_to(start + static_cast<Tick>(poll) * ticks_from_ms(1));
    s.rec.observe_outputs();
    s.each({0xD0, 0x00, 0x00});
  }
  return s.trace;
}

struct Results {
  ReplayResult replay;
  std::vector<std::string> reports;
  std::string decode;
};

/// Replay through `chain_spec` (with --continue) and decode, line references taken out.
Results run_both(const std::string& text, const std::string& chain_spec) {
  static const std::regex line_ref(R"(t\.trace:[0-9]+( \(?repetition [0-9]+\)?)?)");
  Results r;
  {
    NativeTraceReader in(text, "t.trace");
    Chain chain = make_chain(parse_chain_spec(chain_spec));
    ReplayOptions o;
    o.keep_going = true;
    o.max_reports = 0;
    r.replay = replay_trace(in, chain, o);
    for (const Divergence& d : r.replay.divergences) r.reports.push_back(std::regex_replace(d.report, line_ref, "t.trace:N"));
  }
  {
    NativeTraceReader in(text, "t.trace");
    Chain chain = make_chain(parse_chain_spec(chain_spec));
    std::ostringstream out;
    DecodeOptions o;
    o.max_repeats = 0;
    decode_trace(in, chain, out, o);
    r.decode = std::regex_replace(out.str(), line_ref, "t.trace:N");
  }
  return r;
}

void expect_same(const Results& a, const Results& b) {
  EXPECT_EQ(a.replay.frames, b.replay.frames);
  EXPECT_EQ(a.replay.bytes_compared, b.replay.bytes_compared);
  EXPECT_EQ(a.replay.pin_checks, b.replay.pin_checks);
  EXPECT_EQ(a.replay.divergent_frames, b.replay.divergent_frames);
  EXPECT_EQ(a.replay.pin_mismatches, b.replay.pin_mismatches);
  ASSERT_EQ(a.replay.divergences.size(), b.replay.divergences.size());
  for (std::size_t i = 0; i < a.replay.divergences.size(); ++i) {
    EXPECT_EQ(a.replay.divergences[i].frame, b.replay.divergences[i].frame);
    EXPECT_EQ(a.replay.divergences[i].tick, b.replay.divergences[i].tick);
    EXPECT_EQ(a.reports[i], b.reports[i]);
  }
  EXPECT_EQ(a.decode, b.decode);
}

TEST(CompactTrace, ThePollingHostFixtureIsWhatTheRecorderWritesToday) {
  const std::string fresh = to_native_text(polling_host_session(), true);
  const std::string path = test::fixture_path("polling_host.trace");
  if (std::getenv("L6470EMU_UPDATE_FIXTURES") != nullptr) std::ofstream(path, std::ios::binary) << fresh;
  EXPECT_EQ(test::fixture("polling_host.trace"), fresh)
      << "the recorder changed: L6470EMU_UPDATE_FIXTURES=1 rewrites the fixture";
}

TEST(CompactTrace, ThePollingHostIsAFewLinesInsteadOfThousands) {
  const Trace session = polling_host_session();
  const std::string compact = to_native_text(session, true);
  const std::string expanded = to_native_text(session, false);
  EXPECT_EQ(session.frame_count(), 3u * 1201 + 4);
  EXPECT_LT(compact.size() * 20, expanded.size()) << compact;
}

TEST(CompactTrace, ReplaysAndDecodesThePollingHostExactlyAsTheExpandedTrace) {
  const std::string compact = test::fixture("polling_host.trace");
  const std::string expanded = to_native_text(read_native_trace(compact, "t.trace"), false);
  ASSERT_EQ(expanded.find("repeat"), std::string::npos);
  const Results a = run_both(compact, "2"), b = run_both(expanded, "2");
  EXPECT_TRUE(a.replay.matched());
  EXPECT_GT(a.replay.pin_checks, 0u);
  expect_same(a, b);
  EXPECT_NE(a.decode.find("GetStatus"), std::string::npos);
}

TEST(CompactTrace, DivergesInTheSameFramesWithTheSameReportsAsTheExpandedTrace) {
  // Replayed through a chain whose chip 1 answers differently (an L6480's STATUS), every
  // poll diverges: the reports of repeated frames match the expanded trace's one for one.
  const std::string compact = test::fixture("polling_host.trace");
  const std::string expanded = to_native_text(read_native_trace(compact, "t.trace"), false);
  const Results a = run_both(compact, "L6470,L6480"), b = run_both(expanded, "L6470,L6480");
  EXPECT_FALSE(a.replay.matched());
  EXPECT_GT(a.replay.divergent_frames, 1000u);
  expect_same(a, b);
}

TEST(CompactTrace, ReportsOfARepeatedFrameNameItsRepeatLineAndRepetition) {
  const std::string compact = test::fixture("polling_host.trace");
  NativeTraceReader in(compact, "t.trace");
  Chain chain = make_chain(parse_chain_spec("L6470,L6480"));
  ReplayOptions o;
  o.keep_going = true;
  o.max_reports = 0;
  const ReplayResult r = replay_trace(in, chain, o);
  bool found = false;
  for (const Divergence& d : r.divergences)
    if (d.summary.find(" (repetition ") != std::string::npos) found = true;
  EXPECT_TRUE(found);
}

}  // namespace
}  // namespace l6470emu
