// make_report_data (tools/report_data.hpp): the page's timeline holds every frame of the trace
// with exactly the commands and answers `decode` finds, repeated frames collapse without loss,
// the registers after a frame are the chip's, long runs stay within the limits with their
// extremes kept, and findings (diagnostics, sanitizer rules, divergences) name their frames.
// Also `l6470emu report` as a user runs it: a page written, bad input in one line with exit 2.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>

#include "daisychain/decode.hpp"
#include "daisychain/host.hpp"
#include "spi/trace_native.hpp"
#include "support/trace_test_support.hpp"
#include "tools/report_data.hpp"
#include "tools/report_page.hpp"

namespace l6470emu {
namespace {

using test::fixture_path;
using test::read_text;
using test::run_command;
using test::TempDir;

struct Frame {
  Tick tick, duration;
  std::string mosi, miso;
  std::vector<std::string> texts;
};

/// Every frame the timeline stands for, entries expanded (gaps as frames with no bytes).
std::vector<Frame> expand(const ReportChain& d) {
  std::vector<Frame> out;
  std::size_t g = 0;
  auto gaps_before = [&](std::uint64_t frame) {
    for (; g < d.gaps.size() && d.gaps[g].first_frame <= frame; ++g)
      for (std::uint64_t i = 0; i < d.gaps[g].frames; ++i) out.push_back({d.gaps[g].from, 0, "", "", {}});
  };
  for (const ReportEntry& e : d.entries) {
    gaps_before(e.first_frame);
    EXPECT_EQ(e.first_frame, out.size()) << "entries follow each other";
    for (std::uint64_t r = 0; r < e.repetitions; ++r)
      for (const ReportRow& row : e.rows)
        out.push_back({e.tick + r * e.period + row.tick, row.duration, row.mosi, row.miso, row.texts});
  }
  gaps_before(~std::uint64_t{0});
  return out;
}

ReportChain data_of(const std::string& path, const ReportOptions& o = {}) {
  const TraceFile file(path, TraceInputOptions{});
  return make_report_chain(file, world_for_trace({}, file), o);
}

std::string save(const Trace& t, const TempDir& dir, const std::string& name) {
  const std::string path = dir.file(name);
  NativeTraceWriter w(path, false);
  w.write_header(t.header);
  auto r = t.reader();
  TraceEvent e;
  while (r->next(e)) w.write(e);
  w.finish();
  return path;
}

/// A recorded session on `n` L6470s driven through ChainHost.
struct Session {
  Chain chain;
  Trace trace;
  RecordingChain rec;
  ChainHost host;
  explicit Session(std::size_t n) : chain(n), rec(chain, trace), host(chain, rec) {}
};

const char* const kFixtures[] = {"three_chips.trace", "polling_host.trace", "single_chip.trace", "homing_axis.trace"};

TEST(ReportData, TheTimelineHoldsEveryFrameOfEachFixture) {
  for (const char* name : kFixtures) {
    SCOPED_TRACE(name);
    const ReportChain d = data_of(fixture_path(name));
    const TraceFile file(fixture_path(name), TraceInputOptions{});
    auto in = file.read();
    std::vector<TraceEvent> frames;
    std::vector<std::string> mosi;
    TraceEvent e;
    while (in->next(e))
      if (e.kind == TraceEventKind::frame) {
        frames.push_back(e);
        std::string m;
        for (std::uint8_t b : e.mosi) {
          char buf[4];
          std::snprintf(buf, sizeof buf, m.empty() ? "%02X" : " %02X", b);
          m += buf;
        }
        mosi.push_back(m);
      }
    EXPECT_EQ(d.frames, frames.size());
    EXPECT_TRUE(d.gaps.empty());
    const std::vector<Frame> all = expand(d);
    ASSERT_EQ(all.size(), frames.size());
    for (std::size_t i = 0; i < all.size(); ++i) {
      ASSERT_EQ(all[i].tick, frames[i].tick) << "frame " << i + 1;
      ASSERT_EQ(all[i].duration, frames[i].duration) << "frame " << i + 1;
      ASSERT_EQ(all[i].mosi, mosi[i]) << "frame " << i + 1;
    }
  }
}

TEST(ReportData, RepeatedPollingCollapsesIntoRuns) {
  const ReportChain d = data_of(fixture_path("polling_host.trace"));
  EXPECT_EQ(d.frames, 3607u);
  EXPECT_LT(d.entries.size(), 200u) << "GetStatus every millisecond on two chips: runs, not 3607 rows";
  EXPECT_TRUE(std::any_of(d.entries.begin(), d.entries.end(), [](const ReportEntry& e) { return e.repetitions > 100; }));
}

TEST(ReportData, EachChipsTextsAreWhatDecodeSays) {
  for (const char* name : kFixtures) {
    SCOPED_TRACE(name);
    const ReportChain d = data_of(fixture_path(name));
    const TraceFile file(fixture_path(name), TraceInputOptions{});
    Chain chain = world_for_trace({}, file).make_chain();
    auto in = file.read();
    std::ostringstream log;
    decode_trace(*in, chain, log);
    // "t=0.001003 s  chip 0   GetStatus → 0x7C03 [HiZ REV STOPPED UVLO]": every command and answer line.
    std::multiset<std::pair<std::size_t, std::string>> decoded, shown;
    std::istringstream lines(log.str());
    std::string line;
    const std::regex row(R"(^t=[0-9.]+ s  chip ([0-9]+) +([A-Z][A-Za-z]+(\(| →|$).*)$)");
    std::smatch m;
    while (std::getline(lines, line))
      if (std::regex_match(line, m, row) && line.find("pin") == std::string::npos && line.find(" output ") == std::string::npos)
        decoded.insert({std::stoul(m[1]), m[2]});
    for (const Frame& f : expand(d))
      for (std::size_t k = 0; k < f.texts.size(); ++k)
        if (!f.texts[k].empty()) shown.insert({k, f.texts[k]});
    EXPECT_EQ(shown, decoded);
  }
}

TEST(ReportData, TheRegistersAfterAFrameAreTheChips) {
  Session s(2);
  s.host.get_status(0);
  s.host.set_param(1, Reg::ACC, 0x123);
  s.host.move(0, true, 3200);
  s.host.wait_ms(2000);
  const std::int32_t pos = static_cast<std::int32_t>(s.host.get_param(0, Reg::ABS_POS));
  const std::uint16_t status = s.host.get_status(0);
  TempDir dir;
  const ReportChain d = data_of(save(s.trace, dir, "t.trace"));
  ASSERT_EQ(d.chips.size(), 2u);
  const ReportChip& c0 = d.chips[0];
  EXPECT_EQ(c0.states.back().abs_pos, pos);
  EXPECT_EQ(pos, 3200);
  EXPECT_EQ(c0.states.back().status, status);
  const ReportChip& c1 = d.chips[1];
  const auto acc = std::find_if(c1.registers.begin(), c1.registers.end(),
                                [](const RegisterChange& r) { return r.name == "ACC" && r.tick > 0; });
  ASSERT_NE(acc, c1.registers.end());
  EXPECT_EQ(acc->value, 0x123u);
  EXPECT_EQ(acc->text.rfind("0x123 = ", 0), 0u) << acc->text;
  // Power-up values first, at tick 0, named from the variant's table.
  EXPECT_TRUE(std::any_of(c1.registers.begin(), c1.registers.end(),
                          [](const RegisterChange& r) { return r.tick == 0 && r.name == "KVAL_RUN" && r.value == 0x29; }));
  EXPECT_EQ(c0.live_registers.front(), (std::pair<std::uint8_t, std::string>{0x01, "ABS_POS"}));
}

TEST(ReportData, ThePhaseDriveWalksTheFullStepPoints) {
  Session s(1);
  s.host.get_status(0);
  s.host.set_param(0, Reg::STEP_MODE, 0);
  s.host.move(0, true, 12);
  s.host.wait_ms(1500);
  s.host.get_status(0);
  TempDir dir;
  const ReportChain d = data_of(save(s.trace, dir, "t.trace"));
  std::set<std::pair<int, int>> points;
  for (const PhaseSample& p : d.chips[0].phase)
    if (p.coil_a != 0 || p.coil_b != 0) points.insert({p.coil_a, p.coil_b});
  EXPECT_EQ(points.size(), 4u) << "two phases on: (+,+) (+,-) (-,-) (-,+)";
  for (const auto& [a, b] : points) EXPECT_EQ(std::abs(a), std::abs(b));
}

TEST(ReportData, ALongRunStaysWithinTheLimitsWithItsExtremesKept) {
  // GetParam(ABS_POS) every millisecond during moves back and forth: every answer differs.
  Session s(1);
  s.host.get_status(0);
  std::int32_t lo = 0, hi = 0;
  for (int leg = 0; leg < 6; ++leg) {
    s.host.move(0, leg % 2 == 0, 20000 + 5000 * leg);
    for (int ms = 0; ms < 700; ++ms) {
      const std::int32_t p = sign_extend(s.host.get_param(0, Reg::ABS_POS), 22);
      lo = std::min(lo, p);
      hi = std::max(hi, p);
      s.host.wait_ms(1);
    }
  }
  TempDir dir;
  ReportOptions o;
  o.limits.timeline_rows = 500;
  o.limits.state_samples = 300;
  o.limits.phase_samples = 300;
  o.limits.motion_points = 300;
  const ReportChain d = data_of(save(s.trace, dir, "t.trace"), o);
  EXPECT_TRUE(d.summarised);
  EXPECT_FALSE(d.gaps.empty());
  std::size_t rows = 0;
  for (const ReportEntry& e : d.entries) rows += e.rows.size();
  EXPECT_LE(rows, 500u);
  EXPECT_EQ(expand(d).size(), d.frames) << "summarised frames are still counted";
  const std::vector<StateSample>& st = d.chips[0].states;
  EXPECT_LE(st.size(), 300u);
  const auto [mn, mx] = std::minmax_element(st.begin(), st.end(), [](auto& a, auto& b) { return a.abs_pos < b.abs_pos; });
  EXPECT_LE(mn->abs_pos, lo);
  EXPECT_GE(mx->abs_pos, hi);
  EXPECT_LE(d.chips[0].phase.size(), 300u);
  // Commands are kept in full even where polls are summarised.
  std::size_t moves = 0;
  for (const ReportEntry& e : d.entries)
    for (const ReportRow& r : e.rows) moves += r.texts[0].rfind("Move(", 0) == 0;
  EXPECT_EQ(moves, 6u);
}

TEST(ReportData, FindingsNameTheirFrames) {
  // Frame 2 holds a reserved opcode (WRONG_CMD); frame 3 a MISO byte the emulator does not give.
  TempDir dir;
  const std::string path = dir.write("bad.trace",
                                     "l6470emu-trace 2\nchain 1*L6470\n"
                                     "0.00100000 frame 1.75us D0 | 00\n"
                                     "0.00200000 frame 1.75us EB | 7C\n"
                                     "0.00300000 frame 1.75us 00 | 55\n");
  const ReportChain d = data_of(path);
  auto find = [&](const std::string& kind, const std::string& name) {
    return std::find_if(d.findings.begin(), d.findings.end(),
                        [&](const Finding& f) { return f.kind == kind && f.name == name; });
  };
  const auto wrong = find("diagnostic", "WRONG_CMD");
  ASSERT_NE(wrong, d.findings.end());
  EXPECT_EQ(wrong->frame, 2u);
  EXPECT_EQ(wrong->chip, "chip 0");
  const auto rule = find("sanitizer", "WRONG_CMD");
  ASSERT_NE(rule, d.findings.end());
  EXPECT_EQ(rule->frame, 2u);
  const auto div = find("divergence", "replay");
  ASSERT_NE(div, d.findings.end());
  EXPECT_FALSE(d.first_divergence.empty());
  EXPECT_GE(d.divergent_frames, 1u);
  const std::vector<Frame> all = expand(d);
  EXPECT_EQ(all[1].texts[0], "");
}

TEST(ReportData, TheJsonIsDeterministicAndCountsTheFrames) {
  const ReportChain d = data_of(fixture_path("three_chips.trace"));
  const std::string a = report_chain_json(d), b = report_chain_json(data_of(fixture_path("three_chips.trace")));
  EXPECT_EQ(a, b);
  const auto j = nlohmann::json::parse(a);
  EXPECT_EQ(j["frames"], 30);
  EXPECT_EQ(j["chips"].size(), 3u);
  std::uint64_t frames = 0;
  for (const auto& e : j["entries"]) frames += e[2].get<std::uint64_t>() * e[4].size();
  EXPECT_EQ(frames, 30u);
}

TEST(ReportPage, IsOneFileThatLoadsNothing) {
  if (!report_page_available()) GTEST_SKIP() << "built without libjs-dygraphs";
  ReportData d;
  d.chains.push_back(data_of(fixture_path("three_chips.trace")));
  d.title = "</script><script>alert(1)</script>";
  std::ostringstream page;
  write_report_page(d, page);
  const std::string html = page.str();
  EXPECT_NE(html.find("Content-Security-Policy\" content=\"default-src 'none'"), std::string::npos);
  EXPECT_EQ(html.find("<script src"), std::string::npos) << "no external script";
  EXPECT_EQ(html.find("<link"), std::string::npos) << "no external style sheet";
  EXPECT_EQ(html.find("src=\"http"), std::string::npos) << "no image or frame from elsewhere";
  EXPECT_EQ(html.find("sourceMappingURL"), std::string::npos);
  // The title reaches the page escaped, in the <title> and in the data alike.
  EXPECT_EQ(html.find("<script>alert"), std::string::npos);
  EXPECT_NE(html.find("Dygraph"), std::string::npos);
}

// ---- the command ---------------------------------------------------------------------------

test::RunResult l6470emu(const std::string& args) {
  return run_command(std::string(L6470EMU_BINARY) + " " + args + " </dev/null");
}
bool one_line(const std::string& out) { return !out.empty() && out.back() == '\n' && out.find('\n') == out.size() - 1; }

TEST(ReportCommand, WritesAPageAndSaysWhere) {
  TempDir dir;
  const auto r = l6470emu("report " + fixture_path("three_chips.trace") + " -o " + dir.file("r.html"));
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("30 frames, 3 chips"), std::string::npos) << r.out;
  EXPECT_NE(read_text(dir.file("r.html")).find("<!DOCTYPE html>"), std::string::npos);
}

TEST(ReportCommand, BadInputIsOneLineAndExitTwo) {
  TempDir dir;
  const std::string trace = fixture_path("three_chips.trace");
  const std::string not_coverage = dir.write("c.json", "{\"hello\": 1}\n");
  const std::string not_campaign = dir.write("k.json", "{\"format\": \"something else\"}\n");
  const std::string copy = dir.write("copy.trace", read_text(trace));
  const std::string out = dir.file("r.html");
  for (const std::string& args :
       {"report " + dir.file("missing.trace") + " -o " + out, "report " + dir.write("junk.trace", "hello\n") + " -o " + out,
        "report " + trace + " --coverage " + not_coverage + " -o " + out,
        "report " + trace + " --coverage " + dir.file("none.json") + " -o " + out,
        "report " + trace + " --campaign " + not_campaign + " -o " + out,
        "report " + copy + " -o " + copy, "report " + trace + " --coverage " + not_coverage + " -o " + not_coverage,
        "report " + trace + " -o " + dir.file("no/such/dir.html")}) {
    SCOPED_TRACE(args);
    const auto r = l6470emu(args);
    EXPECT_EQ(r.status, 2) << r.out;
    EXPECT_TRUE(one_line(r.out)) << r.out;
    EXPECT_EQ(r.out.rfind("l6470emu report: ", 0), 0u) << r.out;
    struct stat st {};
    EXPECT_NE(stat(out.c_str(), &st), 0) << "no page left behind";
  }
  EXPECT_EQ(read_text(copy), read_text(trace)) << "the input is untouched";
}

}  // namespace
}  // namespace l6470emu
