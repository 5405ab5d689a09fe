// The emulated CP2112 bridge's reports, as Linux's hid-cp2112 driver sends them: probing,
// direction changes, reads of the chip's outputs and writes that reach the chip's inputs.
#include <gtest/gtest.h>

#include <map>
#include <vector>

#include "linux/kernel/cp2112_reports.hpp"

namespace l6470emu::test {
namespace {

struct FakeChip {
  // DIR reads high as the board reads the DIR of a chip without one (an L6470).
  std::map<Pin, bool> level{{Pin::BUSY, true},      {Pin::FLAG, true}, {Pin::SW, true}, {Pin::STCK, false},
                            {Pin::STBY_RST, true}, {Pin::DIR, true}};
  std::vector<std::pair<Pin, bool>> driven;
  Cp2112Pins pins() {
    return {[this](Pin p) { return level[p]; }, [this](Pin p, bool v) {
              driven.emplace_back(p, v);
              level[p] = v;
            }};
  }
};

TEST(Cp2112Reports, ProbingFindsAVersionAnSmbusConfigAndALockByteOfTheSizesTheDriverChecks) {
  FakeChip chip;
  Cp2112Reports r(chip.pins(), "chip 0", "serial");
  EXPECT_EQ(r.get(0x05).size(), 3u);
  EXPECT_EQ(r.get(0x06).size(), 14u) << "sizeof(struct cp2112_smbus_config_report)";
  EXPECT_EQ(r.get(0x20).size(), 2u);
  std::vector<std::uint8_t> config = r.get(0x06);
  config[12] = 0;
  config[13] = 1;  // retry_time = 1, as the driver writes it back
  EXPECT_EQ(r.set(config), 0);
  EXPECT_EQ(r.get(0x06), config);
}

TEST(Cp2112Reports, InputsReadTheChipsLevelsAndUnusedPinsReadHigh) {
  FakeChip chip;
  Cp2112Reports r(chip.pins(), "chip 0", "serial");
  chip.level[Pin::BUSY] = false;  // a move in progress
  const std::vector<std::uint8_t> got = r.get(0x03);
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[0], 0x03);
  EXPECT_EQ(got[1] & 0x01, 0) << "BUSY low";
  EXPECT_EQ(got[1] & 0x02, 0x02) << "FLAG high";
  EXPECT_EQ(got[1] & 0xE0, 0xE0) << "DIR (pin 5) high, pins 6 and 7 unused";
  chip.level[Pin::DIR] = false;  // an L6474 whose DIR is driven low
  EXPECT_EQ(r.get(0x03)[1] & 0x20, 0);
}

TEST(Cp2112Reports, AnOutputTheHostDrivesReachesTheChipAndReadsBack) {
  FakeChip chip;
  Cp2112Reports r(chip.pins(), "chip 0", "serial");
  // direction_output(SW): read the config, set the bit, write it; then set the value.
  std::vector<std::uint8_t> config = r.get(0x02);
  config[1] |= 1u << 2;
  config[2] = 0xFF;
  EXPECT_EQ(r.set(config), 0);
  EXPECT_EQ(r.set(std::vector<std::uint8_t>{0x04, 0x00, 1u << 2}), 0);
  ASSERT_EQ(chip.driven.size(), 1u);
  EXPECT_EQ(chip.driven[0], std::make_pair(Pin::SW, false));
  EXPECT_EQ(r.get(0x03)[1] & 0x04, 0) << "the latch reads back";
}

TEST(Cp2112Reports, WritesToPinsTheHostDoesNotDriveOrTheChipDrivesGoNowhere) {
  FakeChip chip;
  Cp2112Reports r(chip.pins(), "chip 0", "serial");
  EXPECT_EQ(r.set(std::vector<std::uint8_t>{0x04, 0x00, 0xFF}), 0);  // every pin still an input
  EXPECT_TRUE(chip.driven.empty());
  EXPECT_EQ(r.set(std::vector<std::uint8_t>{0x02, 0xFF, 0xFF, 0x00, 0x00}), 0);
  EXPECT_EQ(r.set(std::vector<std::uint8_t>{0x04, 0x00, 0x03}), 0);  // BUSY and FLAG: the chip's outputs
  EXPECT_TRUE(chip.driven.empty());
}

TEST(Cp2112Reports, SmbusTransfersFailAtOnceAndUnknownReportsAreErrors) {
  FakeChip chip;
  Cp2112Reports r(chip.pins(), "chip 0", "serial");
  EXPECT_EQ(r.output(std::vector<std::uint8_t>{0x15, 0x01})[1], 0x03) << "status: error";
  EXPECT_TRUE(r.get(0x42).empty());
  EXPECT_NE(r.set(std::vector<std::uint8_t>{0x42}), 0);
  EXPECT_NE(r.set(std::vector<std::uint8_t>{0x04, 0x00}), 0) << "too short";
}

TEST(Cp2112Reports, TheDescriptorDeclaresEveryReportInOneVendorCollection) {
  const std::vector<std::uint8_t> d = Cp2112Reports::descriptor();
  EXPECT_EQ(d.front(), 0x06);
  EXPECT_EQ(d.back(), 0xC0);
  int ids = 0;
  for (std::size_t i = 0; i + 1 < d.size(); ++i)
    if (d[i] == 0x85) ++ids;
  EXPECT_EQ(ids, 18);
}

}  // namespace
}  // namespace l6470emu::test
