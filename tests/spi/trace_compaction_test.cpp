// Repeat lines of the native format: a writer collapses a group of frames that repeats at a
// constant period, a reader hands every frame back; lossless in both directions, strict about
// malformed repeat lines, and nothing lost when the recording process is killed mid-run.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <random>
#include <sstream>

#include "spi/trace_file.hpp"
#include "spi/trace_native.hpp"
#include "spi/trace_output.hpp"
#include "support/trace_test_support.hpp"

namespace l6470emu {
namespace {

using test::frame_at;
using test::TempDir;
using Bytes = std::vector<std::uint8_t>;

/// A host polling GetStatus on one chip, one frame per byte, `polls` times every `period` ticks.
Trace polling(int polls, Tick period, Tick start = 400) {
  Trace t;
  t.header.chain = "1";
  const Bytes d0{0xD0}, zero{0x00}, a{0x00}, b{0x7C}, c{0x03};
  for (int i = 0; i < polls; ++i) {
    const Tick at = start + static_cast<Tick>(i) * period;
    t.write(frame_at(at, 7, d0, a));
    t.write(frame_at(at + 12, 7, zero, b));
    t.write(frame_at(at + 24, 7, zero, c));
  }
  return t;
}

std::string error_of(const std::string& text) {
  try {
    read_native_trace(text, "t.trace");
  } catch (const TraceError& e) {
    return e.what();
  }
  return "(no error)";
}

void expect_same_events(const Trace& a, const Trace& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    const TraceEvent x = a[i], y = b[i];
    ASSERT_EQ(NativeTraceWriter::format_event(x), NativeTraceWriter::format_event(y)) << "event " << i;
  }
}

TEST(TraceCompaction, CollapsesAPollingLoopIntoOneRepeatLine) {
  const std::string text = to_native_text(polling(1000, 4000), true);
  EXPECT_EQ(text,
            "l6470emu-trace 3\n"
            "chain 1\n"
            "# chip numbers count from the MISO end: chip 0 drives MISO, byte k of a frame goes to chip k\n"
            "0.00010000 frame 1.75us D0 | 00\n"
            "0.00010300 frame 1.75us 00 | 7C\n"
            "0.00010600 frame 1.75us 00 | 03\n"
            "0.00110000 frame 1.75us D0 | 00\n"
            "0.00110300 frame 1.75us 00 | 7C\n"
            "0.00110600 frame 1.75us 00 | 03\n"
            "0.99910600 repeat 3 frames 998 times every 1000.00us\n");
}

TEST(TraceCompaction, ReadsBackExactlyTheFramesThatWereCollapsed) {
  const Trace original = polling(1000, 4000);
  const Trace back = read_native_trace(to_native_text(original, true), "c.trace");
  expect_same_events(original, back);
  // Each repeated frame says which repetition of which line it came from.
  EXPECT_EQ(back[6].line, 10u);  // the repeat line, after the header, chain, numbering comment and 6 frames
  EXPECT_EQ(back[6].repetition, 1u);
  EXPECT_EQ(back[back.size() - 1].repetition, 998u);
  EXPECT_EQ(back[5].repetition, 0u);
}

TEST(TraceCompaction, KeepsFramesWhoseTimingOrBytesBreakTheRunAsLinesOfTheirOwn) {
  Trace t = polling(5, 4000);
  // A late poll, then a different answer, then pins: each breaks the run.
  const Bytes d0{0xD0}, zero{0x00}, a{0x00}, b{0x7C}, c{0x03}, other{0x7E};
  t.write(frame_at(400 + 5 * 4000 + 1, 7, d0, a));
  t.write(frame_at(400 + 6 * 4000, 7, zero, other));
  TraceEvent pin;
  pin.kind = TraceEventKind::pin;
  pin.pin = TracePin::BUSY;
  pin.value = 1;
  pin.tick = 400 + 6 * 4000 + 50;
  t.write(pin);
  const Trace more = polling(4, 4000, 400 + 7 * 4000);
  for (std::size_t i = 0; i < more.size(); ++i) t.write(more[i]);
  const std::string text = to_native_text(t, true);
  expect_same_events(t, read_native_trace(text, "t"));
  EXPECT_NE(text.find("repeat 3 frames 3 times"), std::string::npos) << text;
  EXPECT_NE(text.find("repeat 3 frames 2 times"), std::string::npos) << text;
}

TEST(TraceCompaction, FindsGroupsOfOneToSixteenFrames) {
  for (std::size_t k : {1u, 2u, 5u, 16u}) {
    Trace t;
    for (int rep = 0; rep < 10; ++rep)
      for (std::size_t j = 0; j < k; ++j) {
        const Bytes mosi{static_cast<std::uint8_t>(j)}, miso{static_cast<std::uint8_t>(j + 1)};
        t.write(frame_at(static_cast<Tick>(rep) * 1000 + j * 20, 8, mosi, miso));
      }
    const std::string text = to_native_text(t, true);
    EXPECT_NE(text.find(" repeat " + std::to_string(k) + (k == 1 ? " frame 8 times" : " frames 8 times")),
              std::string::npos)
        << text;
    expect_same_events(t, read_native_trace(text, "t"));
  }
}

/// A driver's poll as python3-spidev sends it: GetStatus, then GetParam(ABS_POS), a byte a frame;
/// ABS_POS 5: two answer frames alike (NOP in, 0x00 out) and evenly spaced, a group of one
/// inside the group of seven.
Trace poll_with_alike_neighbours(int polls) {
  Trace t;
  t.header.chain = "1";
  const Bytes d0{0xD0}, g{0x21}, zero{0x00}, s1{0x7C}, s2{0x03}, five{0x05};
  for (int i = 0; i < polls; ++i) {
    const Tick at = 400 + static_cast<Tick>(i) * 1000;
    t.write(frame_at(at, 7, d0, zero));
    t.write(frame_at(at + 40, 7, zero, s1));
    t.write(frame_at(at + 80, 7, zero, s2));
    t.write(frame_at(at + 120, 7, g, zero));
    t.write(frame_at(at + 160, 7, zero, zero));
    t.write(frame_at(at + 200, 7, zero, zero));
    t.write(frame_at(at + 240, 7, zero, five));
  }
  return t;
}

TEST(TraceCompaction, AGroupHoldingAlikeNeighboursIsStillFound) {
  // The alike frames start a run of one frame that ends at once; the longer group around them
  // must still be seen (it was not: every poll stayed seven lines, and a .gz recording of such
  // a driver grew larger than the plain one).
  const Trace t = poll_with_alike_neighbours(2000);
  const std::string closed = to_native_text(t, true);
  expect_same_events(t, read_native_trace(closed, "t"));
  EXPECT_NE(closed.find(" repeat 7 frames "), std::string::npos) << closed.substr(0, 2000);
  EXPECT_LT(std::count(closed.begin(), closed.end(), '\n'), 60) << closed.substr(0, 3000);
  // The same with open repeat lines, as a plain recording writes them.
  TempDir dir;
  const std::string path = dir.file("live.trace");
  {
    NativeTraceWriter w(path);
    w.write_header(t.header);
    for (std::size_t i = 0; i < t.size(); ++i) w.write(t[i]);
    w.finish();
  }
  const std::string open = test::read_text(path);
  expect_same_events(t, read_native_trace(open, "t"));
  EXPECT_NE(open.find(" repeat 7 frames every 250.00us times"), std::string::npos) << open.substr(0, 2000);
  EXPECT_LT(std::count(open.begin(), open.end(), '\n'), 60) << open.substr(0, 3000);
}

TEST(TraceCompaction, ChainsRepeatLinesAndAcceptsThemFromOtherWriters) {
  // Two repeat lines in a row repeat the same group (the second starts where the first ended).
  const std::string text =
      "l6470emu-trace 1\n"
      "0.00000000 frame 0.25us 00 | 7C\n"
      "0.00000100 repeat 1 frame 4 times every 0.25us\n"
      "0.00000150 repeat 1 frame 2 times every 0.25us\n"
      "# a comment between does not matter\n"
      "0.00000175 frame 00 | 7C\n";
  const Trace t = read_native_trace(text, "t");
  ASSERT_EQ(t.size(), 8u);
  for (std::size_t i = 0; i < 7; ++i) EXPECT_EQ(t[i].tick, i) << i;
}

/// Polls of random shapes repeated a random number of times, with odd frames, changed bytes
/// and shifted times among them: what a collapsing writer must keep frame for frame.
Trace random_polls(unsigned seed) {
  std::mt19937 rng(seed);
  auto pick = [&rng](int lo, int hi) { return std::uniform_int_distribution<int>(lo, hi)(rng); };
  Trace t;
  t.header.chain = "2";
  Tick at = 100;
  for (int block = 0; block < 120; ++block) {
    const int group = pick(1, 20), repeats = pick(0, 12);
    const Tick gap = static_cast<Tick>(pick(10, 30));
    std::vector<Bytes> mosi(static_cast<std::size_t>(group)), miso(mosi.size());
    for (std::size_t j = 0; j < mosi.size(); ++j) {
      mosi[j] = {static_cast<std::uint8_t>(pick(0, 3)), static_cast<std::uint8_t>(pick(0, 1))};
      miso[j] = {static_cast<std::uint8_t>(pick(0, 2)), 0x7C};
    }
    for (int r = 0; r <= repeats; ++r) {
      for (std::size_t j = 0; j < mosi.size(); ++j) {
        Bytes out = miso[j];
        if (pick(0, 40) == 0) out[1] = static_cast<std::uint8_t>(pick(0, 255));  // a changed answer
        t.write(frame_at(at, 7, mosi[j], out));
        at += gap + (pick(0, 50) == 0 ? 1 : 0);  // now and then a tick late
      }
      if (pick(0, 30) == 0) {  // another event between polls ends any run
        TraceEvent e;
        e.kind = TraceEventKind::pin;
        e.tick = at;
        e.pin = TracePin::SW;
        e.value = static_cast<std::uint8_t>(pick(0, 1));
        t.write(e);
      }
    }
  }
  return t;
}

TEST(TraceCompaction, RandomPollsReadBackFrameForFrameFromOpenAndClosedRepeatLines) {
  TempDir dir;
  for (unsigned seed = 1; seed <= 12; ++seed) {
    const Trace t = random_polls(seed);
    // Closed lines (a stream) and open lines (a plain file rewritten in place).
    std::ostringstream closed;
    NativeTraceWriter stream(closed, NativeWriteOptions{false, true});
    const std::string path = dir.file("open" + std::to_string(seed) + ".trace");
    NativeTraceWriter file(path);
    stream.write_header(t.header);
    file.write_header(t.header);
    for (std::size_t i = 0; i < t.size(); ++i) {
      stream.write(t[i]);
      file.write(t[i]);
    }
    stream.finish();
    file.finish();
    const std::string closed_text = closed.str();
    const Trace from_stream = read_native_trace(closed_text, "closed.trace");
    const Trace from_file = read_native_trace(test::read_text(path), "open.trace");
    expect_same_events(t, from_stream);
    expect_same_events(t, from_file);
    // And runs were found (groups above 16 frames, short runs and the odd changes stay lines).
    EXPECT_LT(std::count(closed_text.begin(), closed_text.end(), '\n'), static_cast<long>(t.size()) * 9 / 10) << seed;
  }
}

TEST(TraceCompaction, RefusesMalformedRepeatLinesNamingTheLine) {
  const std::string head = "l6470emu-trace 1\n0 frame 1.75us D0 | 00\n0.00000300 frame 1.75us 00 | 7C\n";
  const std::string form = " (expected 'TIME repeat K frames N times every PERIODus')";
  EXPECT_EQ(error_of("l6470emu-trace 1\n0 repeat 1 frame 1 time every 1us\n"),
            "t.trace:2: repeat: there are 0 frame lines to repeat since the last pin or fault event, not 1");
  EXPECT_EQ(error_of(head + "0.00100300 repeat 3 frames 1 time every 1000.00us\n"),
            "t.trace:4: repeat: there are 2 frame lines to repeat since the last pin or fault event, not 3");
  EXPECT_EQ(error_of(head + "1 repeat 0 frames 1 time every 1us\n"),
            "t.trace:4: repeat: group size \"0\" is not a number of frames from 1 to 16" + form);
  EXPECT_EQ(error_of(head + "1 repeat 17 frames 1 time every 1us\n"),
            "t.trace:4: repeat: group size \"17\" is not a number of frames from 1 to 16" + form);
  EXPECT_EQ(error_of(head + "1 repeat 2 frames 0 times every 1us\n"),
            "t.trace:4: repeat: count \"0\" is not a number of repetitions from 1 to 10^12" + form);
  EXPECT_EQ(error_of(head + "1 repeat 2 frames 99999999999999999999 times every 1us\n"),
            "t.trace:4: repeat: count \"99999999999999999999\" is not a number of repetitions from 1 to 10^12" + form);
  EXPECT_EQ(error_of(head + "1 repeat 2 frames 1 times each 1us\n"),
            "t.trace:4: repeat: \"each\" where 'every' belongs" + form);
  EXPECT_EQ(error_of(head + "1 repeat 2 frames 1 times every 1ms\n"),
            "t.trace:4: repeat: period \"1ms\" is not a number of microseconds up to 10^12 s (e.g. 1000.00us)" + form);
  EXPECT_EQ(error_of(head + "1 repeat 2 frames 1 times every 1us extra\n"),
            "t.trace:4: too many fields in the repeat line" + form);
  EXPECT_EQ(error_of(head + "0.00000775 repeat 2 frames 1 times every 2us\n"),
            "t.trace:4: repeat: period \"2us\" is shorter than the 2 frames it repeats (4.75 us from the first CS "
            "falling edge to the last CS rising edge): repetitions would overlap");
  EXPECT_EQ(error_of(head + "0.5 repeat 2 frames 1 times every 10us\n"),
            "t.trace:4: repeat: the line's time 0.5 s is not when the last repetition's last frame starts "
            "(0.00001300 s: its last frame at 0.00000300 s plus 1 periods)");
  // A repeat after a pin line only repeats frames after it.
  EXPECT_EQ(error_of(head + "0.00001 pin 0 SW 0\n0.00002 repeat 1 frame 1 time every 10us\n"),
            "t.trace:5: repeat: there are 0 frame lines to repeat since the last pin or fault event, not 1");
}

TEST(TraceCompaction, AHugeCountIsReadLazilyWithoutMemoryOrTimeToMatch) {
  // 10^12 repetitions of one frame, allowed (max_frames 0: no limit): opening and reading the
  // first events takes no time.
  const std::string text =
      "l6470emu-trace 1\n0 frame 0.25us 00 | 7C\n250000.00000000 repeat 1 frame 1000000000000 times every 0.25us\n";
  NativeTraceReader r(text, "huge.trace", 0);
  TraceEvent e;
  for (int i = 0; i < 1000; ++i) ASSERT_TRUE(r.next(e));
  EXPECT_EQ(e.tick, 999u);
  // Beyond 10^12 s is refused, not wrapped around.
  EXPECT_EQ(error_of("l6470emu-trace 1\n0 frame 0.25us 00\n1 repeat 1 frame 1000000000000 times every 18446744073us\n"),
            "t.trace:3: repeat: the line's time 1 s is not when the last repetition's last frame starts (beyond 10^12 s: "
            "its last frame at 0.00000000 s plus 1000000000000 periods)");
}

TEST(TraceCompaction, ExpandedOutputStaysOneLinePerFrame) {
  const Trace t = polling(10, 4000);
  const std::string text = to_native_text(t);
  EXPECT_EQ(text.find("repeat"), std::string::npos);
  expect_same_events(t, read_native_trace(text, "t"));
}

/// Lines of a file, with a rewritten plain recording's blank comment lines dropped.
std::string file_events(const std::string& path) {
  NativeTraceReader r(path);
  std::string out;
  TraceEvent e;
  while (r.next(e)) out += NativeTraceWriter::format_event(e) + "\n";
  return out;
}

TEST(TraceCompaction, APlainRecordingHoldsEveryFrameOfARunAfterEveryWrite) {
  TempDir dir;
  const std::string path = dir.file("live.trace");
  const Trace t = polling(50, 4000);
  NativeTraceWriter w(path);
  w.write_header(t.header);
  std::string expected;
  for (std::size_t i = 0; i < t.size(); ++i) {
    w.write(t[i]);
    expected += NativeTraceWriter::format_event(t[i]) + "\n";
    // Not closed: the file read now already gives every frame written so far.
    ASSERT_EQ(file_events(path), expected) << "after frame " << i << ":\n" << test::read_text(path);
  }
  w.finish();
  EXPECT_EQ(file_events(path), expected);
  // 150 frames in 10 lines: three polls, then an open repeat line whose count went up in place.
  EXPECT_LT(test::read_text(path).size(), 480u);
  EXPECT_NE(test::read_text(path).find("0.00210600 repeat 3 frames every 1000.00us times      47\n"), std::string::npos)
      << test::read_text(path);
}

/// Writes `t` to `path` in a child that is killed after the last write (no destructor runs).
void record_and_kill(const std::string& path, const Trace& t, const TraceFlushPolicy& policy = {}) {
  int ready[2];
  ASSERT_EQ(pipe(ready), 0);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    NativeTraceWriter w(open_trace_file_output(path, policy));
    w.write_header(t.header);
    for (std::size_t i = 0; i < t.size(); ++i) w.write(t[i]);
    const char c = 'x';
    (void)!write(ready[1], &c, 1);
    for (;;) pause();
  }
  char c;
  ASSERT_EQ(read(ready[0], &c, 1), 1);
  kill(child, SIGKILL);
  waitpid(child, nullptr, 0);
  close(ready[0]);
  close(ready[1]);
}

