// The trace subcommands as a user runs them (tools/cmd_replay.cpp, cmd_decode.cpp,
// cmd_convert.cpp): exit statuses, what is printed, conversions, and one-line errors
// with the file and line for bad input.
#include <gtest/gtest.h>

#include "support/trace_test_support.hpp"

namespace l6470emu {
namespace {

using test::fixture_path;
using test::run_command;
using test::RunResult;

RunResult l6470emu(const std::string& args) { return run_command(std::string(L6470EMU_BINARY) + " " + args); }

TEST(ReplayCommand, ExitsZeroWhenTheCaptureMatches) {
  const RunResult r = l6470emu("replay " + fixture_path("three_chips.trace"));
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("through 3*L6470 (from the trace)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("30 frames, 90 MISO bytes compared, 18 BUSY/FLAG levels checked: matched"), std::string::npos)
      << r.out;
}

TEST(ReplayCommand, ExitsOneWithAReportWhenItDiverges) {
  const RunResult r = l6470emu("replay " + fixture_path("ftrace_spi_set_cs.txt"));
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("ftrace_spi_set_cs.txt:169: frame 23 at t=1523.803136000 s: MISO byte 0 expected 0xF0, emulated 0xCD"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("DIVERGED (stopped at the first divergence; --continue reports them all)"), std::string::npos)
      << r.out;
  const RunResult all = l6470emu("replay --continue --quiet " + fixture_path("ftrace_spi_set_cs.txt"));
  EXPECT_EQ(all.status, 1);
  EXPECT_NE(all.out.find("DIVERGED in 5 frames"), std::string::npos) << all.out;
}

TEST(ReplayCommand, ReadsEveryImportFormat) {
  for (const char* f : {"saleae_logic2.csv", "saleae_logic2_decimal_no_duration.csv", "ftrace_trace_cmd_report.txt",
                        "sigrok_spi.json"}) {
    const RunResult r = l6470emu("replay " + fixture_path(f));
    EXPECT_EQ(r.status, 0) << f << "\n" << r.out;
  }
}

TEST(ReplayCommand, RunsSigrokCliOnALogicCapture) {
  if (!test::have_program("sigrok-cli")) GTEST_SKIP() << "sigrok-cli not installed (Debian package sigrok-cli)";
  const RunResult r = l6470emu("replay " + fixture_path("two_chips.vcd"));
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("17 frames, 34 MISO bytes compared: matched"), std::string::npos) << r.out;
}

TEST(ReplayCommand, ExitsTwoWithAOneLineErrorForBadInput) {
  test::TempDir dir;
  const std::string csv = dir.write("capture.csv", "name,type,start_time,duration,\"mosi\",\"miso\"\n"
                                                   "\"SPI\",\"enable\",0.1,2e-08,,\n"
                                                   "\"SPI\",\"result\",0.1000001,1e-06,0xD0,0xZZ\n");
  RunResult r = l6470emu("replay " + csv);
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.out, "l6470emu replay: " + csv + ":3: MISO \"0xZZ\" is not a byte\n");
  r = l6470emu("replay " + dir.file("missing.trace"));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("missing.trace: cannot open: No such file or directory"), std::string::npos) << r.out;
  r = l6470emu("replay --chain 3*L6499 " + fixture_path("three_chips.trace"));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("--chain: unknown chip variant \"L6499\""), std::string::npos) << r.out;
  r = l6470emu("replay " + dir.write("junk.bin", "hello\n"));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("unknown trace format"), std::string::npos) << r.out;
  r = l6470emu("replay");
  EXPECT_NE(r.status, 0);
}

TEST(DecodeCommand, PrintsTheExplainedLog) {
  const RunResult r = l6470emu("decode " + fixture_path("saleae_logic2.csv"));
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("t=0.421855 s  chip 0   GetStatus → 0x7C03 [HiZ REV STOPPED UVLO]"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("chip 0   SetParam(ACC, 0x100 = 3725 step/s²)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("chip 0   Move(FWD, 3200 microsteps)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("# 54 frames, 4 commands, 12 answers, 0 diagnostics"), std::string::npos) << r.out;
}

TEST(ConvertCommand, WritesNativeVcdAndUmockdevFiles) {
  test::TempDir dir;
  RunResult r = l6470emu("convert " + fixture_path("saleae_logic2.csv") + " -o " + dir.file("c.trace"));
  ASSERT_EQ(r.status, 0) << r.out;
  const std::string native = test::read_text(dir.file("c.trace"));
  EXPECT_EQ(native.rfind("l6470emu-trace 1\n# converted from ", 0), 0u) << native;
  // The converted trace replays as the original does.
  r = l6470emu("replay --chain 1 " + dir.file("c.trace"));
  EXPECT_EQ(r.status, 0) << r.out;

  r = l6470emu("convert " + fixture_path("three_chips.trace") + " -o " + dir.file("c.vcd"));
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(test::read_text(dir.file("c.vcd")).find("$var real 64"), std::string::npos);

  r = l6470emu("convert " + fixture_path("single_chip.trace") + " -o " + dir.file("c.ioctl"));
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(test::read_text(dir.file("c.ioctl")).rfind("@DEV /dev/spidev0.0 (SPI)\n", 0), 0u);

  r = l6470emu("convert " + fixture_path("single_chip.trace") + " --to ioctl -o -");
  EXPECT_NE(r.out.find("TW d0\n R 00\n"), std::string::npos) << r.out;
}

TEST(ConvertCommand, WritesAndReadsGzipTracesOfAnyFormat) {
  test::TempDir dir;
  // A capture converted to gzip-compressed native text replays as the original.
  RunResult r = l6470emu("convert " + fixture_path("polling_host.trace") + " -o " + dir.file("p.trace.gz"));
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(test::read_text(dir.file("p.trace.gz")).substr(0, 2), "\x1f\x8b");
  r = l6470emu("replay " + dir.file("p.trace.gz"));
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("3607 frames"), std::string::npos) << r.out;
  // Other formats too: a gzip-compressed Saleae export is recognised by its content.
  r = l6470emu("convert " + fixture_path("saleae_logic2.csv") + " --to vcd --no-emulation -o " + dir.file("s.vcd.gz"));
  ASSERT_EQ(r.status, 0) << r.out;
  ASSERT_EQ(std::system(("gzip -c " + fixture_path("saleae_logic2.csv") + " > " + dir.file("s.csv.gz")).c_str()), 0);
  r = l6470emu("replay --chain 1 " + dir.file("s.csv.gz"));
  EXPECT_EQ(r.status, 0) << r.out;
}

