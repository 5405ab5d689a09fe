// Every SPI setting a spidev client may choose is in its recording and reproduced: a client in
// any mode, bit order, word size, speed and cs_change use, recorded under the preload library and
// by the daemon, replays and decodes with no divergence (issue 35, point 17: a mode-0 client's
// recording diverged at frame 2, recorded FC, emulated 7C).
#include <signal.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "run_program.hpp"

namespace l6470emu::test {
namespace {

namespace fs = std::filesystem;

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// The first `n` lines of `text`.
std::string head(const std::string& text, int n = 30) {
  std::size_t at = 0;
  for (int i = 0; i < n && at != std::string::npos; ++i) at = text.find('\n', at == 0 ? 0 : at + 1);
  return at == std::string::npos ? text : text.substr(0, at + 1) + "...\n";
}

/// `l6470emu replay`, `decode` (and `plot` when asked) on the file: no divergence.
::testing::AssertionResult replays_and_decodes_clean(const std::string& path, bool plot = false) {
  const RunResult r = run_program({l6470emu_program(), "replay", path}, {}, 60);
  if (r.status != 0 || r.out.find(": matched") == std::string::npos)
    return ::testing::AssertionFailure() << "replay exit " << r.status << "\n" << head(r.out, 40) << head(r.err, 10)
                                         << "--- the trace\n" << head(read_text(path), 40);
  const RunResult d = run_program({l6470emu_program(), "decode", path}, {}, 60);
  if (d.status != 0 || d.out.find("DIVERGED") != std::string::npos || d.out.find("the emulator answers") != std::string::npos)
    return ::testing::AssertionFailure() << "decode exit " << d.status << "\n" << head(d.out, 60) << head(d.err, 10);
  if (plot) {
    const RunResult p = run_program({l6470emu_program(), "plot", path, "-o", path + ".png"}, {}, 120);
    std::remove((path + ".png").c_str());
    if (p.status != 0) return ::testing::AssertionFailure() << "plot exit " << p.status << "\n" << head(p.err, 20);
  }
  return ::testing::AssertionSuccess();
}

/// Whether `l6470emu plot` can draw here (this build's Python package and python3-matplotlib).
bool can_plot() {
  static const bool yes = fs::exists(build_dir() + "/python/l6470emu/__init__.py") &&
                          run_program({system_python(), "-c", "import matplotlib"}).status == 0;
  return yes;
}

Env preload_env(const std::string& trace) {
  return {{"LD_PRELOAD", preload_library()},
          {"L6470EMU_CHAIN", "bus=0 cs=0 chips=L6470; time=virtual"},
          {"L6470EMU_TRACE", trace}};
}

/// A fresh trace path; the file is removed when the test passes.
class SpiSettingsRecording : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string why = missing_prerequisites();
    if (!why.empty()) GTEST_SKIP() << why;
    trace_ = temp_socket_path("wire") + ".trace";
  }
  void TearDown() override {
    if (!HasFailure()) std::remove(trace_.c_str());
    else std::fprintf(stderr, "the recording is kept: %s\n", trace_.c_str());
  }
  std::string trace_;
};

// ---- the case ------------------------------------------------------------------------

/// py-spidev opened and left at its default mode (0): GetStatus a byte per frame, twice.
const std::vector<std::string>& mode_zero_python_client() {
  static const std::vector<std::string> argv{
      system_python(), "-c",
      "import spidev\ns = spidev.SpiDev(); s.open(0, 0)\nassert s.mode == 0\n"
      "print([s.xfer2([b])[0] for b in (0xD0, 0, 0, 0xD0, 0, 0)])\n"};
  return argv;
}

TEST_F(SpiSettingsRecording, AModeZeroClientRecordedInProcessReplaysWhereItDivergedAtFrameTwo) {
  const RunResult r = run_program(mode_zero_python_client(), preload_env(trace_));
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const std::string text = read_text(trace_);
  // The host read the chip's stale SDO latch as the first bit: 0xFC where mode 3 reads 0x7C.
  EXPECT_NE(text.find("us 00 | FC\n"), std::string::npos) << text;
  EXPECT_NE(text.find(" wire mode=0 order=msb bits=8 speed="), std::string::npos) << text;
  EXPECT_TRUE(replays_and_decodes_clean(trace_));
}

TEST_F(SpiSettingsRecording, AModeZeroClientRecordedByTheDaemonReplaysWhereItDivergedAtFrameTwo) {
  auto daemon = std::make_unique<ServeDaemon>("bus=0 cs=0 chips=L6470", std::vector<std::string>{"--record", trace_});
  ASSERT_TRUE(daemon->ready());
  const RunResult r = run_program(mode_zero_python_client(), daemon->env());
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const RunResult d = daemon->process().stop(SIGTERM);
  daemon.reset();
  ASSERT_EQ(d.status, 0) << d.err;
  const std::string text = read_text(trace_);
  EXPECT_NE(text.find("us 00 | FC\n"), std::string::npos) << text;
  EXPECT_NE(text.find(" wire mode=0 order=msb "), std::string::npos) << text;
  EXPECT_TRUE(replays_and_decodes_clean(trace_));
}