TEST(TraceCompaction, AKilledPlainRecordingLosesNoRepetition) {
  TempDir dir;
  const std::string path = dir.file("killed.trace");
  Trace t = polling(300, 4000);
  // Killed in the middle of a repetition: two frames of the 301st poll written.
  const Bytes d0{0xD0}, zero{0x00}, a{0x00}, b{0x7C};
  t.write(frame_at(400 + 300 * 4000, 7, d0, a));
  t.write(frame_at(400 + 300 * 4000 + 12, 7, zero, b));
  record_and_kill(path, t);
  expect_same_events(t, read_native_trace(test::read_text(path), path));
}

TEST(TraceCompaction, AKilledGzipRecordingKeepsEverythingUpToItsLastCheckpoint) {
  TempDir dir;
  const std::string path = dir.file("killed.trace.gz");
  const Trace t = polling(3000, 4000);  // 1 ms polls: a checkpoint every second (1000 repetitions)
  // A sync-flush point at the end of every event that wrote something (the checkpoints).
  TraceFlushPolicy every_line;
  every_line.gzip_bytes = 1;
  record_and_kill(path, t, every_line);
  Trace back;
  try {
    NativeTraceReader r(path);
    TraceEvent e;
    while (r.next(e)) back.write(e);
    FAIL() << "no error for a gzip file without its end";
  } catch (const TraceError& e) {
    EXPECT_NE(std::string(e.what()).find("the gzip data ends early"), std::string::npos) << e.what();
  }
  // The first two checkpoints (1000 and 2000 repetitions after the first two polls) are there.
  ASSERT_GE(back.size(), 3u * (2 + 2000));
  for (std::size_t i = 0; i < back.size(); ++i)
    ASSERT_EQ(NativeTraceWriter::format_event(back[i]), NativeTraceWriter::format_event(t[i])) << i;
}

