// Saleae Logic SPI analyzer exports (spi/import_saleae.cpp): the Logic 2 table with and
// without duration, hex and decimal, Logic 1.x, captures without an Enable channel, and
// one-line errors for what a truncated or foreign CSV looks like.
#include <gtest/gtest.h>

#include "spi/trace_import.hpp"
#include "support/trace_test_support.hpp"

namespace l6470emu {
namespace {

using Bytes = std::vector<std::uint8_t>;
using test::fixture;

Bytes bytes(std::span<const std::uint8_t> s) { return Bytes(s.begin(), s.end()); }

std::string error_of(const std::string& text) {
  try {
    import_saleae_csv(text, "capture.csv");
  } catch (const TraceError& e) {
    return e.what();
  }
  return "(no error)";
}

const std::string kHeader = "name,type,start_time,duration,\"mosi\",\"miso\"\n";

TEST(SaleaeImport, ReadsTheLogic2FixtureOneFramePerEnableDisablePair) {
  const Trace t = import_saleae_csv(fixture("saleae_logic2.csv"), "saleae_logic2.csv");
  EXPECT_EQ(t.header.format, "saleae");
  ASSERT_EQ(t.frame_count(), 54u);
  EXPECT_EQ(bytes(t[0].mosi), Bytes{0xD0});
  EXPECT_EQ(bytes(t[1].miso), Bytes{0x7C});
  EXPECT_EQ(bytes(t[2].miso), Bytes{0x03});
  EXPECT_EQ(t[0].tick, 0u);                 // ticks count from the first frame
  EXPECT_EQ(t[0].duration, 34u);            // 0.421855200 -> 0.421863700 s = 8.5 µs
  EXPECT_EQ(t[1].tick, 42u);                // 10.5 µs later
  EXPECT_DOUBLE_EQ(t[0].source_time, 0.4218552);  // the capture's own time, for reports
  EXPECT_EQ(t[0].line, 2u);
}

TEST(SaleaeImport, ReadsDecimalValuesAndTheOlderHeaderWithoutDuration) {
  const Trace hex = import_saleae_csv(fixture("saleae_logic2.csv"), "a");
  const Trace dec = import_saleae_csv(fixture("saleae_logic2_decimal_no_duration.csv"), "b");
  ASSERT_EQ(dec.size(), hex.size());
  for (std::size_t i = 0; i < hex.size(); ++i) {
    EXPECT_EQ(bytes(dec[i].mosi), bytes(hex[i].mosi)) << i;
    EXPECT_EQ(bytes(dec[i].miso), bytes(hex[i].miso)) << i;
    EXPECT_EQ(dec[i].tick, hex[i].tick) << i;
  }
}

TEST(SaleaeImport, GroupsSeveralResultsOfOneEnableIntoOneFrame) {
  const Trace t = import_saleae_csv(kHeader +
                                        "\"SPI\",\"enable\",0.5,2e-08,,\n"
                                        "\"SPI\",\"result\",0.5000002,1.6e-06,0xD0,0x00\n"
                                        "\"SPI\",\"result\",0.5000018,1.6e-06,0b11010000,0x7C\n"
                                        "\"SPI\",\"result\",0.5000034,1.6e-06,208,124\n"
                                        "\"SPI\",\"disable\",0.500006,2e-08,,\n",
                                    "c.csv");
  ASSERT_EQ(t.size(), 1u);
  EXPECT_EQ(bytes(t[0].mosi), (Bytes{0xD0, 0xD0, 0xD0}));
  EXPECT_EQ(bytes(t[0].miso), (Bytes{0x00, 0x7C, 0x7C}));
  EXPECT_EQ(t[0].duration, 24u);
}

TEST(SaleaeImport, AcceptsAByteOrderMarkAndWindowsLineEnds) {
  const Trace t = import_saleae_csv("\xEF\xBB\xBFTime [s],Packet ID,MOSI,MISO\r\n0.5,0,0xD0,0x00\r\n", "bom.csv");
  ASSERT_EQ(t.size(), 1u);
  EXPECT_EQ(t[0].mosi[0], 0xD0);
}

TEST(SaleaeImport, TakesEveryByteAsAFrameWithoutAnEnableChannel) {
  const Trace t = import_saleae_csv(kHeader +
                                        "\"SPI\",\"result\",0,0.0000076,0x80,0x00\n"
                                        "\"SPI\",\"result\",0.000009,0.0000076,0xD4,0x00\n",
                                    "noenable.csv");
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(t[1].tick, 36u);
  EXPECT_EQ(t[0].duration, 30u);
  ASSERT_EQ(t.header.notes.size(), 1u);
  EXPECT_NE(t.header.notes[0].find("no enable/disable rows"), std::string::npos);
}

TEST(SaleaeImport, SkipsRowsOfAFrameTheCaptureBeganIn) {
  const Trace t = import_saleae_csv(kHeader +
                                        "\"SPI\",\"result\",0.1,1e-06,0x00,0x12\n"
                                        "\"SPI\",\"disable\",0.2,2e-08,,\n"
                                        "\"SPI\",\"enable\",0.3,2e-08,,\n"
                                        "\"SPI\",\"result\",0.3000001,1e-06,0xD0,0x00\n"
                                        "\"SPI\",\"disable\",0.3000020,2e-08,,\n",
                                    "mid.csv");
  ASSERT_EQ(t.size(), 1u);
  EXPECT_EQ(bytes(t[0].mosi), Bytes{0xD0});
  EXPECT_NE(t.header.notes.back().find("2 rows before the first enable row skipped"), std::string::npos);
}

TEST(SaleaeImport, LeavesMisoUnknownWhenTheColumnIsEmptyOrMissing) {
  const Trace t = import_saleae_csv("name,type,start_time,duration,\"mosi\"\n"
                                    "\"SPI\",\"enable\",0,2e-08,\n\"SPI\",\"result\",0.0000001,1e-06,0xD0\n"
                                    "\"SPI\",\"disable\",0.000002,2e-08,\n",
                                    "mosi-only.csv");
  ASSERT_EQ(t.size(), 1u);
  EXPECT_TRUE(t[0].miso.empty());
  const Trace p = import_saleae_csv(kHeader +
                                        "\"SPI\",\"enable\",0,2e-08,,\n"
                                        "\"SPI\",\"result\",0.0000001,1e-06,0xD0,\n"
                                        "\"SPI\",\"result\",0.0000011,1e-06,0x00,0x7E\n"
                                        "\"SPI\",\"disable\",0.000003,2e-08,,\n",
                                    "partial.csv");
  EXPECT_FALSE(p[0].miso_byte_known(0));
  EXPECT_TRUE(p[0].miso_byte_known(1));
}

TEST(SaleaeImport, ReadsLogic1ExportsFramedByPacketId) {
  const Trace t = import_saleae_csv("Time [s],Packet ID,MOSI,MISO\n"
                                    "4.742270536,0,0xC2,0x00\n4.742271160,0,0x00,0x00\n"
                                    "4.742280000,1,0xD0,0x00\n",
                                    "logic1.csv");
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(bytes(t[0].mosi), (Bytes{0xC2, 0x00}));
}

TEST(SaleaeImport, ChoosesOneAnalyzerWhenTheTableHasSeveral) {
  const std::string two = kHeader +
                          "\"SPI\",\"enable\",0,2e-08,,\n\"SPI 2\",\"enable\",0.0000001,2e-08,,\n";
  EXPECT_EQ(error_of(two), "capture.csv:3: rows of several analyzers (\"SPI\" and \"SPI 2\"): choose one with --select NAME");
  ImportOptions o;
  o.select = "SPI";
  const Trace t = import_saleae_csv(kHeader +
                                        "\"SPI\",\"enable\",0,2e-08,,\n\"SPI 2\",\"result\",0.0000001,1e-06,0x11,0x22\n"
                                        "\"SPI\",\"result\",0.0000002,1e-06,0xD0,0x00\n\"SPI\",\"disable\",0.000002,2e-08,,\n",
                                    "two.csv", o);
  ASSERT_EQ(t.size(), 1u);
  EXPECT_EQ(bytes(t[0].mosi), Bytes{0xD0});
}

TEST(SaleaeImport, ASelectThatMatchesNoAnalyzerNamesTheOnesTheFileHas) {
  ImportOptions o;
  o.select = "SPI 3";
  try {
    import_saleae_csv(kHeader + "\"SPI\",\"enable\",0,2e-08,,\n\"SPI 2\",\"result\",0.0000001,1e-06,0x11,0x22\n", "two.csv", o);
    FAIL() << "no error";
  } catch (const TraceError& e) {
    EXPECT_EQ(std::string(e.what()), "two.csv: no rows of an analyzer called \"SPI 3\" (the file has \"SPI\", \"SPI 2\"): see --select");
  }
}

TEST(SaleaeImport, RejectsBadInputWithOneLineErrors) {
  const std::string open = "\"SPI\",\"enable\",0.1,2e-08,,\n";
  EXPECT_EQ(error_of(kHeader + open + "\"SPI\",\"result\",0.10000001,1e-06,0xD0,0xZZ\n"),
            "capture.csv:3: MISO \"0xZZ\" is not a byte");
  EXPECT_EQ(error_of(kHeader + open + "\"SPI\",\"result\",0.10000001,1e-06,0x1D0,0x00\n"),
            "capture.csv:3: MOSI \"0x1D0\" is not a byte");
  EXPECT_EQ(error_of(kHeader + open + "\"SPI\",\"result\",0.10000001,1e-06,,0x00\n"), "capture.csv:3: MOSI is empty");
  EXPECT_EQ(error_of(kHeader + open + "\"SPI\",\"result\",0.10000001,0xD0,0x00\n"),
            "capture.csv:3: 5 fields, the header has 6 (name,type,start_time,duration,\"mosi\",\"miso\")");
  EXPECT_EQ(error_of(kHeader + open + "\"SPI\",\"result\",soon,1e-06,0xD0,0x00\n"),
            "capture.csv:3: start_time \"soon\" is not a time in seconds");
  EXPECT_EQ(error_of(kHeader + open + "\"SPI\",\"result\",0.10000001,1e-06,0xD0,0x00\n\"SPI\",\"res"),
            "capture.csv:4: unterminated quote in the row \"SPI\",\"res (the last line has no newline: truncated file?)");
  EXPECT_EQ(error_of(kHeader + open + "\"SPI\",\"result\",0.10000001,1e-06,0xD0,0x00\n\"SPI\",\"result\",0.1"),
            "capture.csv:4: 3 fields, the header has 6 (name,type,start_time,duration,\"mosi\",\"miso\") "
            "(the last line has no newline: truncated file?)");
  EXPECT_EQ(error_of(kHeader + open + "\"SPI\",\"result\",0.10000001,1e-06,0xD0,0x00\n"),
            "capture.csv:2: this enable row has no disable row after it: truncated file? (cut the capture before "
            "this row)");
  EXPECT_EQ(error_of(kHeader + open + "\"SPI\",\"disable\",0.2,2e-08,,\n" + "\"SPI\",\"enable\",0.15,2e-08,,\n" +
                     "\"SPI\",\"disable\",0.16,2e-08,,\n"),
            "capture.csv:4: frame at 0.15 s begins before the previous one ended (0.2 s)");
  EXPECT_EQ(error_of(kHeader + open + "\"SPI\",\"disable\",0.2,2e-08,,\n" + "\"SPI\",\"enable\",0.05,2e-08,,\n" +
                     "\"SPI\",\"disable\",0.06,2e-08,,\n"),
            "capture.csv:4: time 0.05 s goes backwards (the previous frame began at 0.1 s)");
  EXPECT_EQ(error_of(kHeader + open + "\"SPI\",\"result\",0.09,1e-06,0xD0,0x00\n"),
            "capture.csv:3: time 0.09 s goes backwards (the frame began at 0.1 s)");
  EXPECT_EQ(error_of(kHeader + open + open), "capture.csv:3: enable row while the frame opened on line 2 is still open");
  EXPECT_EQ(error_of("a,b,c\n1,2,3\n"),
            "capture.csv:1: not a Saleae SPI analyzer export: the header \"a,b,c\" lacks type and start_time (expected "
            "name,type,start_time,duration,\"mosi\",\"miso\")");
  EXPECT_EQ(error_of("name,type,start_time,duration,\"miso\"\n"),
            "capture.csv:1: no \"mosi\" column in the header \"name,type,start_time,duration,\"miso\"\" (export the "
            "SPI analyzer with MOSI enabled)");
  EXPECT_EQ(error_of(kHeader + open + "\"SPI\",\"blink\",0.2,2e-08,,\n"),
            "capture.csv:3: unknown row type \"blink\" (enable, result, disable or error)");
  EXPECT_EQ(error_of(""), "capture.csv: empty file (expected a Saleae CSV export)");
  EXPECT_EQ(error_of(kHeader), "capture.csv: no SPI frames in the file");
}

TEST(SaleaeImport, RefusesANegativeDuration) {
  const std::string open = "\"SPI\",\"enable\",0.1,2e-08,,\n";
  EXPECT_EQ(error_of(kHeader + open + "\"SPI\",\"result\",0.10000001,-1,0xD0,0x00\n"),
            "capture.csv:3: duration \"-1\" is negative");
  EXPECT_EQ(error_of(kHeader + "\"SPI\",\"result\",0.1,-1e-06,0xD0,0x00\n"), "capture.csv:2: duration \"-1e-06\" is negative");
  EXPECT_EQ(error_of(kHeader + open + "\"SPI\",\"result\",0.10000001,1e300,0xD0,0x00\n"),
            "capture.csv:3: duration \"1e300\" is out of range");
}

TEST(SaleaeImport, AcceptsTimesWithALeadingDotAsSaleaeWritesThem) {
  const Trace t = import_saleae_csv(kHeader +
                                        "\"SPI\",\"enable\",.5,2e-08,,\n"
                                        "\"SPI\",\"result\",.5000002,1.6e-06,0xD0,0x00\n"
                                        "\"SPI\",\"disable\",.500006,.00000002,,\n",
                                    "dot.csv");
  ASSERT_EQ(t.frame_count(), 1u);
  EXPECT_DOUBLE_EQ(t[0].source_time, 0.5);
  EXPECT_EQ(t[0].duration, 24u);  // 6 µs
  const Trace logic1 = import_saleae_csv("Time [s],Packet ID,MOSI,MISO\n.25,0,0xD0,0x00\n", "l1.csv");
  EXPECT_DOUBLE_EQ(logic1[0].source_time, 0.25);
}

TEST(SaleaeImport, QuotesAHugeBadValueShortAndEscaped) {
  const std::string open = "\"SPI\",\"enable\",0.1,2e-08,,\n";
  const std::string huge(5'000'000, 'Z');
  const std::string e = error_of(kHeader + open + "\"SPI\",\"result\",0.10000001,1e-06,0x" + huge + ",0x00\n");
  EXPECT_LT(e.size(), 200u);
  EXPECT_EQ(e, "capture.csv:3: MOSI \"0x" + std::string(58, 'Z') + "\u2026\" is not a byte");
  // A line longer than any trace needs is refused as such.
  EXPECT_EQ(error_of(kHeader + open + "\"SPI\",\"result\",0.10000001,1e-06,0x" + huge + huge + ",0x00\n"),
            "capture.csv:3: a line longer than 8388608 bytes (a frame holds at most 1048576 bytes: not a trace, or a "
            "damaged one)");
  EXPECT_EQ(error_of(kHeader + open + "\"SPI\",\"result\",0.10000001,1e-06,0x\x1b[2J\x07,0x00\n"),
            "capture.csv:3: MOSI \"0x\\x1B[2J\\x07\" is not a byte");
}

}  // namespace
}  // namespace l6470emu
