// The report of a run of several chains (tools/report_data.hpp, make_report_data on a recording
// per chain): each chain on the page under its board name with its own frames, chips and
// registers, the page's limits shared among the chains, and two recordings of one chain refused.
#include <gtest/gtest.h>

#include <deque>
#include <nlohmann/json.hpp>

#include "daisychain/host.hpp"
#include "spi/trace_native.hpp"
#include "support/trace_test_support.hpp"
#include "tools/report_data.hpp"

namespace l6470emu {
namespace {

using test::TempDir;

/// A chain of `n` L6470s driven through ChainHost and recorded with the board lines of `board`.
struct Recorded {
  Chain chain;
  Trace trace;
  RecordingChain rec;
  ChainHost host;
  Recorded(std::size_t n, const std::string& board)
      : chain(n), rec(chain, trace, RecordOptions{.board = board}), host(chain, rec) {}

  std::string save(const TempDir& dir, const std::string& name) const {
    const std::string path = dir.file(name);
    NativeTraceWriter w(path, false);
    w.write_header(trace.header);
    auto r = trace.reader();
    TraceEvent e;
    while (r->next(e)) w.write(e);
    w.finish();
    return path;
  }
  std::uint64_t frames() const {
    std::uint64_t n = 0;
    auto r = trace.reader();
    TraceEvent e;
    while (r->next(e)) n += e.kind == TraceEventKind::frame;
    return n;
  }
};

/// The page's data of the recordings at `paths`, each through its own world.
ReportData page_of(const std::vector<std::string>& paths, const ReportOptions& o = {}) {
  std::deque<TraceFile> files;
  std::deque<TraceWorld> worlds;
  std::vector<ReportRecording> recordings;
  for (const std::string& p : paths) {
    files.emplace_back(p, TraceInputOptions{});
    worlds.push_back(world_for_trace({}, files.back()));
    recordings.push_back({files.back(), worlds.back()});
  }
  return make_report_data(recordings, o);
}

TEST(ReportChains, EachChainOfATwoChainRunIsShownUnderItsNameWithItsOwnFramesAndChips) {
  // spidev0.0: one chip, polled; spidev0.1: two chips, the second moved 3200 microsteps.
  Recorded a(1, "bus=0 cs=0 chips=L6470"), b(2, "bus=0 cs=1 chips=2xL6470");
  for (int i = 0; i < 5; ++i) a.host.get_status(0);
  b.host.get_status(1);
  b.host.move(1, true, 3200);
  b.host.wait_ms(2000);
  const auto pos = static_cast<std::int32_t>(b.host.get_param(1, Reg::ABS_POS));
  ASSERT_EQ(pos, 3200);
  TempDir dir;
  const ReportData d = page_of({a.save(dir, "run.spidev0.0.trace"), b.save(dir, "run.spidev0.1.trace")});
  ASSERT_EQ(d.chains.size(), 2u);
  EXPECT_EQ(d.chains[0].name, "spidev0.0");
  EXPECT_EQ(d.chains[0].where, "bus 0, cs 0");
  EXPECT_EQ(d.chains[1].name, "spidev0.1");
  EXPECT_EQ(d.chains[1].where, "bus 0, cs 1");
  EXPECT_EQ(d.chains[0].frames, a.frames());
  EXPECT_EQ(d.chains[1].frames, b.frames());
  EXPECT_NE(a.frames(), b.frames());
  EXPECT_EQ(d.frames(), a.frames() + b.frames());
  EXPECT_EQ(d.chains[0].chips.size(), 1u);
  ASSERT_EQ(d.chains[1].chips.size(), 2u);
  EXPECT_EQ(d.chips(), 3u);
  EXPECT_EQ(d.chains[1].chips[1].states.back().abs_pos, pos) << "the second chain's chip 1 as its own recording has it";
  EXPECT_EQ(d.chains[0].chips[0].states.back().abs_pos, 0) << "the first chain never moved";
  EXPECT_EQ(d.title, dir.file("run.spidev0.0.trace") + ", " + dir.file("run.spidev0.1.trace"));
  // The JSON the script reads: a chain object each, in the order given, with its own frames.
  const auto j = nlohmann::json::parse(report_json(d));
  EXPECT_EQ(j["format"], "l6470emu-report 2");
  ASSERT_EQ(j["chains"].size(), 2u);
  EXPECT_EQ(j["chains"][1]["name"], "spidev0.1");
  EXPECT_EQ(j["chains"][0]["frames"], a.frames());
  EXPECT_EQ(j["chains"][1]["frames"], b.frames());
  EXPECT_EQ(j["chains"][1]["chips"].size(), 2u);
  EXPECT_EQ(j["shown_to"], std::max(d.chains[0].shown_to, d.chains[1].shown_to));
}

TEST(ReportChains, OneChainIsReadAsItAlwaysWas) {
  Recorded a(2, "bus=0 cs=0 chips=2xL6470");
  a.host.get_status(0);
  a.host.move(0, true, 100);
  a.host.wait_ms(500);
  a.host.get_status(1);
  TempDir dir;
  const std::string path = a.save(dir, "one.trace");
  const ReportData d = page_of({path});
  ASSERT_EQ(d.chains.size(), 1u);
  const TraceFile file(path, TraceInputOptions{});
  EXPECT_EQ(report_chain_json(d.chains[0]), report_chain_json(make_report_chain(file, world_for_trace({}, file))));
  EXPECT_EQ(d.title, path);
}

TEST(ReportChains, TheLimitsAreSharedAmongTheChainsSoThatThePageStaysBounded) {
  ReportLimits page;
  page.timeline_rows = 1000;
  // A chain with fewer frames than an equal share keeps them all; the other gets the rest.
  const std::vector<ReportLimits> shares = share_limits(page, {100, 50'000}, {1, 3});
  ASSERT_EQ(shares.size(), 2u);
  EXPECT_EQ(shares[0].timeline_rows, 100u);
  EXPECT_EQ(shares[1].timeline_rows, 900u);
  // Series and per-chip lists in proportion to the chips, findings equally: never more than the page's.
  EXPECT_EQ(shares[0].motion_points + shares[1].motion_points, page.motion_points);
  EXPECT_EQ(shares[1].state_samples, 3 * shares[0].state_samples);
  EXPECT_LE(shares[0].phase_samples + shares[1].phase_samples, page.phase_samples);
  EXPECT_LE(shares[0].register_changes + shares[1].register_changes, page.register_changes);
  EXPECT_LE(shares[0].input_edges + shares[1].input_edges, page.input_edges);
  EXPECT_LE(shares[0].findings + shares[1].findings, page.findings);
  // Two long chains share equally; one chain keeps the page's limits.
  const std::vector<ReportLimits> even = share_limits(page, {60'000, 80'000}, {1, 1});
  EXPECT_EQ(even[0].timeline_rows, 500u);
  EXPECT_EQ(even[1].timeline_rows, 500u);
  EXPECT_EQ(share_limits(page, {60'000}, {3})[0].timeline_rows, 1000u);
}

TEST(ReportChains, ALongSecondChainIsSummarisedWhileAShortFirstOneIsShownWhole) {
  Recorded a(1, "bus=0 cs=0 chips=L6470"), b(1, "bus=1 cs=0 chips=L6470");
  for (int i = 0; i < 20; ++i) a.host.get_status(0);
  b.host.move(0, true, 60000);
  for (int ms = 0; ms < 1500; ++ms) {  // every answer differs while the motor moves: no runs
    b.host.get_param(0, Reg::ABS_POS);
    b.host.wait_ms(1);
  }
  TempDir dir;
  ReportOptions o;
  o.limits.timeline_rows = 1000;
  const ReportData d = page_of({a.save(dir, "a.trace"), b.save(dir, "b.trace")}, o);
  ASSERT_EQ(d.chains.size(), 2u);
  EXPECT_EQ(d.chains[1].name, "spidev1.0");
  EXPECT_TRUE(d.chains[0].gaps.empty()) << "the short chain is whole";
  EXPECT_FALSE(d.chains[0].summarised);
  EXPECT_FALSE(d.chains[1].gaps.empty()) << "the long one is summarised";
  EXPECT_TRUE(d.summarised());
  std::size_t rows = 0;
  for (const ReportChain& c : d.chains)
    for (const ReportEntry& e : c.entries) rows += e.rows.size();
  EXPECT_LE(rows, 1000u) << "the page's row limit holds for both chains together";
  std::uint64_t frames = 0;
  for (const ReportEntry& e : d.chains[1].entries) frames += e.frames();
  for (const ReportGap& g : d.chains[1].gaps) frames += g.frames;
  EXPECT_EQ(frames, b.frames()) << "summarised frames are still counted";
}

TEST(ReportChains, TwoRecordingsOfOneChainAreRefused) {
  Recorded a(1, "bus=0 cs=0 chips=L6470"), b(1, "bus=0 cs=0 chips=L6470");
  a.host.get_status(0);
  b.host.get_status(0);
  TempDir dir;
  const std::string first = a.save(dir, "first.trace"), second = b.save(dir, "second.trace");
  EXPECT_THROW(page_of({first, first}), std::invalid_argument) << "a file given twice";
  try {
    page_of({first, second});
    ADD_FAILURE() << "two recordings of spidev0.0 make no run";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("both record spidev0.0 (bus 0, cs 0)"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace l6470emu
