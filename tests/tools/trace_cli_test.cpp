// The trace subcommands as a user runs them (tools/cmd_replay.cpp, cmd_decode.cpp,
// cmd_convert.cpp): exit statuses, what is printed, conversions, and one-line errors
// with the file and line for bad input.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>

#include "spi/trace_native.hpp"
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
  EXPECT_NE(r.out.find("30 frames, 90 MISO bytes compared, 18 pin levels checked (BUSY, FLAG, SW the axis drove): matched"), std::string::npos)
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

TEST(DecodeCommand, ACaptureTheModelDoesNotReproduceIsMarkedAndExitsOneUnlessAccepted) {
  const std::string capture = fixture_path("ftrace_spi_set_cs.txt");
  RunResult r = l6470emu("decode " + capture + " 2>&1");
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("t=1523.803136 s  !!!!!!!! DIVERGED: " + capture +
                       ":169: frame 23 at t=1523.803136 s: chip 0: MISO byte 0 expected 0xF0, emulated 0xCD\n"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("from there on the log is the emulator's model, not the trace"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("l6470emu decode: the emulator does not reproduce " + capture), std::string::npos) << r.out;
  r = l6470emu("decode --accept-divergence " + capture + " 2>&1");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("DIVERGED"), std::string::npos) << "accepted, still marked: " << r.out;
  // A trace the emulator reproduces: exit 0, no mark.
  r = l6470emu("decode " + fixture_path("homing_axis.trace") + " 2>&1");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(r.out.find("DIVERGED"), std::string::npos) << r.out;
}

TEST(ReplayCommand, AForeignCaptureRunsThroughTheBoardItIsGivenAndSaysWhence) {
  test::TempDir dir;
  const std::string capture = fixture_path("homing_axis_saleae.csv");  // a homing run; its switch is in no capture
  const std::string rig = "chips=L6470 axis.0=stops=-6400..300000,start=51200,switch=home@0:below:hyst=64";
  RunResult r = l6470emu("replay " + capture + " 2>&1");
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find(":1874: frame 625 at t=2.057488000 s: MISO byte 0 expected 0x0E, emulated 0x60"), std::string::npos) << r.out;
  const std::string board = dir.write("rig.conf", "# the rig: one L6470, a carriage, a home switch\n" + rig + "\n");
  r = l6470emu("replay --board " + board + " " + capture + " 2>&1");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("through L6470 with an axis behind chip 0 (from --board " + board + ")"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(": 800 frames, 800 MISO bytes compared: matched"), std::string::npos) << r.out;
  r = l6470emu("replay --chain '" + rig + "' " + capture + " 2>&1");
  EXPECT_EQ(r.status, 0) << r.out;
  r = l6470emu("decode --board " + board + " " + capture + " 2>&1");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("# 800 frames, 4 commands, 263 answers, 0 diagnostics"), std::string::npos) << r.out;
  // A native recording's own board is replaced only when told, and the output says so.
  r = l6470emu("replay --chain L6470 " + fixture_path("homing_axis.trace") + " 2>&1");
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("the trace's own description (its board lines, from line 3) is not used"), std::string::npos) << r.out;
  // A bad board file: one line naming it.
  r = l6470emu("replay --board " + dir.write("bad.conf", "chips=L6470 axis.3=default\n") + " " + capture + " 2>&1");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_NE(r.out.find("bad.conf"), std::string::npos) << r.out;
}

