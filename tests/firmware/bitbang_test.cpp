// SPI bit-banged on the program's own pins (sck_pin=, mosi_pin=, miso_pin=) through the firmware
// runtime: mode-3-shaped edges read what the SPI controller reads, mode-0-shaped ones the stale
// first bit silicon gives (and SPI_MODE), bytes the chips never hear are named (SPI_PINS). The
// sketches and programs in sketches/bitbang_* do the same through the Arduino, HAL and C calls.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "firmware/runtime.hpp"
#include "support/board_config_support.hpp"

namespace l6470emu::test {
namespace {

constexpr const char* kThreeChips = "chips=3xL6470 cs_pin=D4 sck_pin=D5 mosi_pin=D6 miso_pin=D7 check=warn";

/// A program bit-banging CS on D4, SCK on D5, MOSI on D6 and MISO on D7 as a sketch does with
/// digitalWrite and digitalRead (one call's time per pin call), shaped as SPI mode 3 or mode 0.
struct BitBang {
  explicit BitBang(const std::string& description, int mode = 3)
      : rt(config_of(description), FirmwareFront::arduino, [this](std::string_view l) { log.emplace_back(l); }),
        mode(mode) {
    rt.board().sanitizer().set_broken_sink([this](const Violation& v) { broken.push_back(v); });
    write(cs, true);
    rt.set_pin_mode(cs, McuPinMode::output);
    write(sck, mode == 3);  // the clock's idle level
    rt.set_pin_mode(sck, McuPinMode::output);
    rt.set_pin_mode(mosi, McuPinMode::output);
    rt.set_pin_mode(miso, McuPinMode::input);
  }
  void write(int pin, bool level) {
    rt.call();
    rt.write_pin(pin, level);
  }
  bool read(int pin) {
    rt.call();
    return rt.read_pin(pin);
  }
  /// `bits` bits of `out`, most significant first; what MISO read at each.
  std::uint8_t clock_bits(std::uint8_t out, int bits = 8) {
    std::uint8_t in = 0;
    for (int bit = 7; bit > 7 - bits; --bit) {
      const bool b = (out >> bit) & 1u;
      if (mode == 3) {  // MOSI while the clock is low, MISO after it rose
        write(sck, false);
        write(mosi, b);
        write(sck, true);
        in = static_cast<std::uint8_t>(in << 1 | read(miso));
      } else {  // MOSI before the clock rises, MISO while it is high (Arduino's shiftIn)
        write(mosi, b);
        write(sck, true);
        in = static_cast<std::uint8_t>(in << 1 | read(miso));
        write(sck, false);
      }
    }
    return in;
  }
  std::vector<std::uint8_t> frame(const std::vector<std::uint8_t>& tx, int cs_pin = 4) {
    std::vector<std::uint8_t> rx;
    write(cs_pin, false);
    for (const std::uint8_t b : tx) rx.push_back(clock_bits(b));
    write(cs_pin, true);
    return rx;
  }
  std::vector<std::string> rules() const {
    std::vector<std::string> names;
    for (const Violation& v : broken) names.emplace_back(rule_info(v.rule).name);
    return names;
  }
  std::size_t log_lines_with(const std::string& text) const {
    return std::count_if(log.begin(), log.end(), [&](const std::string& l) { return l.find(text) != std::string::npos; });
  }