TEST(ConvertCommand, ExpandsRepeatLinesOnRequest) {
  const RunResult compact = l6470emu("convert " + fixture_path("polling_host.trace") + " -o -");
  const RunResult expanded = l6470emu("convert --expand " + fixture_path("polling_host.trace") + " -o -");
  ASSERT_EQ(expanded.status, 0) << expanded.out;
  EXPECT_NE(compact.out.find(" repeat 3 frames 568 times every 1000.00us"), std::string::npos) << compact.out;
  EXPECT_EQ(expanded.out.find(" repeat "), std::string::npos);
  EXPECT_GT(expanded.out.size(), 50 * compact.out.size());
}

TEST(ReplayCommand, NamesTheFileLineAndByteWhereAGzipTraceIsCutShort) {
  test::TempDir dir;
  ASSERT_EQ(l6470emu("convert --expand " + fixture_path("polling_host.trace") + " -o " + dir.file("p.trace.gz")).status, 0);
  const std::string whole = test::read_text(dir.file("p.trace.gz"));
  const std::string cut = dir.write("cut.trace.gz", whole.substr(0, whole.size() / 2));
  const RunResult r = l6470emu("replay " + cut);
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("l6470emu replay: " + cut + ":"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(": the gzip data ends early, after "), std::string::npos) << r.out;
}

TEST(DecodeCommand, NumbersChipsFromTheMosiEndWhenAskedAndSaysSo) {
  const RunResult r = l6470emu("decode --number-from mosi " + fixture_path("three_chips.trace"));
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("chain 3*L6470 (from the trace); chip numbers count from the MOSI end"), std::string::npos) << r.out;
  // The thermal warning happened on the chain's chip 2, the one nearest the host's MOSI.
  EXPECT_NE(r.out.find("chip 0   fault THERMAL warning"), std::string::npos) << r.out;
  const RunResult miso = l6470emu("decode " + fixture_path("three_chips.trace"));
  EXPECT_NE(miso.out.find("chip numbers count from the MISO end"), std::string::npos) << miso.out;
  EXPECT_NE(miso.out.find("chip 2   fault THERMAL warning"), std::string::npos) << miso.out;
  const RunResult only = l6470emu("decode --number-from mosi --chip 0 " + fixture_path("three_chips.trace"));
  EXPECT_NE(only.out.find("chip 0   fault THERMAL warning"), std::string::npos) << only.out;
  EXPECT_EQ(only.out.find("chip 2 "), std::string::npos) << only.out;
}

TEST(ReplayCommand, SaysHowItNumbersChipsBeforeTheFirstReport) {
  const RunResult r = l6470emu("replay --number-from mosi --chain 3 " + fixture_path("ftrace_spi_set_cs.txt"));
  EXPECT_EQ(r.status, 1) << r.out;
  const auto said = r.out.find("# chip numbers count from the MOSI end");
  const auto report = r.out.find("frame 23 at t=1523.803136000 s: MISO byte 0 expected 0xF0");
  ASSERT_NE(said, std::string::npos) << r.out;
  EXPECT_LT(said, report) << r.out;
  // MISO byte 0 comes from the chain's chip 0, the MISO end: chip 2 counted from MOSI.
  EXPECT_NE(r.out.find("byte 0: chip 2: byte 3 of 3 of the GetParam(ABS_POS) answer"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("  chip 2 state (emulated, as it answered):"), std::string::npos) << r.out;
}

TEST(TraceCommands, RejectAnUnknownNumberingInOneLineWithStatusTwo) {
  for (const char* cmd : {"decode", "replay"}) {
    const RunResult r = l6470emu(std::string(cmd) + " --number-from x " + fixture_path("three_chips.trace"));
    EXPECT_EQ(r.status, 2) << cmd;
    EXPECT_EQ(r.out, std::string("l6470emu ") + cmd +
                         ": --number-from: 'x' is not a chip numbering: write miso (chip 0 drives MISO) or mosi "
                         "(chip 0 reads the host's MOSI)\n");
  }
}

}  // namespace
}  // namespace l6470emu
