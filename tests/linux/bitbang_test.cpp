// SPI at the pins on Linux: a chain described with sck_pin= gets CS, SCK, MOSI and MISO lines on
// its gpiochip, and unmodified programs bit-bang the chain through them (libgpiod 1.6 on the v1
// uAPI, raw v2 ioctls, python3-libgpiod), in process and through `l6470emu serve`.
#include <gtest/gtest.h>

#include <signal.h>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <unistd.h>

#include "run_program.hpp"

namespace l6470emu::test {
namespace {

// Three L6470s whose SPI is on pins (the pin names are the firmware's; on Linux they only say so).
const std::string kPins = "bus=0 cs=0 chips=3xL6470 sck_pin=D13 mosi_pin=D11 miso_pin=D12 cs_pin=D10";

bool has_line(const std::string& text, const std::string& line) {
  return ("\n" + text).find("\n" + line + "\n") != std::string::npos;
}

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class BitBangedSpi : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string why = missing_prerequisites();
    if (!why.empty()) GTEST_SKIP() << why;
  }
  static Env env(const std::string& chain) { return {{"LD_PRELOAD", preload_library()}, {"L6470EMU_CHAIN", chain}}; }
  /// The libgpiod client, or a skip when libgpiod-dev was not there to build it.
  static bool have_gpiod_client() { return access(client("gpiod_bitbang").c_str(), X_OK) == 0; }
  /// The three chips answered CONFIG's reset value and moved by 1000, 2000 and 3000 microsteps.
  static void expect_config_and_moves(const RunResult& r, const std::string& config = "0x2E88") {
    for (int k = 0; k < 3; ++k) {
      EXPECT_TRUE(has_line(r.out, "config" + std::to_string(k) + "=" + config)) << r.out << r.err;
      EXPECT_TRUE(has_line(r.out, "abs_pos" + std::to_string(k) + "=" + std::to_string(1000 * (k + 1)))) << r.out << r.err;
    }
  }
};