TEST(ConvertCommand, WritesNativeVcdAndUmockdevFiles) {
  test::TempDir dir;
  RunResult r = l6470emu("convert " + fixture_path("saleae_logic2.csv") + " -o " + dir.file("c.trace"));
  ASSERT_EQ(r.status, 0) << r.out;
  const std::string native = test::read_text(dir.file("c.trace"));
  EXPECT_EQ(native.rfind("l6470emu-trace 3\n# " + std::string(kNativeTraceNumbering) + "\n# converted from ", 0), 0u)
      << native;
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

/// How many lines `text` has.
std::size_t lines_in(const std::string& text) { return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')); }

TEST(ConvertCommand, NamesWhereItWasWritingWhenAWriteFails) {
  if (::access("/dev/full", W_OK) != 0) GTEST_SKIP() << "no /dev/full";
  const std::string in = fixture_path("polling_host.trace");
  RunResult r = l6470emu("convert --expand " + in + " -o /dev/full");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.out, "l6470emu convert: /dev/full: write failed: No space left on device\n");
  // Standard error to the pipe, standard output to the full disk.
  r = run_command("{ " + std::string(L6470EMU_BINARY) + " convert --expand " + in + " -o - >/dev/full; }");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.out, "l6470emu convert: standard output: write failed: No space left on device\n");
  r = run_command("{ " + std::string(L6470EMU_BINARY) + " convert --to ioctl " + in + " -o - >/dev/full; }");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.out, "l6470emu convert: standard output: write failed: No space left on device\n");
}

TEST(ConvertCommand, StopsAVcdAtItsFirstFailedWrite) {
  if (::access("/dev/full", W_OK) != 0) GTEST_SKIP() << "no /dev/full";
  const std::string in = fixture_path("polling_host.trace");
  RunResult r = l6470emu("convert --to vcd " + in + " -o /dev/full");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.out, "l6470emu convert: /dev/full: write failed: No space left on device\n");
  r = run_command("{ " + std::string(L6470EMU_BINARY) + " convert --to vcd --no-emulation " + in + " -o - >/dev/full; }");
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.out, "l6470emu convert: standard output: write failed: No space left on device\n");
}

TEST(ConvertCommand, StopsAnEmulatedVcdAtTheOutputLimitWhenTheMotorsSamplesPassIt) {
  // The wires of polling_host.trace take at least 1.5 MiB of VCD; the emulated chain's samples
  // of its move (not told by the trace's counts) make it 2.3 MiB.
  test::TempDir dir;
  const std::string out = dir.file("p.vcd");
  const RunResult r = l6470emu("convert " + fixture_path("polling_host.trace") + " -o " + out + " --max-output 2M");
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_EQ(r.out, "l6470emu convert: " + out +
                       ": stopped at 2.0 MiB, the output limit: what was written is incomplete (raise it with "
                       "--max-output SIZE; 0 = no limit)\n");
  EXPECT_EQ(test::read_text(out).size(), 2u << 20);
  EXPECT_EQ(l6470emu("convert " + fixture_path("polling_host.trace") + " -o " + out + " --max-output 3M").status, 0);
  EXPECT_EQ(l6470emu("convert " + fixture_path("polling_host.trace") + " -o " + out + " --max-output 0").status, 0);
}

TEST(ConvertCommand, TakesMaxOutputInBytesOrBinaryUnitsAndRefusesAnythingElseInOneLine) {
  test::TempDir dir;
  const std::string in = fixture_path("single_chip.trace");
  for (const char* ok : {"100000", "1G", "500M", "0.5g", "64KiB", "2TB", "0"})
    EXPECT_EQ(l6470emu("convert " + in + " -o " + dir.file("o.ioctl") + " --max-output " + ok).status, 0) << ok;
  for (const char* bad : {"x", "-1", "10Q", "1.5.2", "99999999999999999999"}) {
    const RunResult r = l6470emu("convert " + in + " -o " + dir.file("o.ioctl") + " --max-output " + bad);
    EXPECT_EQ(r.status, 2) << bad;
    EXPECT_EQ(r.out, "l6470emu convert: --max-output: '" + std::string(bad) +
                         "' is not a size: bytes, or a number with K, M, G or T (500M, 10G); 0 = no limit\n")
        << bad;
  }
  const RunResult r = l6470emu("convert " + in + " -o " + dir.file("o.ioctl") + " --max-output 100");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("more than 100 bytes, the output limit (raise it with --max-output 1M; 0 = no limit)\n"),
            std::string::npos)
      << r.out;
}

