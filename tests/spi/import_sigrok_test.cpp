// sigrok-cli's JSON trace of its spi decoder (spi/import_sigrok.cpp): CS frames from the
// transfer annotations, bytes alone without a cs channel, and one-line errors.
#include <gtest/gtest.h>

#include "spi/trace_import.hpp"
#include "support/trace_test_support.hpp"

namespace l6470emu {
namespace {

using Bytes = std::vector<std::uint8_t>;

Bytes bytes(std::span<const std::uint8_t> s) { return Bytes(s.begin(), s.end()); }

std::string ev(const char* ph, double ts, const char* tid, const char* name) {
  char buf[200];
  std::snprintf(buf, sizeof buf, "{\"ph\": \"%s\", \"ts\": %f, \"pid\": \"spi-1\", \"tid\": \"%s\", \"name\": \"%s\"}", ph, ts,
                tid, name);
  return buf;
}

std::string doc(const std::vector<std::string>& events) {
  std::string s = "{\"traceEvents\": [\n";
  for (std::size_t i = 0; i < events.size(); ++i) s += events[i] + (i + 1 < events.size() ? ",\n" : "\n");
  return s + "]}\n";
}

std::string error_of(const std::string& text) {
  try {
    import_sigrok_json(text, "spi.json");
  } catch (const TraceError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(SigrokImport, ReadsTheTransferAnnotationsOfTheFixture) {
  // fixtures/traces/sigrok_spi.json is sigrok-cli's own output for two_chips.vcd.
  const Trace t = import_sigrok_json(test::fixture("sigrok_spi.json"), "sigrok_spi.json");
  EXPECT_EQ(t.header.format, "sigrok");
  ASSERT_EQ(t.frame_count(), 17u);
  EXPECT_EQ(bytes(t[0].mosi), (Bytes{0xD0, 0xD0}));
  EXPECT_EQ(bytes(t[1].miso), (Bytes{0x7C, 0x7C}));
  EXPECT_EQ(t[0].tick, 0u);
  EXPECT_GT(t[0].line, 1u);
}

TEST(SigrokImport, TakesEachByteAsAFrameWithoutTransferAnnotations) {
  const Trace t = import_sigrok_json(doc({ev("B", 1.3, "MOSI data", "21"), ev("E", 2.9, "MOSI data", "21"),
                                          ev("B", 1.3, "MISO data", "00"), ev("E", 2.9, "MISO data", "00"),
                                          ev("B", 5.9, "MOSI data", "00"), ev("E", 7.5, "MOSI data", "00")}),
                                     "d.json");
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(t[1].tick, 18u);  // 4.6 µs later
  EXPECT_TRUE(t[1].miso.empty());
  EXPECT_NE(t.header.notes[0].find("no MOSI/MISO transfer annotations"), std::string::npos);
}

TEST(SigrokImport, RejectsBadInputWithOneLineErrors) {
  EXPECT_EQ(error_of(doc({ev("B", 1.0, "MOSI transfer", "21 D0"), ev("E", 4.6, "MOSI transfer", "21 D0"),
                          ev("B", 1.0, "MISO transfer", "00"), ev("E", 4.6, "MISO transfer", "00")})),
            "spi.json:4: MOSI has 2 bytes but MISO has 1 in the frame at 0.000001 s");
  EXPECT_EQ(error_of(doc({ev("B", 9.0, "MOSI transfer", "21"), ev("E", 10.0, "MOSI transfer", "21"),
                          ev("B", 1.0, "MOSI transfer", "00"), ev("E", 2.0, "MOSI transfer", "00")})),
            "spi.json:4: time 0.000001 s goes backwards (the previous frame began at 0.000009 s)");
  EXPECT_EQ(error_of(doc({ev("B", 1.0, "MOSI transfer", "2100"), ev("E", 2.0, "MOSI transfer", "2100")})),
            "spi.json:2: MOSI \"2100\" is not a byte (set the spi decoder to 8-bit words)");
  EXPECT_EQ(error_of("{\"traceEvents\": [\n" + ev("B", 1.0, "MOSI transfer", "21") + ",\n{\"ph\": \"E\", \"ts\": 2."),
            "spi.json:3: unexpected end of file, expected ',' (truncated file?)");
  EXPECT_EQ(error_of("1750-5750 spi-1: 21\n"),
            "spi.json:1: not JSON (expected sigrok-cli --protocol-decoder-jsontrace output, which starts with '{')");
  EXPECT_EQ(error_of(doc({})), "spi.json: no spi decoder annotations (run sigrok-cli -P spi:...:cs=CS --protocol-decoder-jsontrace)");
}

TEST(SigrokImport, RefusesATimestampOutOfRange) {
  EXPECT_EQ(error_of(doc({"{\"ph\": \"B\", \"ts\": 1e308, \"pid\": \"spi-1\", \"tid\": \"MOSI transfer\", \"name\": \"21\"}",
                          "{\"ph\": \"E\", \"ts\": 1e308, \"pid\": \"spi-1\", \"tid\": \"MOSI transfer\", \"name\": \"21\"}"})),
            "spi.json:2: \"ts\" \"1e308\" is out of range (a time in microseconds)");
  // Beyond a double: nlohmann-json's own overflow error, still with the line.
  EXPECT_EQ(error_of("{\"traceEvents\": [\n{\"ph\": \"B\", \"ts\": 1e999}]}"), "spi.json:2: number \"1e999\" is out of range");
}

TEST(SigrokImport, RefusesDeepNestingWithAnErrorInsteadOfACrash) {
  // 200000 nested arrays crashed the recursive reader before nlohmann-json's SAX parser.
  EXPECT_EQ(error_of("{\"traceEvents\": [{\"args\": " + std::string(200'000, '[')),
            "spi.json:1: JSON nested deeper than 512 levels (not a sigrok-cli trace)");
  EXPECT_EQ(error_of(std::string(200'000, '[') + std::string(200'000, ']')),
            "spi.json:1: the array of events holds something other than event objects");
  // Nesting a real trace has (and a little more in "args") is fine.
  std::string nested = "{\"traceEvents\": [{\"ph\": \"B\", \"ts\": 1, \"pid\": \"spi-1\", \"tid\": \"MOSI data\", "
                       "\"name\": \"21\", \"args\": " + std::string(400, '[') + std::string(400, ']') + "}, " +
                       ev("E", 2.0, "MOSI data", "21") + "]}";
  EXPECT_EQ(import_sigrok_json(nested, "n.json").frame_count(), 1u);
}

TEST(SigrokImport, NamesTheLineOfASyntaxErrorFromItsByteOffset) {
  EXPECT_EQ(error_of("{\"traceEvents\": [\n" + ev("B", 1.0, "MOSI transfer", "21") + ",\n\n{\"ph\" \"E\"}]}"),
            "spi.json:4: malformed JSON: unexpected string literal; expected ':' at \"\"E\"\"");
  EXPECT_EQ(error_of("{\"traceEvents\": [\n{\"ph\": \"B\",\n\"ts\": \"1.0\"}]}"), "spi.json:3: \"ts\" must be a number");
  EXPECT_EQ(error_of("{\"traceEvents\": [\n{\"ph\": 1}]}"), "spi.json:2: \"ph\" must be a string");
  EXPECT_EQ(error_of("{\"traceEvents\": {}}"), "spi.json:1: \"traceEvents\" must be an array of events");
  EXPECT_EQ(error_of("{\"other\": []}"),
            "spi.json: no \"traceEvents\" array (expected sigrok-cli --protocol-decoder-jsontrace output)");
  EXPECT_EQ(error_of("{\"traceEvents\": [\n\"x\"]}"), "spi.json:2: \"traceEvents\" holds something other than event objects");
  EXPECT_EQ(error_of("{\"traceEvents\": []}\n\n[]"), "spi.json:3: malformed JSON: unexpected '['; expected end of input");
}

TEST(SigrokImport, SaysWhatATruncatedFileWasCutShortIn) {
  const std::string head = "{\"traceEvents\": [\n" + ev("B", 1.0, "MOSI transfer", "21");
  EXPECT_EQ(error_of(head), "spi.json:2: unexpected end of file, expected ',' (truncated file?)");
  EXPECT_EQ(error_of(head + ",\n"), "spi.json:3: unexpected end of file, expected a value (truncated file?)");
  EXPECT_EQ(error_of(head + ",\n{\"ph\""), "spi.json:3: unexpected end of file, expected ':' (truncated file?)");
  EXPECT_EQ(error_of(head + ",\n{\"ph\": \"E"), "spi.json:3: unterminated string (truncated file?)");
  EXPECT_EQ(error_of(head + ",\n{"), "spi.json:3: unexpected end of file, expected '\"' (truncated file?)");
}

}  // namespace
}  // namespace l6470emu