TEST_F(BitBangedSpi, ALibgpiodProgramReadsConfigOfEachChipOfAThreeChipChainAndMovesThemInVirtualTime) {
  if (!have_gpiod_client()) GTEST_SKIP() << "libgpiod-dev was not there to build the client";
  const RunResult r = run_program({client("gpiod_bitbang"), "/dev/gpiochip0", "3", "config-move"}, env(kPins + "; time=virtual"));
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  expect_config_and_moves(r);
  // Each set call takes 1 µs, so CS setup and CS high time are kept: the sanitizer says nothing.
  EXPECT_EQ(r.err.find("CS_"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("SPI_"), std::string::npos) << r.err;
}

TEST_F(BitBangedSpi, ARawV2ProgramSetsSckAndMosiInOneCallWithAMaskAndReadsMisoFromTheSameRequest) {
  const RunResult r = run_program({client("gpio_v2_bitbang"), "/dev/gpiochip0"}, env(kPins + "; time=virtual"));
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_TRUE(has_line(r.out, "offsets=15,16,17,18 of 19")) << r.out;  // after the chips' 15 lines
  EXPECT_TRUE(has_line(r.out, "miso_busy=EBUSY")) << r.out;
  EXPECT_TRUE(has_line(r.out, "miso_edges=EOPNOTSUPP")) << r.out;
  EXPECT_TRUE(has_line(r.out, "ioctls_per_byte=24.0")) << r.out;  // per bit: set SCK+MOSI, get MISO, set SCK
  expect_config_and_moves(r);
  EXPECT_EQ(r.err.find("SPI_"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("edge events on MISO are not emulated"), std::string::npos) << r.err;
}

TEST_F(BitBangedSpi, PythonLibgpiodSeesTheFourLinesAfterTheChipsLinesAndReadsConfig) {
  const RunResult r = run_program(
      {system_python(), "-c",
       "import gpiod\n"
       "chip = gpiod.Chip('gpiochip0')\n"
       "print('lines', chip.num_lines(), [chip.get_line(o).name() for o in range(15, chip.num_lines())])\n"
       "cs, sck, mosi = (chip.find_line(n) for n in ('CS', 'SCK', 'MOSI'))\n"
       "miso = chip.find_line('MISO')\n"
       "for l, v in ((cs, 1), (sck, 1), (mosi, 0)): l.request(consumer='py', type=gpiod.LINE_REQ_DIR_OUT, default_val=v)\n"
       "miso.request(consumer='py', type=gpiod.LINE_REQ_DIR_IN)\n"
       "def byte(out):\n"
       "    got = 0\n"
       "    for b in range(7, -1, -1):\n"
       "        sck.set_value(0); mosi.set_value(out >> b & 1); got = got << 1 | miso.get_value(); sck.set_value(1)\n"
       "    return got\n"
       "def frame(tx):\n"
       "    cs.set_value(0); rx = [byte(b) for b in tx]; cs.set_value(1); return rx\n"
       "frame([0x38] * 3); hi = frame([0] * 3); lo = frame([0] * 3)\n"
       "print('config', ['0x%04X' % (h << 8 | l) for h, l in zip(hi, lo)])\n"},
      env(kPins + "; time=virtual"));
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_TRUE(has_line(r.out, "lines 19 ['CS', 'SCK', 'MOSI', 'MISO']")) << r.out;
  EXPECT_TRUE(has_line(r.out, "config ['0x2E88', '0x2E88', '0x2E88']")) << r.out;
}

TEST_F(BitBangedSpi, AChainWithoutSckPinKeepsItsLinesAndOneWithGpiochipNoneHasNone) {
  const RunResult r = run_program(
      {system_python(), "-c",
       "import gpiod, os\n"
       "print('lines', gpiod.Chip('gpiochip0').num_lines())\n"
       "print('spidev', os.path.exists('/dev/spidev0.0'), 'gpiochip1', os.path.exists('/dev/gpiochip1'))\n"},
      env("bus=0 cs=0 chips=3xL6470; bus=0 cs=1 chips=L6470 gpiochip=none sck_pin=D13 mosi_pin=D11 cs_pin=D10"));
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_TRUE(has_line(r.out, "lines 15")) << r.out;
  EXPECT_TRUE(has_line(r.out, "spidev True gpiochip1 False")) << r.out;
}

TEST_F(BitBangedSpi, AModeZeroProgramReadsTheStaleFirstBitAndTheSanitizerNamesSpiMode) {
  if (!have_gpiod_client()) GTEST_SKIP() << "libgpiod-dev was not there to build the client";
  const RunResult r = run_program({client("gpiod_bitbang"), "/dev/gpiochip0", "0", "config-move"}, env(kPins + "; time=virtual"));
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  // Each byte's first bit is the chips' stale latch (the last bit of the byte before): CONFIG's
  // low byte 0x88 reads 0x08, as through spidev in mode 0 and on silicon.
  EXPECT_TRUE(has_line(r.out, "config0=0x2E08")) << r.out << r.err;
  EXPECT_NE(r.err.find("SPI_MODE"), std::string::npos) << r.err;
}

TEST_F(BitBangedSpi, AFrameEndingInsideAByteIsNamedSpiPins) {
  if (!have_gpiod_client()) GTEST_SKIP() << "libgpiod-dev was not there to build the client";
  const RunResult r = run_program({client("gpiod_bitbang"), "/dev/gpiochip0", "3", "partial"}, env(kPins + "; time=virtual"));
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  EXPECT_NE(r.err.find("SPI_PINS"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("the frame ended 3 bits into byte 1"), std::string::npos) << r.err;
}

TEST_F(BitBangedSpi, ClockEdgesWithCsHighAndAFrameWithNoClockAreNamedSpiPinsButACsRequestedLowIsNot) {
  const RunResult r = run_program(
      {system_python(), "-c",
       "import gpiod, sys\n"
       "chip = gpiod.Chip('gpiochip0')\n"
       "cs, sck = chip.find_line('CS'), chip.find_line('SCK')\n"
       "cs.request(consumer='py', type=gpiod.LINE_REQ_DIR_OUT, default_val=0)\n"
       "sck.request(consumer='py', type=gpiod.LINE_REQ_DIR_OUT, default_val=0)\n"
       "cs.set_value(1)\n"
       "print('requested low', file=sys.stderr, flush=True)\n"
       "for i in range(8): sck.set_value(1); sck.set_value(0)\n"
       "print('clocked', file=sys.stderr, flush=True)\n"
       "cs.set_value(0); cs.set_value(1)\n"},
      env(kPins + "; time=virtual"));
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const auto requested = r.err.find("requested low\n"), clocked = r.err.find("clocked\n");
  ASSERT_NE(clocked, std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("SPI_PINS"), r.err.find("SPI_PINS: clock edges on SCK while CS is high")) << r.err;
  EXPECT_GT(r.err.find("SPI_PINS"), requested) << "the frame a CS requested low starts is no program's frame\n" << r.err;
  EXPECT_LT(r.err.find("SPI_PINS"), clocked) << r.err;
  EXPECT_NE(r.err.find("SPI_PINS: a chip-select frame with no clock edge", clocked), std::string::npos) << r.err;
}

TEST_F(BitBangedSpi, ARecordingOfABitBangedRunReplaysClean) {
  if (!have_gpiod_client()) GTEST_SKIP() << "libgpiod-dev was not there to build the client";
  const std::string trace = temp_socket_path("bitbang") + ".trace";
  Env e = env(kPins + "; time=virtual");
  e.push_back({"L6470EMU_TRACE", trace});
  const RunResult r = run_program({client("gpiod_bitbang"), "/dev/gpiochip0", "3", "config-move"}, e);
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  expect_config_and_moves(r);
  const RunResult rep = run_program({l6470emu_program(), "replay", trace});
  EXPECT_EQ(rep.status, 0) << rep.out << rep.err << read_file(trace);
  EXPECT_NE(rep.out.find(": matched"), std::string::npos) << rep.out << rep.err;
  std::remove(trace.c_str());
}

TEST_F(BitBangedSpi, ThroughTheDaemonTheSameProgramReadsConfigAndMovesTheChips) {
  if (!have_gpiod_client()) GTEST_SKIP() << "libgpiod-dev was not there to build the client";
  ServeDaemon d(kPins);
  ASSERT_TRUE(d.ready()) << d.process().out();
  const RunResult r = run_program({client("gpiod_bitbang"), "/dev/gpiochip0", "3", "config-move"}, d.env());
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  expect_config_and_moves(r);
  const RunResult end = d.process().stop(SIGTERM);
  EXPECT_EQ(end.status, 0) << end.out << end.err;
  EXPECT_EQ(end.err.find("SPI_"), std::string::npos) << end.err;
}

TEST_F(BitBangedSpi, ABitBangedBytesCostThroughThePreloadIsMeasured) {
  if (!have_gpiod_client()) GTEST_SKIP() << "libgpiod-dev was not there to build the client";
  // Not a timed assertion: the numbers are printed for the record (docs/linux.md § gpiochip).
  const RunResult r = run_program({client("gpiod_bitbang"), "/dev/gpiochip0", "3", "bench", "200"}, env(kPins + "; time=virtual"));
  ASSERT_EQ(r.status, 0) << r.out << r.err;
  const auto kv = key_values(r.out);
  EXPECT_EQ(kv.count("config0") ? kv.at("config0") : "", "0x2E88") << r.out;
  EXPECT_EQ(kv.count("ioctls_per_byte") ? kv.at("ioctls_per_byte") : "", "32.0") << r.out;  // v1: 3 sets + 1 get per bit
  // Board time: 24 sets of 1 µs a byte, and a frame's two CS sets over its three bytes.
  EXPECT_EQ(kv.count("board_ns_per_byte") ? kv.at("board_ns_per_byte") : "", "24667") << r.out;
  std::cout << "bit-banged byte through the preload (libgpiod v1, in process, virtual time):\n" << r.out;
  RecordProperty("ns_per_ioctl", kv.count("ns_per_ioctl") ? kv.at("ns_per_ioctl") : "?");
  RecordProperty("ns_per_byte", kv.count("ns_per_byte") ? kv.at("ns_per_byte") : "?");
}

}  // namespace
}  // namespace l6470emu::test
