// Linux ftrace spi events (spi/import_ftrace.cpp): tracefs and trace-cmd report layouts,
// CS frames from spi_set_cs, per transfer or per message, and one-line errors.
#include <gtest/gtest.h>

#include "spi/trace_import.hpp"
#include "support/trace_test_support.hpp"

namespace l6470emu {
namespace {

using Bytes = std::vector<std::uint8_t>;

Bytes bytes(std::span<const std::uint8_t> s) { return Bytes(s.begin(), s.end()); }

std::string line(double ts, const std::string& event, const std::string& rest) {
  char buf[300];
  std::snprintf(buf, sizeof buf, "     stepper-812     [002] .....  %.6f: %s: %s\n", ts, event.c_str(), rest.c_str());
  return buf;
}

std::string error_of(const std::string& text, ImportOptions o = {}) {
  try {
    import_ftrace(text, "trace.txt", o);
  } catch (const TraceError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(FtraceImport, FramesByCsEventsInTheTracefsFixture) {
  const Trace t = import_ftrace(test::fixture("ftrace_spi_set_cs.txt"), "ftrace_spi_set_cs.txt");
  EXPECT_EQ(t.header.format, "ftrace");
  EXPECT_TRUE(t.header.notes.empty());
  ASSERT_EQ(t.frame_count(), 30u);
  EXPECT_EQ(bytes(t[0].mosi), (Bytes{0xD0, 0xD0, 0xD0}));
  EXPECT_EQ(bytes(t[1].miso), (Bytes{0x7C, 0x7C, 0x7C}));
  EXPECT_DOUBLE_EQ(t[0].source_time, 1523.782943);
  EXPECT_EQ(t[0].duration, 24u);  // activate 1523.782943 -> deactivate 1523.782949
}

TEST(FtraceImport, TakesEachTransferAsAFrameInATraceCmdReportWithoutCsEvents) {
  const Trace t = import_ftrace(test::fixture("ftrace_trace_cmd_report.txt"), "report.txt");
  ASSERT_EQ(t.frame_count(), 17u);
  EXPECT_EQ(bytes(t[2].miso), (Bytes{0x03, 0x03}));
  ASSERT_EQ(t.header.notes.size(), 1u);
  EXPECT_NE(t.header.notes[0].find("no spi_set_cs events"), std::string::npos);
}

TEST(FtraceImport, GroupsTransfersByMessageOrCsWhenAsked) {
  const std::string text = line(1.0, "spi_message_start", "spi0.0 00000000deadbeef") +
                           line(1.000001, "spi_set_cs", "spi0.0 activate") +
                           line(1.000002, "spi_transfer_stop", "spi0.0 0000000000000001 len=1 tx=[21] rx=[00]") +
                           line(1.000003, "spi_transfer_stop", "spi0.0 0000000000000002 len=2 tx=[] rx=[12-34]") +
                           line(1.000004, "spi_set_cs", "spi0.0 deactivate") +
                           line(1.000005, "spi_message_done", "spi0.0 00000000deadbeef len=3/3");
  ImportOptions o;
  o.ftrace_framing = FtraceFraming::message;
  const Trace m = import_ftrace(text, "m", o);
  ASSERT_EQ(m.size(), 1u);
  EXPECT_EQ(bytes(m[0].mosi), (Bytes{0x21, 0x00, 0x00}));  // no tx: zeros clocked out
  EXPECT_FALSE(m[0].miso_byte_known(0) && m[0].miso[0] != 0x00);
  EXPECT_EQ(m[0].duration, 20u);
  const Trace cs = import_ftrace(text, "cs");  // automatic: spi_set_cs is there
  ASSERT_EQ(cs.size(), 1u);
  EXPECT_EQ(cs[0].duration, 12u);
  o.ftrace_framing = FtraceFraming::transfer;
  EXPECT_EQ(import_ftrace(text, "t", o).size(), 2u);
}

TEST(FtraceImport, ChoosesOneDeviceWhenSeveralAreTraced) {
  const std::string text = line(1.0, "spi_transfer_stop", "spi0.0 0000000000000001 len=1 tx=[21] rx=[00]") +
                           line(1.1, "spi_transfer_stop", "spi1.0 0000000000000001 len=1 tx=[99] rx=[00]");
  EXPECT_EQ(error_of(text), "trace.txt:2: events of several SPI devices (spi0.0 and spi1.0): choose one with --select");
  ImportOptions o;
  o.select = "spi1.0";
  const Trace t = import_ftrace(text, "t", o);
  ASSERT_EQ(t.size(), 1u);
  EXPECT_EQ(t[0].mosi[0], 0x99);
}

TEST(FtraceImport, RejectsBadInputWithOneLineErrors) {
  EXPECT_EQ(error_of(line(1.0, "spi_transfer_stop", "spi0.0 01 len=2 tx=[21-00] rx=[00]")),
            "trace.txt:1: tx has 2 bytes but rx has 1");
  EXPECT_EQ(error_of(line(1.0, "spi_transfer_stop", "spi0.0 01 len=3 tx=[21-00] rx=[00-00]")),
            "trace.txt:1: tx has 2 bytes but len=3");
  EXPECT_EQ(error_of(line(1.0, "spi_transfer_stop", "spi0.0 01 len=1 tx=[2g] rx=[00]")),
            "trace.txt:1: tx byte \"2g\" is not hex");
  std::string big;
  for (int i = 0; i < 64; ++i) big += i ? "-00" : "00";
  EXPECT_EQ(error_of(line(1.0, "spi_transfer_stop", "spi0.0 01 len=100 tx=[" + big + "] rx=[]")),
            "trace.txt:1: transfer of 100 bytes: the kernel prints at most 64 of them, so this trace cannot be replayed");
  EXPECT_EQ(error_of(line(2.0, "spi_transfer_stop", "spi0.0 01 len=1 tx=[21] rx=[00]") +
                     line(1.0, "spi_transfer_stop", "spi0.0 01 len=1 tx=[21] rx=[00]")),
            "trace.txt:2: time 1.0 s goes backwards (the previous event was at 2.0 s)");
  EXPECT_EQ(error_of(line(1.0, "spi_transfer_stop", "spi0.0 01 len=1 tx=[21]")),
            "trace.txt:1: expected rx=[..], found \"\"");
  EXPECT_EQ(error_of("nothing to see\n"),
            "trace.txt: no spi_transfer_start/stop events (record with: trace-cmd record -e spi, or echo 1 > "
            "/sys/kernel/tracing/events/spi/enable)");
}

TEST(FtraceImport, RefusesATimestampOutOfRange) {
  EXPECT_EQ(error_of("     stepper-812     [002] .....  1e999: spi_transfer_stop: spi0.0 01 len=1 tx=[21] rx=[00]\n"),
            "trace.txt:1: timestamp \"1e999\" is out of range");
}

}  // namespace
}  // namespace l6470emu