TEST(ConvertCommand, NeverWritesOverItsInput) {
  test::TempDir dir;
  const std::string original = test::fixture("polling_host.trace");
  const std::string in = dir.write("p.trace", original);
  ASSERT_EQ(::link(in.c_str(), dir.file("same.trace").c_str()), 0);
  for (const std::string& out : {in, dir.file("same.trace")})
    for (const char* opts : {"", " --expand", " --to vcd", " --to ioctl"}) {
      const RunResult r = l6470emu("convert " + in + " -o " + out + opts);
      EXPECT_EQ(r.status, 2) << out << opts;
      EXPECT_EQ(r.out, "l6470emu convert: cannot write " + out + ": it is one of the inputs (" + in +
                           "): an output never overwrites an input\n")
          << opts;
      EXPECT_EQ(test::read_text(in), original) << out << opts;
    }
  // Nor the board description it was given.
  const std::string board = dir.write("b.board", "chips=2*L6470\n");
  const RunResult r = l6470emu("convert " + in + " --board " + board + " -o " + board);
  EXPECT_EQ(r.status, 2) << r.out;
  EXPECT_EQ(test::read_text(board), "chips=2*L6470\n");
}

TEST(ConvertCommand, SaysSoInOneLineWhenItsReaderGoesAway) {
  test::TempDir dir;
  // The reader takes 10 bytes of a 100 kB output and closes the pipe.
  const std::string cmd = "(" + std::string(L6470EMU_BINARY) + " convert --expand " + fixture_path("polling_host.trace") +
                          " -o - 2>" + dir.file("err") + "; echo $? >" + dir.file("status") + ") | head -c 10 >/dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  EXPECT_EQ(test::read_text(dir.file("status")), "2\n");
  EXPECT_EQ(test::read_text(dir.file("err")), "l6470emu convert: standard output: write failed: Broken pipe\n");
}

TEST(ConvertCommand, KeepsWhatItWroteBeforeABadLine) {
  test::TempDir dir;
  const std::string bad = dir.write("bad.trace", "l6470emu-trace 1\n0.001 frame 00 | 00\n0.002 frame ZZ | 00\n");
  RunResult r = l6470emu("convert " + bad + " -o " + dir.file("out.trace"));
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.out, "l6470emu convert: " + bad + ":3: MOSI \"ZZ\" is not a byte (two hex digits)\n");
  const std::string written =
      "l6470emu-trace 3\n# " + std::string(kNativeTraceNumbering) + "\n0.00100000 frame 0.00us 00 | 00\n";
  EXPECT_EQ(test::read_text(dir.file("out.trace")), written);
  r = run_command("{ " + std::string(L6470EMU_BINARY) + " convert " + bad + " -o - 2>/dev/null; }");
  EXPECT_EQ(r.out, written);
}