// ---- the property: every setting -----------------------------------------------------------

struct Setting {
  unsigned mode;
  bool lsb_first;
  unsigned bits;
  unsigned speed_hz;
  bool cs_change;
};

std::string name_of(const Setting& s) {
  return "Mode" + std::to_string(s.mode) + (s.lsb_first ? "LsbFirst" : "MsbFirst") + std::to_string(s.bits) + "BitWords" +
         "At" + std::to_string(s.speed_hz) + "Hz" + (s.cs_change ? "WithCsChange" : "WithoutCsChange");
}

void PrintTo(const Setting& s, std::ostream* os) { *os << name_of(s); }

/// Every setting the preload accepts from a client: the four modes, both bit orders, the word
/// sizes of the emulated controller (8, 16, 32), a slow, the chip's fastest and a too-fast clock,
/// and transfers with and without cs_change.
std::vector<Setting> every_setting() {
  std::vector<Setting> all;
  for (unsigned mode = 0; mode < 4; ++mode)
    for (bool lsb : {false, true})
      for (unsigned bits : {8u, 16u, 32u})
        for (unsigned hz : {400'000u, 5'000'000u, 10'000'000u})
          for (bool cs : {false, true}) all.push_back({mode, lsb, bits, hz, cs});
  return all;
}

class EverySpiSetting : public ::testing::TestWithParam<Setting> {
 protected:
  void SetUp() override {
    const std::string why = missing_prerequisites();
    if (!why.empty()) GTEST_SKIP() << why;
    trace_ = temp_socket_path("setting") + ".trace";
  }
  void TearDown() override {
    if (!HasFailure()) std::remove(trace_.c_str());
    else std::fprintf(stderr, "the recording is kept: %s\n", trace_.c_str());
  }
  std::string trace_;
};

TEST_P(EverySpiSetting, AClientRecordedUnderThePreloadReplaysAndDecodesWithNoDivergence) {
  const Setting& s = GetParam();
  const RunResult r = run_program({client("spidev_settings"), "/dev/spidev0.0", std::to_string(s.mode),
                                   s.lsb_first ? "lsb" : "msb", std::to_string(s.bits), std::to_string(s.speed_hz),
                                   s.cs_change ? "1" : "0"},
                                  preload_env(trace_));
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const std::string text = read_text(trace_);
  const std::string wire = " wire mode=" + std::to_string(s.mode) + (s.lsb_first ? " order=lsb" : " order=msb") +
                           " bits=" + std::to_string(s.bits) + " speed=" + std::to_string(s.speed_hz) + " deselect=timed\n";
  EXPECT_NE(text.find(wire), std::string::npos) << "no '" << wire << "' in\n" << head(text);
  // Something was answered: the replay compared more than zeros.
  EXPECT_NE(r.out.find("miso="), std::string::npos) << r.out;
  EXPECT_TRUE(replays_and_decodes_clean(trace_));
}

INSTANTIATE_TEST_SUITE_P(ModesBitOrdersWordSizesSpeedsAndCsChange, EverySpiSetting, ::testing::ValuesIn(every_setting()),
                         [](const ::testing::TestParamInfo<Setting>& info) { return name_of(info.param); });

// ---- settings changed message by message -----------------------------------------------------

TEST_F(SpiSettingsRecording, EverySettingInTurnInOneRecordingReplaysDecodesAndPlotsInProcess) {
  const RunResult r = run_program({client("spidev_settings"), "/dev/spidev0.0", "all"}, preload_env(trace_), 120);
  ASSERT_EQ(r.status, 0) << head(r.out) << head(r.err);
  const std::string text = read_text(trace_);
  for (unsigned mode = 0; mode < 4; ++mode)
    for (const char* order : {" order=msb", " order=lsb"})
      EXPECT_NE(text.find(" wire mode=" + std::to_string(mode) + order), std::string::npos) << mode << order;
  EXPECT_TRUE(replays_and_decodes_clean(trace_, can_plot()));
}

TEST_F(SpiSettingsRecording, EverySettingInTurnRecordedByTheDaemonReplaysAndDecodes) {
  auto daemon = std::make_unique<ServeDaemon>("bus=0 cs=0 chips=2xL6470", std::vector<std::string>{"--record", trace_});
  ASSERT_TRUE(daemon->ready());
  const RunResult r = run_program({client("spidev_settings"), "/dev/spidev0.0", "all"}, daemon->env(), 120);
  ASSERT_EQ(r.status, 0) << head(r.out) << head(r.err);
  const RunResult d = daemon->process().stop(SIGTERM);
  daemon.reset();
  ASSERT_EQ(d.status, 0) << d.err;
  EXPECT_TRUE(replays_and_decodes_clean(trace_));
}

}  // namespace
}  // namespace l6470emu::test
