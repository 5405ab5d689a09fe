// `l6470emu run --html` and `l6470emu report` on a board of two chains, as a CI user runs them:
// one page with both chains, the same run giving the same page byte for byte, no temporary
// recording left behind, `report` taking a trace per chain or the path the run recorded to,
// and two recordings of one chain refused in one line with exit 2.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "support/trace_test_support.hpp"
#include "tools/report_page.hpp"

namespace l6470emu {
namespace {

using test::read_text;
using test::run_command;
using test::TempDir;

constexpr const char* kTwoChains = "'bus=0 cs=0 chips=L6470; bus=0 cs=1 chips=2xL6470'";

/// spidev0.0 (one chip): a GetStatus, 3 frames. spidev0.1 (two chips): a GetStatus to both, chip 0
/// moved 3200 microsteps, a second later GetParam(ABS_POS) to both: 11 frames.
constexpr const char* kDriver = R"(import spidev, time
def dev(cs):
    s = spidev.SpiDev(); s.open(0, cs); s.mode = 3; s.max_speed_hz = 1000000; return s
a, b = dev(0), dev(1)
x = lambda s, *frames: [s.xfer2(list(f)) for f in frames]
x(a, [0xD0], [0], [0])
x(b, [0xD0, 0xD0], [0, 0], [0, 0])
x(b, [0x41, 0], [0, 0], [0x0C, 0], [0x80, 0])
time.sleep(1)
print(x(b, [0x21, 0x21], [0, 0], [0, 0], [0, 0]))
)";

test::RunResult l6470emu(const std::string& args, const std::string& env = "") {
  return run_command(env + " " + std::string(L6470EMU_BINARY) + " " + args + " </dev/null");
}

/// The data a page carries (its JSON script element).
nlohmann::json page_data(const std::string& page) {
  const std::string html = read_text(page);
  const std::string open = "id=\"report-data\">";
  const std::size_t from = html.find(open);
  if (from == std::string::npos) return {};
  const std::size_t to = html.find("</script>", from);
  return nlohmann::json::parse(html.substr(from + open.size(), to - from - open.size()));
}

bool one_line(const std::string& out) { return !out.empty() && out.back() == '\n' && out.find('\n') == out.size() - 1; }

class ReportChainsCommand : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!report_page_available()) GTEST_SKIP() << "built without libjs-dygraphs";
    if (run_command("/usr/bin/python3 -c 'import spidev'").status != 0)
      GTEST_SKIP() << "python3-spidev is not installed";
    driver_ = dir_.write("driver.py", kDriver);
  }
  std::string run_html(const std::string& extra) {
    const auto r = l6470emu("run --chain " + std::string(kTwoChains) + " " + extra + " -- /usr/bin/python3 " + driver_,
                            "TMPDIR=" + tmp_);
    EXPECT_EQ(r.status, 0) << r.out;
    return r.out;
  }
  TempDir dir_;
  std::string driver_;
  std::string tmp_ = [this] {
    std::filesystem::create_directory(dir_.file("tmp"));
    return dir_.file("tmp");
  }();
};

TEST_F(ReportChainsCommand, RunHtmlOnATwoChainBoardWritesOnePageWithBothChains) {
  const std::string page = dir_.file("page.html");
  const std::string out = run_html("--html " + page);
  EXPECT_NE(out.find("run --html: 14 frames, 3 chips, 2 chains"), std::string::npos) << out;
  EXPECT_NE(out.find(" -> " + page), std::string::npos) << out;
  const nlohmann::json d = page_data(page);
  ASSERT_EQ(d["chains"].size(), 2u) << out;
  EXPECT_EQ(d["chains"][0]["name"], "spidev0.0");
  EXPECT_EQ(d["chains"][0]["where"], "bus 0, cs 0");
  EXPECT_EQ(d["chains"][0]["frames"], 3);
  EXPECT_EQ(d["chains"][0]["chips"].size(), 1u);
  EXPECT_EQ(d["chains"][1]["name"], "spidev0.1");
  EXPECT_EQ(d["chains"][1]["frames"], 11);
  EXPECT_EQ(d["chains"][1]["chips"].size(), 2u);
  EXPECT_EQ(d["chains"][1]["trace"]["path"], "(the run's recording of spidev0.1)");
  EXPECT_TRUE(std::filesystem::is_empty(tmp_)) << "the temporary recordings are removed";
}

