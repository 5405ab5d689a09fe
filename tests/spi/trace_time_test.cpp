// Capture times (spi/trace.hpp): decimal seconds parsed exactly to the picosecond, ticks
// rounded to nearest, negative pre-trigger times, and the fixed-width printing of ticks.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "spi/trace.hpp"

namespace l6470emu {
namespace {

SourceTime parse(const char* s, int unit = 0) {
  SourceTime t;
  EXPECT_TRUE(parse_source_time(s, unit, t)) << s;
  return t;
}

TEST(SourceTime, ParsesDecimalsExactlyToThePicosecond) {
  EXPECT_EQ(parse("1.234567891"), (SourceTime{1, 234'567'891'000}));
  EXPECT_EQ(parse("0.000000000001"), (SourceTime{0, 1}));
  EXPECT_EQ(parse("12345.678901"), (SourceTime{12345, 678'901'000'000}));
  EXPECT_EQ(parse("42"), (SourceTime{42, 0}));
}

TEST(SourceTime, ParsesExponentsAndMicroseconds) {
  EXPECT_EQ(parse("1.2e-05"), (SourceTime{0, 12'000'000}));
  EXPECT_EQ(parse("2E+1"), (SourceTime{20, 0}));
  EXPECT_EQ(parse("1.300000", -6), (SourceTime{0, 1'300'000}));  // sigrok's µs
  EXPECT_EQ(parse("10009.2", -6), (SourceTime{0, 10'009'200'000}));
}

TEST(SourceTime, KeepsNegativeTimesBeforeATrigger) {
  const SourceTime t = parse("-0.25");
  EXPECT_EQ(t, (SourceTime{-1, 750'000'000'000}));
  EXPECT_DOUBLE_EQ(t.to_double(), -0.25);
  EXPECT_LT(t, parse("0"));
}

TEST(SourceTime, RoundsBeyondAPicosecond) {
  EXPECT_EQ(parse("0.0000000000015"), (SourceTime{0, 2}));
  EXPECT_EQ(parse("0.9999999999996"), (SourceTime{1, 0}));
}

TEST(SourceTime, RejectsWhatIsNotANumber) {
  SourceTime t;
  for (const char* bad : {"", "-", ".", "1.2.3", "0x10", "1e", "1e+", "abc", "1 ", "1,5"})
    EXPECT_FALSE(parse_source_time(bad, 0, t)) << bad;
}

TEST(TicksBetween, RoundsToTheNearest250NsTick) {
  Tick t = 0;
  ASSERT_TRUE(ticks_between(parse("1"), parse("1.000000124"), t));
  EXPECT_EQ(t, 0u);
  ASSERT_TRUE(ticks_between(parse("1"), parse("1.000000125"), t));
  EXPECT_EQ(t, 1u);
  ASSERT_TRUE(ticks_between(parse("-0.5"), parse("0.5"), t));
  EXPECT_EQ(t, kTicksPerSecond);
  EXPECT_FALSE(ticks_between(parse("2"), parse("1"), t));
}

TEST(FormatSeconds, PrintsTicksExactlyWithEightDecimals) {
  EXPECT_EQ(format_seconds(0), "0.00000000");
  EXPECT_EQ(format_seconds(1), "0.00000025");
  EXPECT_EQ(format_seconds(4'938'271), "1.23456775");
  EXPECT_EQ(format_microseconds(7), "1.75");
}

TEST(FormatSeconds, GivesEveryTimeAsItsWholeSecondsAndEightDecimals) {
  // The exact text, the long way, against write_seconds' short cuts (below 10 000 s) and its
  // general path: around every carry of the whole seconds and of the decimals, and far out.
  auto expected = [](Tick t) {
    std::string decimals = std::to_string(t % kTicksPerSecond * 25);
    return std::to_string(t / kTicksPerSecond) + "." + std::string(8 - decimals.size(), '0') + decimals;
  };
  std::vector<Tick> ticks;
  for (Tick s : {0ull, 1ull, 9ull, 10ull, 99ull, 100ull, 999ull, 1000ull, 9999ull, 10000ull, 123456ull, 1000000000000ull})
    for (Tick d : {0ull, 1ull, 3ull, 4ull, 39ull, 40ull, 399ull, 400ull, 3999ull, 4000ull, 39999ull, 40000ull, 399999ull,
                   400000ull, 3999999ull})
      ticks.push_back(s * kTicksPerSecond + d);
  for (Tick t = 0; t < 40'000'000'000ull; t = t * 3 + 7) ticks.push_back(t);
  for (const Tick t : ticks) {
    char buf[kMaxTimeChars];
    EXPECT_EQ(std::string(buf, write_seconds(buf, t)), expected(t)) << t;
    EXPECT_EQ(format_seconds(t), expected(t)) << t;
  }
}

TEST(HexBytes, MarksUnknownBytes) {
  const std::uint8_t b[] = {0x0A, 0xFF, 0x12};
  const std::uint8_t known[] = {1, 0, 1};
  EXPECT_EQ(hex_bytes(b), "0A FF 12");
  EXPECT_EQ(hex_bytes(b, known), "0A ?? 12");
}

TEST(SourceTime, TellsANumberOutOfRangeFromOneThatIsMalformed) {
  SourceTime t;
  EXPECT_EQ(parse_source_time_checked("1e308", -6, t), TimeParse::out_of_range);
  EXPECT_EQ(parse_source_time_checked("-1e19", 0, t), TimeParse::out_of_range);
  EXPECT_EQ(parse_source_time_checked("1e9999999", 0, t), TimeParse::out_of_range);
  EXPECT_EQ(parse_source_time_checked("1e9999999x", 0, t), TimeParse::malformed);
  EXPECT_EQ(parse_source_time_checked("nan", 0, t), TimeParse::malformed);
  EXPECT_EQ(parse_source_time_checked(".5", 0, t), TimeParse::ok);
  EXPECT_EQ(t, (SourceTime{0, 500'000'000'000}));
}

TEST(TicksBetween, RefusesSpansTooLongWithoutOverflowing) {
  Tick t = 0;
  EXPECT_FALSE(ticks_between(parse("-9e17"), parse("9e17"), t));
  EXPECT_FALSE(ticks_between(parse("0"), parse("9000001"), t));
  EXPECT_TRUE(ticks_between(parse("0"), parse("9000000"), t));
}

}  // namespace
}  // namespace l6470emu
