// The board description parser (text and files), the diagnostic log's file, and the spidev rules.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <pthread.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <thread>

#include "board/board_config.hpp"
#include "linux/board_config_file.hpp"
#include "linux/log.hpp"
#include "linux/spidev_rules.hpp"

namespace l6470emu {
namespace {

TEST(BoardConfig, ParsesChainsVariantsAndGlobals) {
  const auto r = parse_board_config("bus=0 cs=1 chips=2xL6470,L6480 speed=2000000 mode=3; time=virtual\n# comment\nbus=1 chips=L6470*2 gpiochip=none",
                                    "test");
  ASSERT_TRUE(r.config) << r.error.message;
  const BoardConfig& c = *r.config;
  ASSERT_EQ(c.chains.size(), 2u);
  EXPECT_EQ(c.chains[0].path, "/dev/spidev0.1");
  ASSERT_EQ(c.chains[0].chips.size(), 3u);
  EXPECT_EQ(c.chains[0].chips[2]->name, "L6480");
  EXPECT_EQ(c.chains[0].max_speed_hz, 2000000u);
  EXPECT_EQ(c.chains[0].gpiochip, 0u);
  EXPECT_EQ(c.chains[1].chips.size(), 2u);
  EXPECT_FALSE(c.chains[1].gpiochip);
  EXPECT_TRUE(c.time.virtual_time);
}

TEST(BoardConfig, ErrorsNameTheClauseAndTheProblem) {
  auto r = parse_board_config("bus=0 chips=L6470; bus=0 chips=L6470", "X");
  ASSERT_FALSE(r.config);
  EXPECT_EQ(r.error.message, "l6470emu: config X, clause 2: two chains on /dev/spidev0.0 (clause 1 and this one)");
  r = parse_board_config("", "X");
  EXPECT_FALSE(r.config);
  EXPECT_EQ(r.error.message, "l6470emu: config X: no chain (write e.g. 'bus=0 cs=0 chips=L6470' or 'socket=PATH')");
  r = parse_board_config("scale=-1 ; bus=0 chips=L6470", "X");
  EXPECT_FALSE(r.config);
}

// The first error of `text`, without the "l6470emu: config T, clause N: " prefix (checked here;
// "T:LINE, clause N" for a text of several lines).
std::string error_of(std::string_view text, unsigned clause = 1) {
  const auto r = parse_board_config(text, "T");
  if (r.config) return "(accepted)";
  std::string message = r.error.message;
  if (message.rfind("l6470emu: config T:", 0) == 0) {  // the line: digits up to the comma
    const std::size_t comma = message.find(',');
    message = "l6470emu: config T" + message.substr(comma);
  }
  const std::string prefix = "l6470emu: config T, clause " + std::to_string(clause) + ": ";
  if (message.rfind(prefix, 0) != 0) return "(prefix) " + r.error.message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  return message.substr(prefix.size());
}

bool contains(const std::string& text, std::string_view part) { return text.find(part) != std::string::npos; }

TEST(BoardConfig, BoardWideKeysAreAcceptedInsideAChainClause) {
  auto r = parse_board_config("chips=2xL6470 time=virtual", "T");
  ASSERT_TRUE(r.config) << r.error.message;
  EXPECT_TRUE(r.config->time.virtual_time);
  EXPECT_EQ(r.config->chains.at(0).chips.size(), 2u);
  r = parse_board_config("bus=0 cs=0 chips=L6470 scale=10", "T");
  ASSERT_TRUE(r.config) << r.error.message;
  EXPECT_EQ(r.config->time.scale, 10.0);
  r = parse_board_config("bus=0 cs=0 chips=L6470 log=off trace=run.trace socket=/tmp/b.sock; bus=1 chips=L6480", "T");
  ASSERT_TRUE(r.config) << r.error.message;
  EXPECT_EQ(r.config->log, "off");
  EXPECT_EQ(r.config->trace, "run.trace");
  EXPECT_EQ(r.config->socket, "/tmp/b.sock");
  EXPECT_EQ(r.config->chains.size(), 2u);
  r = parse_board_config("time=virtual idle=off; bus=0 chips=L6470", "T");  // a clause of their own still works
  ASSERT_TRUE(r.config) << r.error.message;
  EXPECT_EQ(r.config->time.idle_ns, 0);
}

TEST(BoardConfig, ABoardWideKeyGivenTwiceAnywhereIsAnErrorNamingBothClauses) {
  EXPECT_EQ(error_of("chips=L6470 time=virtual; time=wall", 2),
            "time= is given twice: clause 1 says 'virtual', clause 2 says 'wall' (a board-wide key is given once)");
  EXPECT_EQ(error_of("scale=2\nbus=1 chips=L6470 scale=2", 2),
            "scale= is given twice: clause 1 says '2', clause 2 says '2' (a board-wide key is given once)");
  EXPECT_EQ(error_of("log=a; bus=0 chips=L6470; bus=1 chips=L6470 log=b", 3),
            "log= is given twice: clause 1 says 'a', clause 3 says 'b' (a board-wide key is given once)");
}

TEST(BoardConfig, AKeyGivenTwiceInOneClauseIsAnError) {
  EXPECT_EQ(error_of("bus=0 bus=1 chips=L6470"), "bus= is given twice in this clause ('0', then '1')");
  EXPECT_EQ(error_of("chips=L6470 chips=L6480"), "chips= is given twice in this clause ('L6470', then 'L6480')");
  EXPECT_EQ(error_of("bus=0 chips=L6470 time=wall time=virtual"),
            "time= is given twice in this clause ('wall', then 'virtual')");
}

TEST(BoardConfig, IdleTakesSecondsOrOffWithinItsRange) {
  auto r = parse_board_config("chips=L6470 time=virtual idle=0.25", "T");
  ASSERT_TRUE(r.config) << r.error.message;
  EXPECT_EQ(r.config->time.idle_ns, 250'000'000);
  r = parse_board_config("chips=L6470 time=virtual", "T");
  ASSERT_TRUE(r.config) << r.error.message;
  EXPECT_EQ(r.config->time.idle_ns, 1'000'000'000);  // the default
  r = parse_board_config("chips=L6470 idle=3600 time=virtual", "T");
  ASSERT_TRUE(r.config) << r.error.message;
  EXPECT_EQ(r.config->time.idle_ns, 3'600'000'000'000);
  for (const char* bad : {"0", "0.0001", "3601", "-1", "1e9", "nan", "inf", "500ms", "2s", "0x10", "Off"})
    EXPECT_EQ(error_of(std::string("chips=L6470 time=virtual idle=") + bad),
              "idle must be off or a number of seconds from 0.001 to 3600, not '" + std::string(bad) + "'");
}

TEST(BoardConfig, ScaleOutsideItsRangeOrNotAPlainNumberIsRefusedWithTheRange) {
  for (const char* bad : {"1e-300", "4e-320", "1e-7", "1e7", "1e400", "0", "-1", "nan", "inf", "infinity", "0x1p3", "+2",
                          "1,5", "fast"})
    EXPECT_EQ(error_of(std::string("scale=") + bad + "; chips=L6470"),
              "scale must be a number from 0.000001 to 1000000 (virtual seconds per wall second), not '" +
                  std::string(bad) + "'");
  for (const char* good : {"0.000001", "1000000", "1e3", ".5", "2.5E1"}) {
    const auto r = parse_board_config(std::string("scale=") + good + "; chips=L6470", "T");
    EXPECT_TRUE(r.config) << good << ": " << r.error.message;
  }
}

TEST(BoardConfig, ScaleWithVirtualTimeAndIdleWithWallTimeAreRefused) {
  EXPECT_EQ(error_of("time=virtual; chips=L6470 scale=10", 2),
            "scale= applies to time=wall only: with time=virtual (clause 1) the host program's own clock is the board's");
  EXPECT_EQ(error_of("chips=L6470 idle=0.5 time=wall"), "idle= applies to time=virtual only, and clause 1 says time=wall");
}

TEST(BoardConfig, PathMustBeADeviceNodeThatIsNotOneOfTheSystems) {
  for (const char* node : {"/dev/null", "/dev/zero", "/dev/full", "/dev/urandom", "/dev/tty", "/dev/ttyS0",
                           "/dev/ttyUSB1", "/dev/console", "/dev/pts/3", "/dev/shm/x", "/dev/fd/0", "/dev/stdout"})
    EXPECT_TRUE(contains(error_of(std::string("chips=L6470 path=") + node),
                         "not a spidev node: the emulator would take it over in the host program"))
        << node << ": " << error_of(std::string("chips=L6470 path=") + node);
  EXPECT_EQ(error_of("chips=L6470 path=/dev/gpiochip3"),
            "path '/dev/gpiochip3' is where the emulator puts a chain's pins (gpiochip=N), not a spidev node: the "
            "emulator would take it over in the host program (write e.g. path=/dev/spidev0.0, or leave path= out)");
  EXPECT_EQ(error_of("chips=L6470 path=/tmp/spi"),
            "path must be a device node under /dev/ (e.g. path=/dev/spidev0.0), not '/tmp/spi'");
  EXPECT_EQ(error_of("chips=L6470 path=/dev/../etc/passwd"),
            "path '/dev/../etc/passwd' must name a node directly (no empty, '.' or '..' parts)");
  EXPECT_EQ(error_of("chips=L6470 path=/dev/spi//a"),
            "path '/dev/spi//a' must name a node directly (no empty, '.' or '..' parts)");
  EXPECT_EQ(error_of("chips=L6470 path=/dev/spidev/"), "path '/dev/spidev/' names a directory, not a device node");
  EXPECT_EQ(error_of("chips=L6470 path=/dev/"), "path '/dev/' names a directory, not a device node");
  EXPECT_TRUE(contains(error_of("chips=L6470 path=/dev/spi$dev"), "has a character a device node name does not use"));
  EXPECT_TRUE(contains(error_of("chips=L6470 path=/dev/" + std::string(300, 'a')),
                       "path is 305 bytes long; a device node name has at most 255"));
  const auto r = parse_board_config("chips=L6470 path=/dev/spi/motor-0.1", "T");
  ASSERT_TRUE(r.config) << r.error.message;
  EXPECT_EQ(r.config->chains[0].path, "/dev/spi/motor-0.1");
}

TEST(BoardConfig, ChipCountsOutsideOneTo256SayTheCount) {
  EXPECT_EQ(error_of("chips=257xL6470"), "a chain holds at most 256 chips; '257xL6470' asks for 257");
  EXPECT_EQ(error_of("chips=L6470*300"), "a chain holds at most 256 chips; 'L6470*300' asks for 300");
  EXPECT_EQ(error_of("chips=99999999999999999999999xL6470"),
            "a chain holds at most 256 chips; '99999999999999999999999xL6470' asks for 99999999999999999999999");
  EXPECT_EQ(error_of("chips=0xL6470"), "chip count 0 in '0xL6470': a chain holds 1 to 256 chips");
  EXPECT_EQ(error_of("chips=200xL6470,100xL6480"),
            "a chain holds at most 256 chips; chips='200xL6470,100xL6480' asks for 300");
  EXPECT_TRUE(contains(error_of("chips=3x"), "'3x' names no chip variant (write e.g. chips=3xL6470;"));
  EXPECT_TRUE(contains(error_of("chips=L6470,"), "empty entry in chips='L6470,'"));
  const auto r = parse_board_config("chips=256xL6470", "T");
  ASSERT_TRUE(r.config) << r.error.message;
  EXPECT_EQ(r.config->chains[0].chips.size(), 256u);
  const auto mixed = parse_board_config("chips=2XL6480,powerSTEP01x2,L6472*1,1*l6482", "T");
  ASSERT_TRUE(mixed.config) << mixed.error.message;
  EXPECT_EQ(mixed.config->chains[0].chips.size(), 6u);
}

TEST(BoardConfig, UnknownVariantsAndKeysSuggestTheClosestName) {
  EXPECT_EQ(error_of("chips=L6471"), "unknown chip variant 'L6471' (did you mean L6470, L6472 or L6474? known: " +
                                         known_variant_names() + ")");
  EXPECT_EQ(error_of("chips=powrSTEP01"),
            "unknown chip variant 'powrSTEP01' (did you mean powerSTEP01? known: " + known_variant_names() + ")");
  EXPECT_EQ(error_of("chips=Foo"), "unknown chip variant 'Foo' (known: " + known_variant_names() + ")");
  EXPECT_TRUE(contains(error_of("chip=L6470"), "unknown key 'chip': did you mean chips=? (chain keys: chips, bus, cs,"));
  EXPECT_TRUE(contains(error_of("chips=L6470 spede=1000"), "unknown key 'spede': did you mean speed=?"));
  EXPECT_TRUE(contains(error_of("chips=L6470 timescale=2"), "unknown key 'timescale': did you mean scale=?"));
  EXPECT_TRUE(contains(error_of("chips=L6470 colour=blue"), "unknown key 'colour' (chain keys:"));
}

TEST(BoardConfig, EmptyAndOutOfRangeChainValuesAreRefused) {
  EXPECT_EQ(error_of("bus= chips=L6470"), "bus= has no value (e.g. bus=0)");
  EXPECT_EQ(error_of("chips="), "chips= has no value (e.g. chips=2xL6470,L6480)");
  EXPECT_EQ(error_of("chips=L6470 speed=0"),
            "speed must be a frequency in Hz from 1 to 1000000000 (e.g. speed=5000000), not '0'");
  EXPECT_EQ(error_of("chips=L6470 mode=4"), "mode must be an SPI mode from 0 to 3, not '4'");
  EXPECT_EQ(error_of("chips=L6470 bus=-1"), "bus must be a number from 0 to 32767, not '-1'");
  EXPECT_EQ(error_of("chips=L6470 bus=0x1"), "bus must be a number from 0 to 32767, not '0x1'");
  EXPECT_EQ(error_of("chips=L6470 cs=256"), "cs must be a number from 0 to 255, not '256'");
  EXPECT_EQ(error_of("chips=L6470 gpiochip=1024"), "gpiochip must be a number from 0 to 1023 or none, not '1024'");
  EXPECT_EQ(error_of("chips=L6470 bufsiz=0"), "bufsiz must be a number from 1 to 4194304, not '0'");
  EXPECT_EQ(error_of("time=Virtual; chips=L6470"), "time must be wall or virtual, not 'Virtual'");
  EXPECT_EQ(error_of("chips=L6470 log=stdout"),
            "log=stdout would be a file of that name: write log=stderr, log=off, or log=./stdout if a file is meant");
  EXPECT_EQ(error_of("chips=L6470 trace=/tmp/"), "trace '/tmp/' names a directory; give a file");
  EXPECT_EQ(error_of("chips=L6470 trace=run.t; log=run.t", 2),
            "log= and trace= name the same file 'run.t': diagnostics would be mixed into the trace");
  EXPECT_EQ(error_of("socket=/tmp/" + std::string(103, 's')), "socket path is 108 bytes long; a Unix socket path has at most 107");
}

TEST(BoardConfig, ChainKeysWithoutChipsSayTheClauseNeedsChips) {
  EXPECT_EQ(error_of("bus=1 cs=2"), "bus= describes a chain: add chips= to this clause (e.g. 'bus=0 cs=0 chips=L6470')");
  EXPECT_EQ(error_of("chips=L6470; speed=1000", 2),
            "speed= describes a chain: add chips= to this clause (e.g. 'bus=0 cs=0 chips=L6470')");
}

TEST(BoardConfig, WordsThatAreNotKeyValueAreExplained) {
  EXPECT_EQ(error_of("L6470"), "expected key=value, got 'L6470' (did you mean chips=L6470?)");
  EXPECT_EQ(error_of("chips=L6470 virtual"), "expected key=value, got 'virtual' (did you mean time=virtual?)");
  EXPECT_EQ(error_of("bus = 0 chips=L6470"), "bus needs a value written right after '=', without blanks: e.g. bus=0");
  EXPECT_EQ(error_of("=5 chips=L6470"), "'=5' has no key before '=' (write key=value, without blanks around '=')");
  EXPECT_EQ(error_of("hello chips=L6470"), "expected key=value, got 'hello'");
}

TEST(BoardConfig, QuotedUserTextIsCappedAndControlCharactersEscaped) {
  const std::string huge(900'000, 'z');
  EXPECT_EQ(error_of(huge), "expected key=value, got '" + std::string(60, 'z') + "\u2026' (900000 bytes)");
  EXPECT_EQ(error_of("chips=" + huge), "unknown chip variant '" + std::string(60, 'z') + "\u2026' (900000 bytes) (known: " +
                                           known_variant_names() + ")");
  EXPECT_EQ(error_of("chips=L6470 log=a\x01" "b"), "control character in 'log=a\\x01b' (a board description is plain text)");
  std::string escaped;  // escapes count in the 60 characters shown, and are never cut in half
  for (int i = 0; i < 15; ++i) escaped += "\\x01";
  EXPECT_EQ(error_of("chips=" + std::string(100, '\x01')),
            "control character in 'chips=" + escaped.substr(0, 52) + "\u2026' (106 bytes) (a board description is plain text)");
  EXPECT_EQ(error_of(std::string("chips=L6470 bus=1\0", 18)),
            "control character in 'bus=1\\x00' (a board description is plain text)");
  EXPECT_EQ(error_of("chips=L\xc3\xa9" "6470"), "unknown chip variant 'L\\xc3\\xa96470' (did you mean L6470? known: " +
                                                    known_variant_names() + ")");
  // 10 MB of text is refused whole, before any of it is echoed.
  const auto r = parse_board_config(std::string(10'000'000, 'q'), "T");
  ASSERT_FALSE(r.config);
  EXPECT_EQ(r.error.message, "l6470emu: config T: longer than 1 MiB (a board description is a few lines)");
  // The origin (a file name) is user text too.
  const auto o = parse_board_config("colour=blue", "a\nb");
  EXPECT_EQ(o.error.message.rfind("l6470emu: config a\\x0ab, clause 1: unknown key 'colour'", 0), 0u) << o.error.message;
}

TEST(BoardConfig, ACommentRunsToTheEndOfTheLineEvenPastASemicolon) {
  const auto r = parse_board_config("bus=0 chips=L6470 # main; not a clause\ntime=virtual # ; ;", "T");
  ASSERT_TRUE(r.config) << r.error.message;
  EXPECT_TRUE(r.config->time.virtual_time);
  EXPECT_EQ(r.config->chains.size(), 1u);
  EXPECT_EQ(error_of("bus=0 chips=L6470 # ok\n; colour=red", 3), "unknown key 'colour' (chain keys: chips, bus, cs, "
                                                                 "path, gpiochip, speed, mode, bufsiz, cs/sck/mosi/miso_pin, "
                                                                 "busy/flag/sw/stck/stby_rst/dir_pin, spi, axis.K; board-wide: "
                                                                 "time, scale, idle, log, socket, trace, numbering, "
                                                                 "check, check.allow, call_time, loop_time, limit, apb_clock)");
}

TEST(BoardConfig, DefaultGpiochipsAvoidTheNumbersOtherChainsAskFor) {
  const auto r = parse_board_config("bus=0 chips=L6470; bus=1 chips=L6470 gpiochip=0; bus=2 chips=L6470", "T");
  ASSERT_TRUE(r.config) << r.error.message;
  EXPECT_EQ(r.config->chains[0].gpiochip, 1u);
  EXPECT_EQ(r.config->chains[1].gpiochip, 0u);
  EXPECT_EQ(r.config->chains[2].gpiochip, 2u);
  EXPECT_EQ(error_of("bus=0 chips=L6470 gpiochip=3; bus=1 chips=L6470 gpiochip=3", 2),
            "two chains on /dev/gpiochip3 (clause 1 and this one)");
}

TEST(BoardConfig, ADescriptionReadsBackAsTheSameBoardAndShowsIdleWhenNotTheDefault) {
  for (const char* text : {"bus=1 cs=2 chips=3xL6470,L6480,L6480 gpiochip=none speed=2000000 mode=3 bufsiz=64; scale=0.1",
                           "chips=powerSTEP01 time=virtual idle=0.125 log=off trace=t.trace",
                           "chips=L6470 time=virtual idle=off socket=/tmp/s.sock", "chips=L6470 scale=1.2345678901"}) {
    const auto first = parse_board_config(text, "T");
    ASSERT_TRUE(first.config) << first.error.message;
    const std::string described = describe_board_config(*first.config);
    const auto again = parse_board_config(described, "described");
    ASSERT_TRUE(again.config) << again.error.message << "\n" << described;
    EXPECT_EQ(describe_board_config(*again.config), described);
    EXPECT_EQ(again.config->time.idle_ns, first.config->time.idle_ns);
    EXPECT_EQ(again.config->time.scale, first.config->time.scale);
  }
  auto r = parse_board_config("chips=powerSTEP01 time=virtual idle=0.125", "T");
  EXPECT_TRUE(contains(describe_board_config(*r.config), "time=virtual idle=0.125\n")) << describe_board_config(*r.config);
  r = parse_board_config("chips=L6470 time=virtual", "T");
  EXPECT_TRUE(contains(describe_board_config(*r.config), "time=virtual\n")) << describe_board_config(*r.config);
  r = parse_board_config("chips=L6470 time=virtual idle=off", "T");
  EXPECT_TRUE(contains(describe_board_config(*r.config), "time=virtual idle=off\n"));
  r = parse_board_config("chips=3xL6470,L6480", "T");
  EXPECT_TRUE(contains(describe_board_config(*r.config), "chips=3xL6470,L6480 "));
}

// A fresh directory under /tmp, removed with everything in it.
struct TempDir {
  std::string path;
  TempDir() {
    char name[] = "/tmp/l6470emu-config-XXXXXX";
    path = mkdtemp(name) ? name : "";
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
  std::string file(const std::string& name, const std::string& text) const {
    std::ofstream(path + "/" + name, std::ios::binary) << text;
    return path + "/" + name;
  }
};

TEST(BoardConfigFile, AFileIsParsedWithItsNameAsTheOrigin) {
  TempDir dir;
  const std::string f = dir.file("board.conf", "# two chains\nbus=0 chips=L6470 time=virtual\nbus=1 chips=L6480; idle=off\n");
  auto r = load_board_config_file(f);
  ASSERT_TRUE(r.config) << r.error.message;
  EXPECT_EQ(r.config->chains.size(), 2u);
  EXPECT_EQ(r.config->time.idle_ns, 0);
  r = load_board_config_file(dir.file("bad.conf", "bus=0 chips=L6470\n\nmode=9 chips=L6470\n"));
  EXPECT_EQ(r.error.message, "l6470emu: config " + dir.path + "/bad.conf:3, clause 3: mode must be an SPI mode from 0 to 3, not '9'");
}

TEST(BoardConfigFile, AnErrorNamesTheLineAsWellAsTheClauseWhenTheTextHasSeveralLines) {
  // Two clauses on line 1, the bad one on line 2 is clause 3.
  auto r = parse_board_config("bus=0 chips=L6470; time=virtual\nbus=1 chips=3xL6499\n", "board.conf");
  EXPECT_EQ(r.error.message.rfind("l6470emu: config board.conf:2, clause 3: unknown chip variant 'L6499'", 0), 0u)
      << r.error.message;
  // A gpiochip clash found after the last line still points at its chain's line.
  r = parse_board_config("bus=0 chips=L6470 gpiochip=1023\n\nbus=1 chips=L6470\n", "board.conf");
  ASSERT_TRUE(r.config) << r.error.message;
  // One line (L6470EMU_CHAIN, --chain): the clause says where.
  r = parse_board_config("bus=0 chips=L6470; mode=9 chips=L6470", "L6470EMU_CHAIN");
  EXPECT_EQ(r.error.message.rfind("l6470emu: config L6470EMU_CHAIN, clause 2: ", 0), 0u) << r.error.message;
}

TEST(BoardConfigNumbering, NumberingSaysWhichEndChipZeroIsAtAndDefaultsToMiso) {
  auto r = parse_board_config("bus=0 chips=3xL6470", "T");
  ASSERT_TRUE(r.config);
  EXPECT_EQ(r.config->numbering, NumberFrom::miso);
  r = parse_board_config("bus=0 chips=3xL6470 numbering=mosi", "T");
  ASSERT_TRUE(r.config);
  EXPECT_EQ(r.config->numbering, NumberFrom::mosi);
  EXPECT_NE(describe_board_config(*r.config).find("numbering=mosi\n"), std::string::npos);
  r = parse_board_config("bus=0 chips=3xL6470; numbering=MISO", "T");
  ASSERT_TRUE(r.config);
  EXPECT_EQ(r.config->numbering, NumberFrom::miso);
}

TEST(BoardConfigNumbering, AnUnknownNumberingIsOneLineNamingTheClauseAndTheChoices) {
  const auto r = parse_board_config("bus=0 chips=3xL6470 numbering=x", "T");
  EXPECT_EQ(r.error.message, "l6470emu: config T, clause 1: numbering must be miso (chip 0 drives MISO) or mosi (chip 0 "
                             "reads the host's MOSI), not 'x'");
  const auto twice = parse_board_config("bus=0 chips=L6470 numbering=mosi; numbering=miso", "T");
  EXPECT_NE(twice.error.message.find("numbering= is given twice"), std::string::npos) << twice.error.message;
}

TEST(BoardConfigFile, ADirectoryIsSaidToBeADirectoryAndAMissingFileSaysWhy) {
  TempDir dir;
  auto r = load_board_config_file(dir.path);
  EXPECT_EQ(r.error.message, "l6470emu: config file " + dir.path + ": is a directory (give the board description file)");
  r = load_board_config_file(dir.path + "/missing.conf");
  EXPECT_EQ(r.error.message,
            "l6470emu: config file " + dir.path + "/missing.conf: cannot be read (No such file or directory)");
}

TEST(BoardConfigFile, DevZeroABigFileAndAnEndlessFifoFailFastWithOneLine) {
  auto r = load_board_config_file("/dev/zero");
  EXPECT_EQ(r.error.message, "l6470emu: config file /dev/zero: is a device, not a file: it could block or never end");
  TempDir dir;
  r = load_board_config_file(dir.file("big.conf", "chips=L6470\n" + std::string(kMaxConfigBytes, '#')));
  EXPECT_EQ(r.error.message, "l6470emu: config file " + dir.path +
                                 "/big.conf: longer than 1 MiB (a board description is a few lines: is this the right file?)");
  r = load_board_config_file(dir.file("exact.conf", "chips=L6470 #" + std::string(kMaxConfigBytes - 14, '#') + "\n"));
  EXPECT_TRUE(r.config) << r.error.message;  // exactly 1 MiB is still read

  const std::string fifo = dir.path + "/endless";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  std::thread writer([&] {
    sigset_t pipe_signal;  // this thread's writes fail with EPIPE once the reader has gone
    sigemptyset(&pipe_signal);
    sigaddset(&pipe_signal, SIGPIPE);
    pthread_sigmask(SIG_BLOCK, &pipe_signal, nullptr);
    const int fd = open(fifo.c_str(), O_WRONLY | O_CLOEXEC);
    const std::string block(65536, ' ');
    while (fd >= 0 && write(fd, block.data(), block.size()) > 0) {
    }
    if (fd >= 0) close(fd);
  });
  const auto start = std::chrono::steady_clock::now();
  r = load_board_config_file(fifo);
  writer.join();
  EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
  EXPECT_EQ(r.error.message, "l6470emu: config file " + fifo +
                                 ": longer than 1 MiB (a board description is a few lines: is this the right file?)");
}

// Everything written to stderr (fd 2) while it lives.
class StderrCapture {
 public:
  StderrCapture() : file_(std::tmpfile()), saved_(dup(2)) {
    std::fflush(stderr);
    dup2(fileno(file_), 2);
  }
  ~StderrCapture() { restore(); }
  std::string text() {
    restore();
    std::string out;
    std::rewind(file_);
    for (int c; (c = std::fgetc(file_)) != EOF;) out += static_cast<char>(c);
    return out;
  }

 private:
  void restore() {
    if (saved_ < 0) return;
    std::fflush(stderr);
    dup2(saved_, 2);
    close(saved_);
    saved_ = -1;
  }
  FILE* file_;
  int saved_;
};

TEST(DiagnosticLogFile, AnUnopenableLogIsReportedOnceOnStderrAndStderrIsUsedInstead) {
  TempDir dir;
  const std::string where = dir.path + "/no-such-dir/emu.log";
  StderrCapture capture;
  {
    DiagnosticLog first(where);
    DiagnosticLog second(where);  // the preload opens the log twice: still one report
    EXPECT_EQ(first.open_error(), ENOENT);
    EXPECT_TRUE(first.enabled());
    first.line("still heard");
  }
  EXPECT_EQ(capture.text(), "l6470emu: log file '" + where +
                                "' cannot be opened (No such file or directory): diagnostics go to stderr\n"
                                "l6470emu: still heard\n");
}

TEST(DiagnosticLogFile, ADirectoryOrAFifoNobodyReadsIsReportedInsteadOfBlocking) {
  TempDir dir;
  const std::string fifo = dir.path + "/log.fifo";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  StderrCapture capture;
  {
    DiagnosticLog to_fifo(fifo);
    DiagnosticLog to_dir(dir.path);
    EXPECT_EQ(to_fifo.open_error(), ENXIO);
    EXPECT_EQ(to_dir.open_error(), EISDIR);
  }
  EXPECT_EQ(capture.text(), "l6470emu: log file '" + fifo + "' cannot be opened (a FIFO that nobody reads): diagnostics go to stderr\n"
                            "l6470emu: log file '" + dir.path + "' cannot be opened (Is a directory): diagnostics go to stderr\n");
}

TEST(DiagnosticLogFile, AWritableLogFileGetsTheLinesAndNothingIsReported) {
  TempDir dir;
  const std::string where = dir.path + "/emu.log";
  StderrCapture capture;
  {
    DiagnosticLog log(where);
    EXPECT_EQ(log.open_error(), 0);
    log.line("into the file");
  }
  EXPECT_EQ(capture.text(), "");
  std::ifstream in(where);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "l6470emu: into the file");
}

TEST(SpidevRules, SettingsFollowTheKernel) {
  SpidevSettings s;
  s.max_speed_hz = s.speed_hz = 5000000;
  std::uint32_t v = SPI_MODE_3;
  EXPECT_EQ(spidev_settings_ioctl(s, SPI_IOC_WR_MODE, v), 0);
  v = SPI_3WIRE;
  EXPECT_EQ(spidev_settings_ioctl(s, SPI_IOC_WR_MODE32, v), -EINVAL);
  v = SPI_MODE_3 | SPI_TX_DUAL;  // dual/quad bits are dropped silently
  EXPECT_EQ(spidev_settings_ioctl(s, SPI_IOC_WR_MODE32, v), 0);
  EXPECT_EQ(spidev_settings_ioctl(s, SPI_IOC_RD_MODE32, v), 0);
  EXPECT_EQ(v, std::uint32_t{SPI_MODE_3});
  v = 0;
  EXPECT_EQ(spidev_settings_ioctl(s, SPI_IOC_WR_BITS_PER_WORD, v), 0);
  EXPECT_EQ(s.bits_per_word, 8);
  v = 12;
  EXPECT_EQ(spidev_settings_ioctl(s, SPI_IOC_WR_BITS_PER_WORD, v), -EINVAL);
  v = 200000000;  // kept as asked, clamped per transfer
  EXPECT_EQ(spidev_settings_ioctl(s, SPI_IOC_WR_MAX_SPEED_HZ, v), 0);
  EXPECT_EQ(spidev_settings_ioctl(s, SPI_IOC_RD_MAX_SPEED_HZ, v), 0);
  EXPECT_EQ(v, 200000000u);
}

TEST(SpidevRules, MessageLimitsAreTheBounceBuffers) {
  SpidevSettings s;
  spi_ioc_transfer x[2] = {};
  x[0].tx_buf = 1;
  x[0].len = 4096;
  EXPECT_EQ(validate_spidev_message(s, std::span(x, 1)), 4096);
  x[1].tx_buf = 1;
  x[1].len = 1;
  EXPECT_EQ(validate_spidev_message(s, std::span(x, 2)), -EMSGSIZE);
  x[0].len = 4088;  // 4088 + align8(1) = 4096: fits
  EXPECT_EQ(validate_spidev_message(s, std::span(x, 2)), 4089);
}

}  // namespace
}  // namespace l6470emu

namespace l6470emu {
namespace {

TEST(BoardConfigCheck, CheckAndCheckAllowSetTheSanitizerAndReadBackFromTheDescription) {
  auto r = parse_board_config("chips=L6470", "T");
  ASSERT_TRUE(r.config);
  EXPECT_EQ(r.config->check.level, CheckLevel::warn);  // plain programs: today's log lines
  EXPECT_TRUE(r.config->check.allowed.empty());
  EXPECT_EQ(describe_board_config(*r.config).find("check"), std::string::npos);
  r = parse_board_config("chips=2xL6470 check=error; check.allow=frame_length,SPI_MODE", "T");
  ASSERT_TRUE(r.config) << r.error.message;
  EXPECT_EQ(r.config->check.level, CheckLevel::error);
  EXPECT_TRUE(r.config->check.allowed.contains(Rule::FRAME_LENGTH));
  EXPECT_TRUE(r.config->check.allowed.contains(Rule::SPI_MODE));
  EXPECT_FALSE(r.config->check.allowed.contains(Rule::WRONG_CMD));
  const std::string described = describe_board_config(*r.config);
  EXPECT_NE(described.find("check=error\ncheck.allow=SPI_MODE,FRAME_LENGTH\n"), std::string::npos) << described;
  const auto again = parse_board_config(described, "described");
  ASSERT_TRUE(again.config) << again.error.message;
  EXPECT_EQ(again.config->check, r.config->check);
  r = parse_board_config("chips=L6470 check=off", "T");
  ASSERT_TRUE(r.config);
  EXPECT_NE(describe_board_config(*r.config).find("check=off\n"), std::string::npos);
}

TEST(BoardConfigCheck, MistakesGetOneLineWithASuggestion) {
  auto error_of = [](const char* text) { return parse_board_config(text, "T").error.message; };
  EXPECT_EQ(error_of("chips=L6470 check=eror"),
            "l6470emu: config T, clause 1: check must be off, warn or error, not 'eror' (did you mean error?)");
  EXPECT_EQ(error_of("chips=L6470 check.allow=SPI_MODE,FRAME_LENGHT"),
            "l6470emu: config T, clause 1: check.allow names no rule 'FRAME_LENGHT' (did you mean FRAME_LENGTH? rules: " +
                all_rule_names() + ")");
  EXPECT_EQ(error_of("chips=L6470 check.allow=SPI_MODE,,WRONG_CMD"),
            "l6470emu: config T, clause 1: check.allow has an empty rule name in 'SPI_MODE,,WRONG_CMD' (write e.g. "
            "SPI_MODE,FRAME_LENGTH)");
  EXPECT_EQ(error_of("chips=L6470 sanitizer=error"),
            "l6470emu: config T, clause 1: unknown key 'sanitizer': did you mean check=? (chain keys: chips, bus, cs, "
            "path, gpiochip, speed, mode, bufsiz, cs/sck/mosi/miso_pin, busy/flag/sw/stck/stby_rst/dir_pin, spi, axis.K; board-wide: time, "
            "scale, idle, log, socket, trace, numbering, check, check.allow, call_time, loop_time, limit, apb_clock)");
  EXPECT_EQ(error_of("chips=L6470 check=warn; check=error"),
            "l6470emu: config T, clause 2: check= is given twice: clause 1 says 'warn', clause 2 says 'error' (a "
            "board-wide key is given once)");
}

}  // namespace
}  // namespace l6470emu
