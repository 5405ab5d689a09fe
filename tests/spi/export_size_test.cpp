// Export sizes from a trace's counts (spi/export_size.cpp): exact for the lines of expanded
// native text and umockdev, a lower bound close to the truth for VCD.
#include <gtest/gtest.h>

#include <sstream>

#include "spi/export_size.hpp"
#include "spi/export_umockdev.hpp"
#include "spi/export_vcd.hpp"
#include "spi/trace_native.hpp"
#include "support/trace_test_support.hpp"

namespace l6470emu {
namespace {

/// The fixture, read into memory.
Trace polling_host() {
  NativeTraceReader r(test::fixture_path("polling_host.trace"));
  Trace t;
  t.header = r.header();
  TraceEvent e;
  while (r.next(e)) t.write(e);
  return t;
}

std::uint64_t counted(const Trace& t, ExportFormat format, unsigned timescale_ns = 10) {
  ExportSizeCounter c(format, timescale_ns);
  auto r = t.reader();
  TraceEvent e;
  while (r->next(e)) c.add(e);
  return c.bytes();
}

/// The size of `text` without its first `header_lines` lines.
std::uint64_t without_lines(const std::string& text, std::size_t header_lines) {
  std::size_t at = 0;
  for (std::size_t i = 0; i < header_lines; ++i) at = text.find('\n', at) + 1;
  return text.size() - at;
}

TEST(ExportSize, CountsExpandedNativeTextExactlyLineByLine) {
  const Trace t = polling_host();
  std::ostringstream out;
  {
    NativeTraceWriter w(out, NativeWriteOptions{false, false});
    TraceHeader h = t.header;
    w.write_header(h);
    auto r = t.reader();
    TraceEvent e;
    while (r->next(e)) w.write(e);
    w.finish();
  }
  // The header: the version line, the chain, the numbering comment.
  EXPECT_EQ(counted(t, ExportFormat::native_expanded), without_lines(out.str(), 3));
  // Compact text counts the lines outside `repeat` lines: far fewer.
  EXPECT_LT(counted(t, ExportFormat::native), counted(t, ExportFormat::native_expanded) / 50);
}

TEST(ExportSize, CountsUmockdevTextExactlyLineByLine) {
  const Trace t = polling_host();
  std::ostringstream out;
  auto r = t.reader();
  export_umockdev_ioctl(*r, out);
  // The header: @DEV, "written by", the chain.
  EXPECT_EQ(counted(t, ExportFormat::umockdev_ioctl), without_lines(out.str(), 3));
}

TEST(ExportSize, BoundsAVcdFromBelowWithinAQuarterOfItsSize) {
  const Trace t = polling_host();
  for (unsigned ts : {1u, 10u, 100u}) {
    std::ostringstream out;
    export_vcd(t, out, {ts});
    const std::uint64_t at_least = counted(t, ExportFormat::vcd, ts);
    EXPECT_LE(at_least, out.str().size()) << ts;
    EXPECT_GT(at_least, out.str().size() * 3 / 4) << ts;
  }
}

}  // namespace
}  // namespace l6470emu
