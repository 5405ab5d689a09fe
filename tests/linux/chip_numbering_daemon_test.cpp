// The daemon's chip numbering (numbering= in the board description, serve --number-from,
// ctl --number-from): ctl and serve say which end chip 0 is at, and a chip number given to
// ctl reaches the chip a host program sees at that end of the chain.
#include <signal.h>

#include <algorithm>
#include <sstream>

#include <gtest/gtest.h>

#include "run_program.hpp"

namespace l6470emu::test {
namespace {

const std::string kFromMosi =
    "chip numbers count from the MOSI end (chip 0 reads the host's MOSI and gets a full frame's last byte)";
const std::string kFromMiso =
    "chip numbers count from the MISO end (chip 0 drives MISO and gets a full frame's first byte)";

/// A host program reading every chip's STATUS in 3-byte frames: MISO byte k is the chain's chip k.
const char* const kStatusOfEachChip =
    "import spidev\ns = spidev.SpiDev(); s.open(0, 0); s.mode = 3\n"
    "s.xfer2([0xD0] * 3); hi = s.xfer2([0] * 3); lo = s.xfer2([0] * 3)\n"
    "print(' '.join('%04X' % (h << 8 | l) for h, l in zip(hi, lo)))\n";

class NumberedDaemon : public ::testing::Test {
 protected:
  void start(const std::string& chain, const std::vector<std::string>& extra = {}) {
    const std::string why = missing_prerequisites();
    if (!why.empty()) GTEST_SKIP() << why;
    daemon_ = std::make_unique<ServeDaemon>(chain, extra);
    ASSERT_TRUE(daemon_->ready()) << daemon_->process().out();
  }
  void TearDown() override {
    if (daemon_) {
      stopped_ = daemon_->process().stop(SIGTERM);
      EXPECT_EQ(stopped_.status, 0) << stopped_.out << stopped_.err;
    }
  }
  RunResult ctl(const std::string& command) {
    std::vector<std::string> words;
    std::istringstream in(command);
    for (std::string w; in >> w;) words.push_back(w);
    return daemon_->ctl(words);
  }
  std::unique_ptr<ServeDaemon> daemon_;
  RunResult stopped_;
};

TEST_F(NumberedDaemon, NumberingMosiInTheConfigMakesCtlCallTheMosiEndChipZeroAndSaySo) {
  start("bus=0 cs=0 chips=3xL6470 numbering=mosi");
  const RunResult status = ctl("status");
  ASSERT_EQ(status.status, 0) << status.err;
  EXPECT_EQ(status.out.rfind("# " + kFromMosi + "\n", 0), 0u) << status.out;
  // ctl's chip 0 is the chain's chip 2: the one whose answer is the last MISO byte of a frame.
  ASSERT_EQ(ctl("sw closed --chip 0").out, "chip 0: SW low\n");
  EXPECT_NE(ctl("status --chip 0").out.find("chip 0 (L6470): STATUS 0x7C0E  SW_F SW_EVN"), std::string::npos);
  const RunResult host = run_program({system_python(), "-c", kStatusOfEachChip}, daemon_->env());
  ASSERT_EQ(host.status, 0) << host.err;
  EXPECT_EQ(host.out, "7C03 7C03 7C0E\n");
}

TEST_F(NumberedDaemon, CtlNumberFromOverridesTheDaemonsNumberingForOneCommand) {
  start("bus=0 cs=0 chips=3xL6470 numbering=mosi");
  ASSERT_EQ(ctl("fault ocd on --chip 2 --number-from miso").status, 0);  // the chain's chip 2
  const RunResult miso = ctl("status --number-from miso");
  EXPECT_EQ(miso.out.rfind("# " + kFromMiso + "\n", 0), 0u) << miso.out;
  EXPECT_NE(miso.out.find("chip 2 (L6470): STATUS 0x6C03  HiZ REV STOPPED UVLO OCD\n"), std::string::npos) << miso.out;
  // The same chip is chip 0 counted from MOSI, the daemon's default here.
  EXPECT_NE(ctl("status --chip 0").out.find("chip 0 (L6470): STATUS 0x6C03"), std::string::npos);
  EXPECT_NE(ctl("status --chip 2").out.find("chip 2 (L6470): STATUS 0x7C03"), std::string::npos);
  // Before the command word, as an option of ctl itself.
  const RunResult before = daemon_->ctl({"--number-from", "miso", "status", "--chip", "2"});
  EXPECT_NE(before.out.find("chip 2 (L6470): STATUS 0x6C03"), std::string::npos) << before.out << before.err;
}

TEST_F(NumberedDaemon, ServeSaysHowItNumbersChipsWhenItStarts) {
  start("bus=0 cs=0 chips=2xL6470", {"--number-from", "mosi"});
  EXPECT_NE(daemon_->process().out().find("  " + kFromMosi + " (ctl and diagnostics; numbering=)\n"), std::string::npos)
      << daemon_->process().out();
  EXPECT_NE(ctl("help").out.find(kFromMosi), std::string::npos);
}

TEST_F(NumberedDaemon, CtlRejectsAnUnknownNumberingInOneLineWithStatusTwo) {
  start("bus=0 cs=0 chips=2xL6470");
  const RunResult r = ctl("status --number-from x");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.err, "ctl: --number-from must be miso (chip 0 drives MISO) or mosi (chip 0 reads the host's MOSI), not 'x'\n");
}

TEST(NumberedDaemonConfig, AnUnknownNumberingGivesOneErrorLineAndExitStatus2) {
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"--chain", "bus=0 chips=L6470 numbering=x"},
        std::vector<std::string>{"--chain", "bus=0 chips=L6470", "--number-from", "x"}}) {
    std::vector<std::string> argv = {l6470emu_program(), "serve", "--socket", temp_socket_path("numbering")};
    argv.insert(argv.end(), args.begin(), args.end());
    const RunResult r = run_program(argv);
    EXPECT_EQ(r.status, 2) << r.out << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_NE(r.err.find("must be miso (chip 0 drives MISO) or mosi (chip 0 reads the host's MOSI), not 'x'"),
              std::string::npos)
        << r.err;
  }
}

}  // namespace
}  // namespace l6470emu::test
