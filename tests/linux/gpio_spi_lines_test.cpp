// The SPI lines of a gpiochip (CS, SCK, MOSI, MISO on a chain with sck_pin=), against a
// DeviceBoard on an injected host clock: where they are, the order one call's values reach the
// board in, and what a call costs in board time.
#include <gtest/gtest.h>
#include <linux/gpio.h>
#include <unistd.h>

#include <cstring>
#include <string>
#include <vector>

#include "linux/device_board.hpp"
#include "support/board_config_support.hpp"

namespace l6470emu::test {
namespace {

/// A host clock that only moves when a sleep moves it.
class StillHostClock final : public HostClock {
 public:
  std::int64_t now = 5'000'000'000;
  std::vector<std::int64_t> sleeps;
  std::int64_t monotonic_ns() override { return now; }
  std::int64_t realtime_ns() override { return now; }
  void sleep_until(std::int64_t deadline) override {
    sleeps.push_back(deadline);
    if (deadline > now) now = deadline;
  }
};

/// A board on a still clock with its gpiochip open; `request` asks for lines as a v2 request.
struct Rig {
  StillHostClock clock;
  DiagnosticLog log{"off"};
  DeviceBoard board;
  NewFile chip;
  std::vector<int> fds;

  explicit Rig(const std::string& text) : board(config_of(text), log, clock) {
    for (std::size_t i = 0; i < board.nodes().size(); ++i)
      if (board.nodes()[i].type == DeviceNode::Type::gpiochip) {
        chip = board.open(i, true);
        break;
      }
    fds.push_back(chip.fd);
  }
  ~Rig() {
    for (int fd : fds) ::close(fd);
  }

