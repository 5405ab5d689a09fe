// Recognising a trace file's format from its first bytes (spi/trace_import.cpp), for every fixture.
#include <gtest/gtest.h>

#include "spi/trace_import.hpp"
#include "support/trace_test_support.hpp"

namespace l6470emu {
namespace {

TraceFormat detect(const std::string& name) { return detect_trace_format(test::fixture(name).substr(0, 65536), name); }

TEST(TraceFormatDetection, RecognisesEveryFixture) {
  EXPECT_EQ(detect("three_chips.trace"), TraceFormat::native);
  EXPECT_EQ(detect("saleae_logic2.csv"), TraceFormat::saleae);
  EXPECT_EQ(detect("saleae_logic2_decimal_no_duration.csv"), TraceFormat::saleae);
  EXPECT_EQ(detect("umockdev_spidev.ioctl"), TraceFormat::umockdev);
  EXPECT_EQ(detect("ftrace_spi_set_cs.txt"), TraceFormat::ftrace);
  EXPECT_EQ(detect("ftrace_trace_cmd_report.txt"), TraceFormat::ftrace);
  EXPECT_EQ(detect("sigrok_spi.json"), TraceFormat::sigrok);
  EXPECT_EQ(detect("two_chips.vcd"), TraceFormat::vcd);
}

TEST(TraceFormatDetection, RecognisesLogic1AndUmockdevWithoutHeader) {
  EXPECT_EQ(detect_trace_format("Time [s],Packet ID,MOSI,MISO\n"), TraceFormat::saleae);
  EXPECT_EQ(detect_trace_format("TW d0\n R 00\n"), TraceFormat::umockdev);
  EXPECT_EQ(detect_trace_format("", "capture.sr"), TraceFormat::vcd);
  EXPECT_EQ(detect_trace_format("hello\n"), TraceFormat::unknown);
}

TEST(TraceFormatDetection, NamesFormatsBothWays) {
  for (TraceFormat f : {TraceFormat::native, TraceFormat::saleae, TraceFormat::umockdev, TraceFormat::ftrace,
                        TraceFormat::sigrok, TraceFormat::vcd})
    EXPECT_EQ(trace_format_named(to_string(f)), f);
  EXPECT_EQ(trace_format_named("pcap"), TraceFormat::unknown);
}

TEST(ImportTrace, RefusesALogicCaptureWithoutSigrokAndAnUnknownFormat) {
  EXPECT_THROW(import_trace("$timescale 1 ns $end\n", "x.vcd", TraceFormat::vcd), TraceError);
  try {
    import_trace("?", "x.bin", TraceFormat::unknown);
    FAIL();
  } catch (const TraceError& e) {
    EXPECT_EQ(std::string(e.what()),
              "x.bin: unknown trace format (native, Saleae CSV, umockdev .ioctl, ftrace text, sigrok JSON trace or VCD)");
  }
}

TEST(TraceFormatDetection, SendsDeeplyNestedJsonToTheSigrokReaderWhichRefusesItCleanly) {
  // Whatever the file's name, JSON with "traceEvents" is read as sigrok's trace; 200000 nested
  // arrays once overflowed the stack of the reader.
  const std::string deep = "{\"traceEvents\": [{\"args\": " + std::string(200'000, '[');
  const TraceFormat f = detect_trace_format(deep.substr(0, 65536), "capture.csv");
  ASSERT_EQ(f, TraceFormat::sigrok);
  try {
    import_trace(deep, "capture.csv", f);
    ADD_FAILURE() << "no error";
  } catch (const TraceError& e) {
    EXPECT_STREQ(e.what(), "capture.csv:1: JSON nested deeper than 512 levels (not a sigrok-cli trace)");
  }
}

}  // namespace
}  // namespace l6470emu
