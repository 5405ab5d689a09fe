// The native trace format (docs/trace-format.md): exact times, round trips, streaming
// across read chunks, flushing event by event, and one-line errors for malformed lines.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <sstream>

#include "spi/trace_native.hpp"
#include "support/trace_test_support.hpp"

namespace l6470emu {
namespace {

using test::frame_at;
using test::TempDir;
using Bytes = std::vector<std::uint8_t>;

std::string error_of(const std::string& text, const std::string& name = "t.trace") {
  try {
    read_native_trace(text, name);
  } catch (const TraceError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(NativeTrace, WritesOneLinePerEventWithExactSecondsAndMicroseconds) {
  const Bytes mosi{0xD0, 0x00}, miso{0x00, 0x7E};
  EXPECT_EQ(NativeTraceWriter::format_event(frame_at(4'938'271, 7, mosi, miso)),
            "1.23456775 frame 1.75us D0 00 | 00 7E");
  TraceEvent pin;
  pin.kind = TraceEventKind::pin;
  pin.tick = 4;
  pin.chip = 2;
  pin.pin = TracePin::SW;
  pin.value = 0;
  EXPECT_EQ(NativeTraceWriter::format_event(pin), "0.00000100 pin 2 SW 0");
  TraceEvent fault;
  fault.kind = TraceEventKind::fault;
  fault.chip = 1;
  fault.fault = TraceFault::THERMAL;
  fault.value = 2;
  EXPECT_EQ(NativeTraceWriter::format_event(fault), "0.00000000 fault 1 THERMAL bridge_shutdown");
}

TEST(NativeTrace, RoundTripsEveryKindOfEventExactly) {
  Trace t;
  t.header.chain = "2*L6470";
  const Bytes mosi{0x21, 0x00}, miso{0x00, 0x3F}, known{1, 0};
  t.write(frame_at(0, 9, mosi, miso));
  TraceEvent partial = frame_at(20, 9, mosi, miso);
  partial.miso_known = known;
  t.write(partial);
  t.write(frame_at(40, 0, mosi, {}));  // MISO not captured
  for (TracePin p : {TracePin::SW, TracePin::STCK, TracePin::STBY, TracePin::BUSY, TracePin::FLAG, TracePin::SW_AXIS,
                     TracePin::DIR}) {
    TraceEvent e;
    e.kind = TraceEventKind::pin;
    e.tick = 50;
    e.chip = 1;
    e.pin = p;
    e.value = 1;
    t.write(e);
  }
  for (TraceFault f : {TraceFault::UVLO, TraceFault::UVLO_ADC, TraceFault::OCD, TraceFault::STALL_A,
                       TraceFault::STALL_B, TraceFault::THERMAL, TraceFault::ADCIN}) {
    TraceEvent e;
    e.kind = TraceEventKind::fault;
    e.tick = 60;
    e.fault = f;
    e.value = f == TraceFault::ADCIN ? 17 : 1;
    t.write(e);
  }
  TraceEvent axis;
  axis.kind = TraceEventKind::axis;
  axis.tick = 70;
  axis.text = "steps=400,stops=-100..100,switch=home@0:below:nc:hyst=8";
  t.write(axis);
  TraceEvent stops;
  stops.kind = TraceEventKind::stops;
  stops.tick = 70;
  stops.has_upper_stop = true;
  stops.upper_stop = -25;
  t.write(stops);
  TraceEvent supply;
  supply.kind = TraceEventKind::supply;
  supply.tick = 70;
  supply.supply_mV = 36'000;
  t.write(supply);
  const std::string text = to_native_text(t);
  const Trace back = read_native_trace(text, "x.trace");
  EXPECT_EQ(back.header.chain, "2*L6470");
  ASSERT_EQ(back.size(), t.size());
  EXPECT_EQ(to_native_text(back), text);
  EXPECT_TRUE(back[1].miso_byte_known(0));
  EXPECT_FALSE(back[1].miso_byte_known(1));
  EXPECT_TRUE(back[2].miso.empty());
  EXPECT_EQ(back[0].line, 4u);  // header, chain line, the numbering comment, then the first event
}

TEST(NativeTrace, AChainLineOfBlanksAndCarriageReturnsNamesNoChips) {
  // Found by the fuzzer: "chain \r" read as a chain called "\r", written back as a line that
  // no longer read ("chain " once its line end was taken off).
  EXPECT_EQ(error_of("l6470emu-trace 2\r\nchain \r\r\n"), "t.trace:2: 'chain' needs the chips, e.g. 'chain 3*L6470'");
  EXPECT_EQ(error_of("l6470emu-trace 2\nboard \r \r\n"),
            "t.trace:2: 'board' needs a clause of the board description, e.g. 'board chips=L6470 axis.0=default'");
}

TEST(NativeTrace, RoundsHandWrittenTimesToTheNearestTick) {
  const Trace t = read_native_trace("l6470emu-trace 1\n0.0000001 frame D0\n0.00000013 frame 0.3us 00\n1 frame 00\n", "h");
  EXPECT_EQ(t[0].tick, 0u);   // 100 ns -> 0.4 tick
  EXPECT_EQ(t[1].tick, 1u);   // 130 ns -> 0.52 tick
  EXPECT_EQ(t[1].duration, 1u);
  EXPECT_EQ(t[2].tick, kTicksPerSecond);
  EXPECT_EQ(t[0].duration, 0u);  // the duration may be left out
}

TEST(NativeTrace, IgnoresCommentsAndBlankLines) {
  const Trace t = read_native_trace("l6470emu-trace 1\n# hello\n\n  \nchain 1\n0 frame D0 | 00\n# end\n", "c");
  EXPECT_EQ(t.size(), 1u);
  EXPECT_EQ(t.header.chain, "1");
}

TEST(NativeTrace, RejectsMalformedLinesWithFileAndLineNumber) {
  const std::string head = "l6470emu-trace 1\n";
  EXPECT_EQ(error_of(""), "t.trace: empty file (expected a native trace: 'l6470emu-trace 3')");
  EXPECT_EQ(error_of("name,type\n"), "t.trace:1: not an l6470emu trace: the first line must be 'l6470emu-trace 3'");
  EXPECT_EQ(error_of("l6470emu-trace 4\n"), "t.trace:1: format version 4 (this l6470emu reads versions 1 to 3)");
  EXPECT_EQ(error_of("l6470emu-trace 0\n"), "t.trace:1: format version 0 (this l6470emu reads versions 1 to 3)");
  EXPECT_EQ(error_of(head + "0 frame D0 ZZ\n"), "t.trace:2: MOSI \"ZZ\" is not a byte (two hex digits)");
  EXPECT_EQ(error_of(head + "0 frame D0 | 0xZZ\n"), "t.trace:2: MISO \"0xZZ\" is not a byte (two hex digits, or ?? for unknown)");
  EXPECT_EQ(error_of(head + "0 frame D0 00 | 00\n"), "t.trace:2: frame has 2 MOSI bytes but 1 MISO byte");
  EXPECT_EQ(error_of(head + "1 frame D0\n0.5 frame 00\n"),
            "t.trace:3: time 0.5 s goes backwards (the previous event was at 1.00000000 s)");
  EXPECT_EQ(error_of(head + "0 frame 10us D0\n0.000005 frame 00\n"),
            "t.trace:3: frame at 0.000005 s starts before the previous frame ended (0.00001000 s)");
  EXPECT_EQ(error_of(head + "x frame D0\n"), "t.trace:2: unknown line \"x frame D0\" (expected '<time> frame|repeat|pin|fault|load|advance|axis|stops|supply|wire ...')");
  EXPECT_EQ(error_of(head + "0 blink\n"),
            "t.trace:2: unknown event \"blink\" (frame, repeat, pin, fault, load, advance, axis, stops, supply or wire)");
  EXPECT_EQ(error_of(head + "0 pin 0 RESET 1\n"), "t.trace:2: unknown pin \"RESET\" (SW, STCK, STBY, BUSY, FLAG or DIR)");
  EXPECT_EQ(error_of(head + "0 pin 300 SW 1\n"), "t.trace:2: chip \"300\" is not a chip number (0..255)");
  EXPECT_EQ(error_of(head + "0 fault 0 UVLO maybe\n"), "t.trace:2: UVLO \"maybe\" is not on or off");
  EXPECT_EQ(error_of(head + "0 frame D0\nchain 3\n"), "t.trace:3: 'chain' must come before the first event");
  EXPECT_EQ(error_of(head + "0 pin 0 BUSY 1 axis\n"), "t.trace:2: too many fields in \"0 pin 0 BUSY 1 axis\"");
}

TEST(NativeTrace, ReadsTheAxisEventsAndRefusesMalformedOnesByLine) {
  const std::string head = "l6470emu-trace 2\n";
  const Trace t = read_native_trace(head +
                                        "0 axis 1 start=512,switch=home@0:below:no\n"
                                        "0 pin 1 SW 0 axis\n"
                                        "0.5 stops 1 -6400..\n"
                                        "0.5 stops 1 ..\n"
                                        "0.6 supply 1 7000\n"
                                        "0.7 axis 1 none\n",
                                    "a.trace");
  ASSERT_EQ(t.size(), 6u);
  EXPECT_EQ(t[0].kind, TraceEventKind::axis);
  EXPECT_EQ(t[0].text, "start=512,switch=home@0:below:no");
  EXPECT_EQ(t[1].pin, TracePin::SW_AXIS);
  EXPECT_TRUE(t[1].is_observation());
  EXPECT_TRUE(t[2].has_lower_stop);
  EXPECT_EQ(t[2].lower_stop, -6400);
  EXPECT_FALSE(t[2].has_upper_stop);
  EXPECT_FALSE(t[3].has_lower_stop || t[3].has_upper_stop);
  EXPECT_EQ(t[4].supply_mV, 7000u);
  EXPECT_EQ(t[5].text, "none");
  EXPECT_EQ(error_of(head + "0 axis 0\n"), "t.trace:2: axis without a spec (expected 'TIME axis CHIP SPEC' or 'TIME axis CHIP none')");
  EXPECT_NE(error_of(head + "0 axis 0 stops=9..1\n").find("t.trace:2: axis \"stops=9..1\": "), std::string::npos);
  EXPECT_EQ(error_of(head + "0 stops 0 5..-5\n"),
            "t.trace:2: stops \"5..-5\": the lower stop is above the upper one (expected 'TIME stops CHIP LOWER..UPPER', either side may be empty)");
  EXPECT_EQ(error_of(head + "0 stops 0 5\n"),
            "t.trace:2: stops \"5\" is not LOWER..UPPER (expected 'TIME stops CHIP LOWER..UPPER', either side may be empty)");
  EXPECT_EQ(error_of(head + "0 supply 0 12V\n"),
            "t.trace:2: supply \"12V\" is not a whole number of millivolts (0..1000000) (expected 'TIME supply CHIP MILLIVOLTS')");
  EXPECT_EQ(error_of("l6470emu-trace 1\n0 supply 0 12000\n"),
            "t.trace:2: 'supply' events need format version 2 (the first line says 1)");
}

TEST(NativeTrace, ReportsATruncatedLastLineAsSuch) {
  EXPECT_EQ(error_of("l6470emu-trace 1\n0 frame D0 | 00\n0.001 frame D0 0"),
            "t.trace:3: MOSI \"0\" is not a byte (two hex digits) (the last line has no newline: truncated file?)");
  // A complete last line without a newline is fine.
  EXPECT_EQ(read_native_trace("l6470emu-trace 1\n0 frame D0 | 00", "n").size(), 1u);
}

TEST(NativeTrace, StreamsAFileLongerThanItsReadBuffer) {
  TempDir dir;
  const std::string path = dir.file("long.trace");
  constexpr int kFrames = 60'000;  // ~2.3 MB: several 1 MiB reads, lines cut at chunk ends
  {
    NativeTraceWriter w(path, false);
    TraceHeader h;
    h.chain = "1";
    w.write_header(h);
    for (int i = 0; i < kFrames; ++i) {
      const Bytes mosi{static_cast<std::uint8_t>(i), 0x00, 0xFF}, miso{0x00, static_cast<std::uint8_t>(i >> 8), 0x11};
      w.write(frame_at(static_cast<Tick>(i) * 40, 21, mosi, miso));
    }
  }
  NativeTraceReader r(path);
  EXPECT_EQ(r.header().chain, "1");
  TraceEvent e;
  int n = 0;
  while (r.next(e)) {
    ASSERT_EQ(e.tick, static_cast<Tick>(n) * 40);
    ASSERT_EQ(e.mosi[0], static_cast<std::uint8_t>(n));
    ASSERT_EQ(e.miso[1], static_cast<std::uint8_t>(n >> 8));
    ++n;
  }
  EXPECT_EQ(n, kFrames);
}

TEST(NativeTrace, WriterHandsEveryEventToTheFileBeforeReturning) {
  TempDir dir;
  const std::string path = dir.file("live.trace");
  NativeTraceWriter w(path);
  w.write_header({});
  const Bytes mosi{0xD0}, miso{0x00};
  w.write(frame_at(0, 7, mosi, miso));
  // Still open, nothing closed: the file already holds the header and the frame.
  EXPECT_EQ(test::read_text(path), "l6470emu-trace 3\n# " + std::string(kNativeTraceNumbering) +
                                        "\n0.00000000 frame 1.75us D0 | 00\n");
}

TEST(NativeTrace, AKilledRecorderLeavesACompleteFile) {
  TempDir dir;
  const std::string path = dir.file("killed.trace");
  int ready[2];
  ASSERT_EQ(pipe(ready), 0);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    NativeTraceWriter w(path);
    w.write_header({});
    const Bytes mosi{0xD0, 0x00}, miso{0x00, 0x7E};
    for (int i = 0; i < 1000; ++i) w.write(frame_at(static_cast<Tick>(i) * 20, 14, mosi, miso));
    const char c = 'x';
    (void)!write(ready[1], &c, 1);
    for (;;) pause();  // killed here, destructors never run
  }
  char c;
  ASSERT_EQ(read(ready[0], &c, 1), 1);
  kill(child, SIGKILL);
  waitpid(child, nullptr, 0);
  close(ready[0]);
  close(ready[1]);
  NativeTraceReader r(path);
  TraceEvent e;
  int n = 0;
  while (r.next(e)) ++n;
  EXPECT_EQ(n, 1000);
}

TEST(NativeTrace, CannotOpenAMissingFileSaysSo) {
  try {
    NativeTraceReader r("/nonexistent/x.trace");
    FAIL();
  } catch (const TraceError& e) {
    EXPECT_EQ(std::string(e.what()), "/nonexistent/x.trace: cannot open: No such file or directory");
  }
}

TEST(NativeTrace, SaysBadTimestampForNanInfAndNegativeTimes) {
  const std::string head = "l6470emu-trace 1\n";
  for (const char* t : {"nan", "inf", "-1", "-inf", "+5", ".5", "1.", "1.2.3", "1e5"})
    EXPECT_EQ(error_of(head + t + " frame D0\n"),
              "t.trace:2: bad timestamp \"" + std::string(t) + "\" (seconds from 0, e.g. 0.00100300)")
        << t;
  EXPECT_EQ(error_of(head + "9999999999999 frame D0\n"),
            "t.trace:2: timestamp \"9999999999999\" is too large (at most 10^12 s)");
}

TEST(NativeTrace, QuotesAHugeBadTokenShortAndEscapesControlCharacters) {
  const std::string head = "l6470emu-trace 1\n";
  const std::string e = error_of(head + "0 frame " + std::string(10'000'000, 'Q') + "\n");
  EXPECT_EQ(e, "t.trace:2: MOSI \"" + std::string(60, 'Q') + "\u2026\" is not a byte (two hex digits)");
  EXPECT_EQ(error_of(head + "0 frame D0 \x1b]0;owned\x07\n"),
            "t.trace:2: MOSI \"\\x1B]0;owned\\x07\" is not a byte (two hex digits)");
  // A cut never splits a UTF-8 character.
  const std::string mu = error_of(head + "0 pin 0 " + std::string(59, 'a') + "\u00b5\u00b5 1\n");
  EXPECT_NE(mu.find(std::string(59, 'a') + "\u2026"), std::string::npos) << mu;
}

TEST(NativeTrace, NamesBytesThatAreNotTextByTheirValue) {
  const std::string head = "l6470emu-trace 1\n";
  // Binary junk and Latin-1 are shown as \xNN; well-formed UTF-8 stays as it is.
  EXPECT_EQ(error_of(head + "0 frame \xFF\xFE\n"), "t.trace:2: MOSI \"\\xFF\\xFE\" is not a byte (two hex digits)");
  EXPECT_EQ(error_of(head + "0 frame D\xE9\n"), "t.trace:2: MOSI \"D\\xE9\" is not a byte (two hex digits)");
  EXPECT_EQ(error_of(head + "0 frame \xC2\xB5s\n"), "t.trace:2: MOSI \"\u00b5s\" is not a byte (two hex digits)");
}

TEST(NativeTrace, ClosesItsFileWhenTheHeaderIsMalformed) {
  TempDir dir;
  const std::string path = dir.file("bad.trace");
  std::ofstream(path) << "not a trace\n";
  auto open_descriptors = [] {
    int n = 0;
    for (int fd = 0; fd < 4096; ++fd) n += fcntl(fd, F_GETFD) != -1;
    return n;
  };
  const int before = open_descriptors();
  for (int i = 0; i < 50; ++i) EXPECT_THROW(NativeTraceReader r(path), TraceError);
  EXPECT_EQ(open_descriptors(), before);
}

}  // namespace
}  // namespace l6470emu
