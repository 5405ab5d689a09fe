// The progress bar (tools/progress.hpp): what a line says, that it is drawn over itself and
// cleared on a terminal, and that nothing at all is written when standard error is not one.
#include <gtest/gtest.h>

#include <chrono>
#include <sstream>

#include "spi/trace_native.hpp"
#include "support/trace_test_support.hpp"
#include "tools/progress.hpp"

namespace l6470emu {
namespace {

TEST(ProgressLine, ShowsABarThePercentageAndTheAmounts) {
  EXPECT_EQ(format_progress("replaying run.trace", 12'000'000, 24'000'000, "bytes", 70),
            "replaying run.trace [############------------]  50% 12.0 MB of 24.0 MB");
  EXPECT_EQ(format_progress("decoding x", 3, 4, "events", 50), "decoding x [#############-----]  75% 3 of 4 events");
  EXPECT_EQ(format_progress("x", 0, 1000, "bytes", 40), "x [-----------------]   0% 0 B of 1000 B");
  // The bar takes what the width leaves (here all 70 columns), 40 at most.
  EXPECT_EQ(format_progress("replaying run.trace", 1, 2, "bytes", 70).size(), 70u);
  EXPECT_EQ(format_progress("r", 1, 2, "bytes", 200).find(std::string(20, '#') + std::string(20, '-')), 3u);
}

TEST(ProgressLine, WithoutATotalSaysWhatWasDone) {
  EXPECT_EQ(format_progress("reading pipe", 1'500'000, 0, "bytes"), "reading pipe 1500.0 kB");
}

TEST(ProgressLine, CutsALongLabelFromTheLeftToFitTheWidth) {
  const std::string line =
      format_progress("replaying /a/very/long/directory/name/that/goes/on/capture.trace", 1, 2, "bytes", 60);
  EXPECT_EQ(line.rfind("…", 0), 0u) << line;
  EXPECT_NE(line.find("capture.trace ["), std::string::npos) << line;
  EXPECT_LE(line.size() - 2, 60u) << line;  // "…" is one column in three bytes
}

TEST(ProgressBar, DrawsOverItselfAndClearsTheLineAtTheEnd) {
  std::ostringstream err;
  {
    const auto start = std::chrono::steady_clock::now();
    ProgressBar bar(err, true, "replaying t");
    bar.update(1, 2);  // within 200 ms of the start: not drawn (unless the machine stalled that long)
    if (std::chrono::steady_clock::now() - start < std::chrono::milliseconds(150)) {
      EXPECT_EQ(err.str(), "");
    }
    usleep(210'000);
    bar.update(1, 2);
    EXPECT_EQ(err.str().rfind("\rreplaying t [", 0), 0u) << err.str();
  }
  EXPECT_NE(err.str().find("\r\x1b[K"), std::string::npos);
}

TEST(ProgressBar, WritesNothingWhenDisabled) {
  std::ostringstream err;
  {
    ProgressBar bar(err, false, "replaying t");
    usleep(210'000);
    bar.update(1, 2);
    bar.clear();
  }
  EXPECT_EQ(err.str(), "");
}

TEST(ProgressBar, IsOffWhenStandardErrorIsNotATerminal) {
  // Under ctest standard error is a pipe or a file.
  if (isatty(STDERR_FILENO)) GTEST_SKIP() << "standard error is a terminal";
  EXPECT_FALSE(ProgressBar::on_stderr("x").enabled());
}

TEST(ProgressBar, ReplayOfALargeTraceToAFilePrintsNoProgress) {
  test::TempDir dir;
  // 200 000 frames: long enough for several drawings, were stderr a terminal.
  std::string text = "l6470emu-trace 1\nchain 1\n";
  for (int i = 0; i < 200'000; ++i) text += format_seconds(static_cast<Tick>(i) * 40) + " frame 1.75us 00 | 00\n";
  const std::string path = dir.write("big.trace", text);
  const test::RunResult r = test::run_command(std::string(L6470EMU_BINARY) + " replay " + path);
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(r.out.find('\r'), std::string::npos);
  EXPECT_EQ(r.out.find("\x1b["), std::string::npos);
}

TEST(ProgressReader, PassesEveryEventThrough) {
  const std::string text = "l6470emu-trace 1\n0 frame 00 | 00\n0.001 frame 00 | 00\n0.1 repeat 1 frame 99 times every 1000.00us\n";
  NativeTraceReader in(text, "t");
  std::ostringstream err;
  ProgressBar bar(err, true, "t");
  ProgressTraceReader r(in, bar);
  TraceEvent e;
  int n = 0;
  while (r.next(e)) ++n;
  EXPECT_EQ(n, 101);
  EXPECT_EQ(r.header().name, "t");
}

TEST(ProgressLine, SaysHowManyFramesWentBySoALongRepeatLineStillMovesIt) {
  EXPECT_EQ(format_progress("replaying r.trace", 100, 200, "bytes", 80, 12'345'678),
            "replaying r.trace [############-------------]  50% 100 B of 200 B, 12.3 M frames");
  EXPECT_EQ(format_progress("r", 1, 2, "bytes", 60, 5), "r [###############---------------]  50% 1 B of 2 B, 5 frames");
  EXPECT_EQ(format_progress("r", 1, 2, "bytes", 60, 0), format_progress("r", 1, 2, "bytes", 60));
}

TEST(ProgressReader, CountsTheFramesARepeatLineHandsOutOnTheBar) {
  // 10 000 frames from 4 lines: the bytes stand still at the repeat line, the frames do not.
  const std::string text =
      "l6470emu-trace 1\n0 frame 00 | 00\n0.001 frame 00 | 00\n9.999 repeat 1 frame 9998 times every 1000.00us\n";
  NativeTraceReader in(text, "t");
  std::ostringstream err;
  ProgressBar bar(err, true, "t");
  ProgressTraceReader r(in, bar);
  TraceEvent e;
  usleep(210'000);  // the first update after this draws
  int n = 0;
  while (r.next(e)) ++n;
  EXPECT_EQ(n, 10'000);
  EXPECT_NE(err.str().find(", 4095 frames"), std::string::npos) << err.str();
}

}  // namespace
}  // namespace l6470emu