  const int cs = 4, sck = 5, mosi = 6, miso = 7;
  std::vector<std::string> log;
  std::vector<Violation> broken;
  FirmwareRuntime rt;
  int mode;
};

/// CONFIG of every chip of a three-chip chain in three frames: GetParam(CONFIG) to each, two answers.
std::array<unsigned, 3> read_configs(BitBang& b, int cs_pin = 4) {
  b.frame({0x38, 0x38, 0x38}, cs_pin);
  const auto high = b.frame({0, 0, 0}, cs_pin);
  const auto low = b.frame({0, 0, 0}, cs_pin);
  return {unsigned(high[0] << 8 | low[0]), unsigned(high[1] << 8 | low[1]), unsigned(high[2] << 8 | low[2])};
}

TEST(FirmwareBitBang, ModeThreeEdgesOnDigitalPinsReadEveryChipsConfigAndBreakNoRule) {
  BitBang b(kThreeChips);
  EXPECT_EQ(read_configs(b), (std::array<unsigned, 3>{0x2E88, 0x2E88, 0x2E88}));
  EXPECT_TRUE(b.rt.clocked_bytes());
  EXPECT_EQ(b.rt.board().chain(0).frames(), 3u);
  EXPECT_TRUE(b.broken.empty()) << b.rules().front() << ": " << b.broken.front().what;
  EXPECT_TRUE(b.log.empty()) << b.log.front();
}

TEST(FirmwareBitBang, AMoveBitBangedToEachChipEndsAtItsExactPosition) {
  BitBang b(kThreeChips);
  b.frame({0xD0, 0xD0, 0xD0});  // GetStatus: the power-up flags cleared
  b.frame({0, 0, 0});
  b.frame({0, 0, 0});
  b.frame({0x41, 0x40, 0x41});  // Move FWD 1000, REV 77, FWD 3
  b.frame({0x00, 0x00, 0x00});
  b.frame({0x03, 0x00, 0x00});
  b.frame({0xE8, 0x4D, 0x03});
  EXPECT_FALSE(b.rt.board().pin_level(0, 0, Pin::BUSY)) << "BUSY is low while the motor moves";
  b.rt.sleep_until(b.rt.now() + ticks_from_ms(3000));
  b.frame({0x21, 0x21, 0x21});  // GetParam(ABS_POS)
  std::array<long, 3> pos{};
  for (int i = 0; i < 3; ++i) {
    const auto rx = b.frame({0, 0, 0});
    for (int k = 0; k < 3; ++k) pos[k] = pos[k] << 8 | rx[k];
  }
  for (long& p : pos) p = p & 0x200000 ? p - 0x400000 : p;
  EXPECT_EQ(pos, (std::array<long, 3>{1000, -77, 3}));
  EXPECT_TRUE(b.broken.empty()) << b.rules().front() << ": " << b.broken.front().what;
}

TEST(FirmwareBitBang, ModeZeroShapedEdgesReadWhatTheControllerReadsInModeZeroAndAreNamedSpiMode) {
  BitBang b(kThreeChips, 0);
  const auto banged = read_configs(b);
  EXPECT_EQ(banged[0], 0x2E08u) << "the stale first bit of each answer byte, as silicon";
  ASSERT_FALSE(b.broken.empty());
  EXPECT_EQ(b.rules().front(), "SPI_MODE");

  // The same bytes from the SPI controller in mode 0, on a board of its own.
  FirmwareRuntime rt(config_of("chips=3xL6470 cs_pin=D4 check=off"), FirmwareFront::arduino, [](std::string_view) {});
  rt.set_pin_mode(4, McuPinMode::output);
  BusSettings mode0;
  mode0.mode = 0;
  auto frame = [&](std::array<std::uint8_t, 3> tx) {
    std::array<std::uint8_t, 3> rx{};
    rt.call();
    rt.write_pin(4, true);
    rt.call();
    rt.write_pin(4, false);
    rt.call();
    rt.transfer(0, mode0, tx, rx);
    rt.call();
    rt.write_pin(4, true);
    return rx;
  };
  frame({0x38, 0x38, 0x38});
  const auto high = frame({0, 0, 0});
  const auto low = frame({0, 0, 0});
  for (int k = 0; k < 3; ++k) EXPECT_EQ(banged[k], unsigned(high[k] << 8 | low[k])) << "chip " << k;
}

TEST(FirmwareBitBang, AModeThreeLoopThatReadsMisoBeforeTheClockFallsReadsEachBitOneEdgeLate) {
  BitBang b("chips=L6470 cs_pin=D4 sck_pin=D5 mosi_pin=D6 miso_pin=D7 check=warn");
  b.frame({0x38});  // GetParam(CONFIG): 0x2E 0x88
  auto early_frame = [&] {
    std::uint8_t in = 0;
    b.write(b.cs, false);
    for (int bit = 7; bit >= 0; --bit) {
      in = static_cast<std::uint8_t>(in << 1 | b.read(b.miso));  // before the falling edge moves it
      b.write(b.sck, false);
      b.write(b.mosi, false);
      b.write(b.sck, true);
    }
    b.write(b.cs, true);
    return in;
  };
  EXPECT_EQ(early_frame() & 0x7F, 0x2E >> 1) << "bits 7..1 of 0x2E, after the latch the last frame left";
  EXPECT_EQ(early_frame(), 0x88 >> 1) << "0x2E's bit 0, then bits 7..1 of 0x88";
  EXPECT_TRUE(b.broken.empty()) << b.rules().front() << ": " << b.broken.front().what;
}

TEST(FirmwareBitBang, TwoChainsSharingTheClockAndDataPinsAnswerOnlyWhenTheirChipSelectIsLow) {
  BitBang b("bus=0 cs=0 chips=L6470 cs_pin=D4 sck_pin=D5 mosi_pin=D6 miso_pin=D7 check=warn; "
            "bus=0 cs=1 chips=L6480 cs_pin=D8 sck_pin=D5 mosi_pin=D6 miso_pin=D7");
  b.write(8, true);
  b.rt.set_pin_mode(8, McuPinMode::output);
  auto config = [&](int cs_pin, std::uint8_t opcode) {
    b.frame({opcode}, cs_pin);
    return unsigned(b.frame({0}, cs_pin)[0] << 8 | b.frame({0}, cs_pin)[0]);
  };
  EXPECT_EQ(config(8, 0x3A), 0x2C88u) << "the L6480's CONFIG (0x1A)";
  EXPECT_EQ(config(4, 0x38), 0x2E88u) << "the L6470's CONFIG (0x18)";
  EXPECT_EQ(b.rt.board().chain(0).frames(), 3u);
  EXPECT_EQ(b.rt.board().chain(1).frames(), 3u);
  EXPECT_TRUE(b.broken.empty()) << b.rules().front() << ": " << b.broken.front().what;
}

TEST(FirmwareBitBang, PinsTheDescriptionDoesNotMapAreNamedInOneLineAndAsSpiPins) {
  BitBang b("chips=3xL6470 cs_pin=D4 check=warn");
  for (int i = 0; i < 4; ++i) b.frame({0x38, 0x38, 0x38});
  // The runtime's line, once (the sanitizer's check=warn lines beside it say SPI_PINS).
  EXPECT_EQ(b.log_lines_with("spidev0.0: a chip-select frame with no clock edge: nothing reached the chips; the program "
                             "drives pins 5, 6 the board description does not map (bit-banged SPI? map them with "
                             "sck_pin=, mosi_pin=, miso_pin=)"),
            1u)
      << (b.log.empty() ? "" : b.log.front());
  ASSERT_EQ(b.broken.size(), 4u) << "every clockless frame";
  EXPECT_EQ(b.rules().front(), "SPI_PINS");
  EXPECT_EQ(b.log_lines_with("spidev0.0: every chip: SPI_PINS: a chip-select frame with no clock edge"), 4u);
  EXPECT_FALSE(b.rt.clocked_bytes()) << "nothing reached the chips";
}

TEST(FirmwareBitBang, TheLineNamesThePinsSwitchedInsideTheFrameNotEveryPinTheProgramSetUp) {
  BitBang b("chips=L6470 cs_pin=D4 check=warn");
  for (int pin = 20; pin < 40; ++pin) {  // a firmware's enables, heaters, fans and LEDs
    b.rt.set_pin_mode(pin, McuPinMode::output);
    b.write(pin, true);
  }
  b.frame({0x38});
  EXPECT_EQ(b.log_lines_with("spidev0.0: a chip-select frame with no clock edge: nothing reached the chips; the program "
                             "drives pins 5, 6 the board description does not map"),
            1u)
      << (b.log.empty() ? "" : b.log.front());
}

TEST(FirmwareBitBang, AnLedSwitchedOnWhileThePowerUpFrameIsOpenIsNoBusOnUnmappedPins) {
  // pinMode(CS, OUTPUT) drives CS low until it is written high; a sketch that sets up its LED
  // in between makes one clockless frame around one unmapped write: no bit-banged bus.
  FirmwareRuntime rt(config_of("chips=L6470 cs_pin=D10 check=warn"), FirmwareFront::arduino, [](std::string_view) {});
  std::vector<Violation> broken;
  rt.board().sanitizer().set_broken_sink([&](const Violation& v) { broken.push_back(v); });
  rt.set_pin_mode(10, McuPinMode::output);
  rt.call();
  rt.set_pin_mode(13, McuPinMode::output);
  rt.call();
  rt.write_pin(13, true);
  rt.call();
  rt.write_pin(10, true);
  for (const Violation& v : broken) ADD_FAILURE() << rule_info(v.rule).name << ": " << v.what;
}

TEST(FirmwareBitBang, ClockEdgesWithNoChipSelectLowAreNamedOnce) {
  BitBang b(kThreeChips);
  for (int i = 0; i < 3; ++i) b.clock_bits(0xD0);  // CS never falls
  EXPECT_EQ(b.log_lines_with("spidev0.0: clock edges on 5 (sck_pin=) while no chip select of it is low: they shift nothing"), 1u);
  ASSERT_EQ(b.broken.size(), 1u);
  EXPECT_EQ(b.rules().front(), "SPI_PINS");
  EXPECT_EQ(b.rt.board().spi_pins(0).rising_edges_deselected(), 1u + 24u) << "the clock set to its idle level, then 3 bytes";
  EXPECT_EQ(b.rt.board().chain(0).frames(), 0u);
}

TEST(FirmwareBitBang, AFrameEndingInsideAByteDropsItsBitsAndIsNamed) {
  BitBang b("chips=L6470 cs_pin=D4 sck_pin=D5 mosi_pin=D6 miso_pin=D7 check=warn");
  b.write(b.cs, false);
  b.clock_bits(0x38);
  b.clock_bits(0xFF, 5);
  b.write(b.cs, true);
  ASSERT_EQ(b.broken.size(), 1u);
  EXPECT_EQ(b.rules().front(), "SPI_PINS");
  EXPECT_NE(b.broken.front().what.find("the frame ended 5 bits into byte 1"), std::string::npos) << b.broken.front().what;
  // The whole byte was decoded (GetParam(CONFIG)); the five bits were not: the answer is intact.
  EXPECT_EQ(unsigned(b.frame({0})[0] << 8 | b.frame({0})[0]), 0x2E88u);
}

TEST(FirmwareBitBang, CsTimingAtThePinsIsTheProgramsOwnAndChecked) {
  // call_time=250ns: the first clock edge comes 250 ns after CS fell (t_setCS is 350 ns), and CS
  // is high for 250 ns between frames (t_disCS is 800 ns).
  BitBang fast(std::string(kThreeChips) + " call_time=250ns");
  fast.frame({0xD0, 0xD0, 0xD0});
  fast.frame({0, 0, 0});
  const auto rules = fast.rules();
  ASSERT_GE(rules.size(), 2u);
  EXPECT_EQ(rules[0], "CS_SETUP_TIME");
  EXPECT_NE(fast.broken[0].what.find("the first clock edge came 250 ns after CS fell"), std::string::npos) << fast.broken[0].what;
  EXPECT_NE(std::find(rules.begin(), rules.end(), "CS_DESELECT_TIME"), rules.end());
}

void bit_bang_on_unmapped_pins(const char* description) {
  BitBang b(description);
  for (int i = 0; i < 3; ++i) b.frame({0x38});
  std::fprintf(stderr, "ran on\n");
  std::exit(0);
}

TEST(FirmwareBitBangDeathTest, UnderCheckErrorBitBangingOnPinsTheBoardDoesNotMapEndsTheRunWith86) {
  EXPECT_EXIT(bit_bang_on_unmapped_pins("chips=L6470 cs_pin=D4 check=error"), testing::ExitedWithCode(86),
              "driver sanitizer: SPI_PINS on spidev0.0");
  EXPECT_EXIT(bit_bang_on_unmapped_pins("chips=L6470 cs_pin=D4 check=error check.allow=SPI_PINS"),
              testing::ExitedWithCode(0), "ran on");
}

}  // namespace
}  // namespace l6470emu::test