TEST(TraceCompaction, AGzipRecordingWritesARunsRepeatLineWhenItFlushesNotBefore) {
  // A gzip recording flushes by size and host time; a run's repeat line is only worth writing
  // when a flush takes it. A fast host (1 us between looks at the clock) polling for 100 s of
  // trace time: one flush interval (200 ms) never passes, so the run is one line, not one per
  // 1024 repetitions (which made a .gz recording 28 times gzip -6 of the plain one).
  TempDir dir;
  const std::string path = dir.file("fast.trace.gz");
  std::int64_t now = 0;
  TraceFlushPolicy policy;
  policy.clock = [&now] { return now += 1000; };
  const Trace t = polling(100000, 4000);
  {
    NativeTraceWriter w(open_trace_file_output(path, policy));
    w.write_header(t.header);
    for (std::size_t i = 0; i < t.size(); ++i) w.write(t[i]);
    w.finish();
  }
  const std::string text = read_trace_file(path);
  std::size_t repeats = 0;
  for (std::size_t at = text.find(" repeat "); at != std::string::npos; at = text.find(" repeat ", at + 1)) ++repeats;
  EXPECT_EQ(repeats, 1u) << text;
  expect_same_events(t, read_native_trace(text, "fast.trace"));
  // A slow host (10 ms a look, 10 s in all): flushes are due, and each takes the run's line with
  // it (ever further apart while the run is all that is new: the next test).
  now = 0;
  policy.clock = [&now] { return now += 10'000'000; };
  {
    NativeTraceWriter w(open_trace_file_output(path, policy));
    w.write_header(t.header);
    for (std::size_t i = 0; i < 3000; ++i) w.write(t[i]);
    w.finish();
  }
  const std::string slow = read_trace_file(path);
  repeats = 0;
  for (std::size_t at = slow.find(" repeat "); at != std::string::npos; at = slow.find(" repeat ", at + 1)) ++repeats;
  EXPECT_GE(repeats, 5u) << slow.substr(0, 2000);
}