TEST_F(ReportChainsCommand, TheSameTwoChainRunGivesTheSamePageByteForByte) {
  std::string pages[2];
  for (int i = 0; i < 2; ++i) {
    const std::string page = dir_.file("page" + std::to_string(i) + ".html");
    run_html("--html " + page);
    pages[i] = read_text(page);
  }
  EXPECT_FALSE(pages[0].empty());
  EXPECT_TRUE(pages[0] == pages[1]) << "two runs of one program give two different pages";
}

TEST_F(ReportChainsCommand, CampaignHtmlOnATwoChainBoardShowsBothChainsOfTheCleanRunWithTheMatrix) {
  const std::string page = dir_.file("campaign.html");
  const auto r = run_command("cd " + dir_.file("") + " && TMPDIR=" + tmp_ + " " + L6470EMU_BINARY +
                             " campaign --chain " + kTwoChains + " --faults ocd -j 1 --html " + page +
                             " -- /usr/bin/python3 " + driver_ + " </dev/null");
  EXPECT_NE(r.out.find("campaign --html: 14 frames, 3 chips, 2 chains"), std::string::npos) << r.out;
  const nlohmann::json d = page_data(page);
  ASSERT_EQ(d["chains"].size(), 2u) << r.out;
  EXPECT_EQ(d["chains"][0]["trace"]["path"], "(the clean run's recording of spidev0.0)");
  EXPECT_EQ(d["chains"][1]["frames"], 11);
  EXPECT_FALSE(d["campaign"]["reruns"].empty());
}

TEST_F(ReportChainsCommand, ReportTakesATracePerChainOrThePathTheRunRecordedTo) {
  const std::string record = dir_.file("run.trace");
  run_html("--record " + record + " --html " + dir_.file("run.html"));
  const std::string a = dir_.file("run.spidev0.0.trace"), b = dir_.file("run.spidev0.1.trace");
  ASSERT_TRUE(std::filesystem::exists(a) && std::filesystem::exists(b));
  for (const std::string& traces : {a + " " + b, record}) {
    SCOPED_TRACE(traces);
    const std::string page = dir_.file("report.html");
    const auto r = l6470emu("report " + traces + " -o " + page);
    ASSERT_EQ(r.status, 0) << r.out;
    EXPECT_NE(r.out.find("report: 14 frames, 3 chips, 2 chains"), std::string::npos) << r.out;
    const nlohmann::json d = page_data(page);
    ASSERT_EQ(d["chains"].size(), 2u);
    EXPECT_EQ(d["chains"][0]["trace"]["path"], a);
    EXPECT_EQ(d["chains"][1]["trace"]["path"], b);
    EXPECT_EQ(d["title"], a + ", " + b);
  }
  // The chains in the order given.
  const auto r = l6470emu("report " + b + " " + a + " -o " + dir_.file("swapped.html"));
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(page_data(dir_.file("swapped.html"))["chains"][0]["name"], "spidev0.1");
}

TEST_F(ReportChainsCommand, TwoRecordingsOfOneChainAreOneLineAndExitTwo) {
  run_html("--record " + dir_.file("run.trace") + " --html " + dir_.file("run.html"));
  const std::string a = dir_.file("run.spidev0.0.trace");
  const std::string copy = dir_.write("copy.trace", read_text(a));
  const std::string out = dir_.file("r.html");
  for (const std::string& traces : {a + " " + a, a + " " + copy}) {
    SCOPED_TRACE(traces);
    const auto r = l6470emu("report " + traces + " -o " + out);
    EXPECT_EQ(r.status, 2) << r.out;
    EXPECT_TRUE(one_line(r.out)) << r.out;
    EXPECT_EQ(r.out.rfind("l6470emu report: ", 0), 0u) << r.out;
    struct stat st {};
    EXPECT_NE(stat(out.c_str(), &st), 0) << "no page left behind";
  }
}

}  // namespace
}  // namespace l6470emu
