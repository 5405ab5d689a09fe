// `l6470emu coverage report|merge` as a user runs them (tools/cmd_coverage.cpp): the three
// formats, --fail-under's exit statuses, one-line errors with exit 2 for bad input and outputs
// that would overwrite an input, and the LCOV output through Debian's genhtml.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "board/coverage.hpp"
#include "board/coverage_report.hpp"
#include "support/trace_test_support.hpp"

namespace l6470emu {
namespace {

using test::read_text;
using test::run_command;
using test::RunResult;
using test::TempDir;

RunResult l6470emu(const std::string& args) { return run_command(std::string(L6470EMU_BINARY) + " " + args + " </dev/null"); }

/// Whether `out` is exactly one line.
bool one_line(const std::string& out) { return !out.empty() && out.back() == '\n' && out.find('\n') == out.size() - 1; }

CoverageData small_run() {
  CoverageData d;
  d.use("L6470").positions = {"chip 0 of 1"};
  d.hit("L6470", CoverageCategory::commands, "Move FWD");
  d.hit("L6470", CoverageCategory::registers_read, "ABS_POS");
  d.hit("L6470", CoverageCategory::flags_raised, "OCD");
  d.hit("L6470", CoverageCategory::chain_positions, "chip 0 of 1");
  return d;
}

CoverageData other_run() {
  CoverageData d;
  d.use("L6480").positions = {"chip 1 of 2"};
  d.hit("L6480", CoverageCategory::flags_raised, "CMD_ERROR");
  d.hit("L6480", CoverageCategory::flags_observed, "CMD_ERROR");
  d.hit("L6480", CoverageCategory::rules_broken, "WRONG_CMD");
  return d;
}

/// An L6470 run that hits exactly a quarter of its points: the chain positions present are
/// chosen so that the total divides by four (they count in it).
CoverageData quarter_run() {
  const CoverageUniverse& u = *coverage_universe("L6470");
  std::vector<const CoveragePoint*> counted;
  for (const CoveragePoint& p : u.points())
    if (!counts_against(p.category)) counted.push_back(&p);
  std::size_t positions = 1;
  while ((counted.size() + positions) % 4 != 0) ++positions;
  CoverageData d;
  for (std::size_t k = 0; k < positions; ++k) d.use("L6470").positions.insert(chain_position_name(k, positions));
  const std::size_t quarter = (counted.size() + positions) / 4;
  for (std::size_t i = 0; i < quarter; ++i) d.hit("L6470", counted[i]->category, counted[i]->name);
  return d;
}

TEST(CoverageReportCommand, PrintsATablePerVariantAsText) {
  TempDir dir;
  const std::string a = dir.write("a.json", small_run().to_json());
  const std::string b = dir.write("b.json", other_run().to_json());
  const RunResult r = l6470emu("coverage report " + a + " " + b);
  EXPECT_EQ(r.status, 0) << r.out;
  CoverageData both = small_run();
  both.merge(other_run());
  EXPECT_EQ(r.out, coverage_text(both, false));
  EXPECT_NE(r.out.find("L6470 (chip 0 of 1)\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("L6480 (chip 1 of 2)\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("raised but never observed: OCD\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("rules broken: WRONG_CMD\n"), std::string::npos) << r.out;
  const RunResult missing = l6470emu("coverage report --show-missing " + a);
  EXPECT_EQ(missing.status, 0);
  EXPECT_EQ(missing.out, coverage_text(small_run(), true));
  EXPECT_NE(missing.out.find("never hit:"), std::string::npos);
}

TEST(CoverageReportCommand, WritesJsonWithTheSameNumbers) {
  TempDir dir;
  const std::string a = dir.write("a.json", small_run().to_json());
  const RunResult r = l6470emu("coverage report --format json " + a);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(r.out, coverage_json_report(small_run()));
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["hit"], coverage_total(small_run()).hit);
  EXPECT_EQ(j["total"], coverage_total(small_run()).total);
  // -o writes the same to a file and nothing to standard output.
  const RunResult o = l6470emu("coverage report --format json -o " + dir.file("report.json") + " " + a);
  EXPECT_EQ(o.status, 0) << o.out;
  EXPECT_EQ(o.out, "");
  EXPECT_EQ(read_text(dir.file("report.json")), r.out);
}

TEST(CoverageReportCommand, WritesLcovAndTheListingsItPointsAt) {
  TempDir dir;
  const std::string a = dir.write("a.json", small_run().to_json());
  const std::string b = dir.write("b.json", other_run().to_json());
  const RunResult r = l6470emu("coverage report --format lcov -o " + dir.file("coverage.info") + " " + a + " " + b);
  ASSERT_EQ(r.status, 0) << r.out;
  const std::string info = read_text(dir.file("coverage.info"));
  const std::string listings = dir.file("l6470emu-interface");
  EXPECT_NE(info.find("SF:" + listings + "/L6470.interface\n"), std::string::npos) << info.substr(0, 300);
  EXPECT_NE(info.find("SF:" + listings + "/L6480.interface\n"), std::string::npos);
  EXPECT_NE(read_text(listings + "/L6470.interface").find("Move FWD "), std::string::npos);
  // --listing-dir puts them elsewhere, and goes with lcov only.
  const RunResult elsewhere =
      l6470emu("coverage report --format lcov --listing-dir " + dir.file("here") + " -o " + dir.file("c2.info") + " " + a);
  ASSERT_EQ(elsewhere.status, 0) << elsewhere.out;
  EXPECT_NE(read_text(dir.file("c2.info")).find("SF:" + dir.file("here") + "/L6470.interface\n"), std::string::npos);
  EXPECT_FALSE(read_text(dir.file("here/L6470.interface")).empty());
  const RunResult text = l6470emu("coverage report --listing-dir " + dir.file("here") + " " + a);
  EXPECT_EQ(text.status, 2) << text.out;
  EXPECT_TRUE(one_line(text.out)) << text.out;
}

TEST(CoverageReportCommand, FailUnderExitsOneBelowAndZeroAtOrAboveTheThreshold) {
  TempDir dir;
  const CoverageData quarter = quarter_run();
  ASSERT_EQ(coverage_total(quarter).percent(), 25.0);
  const std::string f = dir.write("q.json", quarter.to_json());
  const std::string report = coverage_text(quarter, false);
  for (const char* pct : {"0", "24.99", "25", "25.0"}) {
    const RunResult r = l6470emu("coverage report --fail-under " + std::string(pct) + " " + f);
    EXPECT_EQ(r.status, 0) << pct << "\n" << r.out;
    EXPECT_EQ(r.out, report) << pct;
  }
  for (const char* pct : {"25.000001", "26", "100"}) {
    const RunResult r = l6470emu("coverage report --fail-under " + std::string(pct) + " " + f);
    EXPECT_EQ(r.status, 1) << pct << "\n" << r.out;
    ASSERT_EQ(r.out.rfind(report, 0), 0u) << pct << ": the report comes first\n" << r.out;
    const std::string last = r.out.substr(report.size());
    EXPECT_TRUE(one_line(last)) << last;
    EXPECT_NE(last.find("total 25.0% is below --fail-under"), std::string::npos) << last;
  }
  // Everything hit: 100 passes.
  CoverageData all;
  all.use("L6470").positions = {"chip 0 of 1"};
  for (const CoveragePoint& p : coverage_universe("L6470")->points())
    if (!counts_against(p.category)) all.hit("L6470", p.category, p.name);
  all.hit("L6470", CoverageCategory::chain_positions, "chip 0 of 1");
  ASSERT_EQ(coverage_total(all).percent(), 100.0);
  const std::string full = dir.write("all.json", all.to_json());
  EXPECT_EQ(l6470emu("coverage report --fail-under 100 " + full).status, 0);
}

TEST(CoverageReportCommand, AThresholdOutsideZeroToAHundredIsOneLineAndExitTwo) {
  TempDir dir;
  const std::string f = dir.write("a.json", small_run().to_json());
  for (const char* pct : {"120", "-1", "x"}) {
    const RunResult r = l6470emu("coverage report --fail-under " + std::string(pct) + " " + f);
    EXPECT_EQ(r.status, 2) << pct << "\n" << r.out;
    EXPECT_TRUE(one_line(r.out)) << pct << "\n" << r.out;
    EXPECT_NE(r.out.find("--fail-under"), std::string::npos) << r.out;
  }
}

// A bad option value of `coverage report` names `coverage report` and its help, as every other
// subcommand names itself.
TEST(CoverageReportCommand, ABadThresholdNamesCoverageReportAndItsHelp) {
  TempDir dir;
  const std::string f = dir.write("a.json", small_run().to_json());
  const RunResult r = l6470emu("coverage report --fail-under 120 " + f);
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.out.rfind("l6470emu coverage report: --fail-under: ", 0), 0u) << r.out;
  EXPECT_NE(r.out.find("(l6470emu coverage report --help)"), std::string::npos) << r.out;
}

TEST(CoverageReportCommand, BadInputIsOneLineAndExitTwo) {
  TempDir dir;
  const std::string good = dir.write("good.json", small_run().to_json());
  const std::vector<std::pair<std::string, std::string>> bad{
      {"corrupt", dir.write("corrupt.json", "{\"format\": \"l6470emu-coverage\", \"vers")},
      {"foreign", dir.write("foreign.json", "{\"name\": \"package\", \"version\": \"1.0.0\"}\n")},
      {"another version", dir.write("v2.json", "{\"format\": \"l6470emu-coverage\", \"version\": 2, \"variants\": {}}\n")},
      {"an unknown variant",
       dir.write("l6471.json", "{\"format\": \"l6470emu-coverage\", \"version\": 1, \"variants\": {\"L6471\": {}}}\n")},
      {"empty", dir.write("empty.json", "")},
      {"missing", dir.file("missing.json")},
      {"a directory", dir.file("")},
  };
  for (const auto& [what, path] : bad) {
    for (const std::string& sub : std::vector<std::string>{"report", "report --format lcov", "merge -o " + dir.file("merged.json")}) {
      const RunResult r = l6470emu("coverage " + sub + " " + good + " " + path);
      EXPECT_EQ(r.status, 2) << what << " (" << sub << ")\n" << r.out;
      EXPECT_TRUE(one_line(r.out)) << what << " (" << sub << ")\n" << r.out;
      EXPECT_NE(r.out.find(path), std::string::npos) << what << ": the file is named\n" << r.out;
    }
    EXPECT_NE(::access(dir.file("merged.json").c_str(), F_OK), 0) << what << ": a merge that failed wrote its output";
  }
  const RunResult none = l6470emu("coverage report");
  EXPECT_EQ(none.status, 2);
  EXPECT_TRUE(one_line(none.out)) << none.out;
}

TEST(CoverageReportCommand, AnOutputThatIsAnInputIsRefusedAndTheInputLeftAsItIs) {
  TempDir dir;
  const std::string a = dir.write("a.json", small_run().to_json());
  const std::string b = dir.write("b.json", other_run().to_json());
  const std::string before = read_text(a);
  for (const std::string& o : {a, dir.file("./a.json"), dir.file("sub/../a.json")}) {
    if (o.find("sub/") != std::string::npos) ::mkdir(dir.file("sub").c_str(), 0755);
    for (const char* format : {"text", "json", "lcov"}) {
      const RunResult r = l6470emu("coverage report --format " + std::string(format) + " -o " + o + " " + b + " " + a);
      EXPECT_EQ(r.status, 2) << o << " " << format << "\n" << r.out;
      EXPECT_TRUE(one_line(r.out)) << r.out;
      EXPECT_EQ(read_text(a), before) << o << " " << format;
    }
  }
  // A hard link to an input is the same file.
  ASSERT_EQ(::link(a.c_str(), dir.file("link.json").c_str()), 0);
  const RunResult link = l6470emu("coverage report -o " + dir.file("link.json") + " " + a);
  EXPECT_EQ(link.status, 2) << link.out;
  EXPECT_EQ(read_text(a), before);
  // Unwritable: refused at start, one line.
  const RunResult nowhere = l6470emu("coverage report -o " + dir.file("no/such/dir/r.txt") + " " + a);
  EXPECT_EQ(nowhere.status, 2) << nowhere.out;
  EXPECT_TRUE(one_line(nowhere.out)) << nowhere.out;
}

TEST(CoverageMergeCommand, JoinsRunsIntoANewFileAndNeverWritesOverAnInput) {
  TempDir dir;
  const std::string a = dir.write("a.json", small_run().to_json());
  const std::string b = dir.write("b.json", other_run().to_json());
  const RunResult r = l6470emu("coverage merge " + a + " " + b + " -o " + dir.file("ab.json"));
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(r.out, "");
  CoverageData both = small_run();
  both.merge(other_run());
  EXPECT_EQ(read_text(dir.file("ab.json")), both.to_json());
  // The order of the inputs makes no difference to the bytes.
  ASSERT_EQ(l6470emu("coverage merge " + b + " " + a + " -o " + dir.file("ba.json")).status, 0);
  EXPECT_EQ(read_text(dir.file("ba.json")), read_text(dir.file("ab.json")));
  // The output may not be one of the inputs, under any spelling.
  const std::string before_a = read_text(a), before_b = read_text(b);
  for (const std::string& o : {a, b, dir.file("./b.json")}) {
    const RunResult same = l6470emu("coverage merge " + a + " " + b + " -o " + o);
    EXPECT_EQ(same.status, 2) << o << "\n" << same.out;
    EXPECT_TRUE(one_line(same.out)) << same.out;
    EXPECT_EQ(same.out.rfind("l6470emu coverage merge: ", 0), 0u) << same.out;
  }
  EXPECT_EQ(read_text(a), before_a);
  EXPECT_EQ(read_text(b), before_b);
  // -o is required.
  const RunResult no_output = l6470emu("coverage merge " + a + " " + b);
  EXPECT_EQ(no_output.status, 2) << no_output.out;
  EXPECT_TRUE(one_line(no_output.out)) << no_output.out;
}

TEST(CoverageReportCommand, GenhtmlRendersTheLcovOutput) {
  if (access("/usr/bin/genhtml", X_OK) != 0) {
    std::printf("genhtml not installed (Debian package lcov): the LCOV output is not rendered here\n");
    GTEST_SKIP() << "/usr/bin/genhtml missing (Debian package lcov)";
  }
  TempDir dir;
  const std::string a = dir.write("a.json", small_run().to_json());
  const std::string b = dir.write("b.json", other_run().to_json());
  const RunResult r = l6470emu("coverage report --format lcov -o " + dir.file("coverage.info") + " " + a + " " + b);
  ASSERT_EQ(r.status, 0) << r.out;
  const RunResult html = run_command("/usr/bin/genhtml --quiet -o " + dir.file("html") + " " + dir.file("coverage.info"));
  EXPECT_EQ(html.status, 0) << html.out;
  // The top page names the listings' folder, whose own index.html names each variant's listing.
  const std::string index = read_text(dir.file("html/index.html"));
  ASSERT_FALSE(index.empty()) << "genhtml wrote no index.html\n" << html.out;
  EXPECT_NE(index.find("l6470emu-interface"), std::string::npos);
  const std::string listings = read_text(dir.file("html/l6470emu-interface/index.html"));
  EXPECT_NE(listings.find("L6470.interface"), std::string::npos) << listings.substr(0, 400);
  EXPECT_NE(listings.find("L6480.interface"), std::string::npos);
  // The variant's own page shows its listing's lines.
  EXPECT_NE(read_text(dir.file("html/l6470emu-interface/L6470.interface.gcov.html")).find("Move FWD"), std::string::npos);
}

}  // namespace
}  // namespace l6470emu