/// The times (ms, rounded down) of a text's `repeat` lines.
std::vector<long> repeat_line_ms(const std::string& text) {
  std::vector<long> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    if (line.find(" repeat ") != std::string::npos) out.push_back(static_cast<long>(std::stod(line) * 1000));
  return out;
}

TEST(TraceCompaction, AGzipRecordingOfAnUnchangingRunFlushesEverLessOftenUntilSomethingNewComes) {
  // A host polling 70 s, one poll per ms of trace and of host time, with a pin event at 60 s.
  // The first flush after 200 ms takes the frame lines before the run; from then on, while the
  // run is all that is new, each flush (with the run's repeat line) comes twice as long after
  // the one before, up to 12.8 s. The pin is news (flushed at once, 200 ms having passed), and
  // after it the same again.
  TempDir dir;
  const std::string path = dir.file("steady.trace.gz");
  std::int64_t host_ms = 0;
  TraceFlushPolicy policy;
  policy.clock = [&host_ms] { return host_ms * 1'000'000; };
  const Trace t = polling(70000, 4000);
  {
    NativeTraceWriter w(open_trace_file_output(path, policy));
    w.write_header(t.header);
    for (std::size_t i = 0; i < t.size(); ++i) {
      host_ms = static_cast<std::int64_t>(i / 3);
      w.write(t[i]);
      if (i == 3 * 60000 + 2) {
        TraceEvent pin;
        pin.kind = TraceEventKind::pin;
        pin.tick = t[i].end();
        pin.pin = TracePin::SW;
        pin.value = 1;
        w.write(pin);
      }
    }
    w.finish();
  }
  const std::string text = read_trace_file(path);
  EXPECT_EQ(repeat_line_ms(text), (std::vector<long>{400, 800, 1600, 3200, 6400, 12800, 25600, 38400, 51200, 60000,
                                                      60400, 60800, 61600, 63200, 66400, 69999}))
      << text;
  // Every frame is there, and the pin.
  const Trace back = read_native_trace(text, "steady.trace");
  EXPECT_EQ(back.size(), t.size() + 1);
}