  std::string name(unsigned offset) {
    std::vector<std::uint8_t> arg(sizeof(gpio_v2_line_info));
    reinterpret_cast<gpio_v2_line_info*>(arg.data())->offset = offset;
    EXPECT_EQ(board.ioctl(chip.handle, GPIO_V2_GET_LINEINFO_IOCTL, arg, nullptr), 0);
    return reinterpret_cast<gpio_v2_line_info*>(arg.data())->name;
  }
  unsigned lines() {
    std::vector<std::uint8_t> arg(sizeof(gpiochip_info));
    EXPECT_EQ(board.ioctl(chip.handle, GPIO_GET_CHIPINFO_IOCTL, arg, nullptr), 0);
    return reinterpret_cast<gpiochip_info*>(arg.data())->lines;
  }
  /// A v2 request of `offsets`, all outputs with `values` (bit i: line i) except those in `inputs`.
  std::uint64_t request(const std::vector<unsigned>& offsets, std::uint64_t values, std::uint64_t inputs = 0) {
    std::vector<std::uint8_t> arg(sizeof(gpio_v2_line_request));
    auto* r = reinterpret_cast<gpio_v2_line_request*>(arg.data());
    for (std::size_t i = 0; i < offsets.size(); ++i) r->offsets[i] = offsets[i];
    r->num_lines = static_cast<std::uint32_t>(offsets.size());
    std::strcpy(r->consumer, "test");
    r->config.flags = GPIO_V2_LINE_FLAG_OUTPUT;
    r->config.num_attrs = 2;
    r->config.attrs[0].attr.id = GPIO_V2_LINE_ATTR_ID_OUTPUT_VALUES;
    r->config.attrs[0].attr.values = values;
    r->config.attrs[0].mask = ~inputs & ((std::uint64_t{1} << offsets.size()) - 1);
    r->config.attrs[1].attr.id = GPIO_V2_LINE_ATTR_ID_FLAGS;
    r->config.attrs[1].attr.flags = GPIO_V2_LINE_FLAG_INPUT;
    r->config.attrs[1].mask = inputs;
    if (!inputs) r->config.num_attrs = 1;
    NewFile line;
    EXPECT_EQ(board.ioctl(chip.handle, GPIO_V2_GET_LINE_IOCTL, arg, &line), 0);
    fds.push_back(line.fd);
    return line.handle;
  }
  void set(std::uint64_t line, std::uint64_t mask, std::uint64_t bits) {
    std::vector<std::uint8_t> arg(sizeof(gpio_v2_line_values));
    *reinterpret_cast<gpio_v2_line_values*>(arg.data()) = {bits, mask};
    EXPECT_EQ(board.ioctl(line, GPIO_V2_LINE_SET_VALUES_IOCTL, arg, nullptr), 0);
  }
  std::uint64_t get(std::uint64_t line, std::uint64_t mask) {
    std::vector<std::uint8_t> arg(sizeof(gpio_v2_line_values));
    *reinterpret_cast<gpio_v2_line_values*>(arg.data()) = {0, mask};
    EXPECT_EQ(board.ioctl(line, GPIO_V2_LINE_GET_VALUES_IOCTL, arg, nullptr), 0);
    return reinterpret_cast<gpio_v2_line_values*>(arg.data())->bits;
  }
};

const std::string kPins = " sck_pin=D13 mosi_pin=D11 miso_pin=D12 cs_pin=D10";

TEST(GpioSpiLines, FourLinesNamedCsSckMosiMisoComeAfterTheChipsLinesAndTheDirLines) {
  Rig two("bus=0 cs=0 chips=2xL6470" + kPins);
  ASSERT_EQ(two.lines(), 14u);
  EXPECT_EQ(two.name(9), "STBY_RST1");
  EXPECT_EQ(two.name(10), "CS");
  EXPECT_EQ(two.name(11), "SCK");
  EXPECT_EQ(two.name(12), "MOSI");
  EXPECT_EQ(two.name(13), "MISO");
  Rig dir("bus=0 cs=0 chips=L6470,L6474" + kPins);
  ASSERT_EQ(dir.lines(), 16u);
  EXPECT_EQ(dir.name(11), "DIR1");
  EXPECT_EQ(dir.name(12), "CS");
  EXPECT_EQ(dir.name(15), "MISO");
  Rig plain("bus=0 cs=0 chips=2xL6470");
  EXPECT_EQ(plain.lines(), 10u);
}

TEST(GpioSpiLines, OneCallsValuesReachTheBoardInOffsetOrderSoARisingClockSamplesTheDataFromBefore) {
  // One L6470, mode 3. Each bit: SCK low alone, then SCK high and the NEXT bit's MOSI in one call.
  // In offset order SCK rises before MOSI changes, so the chip samples each bit one call late:
  // the host sends 0xA0 after a MOSI of 1 and the chip hears 1101 0000, GetStatus (0xD0).
  Rig rig("bus=0 cs=0 chips=L6470" + kPins);
  const unsigned cs = 5, sck = 6, mosi = 7, miso = 8;
  // The request lists MOSI before SCK: the order is the offsets', not the request's.
  const std::uint64_t l = rig.request({mosi, sck, cs, miso}, 0b0111, 0b1000);  // MOSI 1, SCK 1, CS 1; MISO in
  const std::uint64_t kMosi = 1, kSck = 2, kCs = 4, kMiso = 8;
  auto byte = [&](std::uint8_t out) {
    std::uint8_t in = 0;
    for (int b = 7; b >= 0; --b) {
      rig.set(l, kSck, 0);
      in = static_cast<std::uint8_t>(in << 1 | (rig.get(l, kMiso) ? 1 : 0));
      rig.set(l, kSck | kMosi, kSck | ((out >> b) & 1 ? kMosi : 0));
    }
    return in;
  };
  auto frame = [&](std::uint8_t out) {
    rig.set(l, kCs, 0);
    const std::uint8_t in = byte(out);
    rig.set(l, kCs, kCs);
    return in;
  };
  frame(0xA0);  // heard as 0xD0, GetStatus (its last bit, 0, leaves MOSI low)
  const std::uint16_t status = static_cast<std::uint16_t>(frame(0x00) << 8 | frame(0x00));
  EXPECT_EQ(status, 0x7C03);  // power-up: HiZ, UVLO latched
}

TEST(GpioSpiLines, ASetDrivingCsSckOrMosiTakesOneMicrosecondAndReadsAndChipLinesTakeNone) {
  Rig rig("bus=0 cs=0 chips=L6470" + kPins);
  const std::uint64_t spi = rig.request({5, 6, 7, 8}, 0b0011, 0b1000);
  const std::uint64_t sw = rig.request({2}, 1);  // SW of the chip
  ASSERT_TRUE(rig.clock.sleeps.empty()) << "a request takes no board time";
  const std::int64_t t0 = rig.clock.now;
  rig.set(spi, 0b0110, 0b0010);  // SCK high, MOSI low
  ASSERT_EQ(rig.clock.sleeps.size(), 1u);
  EXPECT_EQ(rig.clock.now - t0, 1000);
  rig.get(spi, 0b1000);
  rig.set(sw, 1, 0);
  EXPECT_EQ(rig.clock.sleeps.size(), 1u);
  EXPECT_EQ(DeviceBoard::kSpiLineSetTicks, ticks_from_us(1));
}

}  // namespace
}  // namespace l6470emu::test
