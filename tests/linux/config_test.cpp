// The board description parser and the spidev rules, without any process or file.
#include <gtest/gtest.h>

#include <cerrno>

#include "linux/config.hpp"
#include "linux/spidev_rules.hpp"

namespace l6470emu {
namespace {

TEST(BoardConfig, ParsesChainsVariantsAndGlobals) {
  const auto r = parse_board_config("bus=0 cs=1 chips=2xL6470,L6480 speed=2000000 mode=3; time=virtual\n# comment\nbus=1 chips=L6470*2 gpiochip=none",
                                    "test");
  ASSERT_TRUE(r.config) << r.error.message;
  const BoardConfig& c = *r.config;
  ASSERT_EQ(c.chains.size(), 2u);
  EXPECT_EQ(c.chains[0].path, "/dev/spidev0.1");
  ASSERT_EQ(c.chains[0].chips.size(), 3u);
  EXPECT_EQ(c.chains[0].chips[2]->name, "L6480");
  EXPECT_EQ(c.chains[0].max_speed_hz, 2000000u);
  EXPECT_EQ(c.chains[0].gpiochip, 0u);
  EXPECT_EQ(c.chains[1].chips.size(), 2u);
  EXPECT_FALSE(c.chains[1].gpiochip);
  EXPECT_TRUE(c.time.virtual_time);
}

TEST(BoardConfig, ErrorsNameTheClauseAndTheProblem) {
  auto r = parse_board_config("bus=0 chips=L6470; bus=0 chips=L6470", "X");
  ASSERT_FALSE(r.config);
  EXPECT_EQ(r.error.message, "l6470emu: config X, clause 2: two chains on /dev/spidev0.0");
  r = parse_board_config("bus=0 chips=300xL6470", "X");
  ASSERT_FALSE(r.config);
  EXPECT_NE(r.error.message.find("unknown chip variant"), std::string::npos);
  r = parse_board_config("", "X");
  EXPECT_FALSE(r.config);
  r = parse_board_config("scale=-1 ; bus=0 chips=L6470", "X");
  EXPECT_FALSE(r.config);
}

TEST(SpidevRules, SettingsFollowTheKernel) {
  SpidevSettings s;
  s.max_speed_hz = s.speed_hz = 5000000;
  std::uint32_t v = SPI_MODE_3;
  EXPECT_EQ(spidev_settings_ioctl(s, SPI_IOC_WR_MODE, v), 0);
  v = SPI_3WIRE;
  EXPECT_EQ(spidev_settings_ioctl(s, SPI_IOC_WR_MODE32, v), -EINVAL);
  v = SPI_MODE_3 | SPI_TX_DUAL;  // dual/quad bits are dropped silently
  EXPECT_EQ(spidev_settings_ioctl(s, SPI_IOC_WR_MODE32, v), 0);
  EXPECT_EQ(spidev_settings_ioctl(s, SPI_IOC_RD_MODE32, v), 0);
  EXPECT_EQ(v, std::uint32_t{SPI_MODE_3});
  v = 0;
  EXPECT_EQ(spidev_settings_ioctl(s, SPI_IOC_WR_BITS_PER_WORD, v), 0);
  EXPECT_EQ(s.bits_per_word, 8);
  v = 12;
  EXPECT_EQ(spidev_settings_ioctl(s, SPI_IOC_WR_BITS_PER_WORD, v), -EINVAL);
  v = 200000000;  // kept as asked, clamped per transfer
  EXPECT_EQ(spidev_settings_ioctl(s, SPI_IOC_WR_MAX_SPEED_HZ, v), 0);
  EXPECT_EQ(spidev_settings_ioctl(s, SPI_IOC_RD_MAX_SPEED_HZ, v), 0);
  EXPECT_EQ(v, 200000000u);
}

TEST(SpidevRules, MessageLimitsAreTheBounceBuffers) {
  SpidevSettings s;
  spi_ioc_transfer x[2] = {};
  x[0].tx_buf = 1;
  x[0].len = 4096;
  EXPECT_EQ(validate_spidev_message(s, std::span(x, 1)), 4096);
  x[1].tx_buf = 1;
  x[1].len = 1;
  EXPECT_EQ(validate_spidev_message(s, std::span(x, 2)), -EMSGSIZE);
  x[0].len = 4088;  // 4088 + align8(1) = 4096: fits
  EXPECT_EQ(validate_spidev_message(s, std::span(x, 2)), 4089);
}

}  // namespace
}  // namespace l6470emu