TEST(TraceCompaction, GzipFilesRoundTripAndAreRecognisedByTheirBytes) {
  TempDir dir;
  const Trace t = polling(100, 4000);
  const std::string gz = dir.file("p.trace.gz");
  {
    NativeTraceWriter w(gz);
    w.write_header(t.header);
    for (std::size_t i = 0; i < t.size(); ++i) w.write(t[i]);
  }
  EXPECT_TRUE(starts_with_gzip_magic(test::read_text(gz)));
  // Renamed without .gz, it is still read as gzip.
  const std::string renamed = dir.file("p.trace");
  ASSERT_EQ(std::rename(gz.c_str(), renamed.c_str()), 0);
  NativeTraceReader r(renamed);
  EXPECT_EQ(r.header().chain, "1");
  Trace back;
  TraceEvent e;
  while (r.next(e)) back.write(e);
  expect_same_events(t, back);
}

TEST(TraceCompaction, ATruncatedGzipFileSaysWhereItEnds) {
  TempDir dir;
  const std::string gz = dir.file("t.trace.gz");
  {
    NativeTraceWriter w(gz, NativeWriteOptions{false, false});
    const Trace t = polling(2000, 4000);
    w.write_header(t.header);
    for (std::size_t i = 0; i < t.size(); ++i) w.write(t[i]);
  }
  const std::string whole = test::read_text(gz);
  const std::string cut = dir.write("cut.trace.gz", whole.substr(0, whole.size() / 2));
  try {
    NativeTraceReader r(cut);
    TraceEvent e;
    while (r.next(e)) {
    }
    FAIL();
  } catch (const TraceError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind(cut + ":", 0), 0u) << m;
    EXPECT_GT(e.line(), 2u) << m;
    EXPECT_NE(m.find("the gzip data ends early, after"), std::string::npos) << m;
    EXPECT_NE(m.find("a truncated file, or a recording that was stopped before it was closed"), std::string::npos) << m;
  }
  // Damaged (not cut) data says so too.
  std::string bad = whole;
  for (std::size_t i = 40; i < 60; ++i) bad[i] = static_cast<char>(bad[i] ^ 0x5A);
  const std::string damaged = dir.write("bad.trace.gz", bad);
  EXPECT_THROW(
      {
        NativeTraceReader r(damaged);
        TraceEvent e;
        while (r.next(e)) {
        }
      },
      TraceError);
}

}  // namespace
}  // namespace l6470emu
