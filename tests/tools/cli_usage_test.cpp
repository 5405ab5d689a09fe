// Usage errors of every subcommand of the l6470emu program (tools/cli_errors.cpp): exit status
// 2, one line naming the subcommand, and the near miss named; and the `units` subcommand.
#include <gtest/gtest.h>

#include <string>

#include "core/counted.hpp"
#include "support/trace_test_support.hpp"

namespace l6470emu {
namespace {

using test::run_command;
using test::RunResult;

RunResult l6470emu(const std::string& args) { return run_command(std::string(L6470EMU_BINARY) + " " + args); }

/// Runs `args`, expects exit status 2 and exactly the one line `line` (standard output and error together).
void expect_usage_error(const std::string& args, const std::string& line) {
  const RunResult r = l6470emu(args + " </dev/null");
  EXPECT_EQ(r.status, 2) << "l6470emu " << args << "\n" << r.out;
  EXPECT_EQ(r.out, line + "\n") << "l6470emu " << args;
}

TEST(UsageErrors, AMisspeltSubcommandIsNamedWithTheNearestOne) {
  expect_usage_error("replya x", "l6470emu: unknown subcommand 'replya'; did you mean 'replay'?");
  expect_usage_error("dcode x", "l6470emu: unknown subcommand 'dcode'; did you mean 'decode'?");
  expect_usage_error("frobnicate",
                     "l6470emu: unknown subcommand 'frobnicate' (demo, tables, serve, ctl, run, campaign, coverage, replay, decode, convert, "
                     "plot, units, report; l6470emu --help)");
  expect_usage_error("", "l6470emu: a subcommand is required: demo, tables, serve, ctl, run, campaign, coverage, replay, decode, convert, "
                         "plot, units, report (l6470emu --help)");
  expect_usage_error("--verison", "l6470emu: unknown option '--verison'; did you mean '--version'?");
  expect_usage_error("--decode x", "l6470emu: unknown option '--decode'; did you mean 'decode'?");
}

TEST(UsageErrors, EverySubcommandNamesAMisspeltOption) {
  expect_usage_error("demo --chip 3", "l6470emu demo: unknown option '--chip'; did you mean '--chips'?");
  expect_usage_error("tables --tabel commands", "l6470emu tables: unknown option '--tabel'; did you mean '--table'?");
  expect_usage_error("serve --chian x", "l6470emu serve: unknown option '--chian'; did you mean '--chain'?");
  expect_usage_error("ctl --sockt x status", "l6470emu ctl: unknown option '--sockt'; did you mean '--socket'?");
  expect_usage_error("replay --chian 3 x", "l6470emu replay: unknown option '--chian'; did you mean '--chain'?");
  expect_usage_error("decode --nop x", "l6470emu decode: unknown option '--nop'; did you mean '--nops'?");
  expect_usage_error("convert x -o y --expnd", "l6470emu convert: unknown option '--expnd'; did you mean '--expand'?");
  expect_usage_error("plot --chpis 1 x", "l6470emu plot: unknown option '--chpis'; did you mean '--chips'?");
  expect_usage_error("units --varaint L6480 ACC", "l6470emu units: unknown option '--varaint'; did you mean '--variant'?");
  // run: the program after -- is no excuse to name something else than the misspelt option.
  expect_usage_error("run --chain chips=L6470 --scenaro x -- /bin/true",
                     "l6470emu run: unknown option '--scenaro'; did you mean '--scenario'?");
  expect_usage_error("run --chian L6470 -- /bin/true", "l6470emu run: unknown option '--chian'; did you mean '--chain'?");
}

TEST(UsageErrors, AMisspeltCtlCommandIsNamedBeforeAnyDaemonIsAsked) {
  // No daemon at that socket: the command is checked first, with the near miss.
  expect_usage_error("ctl --socket /nonexistent/l6470emu.sock statsu",
                     "l6470emu ctl: unknown command 'statsu'; did you mean status? (l6470emu ctl help)");
  expect_usage_error("ctl --socket /nonexistent/l6470emu.sock frobnicate",
                     "l6470emu ctl: unknown command 'frobnicate' (l6470emu ctl help)");
}

TEST(UsageErrors, AnOptionOfAnotherSubcommandSaysWhoseItIs) {
  expect_usage_error("decode x -o y",
                     "l6470emu decode: unknown option '-o' ('-o' is an option of convert, plot and report) (l6470emu decode --help)");
}

TEST(UsageErrors, MissingAndBadValuesAreOneLineWithStatusTwo) {
  expect_usage_error("replay", "l6470emu replay: TRACE is required (l6470emu replay --help)");
  expect_usage_error("decode", "l6470emu decode: TRACE is required (l6470emu decode --help)");
  expect_usage_error("convert x", "l6470emu convert: --output is required (l6470emu convert --help)");
  expect_usage_error("ctl", "l6470emu ctl: command is required (l6470emu ctl --help)");
  expect_usage_error("demo --chips 300", "l6470emu demo: --chips: Value 300 not in range 1 to 256 (l6470emu demo --help)");
  expect_usage_error("demo --seconds x", "l6470emu demo: --seconds: Value x not in range 1 to 3600 (l6470emu demo --help)");
  expect_usage_error("demo extra", "l6470emu demo: unexpected argument 'extra' (l6470emu demo --help)");
  expect_usage_error("replay --format nativ x",
                     "l6470emu replay: --format: 'nativ' is not one of auto, native, saleae, umockdev, ftrace, sigrok, "
                     "vcd; did you mean 'native'?");
  expect_usage_error("convert x -o y --to vdc",
                     "l6470emu convert: --to: 'vdc' is not one of auto, native, vcd, ioctl; did you mean 'vcd'?");
  expect_usage_error("tables --table comands",
                     "l6470emu tables: --table: 'comands' is not one of l6470-registers, l6470-status, commands, "
                     "variant-registers, variant-status, variant-differences, sanitizer-rules, units, l6474-registers, "
                     "l6474-status, l6474-commands; did you mean 'commands'?");
  expect_usage_error("serve --time-scale 0", "l6470emu serve: --time-scale: Value 0 not in range 0.000001 to "
                                             "1000000.000000 (l6470emu serve --help)");
  expect_usage_error("plot --dpi", "l6470emu plot: --dpi: 1 required TEXT missing (l6470emu plot --help)");
  expect_usage_error("units a b c", "l6470emu units: unexpected argument 'c' (l6470emu units --help)");
}

TEST(UsageErrors, HelpAndVersionStillExitZero) {
  for (const char* args : {"--help", "--version", "replay --help", "units --help", "ctl --help"}) {
    const RunResult r = l6470emu(args);
    EXPECT_EQ(r.status, 0) << args << "\n" << r.out;
  }
}

TEST(UnitsCommand, ConvertsBothWays) {
  RunResult r = l6470emu("units MAX_SPEED 200step/s");
  EXPECT_EQ(r.status, 0);
  EXPECT_EQ(r.out, "MAX_SPEED 200 step/s -> 0x00D (13) = 198.3642578125 step/s, the nearest value\n");
  r = l6470emu("units MAX_SPEED 0x041");
  EXPECT_EQ(r.out, "MAX_SPEED 0x041 (65) = 991.8212890625 step/s\n");
  r = l6470emu("units SPD '200 step/s'");  // Run's argument: SPEED's scale
  EXPECT_EQ(r.out, "SPEED 200 step/s -> 0x0346E (13422) = 200.0033855438232421875 step/s, the nearest value\n");
  r = l6470emu("units --variant L6480 OCD_TH 1V");
  EXPECT_EQ(r.out, "OCD_TH 1000 mV -> 0x1F (31) exactly\n");
  r = l6470emu("units --variant L6482 T_FAST 0x19");
  EXPECT_EQ(r.out, "T_FAST 0x19 (25) = TOFF_FAST 4 µs, FAST_STEP 20 µs\n");
  r = l6470emu("units MIN_SPEED 0x1010");
  EXPECT_EQ(r.out, "MIN_SPEED 0x1010 (4112) = 3.814697265625 step/s, LSPD_OPT\n");
  r = l6470emu("units ACC inf");
  EXPECT_EQ(r.out, "ACC inf step/s² -> 0xFFF (4095) exactly\n");
  r = l6470emu("units KVAL_RUN 16%");
  EXPECT_EQ(r.out, "KVAL_RUN 0.16 VS -> 0x29 (41) = 0.16015625 VS, the nearest value\n");
  r = l6470emu("units --saturate MAX_SPEED 20000step/s");
  EXPECT_EQ(r.out, "MAX_SPEED 20000 step/s -> 0x3FF (1023) = 15609.7412109375 step/s, the nearest in range\n");
  r = l6470emu("units --variant L6472 TVAL_RUN 1A");  // the UNCONFIRMED source, as a note on standard error
  EXPECT_EQ(r.out, "note: L6472 TVAL_RUN: UNCONFIRMED: one third-party header (no L6472 table was read)\n"
                   "TVAL_RUN 1000 mA -> 0x1F (31) exactly\n");
}

TEST(UnitsCommand, ListsTheVariantsScales) {
  const RunResult r = l6470emu("units --variant powerSTEP01");
  EXPECT_EQ(r.status, 0);
  for (const char* line : {"KVAL_HOLD: n · 0.00390625 VS, 0 … 0.99609375 VS (0x00 … 0xFF)",
                           "TVAL_HOLD: (n + 1) · 7.8125 mV, 7.8125 … 1000 mV (0x00 … 0x7F)",
                           "ACC: n · 14.551915228366851806640625 step/s², 0 … 59575.54094493389129638671875 step/s² (0x000 … 0xFFE); "
                           "0xFFF = infinite acceleration"})
    EXPECT_NE(r.out.find(line), std::string::npos) << line << "\n" << r.out;
}

TEST(UnitsCommand, BadRegistersVariantsAndValuesAreOneLineWithStatusTwo) {
  expect_usage_error("units MAX_SPED 1",
                     "l6470emu units: unknown register 'MAX_SPED'; did you mean 'MAX_SPEED'? (l6470emu units --variant "
                     "L6470 lists them)");
  expect_usage_error("units --variant L6471 ACC 1",
                     "l6470emu units: --variant: unknown chip variant 'L6471' (did you mean L6470, L6472 or L6474? known: "
                     "L6470, L6472, L6480, L6482, powerSTEP01, L6474)");
  expect_usage_error("units TVAL_RUN 100mA",
                     "l6470emu units: L6470 has no TVAL_RUN (a register of L6472, L6482, powerSTEP01); --variant names "
                     "the chip");
  expect_usage_error("units CONFIG 0x2E88", "l6470emu units: CONFIG has no physical unit (l6470emu units --variant "
                                           "L6470 lists the registers with one)");
  expect_usage_error("units MAX_SPEED 200mA", "l6470emu units: MAX_SPEED is in step/s, not 'mA'");
  expect_usage_error("units MAX_SPEED 200.5",
                     "l6470emu units: '200.5': give the unit (200.5step/s) or an integer register value (0x041)");
  expect_usage_error("units MAX_SPEED 0x400", "l6470emu units: MAX_SPEED has 10 bits: 0x400 is above 0x3FF");
  expect_usage_error("units MAX_SPEED 20000step/s",
                     "l6470emu units: MAX_SPEED: 20000 step/s is above the largest value, 15609.7412109375 step/s (0x3FF)");
  expect_usage_error("units --variant L6482 T_FAST 4us",
                     "l6470emu units: T_FAST holds 2 values: TOFF_FAST and FAST_STEP, each with its own scale: convert "
                     "one at a time (or give a register value)");
}

TEST(ServeCommand, NamesThePreloadLibraryItFindsBesideItself) {
  test::TempDir dir;
  const std::string binary = L6470EMU_BINARY;
  const std::string preload = binary.substr(0, binary.rfind('/')) + "/libl6470emu-preload.so";
  // Ended as soon as it has said it (or after 10 s).
  const std::string said = dir.file("said");
  const RunResult r = run_command("env -u L6470EMU_PRELOAD " + binary + " serve --socket " + dir.file("s.sock") + " > " +
                                  said + " & p=$!; for i in $(seq 200); do grep -q 'run programs with' " + said +
                                  " && break; sleep 0.05; done; kill $p; wait $p; cat " + said);
  EXPECT_NE(r.out.find("run programs with: LD_PRELOAD=" + preload + " L6470EMU_SOCKET=" + dir.file("s.sock")),
            std::string::npos)
      << r.out;
}

TEST(Messages, CountOneThingInTheSingular) {
  EXPECT_EQ(counted(1, "chip"), "1 chip");
  EXPECT_EQ(counted(0, "chip"), "0 chips");
  EXPECT_EQ(counted(3, "match", "matches"), "3 matches");
  const RunResult r = l6470emu("decode --chip 1 " + test::fixture_path("single_chip.trace"));
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.out.find("l6470emu decode: --chip 1: the chain has 1 chip\n"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace l6470emu