TEST(TraceCommands, NameTheLineWhereGzipDataIsDamaged) {
  test::TempDir dir;
  ASSERT_EQ(l6470emu("convert --expand " + fixture_path("polling_host.trace") + " -o " + dir.file("p.trace.gz")).status, 0);
  std::string data = test::read_text(dir.file("p.trace.gz"));
  data[data.size() - 8] = static_cast<char>(data[data.size() - 8] ^ 0x5A);  // the CRC-32 of the text: checked at the end
  const std::string bad = dir.write("bad.trace.gz", data);
  const RunResult r = l6470emu("replay " + bad);
  EXPECT_EQ(r.status, 2) << r.out;
  // The last line of the output is the error: the file, the (uncompressed) line, the bytes before it.
  const std::string last = r.out.substr(r.out.rfind("l6470emu replay: "));
  EXPECT_EQ(lines_in(last), 1u) << r.out;
  EXPECT_EQ(last.find("l6470emu replay: " + bad + ":"), 0u) << last;
  EXPECT_NE(last.find(": damaged gzip data after "), std::string::npos) << last;
  EXPECT_EQ(last.find("<fd:"), std::string::npos) << last;  // zlib's name for the descriptor is no help
  const std::size_t line = std::stoul(last.substr(("l6470emu replay: " + bad + ":").size()));
  EXPECT_GT(line, 3000u) << last;
  // A file damaged at its very start: line 1.
  std::string head = test::read_text(dir.file("p.trace.gz"));
  for (std::size_t i = 12; i < 40; ++i) head[i] = static_cast<char>(head[i] ^ 0x5A);
  const RunResult first = l6470emu("decode " + dir.write("head.trace.gz", head));
  EXPECT_EQ(first.status, 2);
  EXPECT_EQ(first.out.find("l6470emu decode: " + dir.file("head.trace.gz") + ":1: "), 0u) << first.out;
}

TEST(TraceCommands, GiveOneLineForEmptyBinaryAndNonTraceFiles) {
  test::TempDir dir;
  std::string binary;
  for (int i = 0; i < 4096; ++i) binary += static_cast<char>((i * 7919) & 0xFF);
  const std::string sr = dir.write("capture.sr", "PK\x03\x04" + binary);
  struct Case {
    std::string path, says;
  } cases[] = {
      {dir.write("empty.trace", ""), ": empty file"},
      {dir.write("noise.bin", binary), ": unknown trace format"},
      {sr, "capture.sr: "},
      {dir.file("."), ": cannot read: it is a directory"},
  };
  for (const Case& c : cases) {
    const RunResult r = l6470emu("decode " + c.path);
    EXPECT_EQ(r.status, 2) << c.path << "\n" << r.out;
    EXPECT_EQ(lines_in(r.out), 1u) << r.out;
    EXPECT_EQ(r.out.find("l6470emu decode: " + c.path), 0u) << r.out;
    EXPECT_NE(r.out.find(c.says), std::string::npos) << r.out;
  }
}

TEST(TraceCommands, RefuseADeviceInEveryFormatInsteadOfReadingItForEver) {
  // /dev/zero never ends: before, `replay --format ftrace /dev/zero` looked for its events for ever.
  for (const std::string format : {"", "--format ftrace ", "--format native ", "--format sigrok "}) {
    const RunResult r = l6470emu("replay --chain L6470 " + format + "/dev/zero");
    EXPECT_EQ(r.status, 2) << format << r.out;
    EXPECT_EQ(r.out, "l6470emu replay: /dev/zero: cannot read: it is a device, not a file: it could block or never end\n")
        << format;
  }
}

TEST(TraceCommands, NameTheChainItemThatIsWrong) {
  const RunResult r = l6470emu("decode --chain 2,3* " + fixture_path("three_chips.trace"));
  EXPECT_EQ(r.status, 2);
  EXPECT_EQ(r.out, "l6470emu decode: --chain: chain item \"3*\" has no variant after '*' (N*VARIANT, e.g. 3*L6470)\n");
}

TEST(DecodeCommand, ListsTheChipsOfOneTimeInTheOrderTheyAreNumbered) {
  const RunResult r = l6470emu("decode --number-from mosi " + fixture_path("three_chips.trace"));
  ASSERT_EQ(r.status, 0) << r.out;
  const auto c0 = r.out.find("t=0.001047 s  chip 0   SetParam(ACC");
  const auto c1 = r.out.find("t=0.001047 s  chip 1   SetParam(MAX_SPEED");
  const auto c2 = r.out.find("t=0.001047 s  chip 2   SetParam(CONFIG");
  ASSERT_NE(c0, std::string::npos) << r.out;
  EXPECT_LT(c0, c1) << r.out;
  EXPECT_LT(c1, c2) << r.out;
}

}  // namespace
}  // namespace l6470emu
