// The recording's memory-mapped plain file (spi/recording_output.hpp) under the trace writer:
// an open run's count, replaced in place one 8-byte word at a time, is right after every
// repetition through every carry of its six digits, and a run longer than the field goes on in a
// new one.
#include <gtest/gtest.h>

#include <string>

#include "spi/recording_output.hpp"
#include "spi/trace_native.hpp"
#include "support/trace_test_support.hpp"

namespace l6470emu {
namespace {

using test::TempDir;

/// A NOP frame at `tick`, 1.75 µs long.
TraceEvent nop_at(Tick tick) {
  static const std::uint8_t zero = 0;
  TraceEvent e;
  e.kind = TraceEventKind::frame;
  e.tick = tick;
  e.duration = 7;
  e.mosi = {&zero, 1};
  e.miso = {&zero, 1};
  return e;
}

/// The count field an open repeat line of the file shows (the six characters before its newline;
/// blanks after "times" align it to 8 bytes).
std::string open_count(const std::string& text) {
  const std::size_t at = text.rfind(" times ");
  if (at == std::string::npos) return "(no open repeat line)";
  const std::size_t end = text.find('\n', at);
  return text.substr(end - 6, 6);
}

std::string right_aligned(std::uint64_t n) {
  std::string s = std::to_string(n);
  return std::string(6 - s.size(), ' ') + s;
}

TEST(RecordingOutput, AnOpenRunsCountIsRightAfterEveryRepetitionThroughEveryCarry) {
  TempDir dir;
  const std::string path = dir.file("count.trace");
  NativeTraceWriter w(open_mapped_trace_output(path));
  w.write_header({});
  constexpr Tick kPeriod = 40;
  // Three alike frames start the run (an open line waits for its group's third copy).
  std::uint64_t frames = 0;
  for (; frames < 3; ++frames) w.write(nop_at(frames * kPeriod));
  ASSERT_EQ(open_count(test::read_text(path)), right_aligned(0)) << test::read_text(path);
  // Every count up to 1200 is looked at, then the ones around each carry and the last.
  auto checked = [](std::uint64_t n) {
    if (n <= 1200) return true;
    for (std::uint64_t p = 10'000; p <= 100'000; p *= 10)
      if (n + 1 == p || n == p) return true;
    return n == 999'998 || n == 999'999 || n % 99'991 == 0;
  };
  for (std::uint64_t count = 1; count <= kMaxOpenRepeatCount; ++count, ++frames) {
    w.write(nop_at(frames * kPeriod));
    if (checked(count)) {
      ASSERT_EQ(open_count(test::read_text(path)), right_aligned(count)) << "after " << count;
    }
  }
  // The field is full: the next frames are a line of their own and then a new run.
  for (int i = 0; i < 5; ++i, ++frames) w.write(nop_at(frames * kPeriod));
  w.finish();
  const std::string text = test::read_text(path);
  EXPECT_NE(text.find("999999\n"), std::string::npos) << "no run of 999999 repetitions";
  // Read back, the file holds every frame at its tick.
  NativeTraceReader r(path, 0);
  TraceEvent e;
  std::uint64_t read = 0;
  while (r.next(e)) {
    ASSERT_EQ(e.tick, read * kPeriod) << "frame " << read;
    ++read;
  }
  EXPECT_EQ(read, frames);
}

}  // namespace
}  // namespace l6470emu
