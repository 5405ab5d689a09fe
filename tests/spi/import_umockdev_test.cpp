// umockdev SPI .ioctl recordings (spi/import_umockdev.cpp): T starts a CS frame, C keeps
// CS asserted, W/R parts, read-only transfers send zeros, made-up timing, and errors.
#include <gtest/gtest.h>

#include <cmath>

#include "spi/trace_import.hpp"
#include "support/trace_test_support.hpp"

namespace l6470emu {
namespace {

using Bytes = std::vector<std::uint8_t>;

Bytes bytes(std::span<const std::uint8_t> s) { return Bytes(s.begin(), s.end()); }

std::string error_of(const std::string& text) {
  try {
    import_umockdev_ioctl(text, "rec.ioctl");
  } catch (const TraceError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(UmockdevImport, ReadsTheFixtureWithReadOnlyTransfersAsZerosOut) {
  const Trace t = import_umockdev_ioctl(test::fixture("umockdev_spidev.ioctl"), "umockdev_spidev.ioctl");
  EXPECT_EQ(t.header.format, "umockdev");
  ASSERT_EQ(t.frame_count(), 54u);
  EXPECT_EQ(bytes(t[0].mosi), Bytes{0xD0});
  EXPECT_EQ(bytes(t[0].miso), Bytes{0x00});
  EXPECT_EQ(bytes(t[1].mosi), Bytes{0x00});  // "TR 7c": nothing written, zeros clocked out
  EXPECT_EQ(bytes(t[1].miso), Bytes{0x7C});
  EXPECT_EQ(t[1].line, 4u);
  EXPECT_TRUE(std::isnan(t[0].source_time));  // umockdev has no times
}

TEST(UmockdevImport, SpacesFramesAsOnTheBusItAssumes) {
  const Trace t = import_umockdev_ioctl("@DEV /dev/spidev0.0 (SPI)\nTW d000\n R 0000\nTW 21\n", "a");
  EXPECT_EQ(t[0].tick, 0u);
  EXPECT_EQ(t[0].duration, 14u);  // 2 bytes at 5 MHz: 7 ticks each
  EXPECT_EQ(t[1].tick, 18u);      // + 1 µs of CS high
  EXPECT_TRUE(t[1].miso.empty()); // write-only: nothing to compare
}

TEST(UmockdevImport, KeepsCsAssertedAcrossAContinuation) {
  const Trace t = import_umockdev_ioctl("@DEV /dev/spidev0.0 (SPI)\nTW 03ff\nCR 81\nTW 31\n", "c");
  ASSERT_EQ(t.size(), 2u);
  EXPECT_EQ(bytes(t[0].mosi), (Bytes{0x03, 0xFF, 0x00}));
  EXPECT_FALSE(t[0].miso_byte_known(0));
  EXPECT_FALSE(t[0].miso_byte_known(1));
  EXPECT_TRUE(t[0].miso_byte_known(2));
  EXPECT_EQ(t[0].miso[2], 0x81);
}

TEST(UmockdevImport, RejectsBadInputWithOneLineErrors) {
  const std::string dev = "@DEV /dev/spidev0.0 (SPI)\n";
  EXPECT_EQ(error_of(dev + "TW d000\n R 00\n"),
            "rec.ioctl:3: W has 2 bytes but R has 1 (read and write of one transfer must have the same length)");
  EXPECT_EQ(error_of(dev + "TW d0z0\n"), "rec.ioctl:2: W byte \"z0\" is not hex");
  EXPECT_EQ(error_of(dev + "TW d00\n"), "rec.ioctl:2: odd number of hex digits in \"d00\"");
  EXPECT_EQ(error_of(dev + "CR 81\n"), "rec.ioctl:2: \"C\" (CS kept asserted) without a transfer before it");
  EXPECT_EQ(error_of(dev + "TX 81\n"), "rec.ioctl:2: transfer direction \"X\" is not W or R");
  EXPECT_EQ(error_of(dev + "TW d0\nTW 0"),
            "rec.ioctl:3: odd number of hex digits in \"0\" (the last line has no newline: truncated file?)");
  EXPECT_EQ(error_of("@DEV /dev/hidraw0\nTW 00\n"), "rec.ioctl:1: device \"/dev/hidraw0\" is not recorded as SPI (no \"(SPI)\" after @DEV)");
  EXPECT_EQ(error_of(dev), "rec.ioctl: no SPI transfers in the file");
}

}  // namespace
}  // namespace l6470emu
