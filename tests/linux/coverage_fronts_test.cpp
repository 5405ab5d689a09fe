// Interface coverage from the Linux fronts (docs/coverage.md): `run --coverage` and
// L6470EMU_COVERAGE under the preload (every process of a program merges into the file), a
// file refused before the program starts, and `serve --coverage` (what the daemon's clients
// met, merged when it stops). The points themselves are tests/board's business.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include "board/coverage_file.hpp"
#include "run_program.hpp"

namespace l6470emu::test {
namespace {

namespace fs = std::filesystem;

class CoverageFronts : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string why = missing_prerequisites();
    if (!why.empty()) GTEST_SKIP() << why;
    dir_ = fs::temp_directory_path() / ("l6470emu-coverage-test-" + std::to_string(getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  std::string file(const std::string& name, const std::string& text) {
    std::ofstream(path(name)) << text;
    return path(name);
  }
  static std::set<std::string> hit(const std::string& coverage, const std::string& category) {
    const CoverageData d = read_coverage_file(coverage);
    const auto& v = d.variants().at("L6470");
    return v.hit[static_cast<std::size_t>(coverage_category_named(category))];
  }
  fs::path dir_;
};

// A Python driver that forks: the parent sends a Move, the child a GoTo; both end normally.
const char* kForkingDriver = R"(import os, spidev
s = spidev.SpiDev(); s.open(0, 0); s.mode = 3; s.max_speed_hz = 1000000
def send(*b):
    for x in b: s.xfer2([x])
pid = os.fork()
if pid == 0:
    send(0x60, 0, 0, 0)   # GoTo 0
    raise SystemExit(0)   # an ordinary exit: atexit handlers run
send(0x41, 0, 0x10, 0)    # Move FWD 4096
os.waitpid(pid, 0)
)";

TEST_F(CoverageFronts, EveryProcessOfARunMergesWhatItMetIntoTheOneFile) {
  const std::string cov = path("cov.json");
  const RunResult r = run_program({l6470emu_program(), "run", "--chain", "chips=L6470", "--coverage", cov, "--",
                                   system_python(), file("fork.py", kForkingDriver)},
                                  {}, 60);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto commands = hit(cov, "commands");
  EXPECT_TRUE(commands.count("Move FWD")) << "the parent's";
  EXPECT_TRUE(commands.count("GoTo")) << "the child's";
}

TEST_F(CoverageFronts, TheEnvironmentVariableAloneCollectsFromAPreloadedProgram) {
  const std::string cov = path("env.json");
  const RunResult r = run_program({system_python(), "-c",
                                   "import spidev\ns = spidev.SpiDev(); s.open(0, 0); s.mode = 3\n"
                                   "[s.xfer2([b]) for b in (0x37, 0)]\n"},  // GetParam(ALARM_EN)
                                  {{"LD_PRELOAD", preload_library()},
                                   {"L6470EMU_CHAIN", "bus=0 cs=0 chips=L6470 time=virtual"},
                                   {"L6470EMU_COVERAGE", cov}});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(hit(cov, "registers read").count("ALARM_EN"));
  EXPECT_TRUE(hit(cov, "chain positions").count("chip 0 of 1"));
}

TEST_F(CoverageFronts, AFileThatIsNoCoverageFileStopsTheProgramBeforeItStartsAndIsLeftAsItWas) {
  const std::string foreign = file("notes.json", "{\"my\": \"notes\"}\n");
  const RunResult r = run_program({system_python(), "-c", "print('main ran')"},
                                  {{"LD_PRELOAD", preload_library()},
                                   {"L6470EMU_CHAIN", "bus=0 cs=0 chips=L6470 time=virtual"},
                                   {"L6470EMU_COVERAGE", foreign}});
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.out, "");
  EXPECT_NE(r.err.find("L6470EMU_COVERAGE: " + foreign + ": not an l6470emu coverage file"), std::string::npos) << r.err;
  std::ifstream in(foreign);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), "{\"my\": \"notes\"}\n");
}

TEST_F(CoverageFronts, RunRefusesAnUnwritableCoverageFileAtStartUp) {
  const RunResult r = run_program({l6470emu_program(), "run", "--chain", "chips=L6470", "--coverage",
                                   path("no/such/dir/cov.json"), "--", system_python(), "-c", "print('main ran')"});
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.out.find("main ran"), std::string::npos);
  EXPECT_NE(r.err.find("l6470emu run: --coverage: "), std::string::npos) << r.err;
}

TEST_F(CoverageFronts, TheDaemonMergesWhatAllItsClientsMetWhenItStops) {
  const std::string cov = path("serve.json");
  ServeDaemon daemon("bus=0 cs=0 chips=L6470", {"--coverage", cov});
  ASSERT_TRUE(daemon.ready()) << daemon.process().out();
  ASSERT_EQ(daemon.ctl({"sw", "closed"}).status, 0);
  ASSERT_EQ(daemon.ctl({"sw", "open"}).status, 0);
  const RunResult r = run_program({system_python(), script("busy_during_move.py"), "0", "0"}, daemon.env());
  ASSERT_EQ(r.status, 0) << r.err;
  ASSERT_EQ(daemon.ctl({"fault", "ocd", "on"}).status, 0);
  const RunResult stopped = daemon.process().stop(SIGTERM);
  EXPECT_NE(stopped.out.find("interface coverage merged into " + cov), std::string::npos) << stopped.out << stopped.err;
  EXPECT_TRUE(hit(cov, "commands").count("Move REV"));
  const auto events = hit(cov, "events");
  EXPECT_TRUE(events.count("SW closed") && events.count("SW opened") && events.count("OCD"));
  const auto edges = hit(cov, "pin edges");
  EXPECT_TRUE(edges.count("BUSY falling") && edges.count("BUSY rising")) << "libgpiod's edge events";
  EXPECT_TRUE(hit(cov, "flags observed").count("BUSY")) << "BUSY read low while the Move ran";
  EXPECT_TRUE(hit(cov, "flags raised").count("OCD"));
  EXPECT_FALSE(hit(cov, "flags observed").count("OCD")) << "nobody read STATUS after the overcurrent";
}

}  // namespace
}  // namespace l6470emu::test
