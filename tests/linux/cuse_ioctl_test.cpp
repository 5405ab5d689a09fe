// The spidev ioctls as the CUSE node answers them, driven in process by a stand-in for the
// kernel's fuse ioctl path (fs/fuse/ioctl.c): each retry's ranges are copied from this
// process's memory and the final bytes scattered over the out ranges, as the kernel does for a
// client. The node must give the same answers as the preload's path, with spidev's errors.
#include <gtest/gtest.h>
#include <linux/spi/spidev.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <vector>

#include "linux/device_board.hpp"
#include "linux/kernel/cuse_ioctl.hpp"
#include "support/board_config_support.hpp"

namespace l6470emu::test {
namespace {

/// A virtual-time board (messages take no wall time) with one spidev file open.
struct Node {
  DiagnosticLog log{"off"};
  DeviceBoard board;
  NewFile file;
  std::vector<CuseIoctlStep> steps;  // every reply of the last ioctl

  explicit Node(const std::string& text = "bus=0 cs=0 chips=3xL6470 mode=3; time=virtual")
      : board(config_of(text), log) {
    file = board.open(board.spidev_node(0), true);
  }
  ~Node() { ::close(file.fd); }

  /// What a client's ioctl(fd, cmd, arg) returns through the kernel's retry loop.
  long ioctl(unsigned long cmd, void* arg, const CuseLimits& limits = {}) {
    steps.clear();
    std::vector<std::uint8_t> in;
    std::vector<CuseRange> out;
    std::size_t out_size = 0;
    for (int calls = 0; calls < 8; ++calls) {
      CuseIoctlStep s = spidev_cuse_ioctl(board, file.handle, 4096, cmd, reinterpret_cast<std::uintptr_t>(arg), in,
                                          out_size, limits);
      steps.push_back(s);
      if (!s.retry) {
        if (s.result < 0) return s.result;
        std::size_t at = 0;
        for (const CuseRange& r : out) {
          const std::size_t n = std::min(r.len, s.data.size() - at);
          std::memcpy(reinterpret_cast<void*>(static_cast<std::uintptr_t>(r.base)), s.data.data() + at, n);
          at += n;
        }
        return s.result;
      }
      in.clear();
      out = s.out;
      out_size = 0;
      for (const CuseRange& r : s.in) {
        const auto* p = reinterpret_cast<const std::uint8_t*>(static_cast<std::uintptr_t>(r.base));
        in.insert(in.end(), p, p + r.len);
      }
      for (const CuseRange& r : s.out) out_size += r.len;
    }
    ADD_FAILURE() << "the handler asked for more than 8 calls";
    return -ELOOP;
  }
};

spi_ioc_transfer transfer(const void* tx, void* rx, std::uint32_t len, bool cs_change = false) {
  spi_ioc_transfer x{};
  x.tx_buf = reinterpret_cast<std::uintptr_t>(tx);
  x.rx_buf = reinterpret_cast<std::uintptr_t>(rx);
  x.len = len;
  x.cs_change = cs_change;
  return x;
}

TEST(CuseSpidevIoctl, AGetStatusOfAThreeChipChainAnswersAsThePreloadPathDoes) {
  // GetStatus to every chip: three frames of three bytes, one byte per chip.
  const std::uint8_t tx[9] = {0xD0, 0xD0, 0xD0, 0, 0, 0, 0, 0, 0};
  std::uint8_t rx[9] = {};
  spi_ioc_transfer x[3] = {transfer(tx, rx, 3, true), transfer(tx + 3, rx + 3, 3, true), transfer(tx + 6, rx + 6, 3)};
  Node cuse;
  EXPECT_EQ(cuse.ioctl(SPI_IOC_MESSAGE(3), x), 9);
  EXPECT_EQ(cuse.steps.size(), 3u) << "nothing, then the array, then the array and the tx data";

  Node preload;
  std::vector<std::uint8_t> rx2(9);
  EXPECT_EQ(preload.board.spi_message(preload.file.handle, x, tx, rx2), 9);
  EXPECT_EQ(std::vector<std::uint8_t>(rx, rx + 9), rx2);
  EXPECT_EQ(rx[3], 0x7C) << "STATUS high byte of chip 0 after power-up";
}

TEST(CuseSpidevIoctl, AsksForTheArrayThenEveryTxBufferAndScattersTheRxBuffers) {
  const std::uint8_t a[2] = {0x00, 0x00}, b[1] = {0x00};
  std::uint8_t ra[2] = {}, rb[1] = {};
  spi_ioc_transfer x[2] = {transfer(a, ra, 2), transfer(b, rb, 1)};
  Node n;
  EXPECT_EQ(n.ioctl(SPI_IOC_MESSAGE(2), x), 3);
  ASSERT_EQ(n.steps.size(), 3u);
  EXPECT_EQ(n.steps[0].in, (std::vector<CuseRange>{{reinterpret_cast<std::uintptr_t>(x), sizeof x}}));
  EXPECT_TRUE(n.steps[0].out.empty());
  EXPECT_EQ(n.steps[1].in, (std::vector<CuseRange>{{reinterpret_cast<std::uintptr_t>(x), sizeof x},
                                                    {reinterpret_cast<std::uintptr_t>(a), 2},
                                                    {reinterpret_cast<std::uintptr_t>(b), 1}}));
  EXPECT_EQ(n.steps[1].out, (std::vector<CuseRange>{{reinterpret_cast<std::uintptr_t>(ra), 2},
                                                     {reinterpret_cast<std::uintptr_t>(rb), 1}}));
  EXPECT_EQ(n.steps[2].data.size(), 3u);
}

TEST(CuseSpidevIoctl, ARxOnlyMessageStillTakesThreeCalls) {
  std::uint8_t rx[4];
  std::memset(rx, 0xEE, sizeof rx);
  spi_ioc_transfer x[1] = {transfer(nullptr, rx, 4)};
  Node n("bus=0 cs=0 chips=L6470 mode=3; time=virtual");
  EXPECT_EQ(n.ioctl(SPI_IOC_MESSAGE(1), x), 4);
  EXPECT_EQ(n.steps.size(), 3u);
  EXPECT_NE(rx[0], 0xEE) << "the rx data was scattered";
}

TEST(CuseSpidevIoctl, ABufferlessMessageRunsOnceTheArrayIsIn) {
  spi_ioc_transfer x[1] = {transfer(nullptr, nullptr, 100)};
  Node n;
  EXPECT_EQ(n.ioctl(SPI_IOC_MESSAGE(1), x), 100);
  EXPECT_EQ(n.steps.size(), 2u);
}

TEST(CuseSpidevIoctl, MessageOfZeroTransfersReturnsZeroWithoutReadingMemory) {
  Node n;
  EXPECT_EQ(n.ioctl(SPI_IOC_MESSAGE(0), nullptr), 0);
  EXPECT_EQ(n.steps.size(), 1u);
}

TEST(CuseSpidevIoctl, PastBufsizIsEmsgsizeBeforeAnyTxDataIsFetched) {
  static std::uint8_t big[5000];
  spi_ioc_transfer x[1] = {transfer(big, nullptr, sizeof big)};
  Node n;
  EXPECT_EQ(n.ioctl(SPI_IOC_MESSAGE(1), x), -EMSGSIZE);
  ASSERT_EQ(n.steps.size(), 2u);
  EXPECT_EQ(n.steps[0].in.size(), 1u) << "only the array was asked for";
}

TEST(CuseSpidevIoctl, WordSizesTheControllerCannotDoAreEinval) {
  const std::uint8_t tx[3] = {};
  spi_ioc_transfer x[1] = {transfer(tx, nullptr, 3)};
  x[0].bits_per_word = 16;
  Node n;
  EXPECT_EQ(n.ioctl(SPI_IOC_MESSAGE(1), x), -EINVAL);
}

TEST(CuseSpidevIoctl, MoreRangesThanOneRetryCarriesIsEnomem) {
  static std::uint8_t bytes[300];
  std::vector<spi_ioc_transfer> x;
  for (int i = 0; i < 300; ++i) x.push_back(transfer(bytes + i, nullptr, 1));
  Node n;
  EXPECT_EQ(n.ioctl(SPI_IOC_MESSAGE(300), x.data()), -ENOMEM);
}

TEST(CuseSpidevIoctl, SettingsAreWrittenAndReadBackInTwoCallsEach) {
  Node n;
  std::uint32_t speed = 2'000'000;
  EXPECT_EQ(n.ioctl(SPI_IOC_WR_MAX_SPEED_HZ, &speed), 0);
  EXPECT_EQ(n.steps.size(), 2u);
  std::uint32_t back = 0;
  EXPECT_EQ(n.ioctl(SPI_IOC_RD_MAX_SPEED_HZ, &back), 0);
  EXPECT_EQ(n.steps.size(), 2u);
  EXPECT_EQ(back, 2'000'000u);
  std::uint8_t mode = 0;
  EXPECT_EQ(n.ioctl(SPI_IOC_RD_MODE, &mode), 0);
  EXPECT_EQ(mode, SPI_MODE_3) << "the config's mode=3";
  std::uint8_t bits = 9;
  EXPECT_EQ(n.ioctl(SPI_IOC_WR_BITS_PER_WORD, &bits), -EINVAL);
}

TEST(CuseSpidevIoctl, UnknownCommandsAreEnottyWithoutTouchingMemory) {
  Node n;
  EXPECT_EQ(n.ioctl(_IOR(SPI_IOC_MAGIC, 99, std::uint32_t), nullptr), -ENOTTY);
  EXPECT_EQ(n.steps.size(), 1u);
  EXPECT_EQ(n.ioctl(_IOW(SPI_IOC_MAGIC, 1, std::uint32_t), nullptr), -ENOTTY) << "right number, wrong size";
  EXPECT_EQ(n.ioctl(0x5401 /* TCGETS */, nullptr), -ENOTTY);
  EXPECT_EQ(n.steps.size(), 1u);
}

TEST(CuseSpidevIoctl, AnArraySizeThatIsNotWholeTransfersIsEinval) {
  Node n;
  EXPECT_EQ(n.ioctl(_IOW(SPI_IOC_MAGIC, 0, char[40]), nullptr), -EINVAL);
}

}  // namespace
}  // namespace l6470emu::test
