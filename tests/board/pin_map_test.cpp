// The microcontroller side of the board description (cs_pin=, busy_pin=, ..., spi=) and a
// firmware run's timing keys (call_time=, loop_time=, limit=, apb_clock=): parsed exactly,
// refused with one line naming the clause and key, and written back by describe_board_config.
#include <gtest/gtest.h>

#include <string>

#include "board/board_config.hpp"

namespace l6470emu::test {
namespace {

BoardConfig parsed(const std::string& text) {
  ParseResult r = parse_board_config(text, "T");
  EXPECT_TRUE(r.config) << r.error.message;
  return r.config ? *r.config : BoardConfig{};
}

std::string error_of(const std::string& text) {
  const ParseResult r = parse_board_config(text, "T");
  EXPECT_FALSE(r.config) << text;
  return r.error.message;
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

McuPin arduino(unsigned n) { return McuPin{McuPin::Kind::arduino, static_cast<std::uint16_t>(n)}; }
McuPin stm32(char port, unsigned n) { return McuPin{McuPin::Kind::stm32, static_cast<std::uint16_t>((port - 'A') * 16 + n)}; }

TEST(McuPinNames, ArduinoNumbersDigitalAnalogAndGpioNamesAndStm32PortPinsAreRead) {
  EXPECT_EQ(parse_mcu_pin("10"), arduino(10));
  EXPECT_EQ(parse_mcu_pin("D10"), arduino(10));
  EXPECT_EQ(parse_mcu_pin("d7"), arduino(7));
  EXPECT_EQ(parse_mcu_pin("A0"), arduino(14));  // as on an Uno
  EXPECT_EQ(parse_mcu_pin("A7"), arduino(21));
  EXPECT_EQ(parse_mcu_pin("GPIO5"), arduino(5));
  EXPECT_EQ(parse_mcu_pin("127"), arduino(127));
  EXPECT_EQ(parse_mcu_pin("PA4"), stm32('A', 4));
  EXPECT_EQ(parse_mcu_pin("pb15"), stm32('B', 15));
  EXPECT_EQ(parse_mcu_pin("PK0"), stm32('K', 0));
  for (const char* bad : {"", "128", "D", "A8", "PA16", "PL0", "P4", "-1", "+3", "10x", "GPIO", "D0x10", "PA"})
    EXPECT_FALSE(parse_mcu_pin(bad)) << bad;
  EXPECT_EQ(to_string(stm32('C', 13)), "PC13");
  EXPECT_EQ(to_string(arduino(14)), "14");
}

TEST(McuPinNames, SpiControllersHaveOneSpellingEachAndAHalHandleNamesItsPeripheral) {
  EXPECT_EQ(parse_spi_controller("SPI"), "SPI");
  EXPECT_EQ(parse_spi_controller("spi2"), "SPI2");
  EXPECT_EQ(parse_spi_controller("hspi1"), "SPI1");
  EXPECT_EQ(parse_spi_controller("HSPI"), "HSPI");
  EXPECT_EQ(parse_spi_controller("vspi"), "VSPI");
  for (const char* bad : {"", "SPI0", "SPI10", "hspi0", "QSPI", "SPI_1"}) EXPECT_FALSE(parse_spi_controller(bad)) << bad;
}

TEST(PinMapConfig, AChainNamesItsChipSelectAndOnePinForAllItsChipsOrOnePerChip) {
  const BoardConfig c = parsed("chips=3xL6470 cs_pin=D10 busy_pin=D3 flag_pin=2,4,- stby_rst_pin=PB10 spi=SPI");
  const ChainPins& p = c.chains.at(0).pins;
  EXPECT_EQ(p.cs, arduino(10));
  EXPECT_EQ(chip_mcu_pin(p, Pin::BUSY, 0), arduino(3));
  EXPECT_EQ(chip_mcu_pin(p, Pin::BUSY, 2), arduino(3));  // one pin for every chip: wired together
  EXPECT_EQ(chip_mcu_pin(p, Pin::FLAG, 1), arduino(4));
  EXPECT_FALSE(chip_mcu_pin(p, Pin::FLAG, 2));             // '-': not connected
  EXPECT_EQ(chip_mcu_pin(p, Pin::STBY_RST, 1), stm32('B', 10));
  EXPECT_FALSE(chip_mcu_pin(p, Pin::SW, 0));
  EXPECT_EQ(p.spi, "SPI");
  EXPECT_TRUE(p.any());
  EXPECT_FALSE(parsed("chips=L6470").chains.at(0).pins.any());
}

TEST(PinMapConfig, BadPinsListsAndNamesAreRefusedNamingTheKey) {
  EXPECT_TRUE(contains(error_of("chips=L6470 cs_pin=PZ1"),
                       "clause 1: cs_pin must be a microcontroller pin: an Arduino pin (10, D10, A0 to A7, GPIO5; 0 to 127) "
                       "or an STM32 port pin (PA0 to PK15), not 'PZ1'"));
  EXPECT_TRUE(contains(error_of("chips=2xL6470 busy_pin=3,x"), "busy_pin must be a microcontroller pin"));
  EXPECT_TRUE(contains(error_of("chips=2xL6470 busy_pin=3,x"), "not 'x' in '3,x'"));
  EXPECT_TRUE(contains(error_of("chips=3xL6470 flag_pin=2,3"),
                       "flag_pin= lists 2 pins for a chain of 3 chips: give one pin for all of them or one per chip, "
                       "'-' for none (e.g. flag_pin=D3,D4,-)"));
  EXPECT_TRUE(contains(error_of("chips=L6470 spi=QSPI"), "spi must name an SPI controller: SPI, SPI1 to SPI9, HSPI"));
  EXPECT_TRUE(contains(error_of("cs_pin=10"), "cs_pin= describes a chain: add chips= to this clause"));
  EXPECT_TRUE(contains(error_of("chips=L6470 busy=3"), "unknown key 'busy': did you mean busy_pin=?"));
  EXPECT_TRUE(contains(error_of("chips=L6470 reset_pin=6"), "did you mean stby_rst_pin=?"));
  EXPECT_TRUE(contains(error_of("chips=L6470 flag_pn=2"), "did you mean flag_pin=?"));
  EXPECT_TRUE(contains(error_of("chips=L6470 cs_pin=10 cs_pin=9"), "cs_pin= is given twice in this clause"));
}

TEST(PinMapConfig, OpenDrainOutputsMayShareAPinButNotWithAnInputOrAChipSelect) {
  // BUSY and FLAG of several chips and chains wired together (open drain), one line to every STBY_RST.
  const BoardConfig c = parsed("chips=2xL6470 cs_pin=10 flag_pin=2 busy_pin=2 stby_rst_pin=6\n"
                               "bus=1 chips=L6470 cs_pin=9 flag_pin=2 stby_rst_pin=6");
  EXPECT_EQ(c.chains.size(), 2u);
  EXPECT_TRUE(contains(error_of("chips=L6470 cs_pin=10\nbus=1 chips=L6470 cs_pin=10"),
                       "T:2, clause 2: pin 10 is cs_pin= of the chain in clause 1 and cs_pin= here: a chip select is a "
                       "pin of its own"));
  EXPECT_TRUE(contains(error_of("chips=L6470 cs_pin=10 busy_pin=10"), "pin 10 is cs_pin= of this chain and busy_pin= here"));
  EXPECT_TRUE(contains(error_of("chips=L6470 flag_pin=2; bus=1 chips=L6470 stby_rst_pin=D2"),
                       "pin 2 is flag_pin= of the chain in clause 1 and stby_rst_pin= here: a chip output (BUSY, FLAG) "
                       "and a chip input (SW, STCK, STBY_RST) cannot share a pin"));
  EXPECT_TRUE(contains(error_of("chips=2xL6470 busy_pin=3,PA1 sw_pin=PA1"), "pin PA1 is busy_pin= of this chain and sw_pin="));
}

TEST(PinMapConfig, AChainOnANamedControllerGetsABusOfItsOwnAndAFreeChipSelect) {
  const BoardConfig c = parsed("chips=L6470 spi=SPI1 cs_pin=PA4\nchips=L6470 spi=SPI1 cs_pin=PA3\n"
                               "chips=L6470 spi=SPI2 cs_pin=PB12\nbus=0 cs=5 chips=L6470 cs_pin=PC0");
  ASSERT_EQ(c.chains.size(), 4u);
  EXPECT_EQ(c.chains[0].bus, 0u);
  EXPECT_EQ(c.chains[1].bus, 0u);   // the bus of the other chain on SPI1
  EXPECT_EQ(c.chains[1].cs, 1u);    // a free chip select there
  EXPECT_EQ(c.chains[1].path, "/dev/spidev0.1");
  EXPECT_EQ(c.chains[2].bus, 1u);   // SPI2: a bus of its own
  EXPECT_EQ(c.chains[3].cs, 5u);    // an unnamed chain joins bus 0 (SPI1) with the cs= it asks for
  EXPECT_TRUE(contains(error_of("chips=L6470 spi=SPI1\nbus=0 cs=1 chips=L6470 spi=SPI2"),
                       "bus 0 is spi=SPI1 in clause 1 and spi=SPI2 here: one bus has one controller"));
  EXPECT_TRUE(contains(error_of("chips=L6470 spi=SPI1\nbus=3 chips=L6470 spi=hspi1"),
                       "spi=SPI1 is bus 0 in clause 1 and bus 3 here: one controller drives one bus"));
}

TEST(FirmwareTimingConfig, DurationsAreWholeTicksWithAUnitWithinTheirRange) {
  const BoardConfig c = parsed("chips=L6470 call_time=250ns loop_time=2.5us limit=90s apb_clock=42000000");
  EXPECT_EQ(c.firmware.call_ticks, 1u);
  EXPECT_EQ(c.firmware.loop_ticks, 10u);
  EXPECT_EQ(c.firmware.limit_ticks, 90 * kTicksPerSecond);
  EXPECT_EQ(c.firmware.apb_clock_hz, 42'000'000u);
  const FirmwareTiming defaults;
  EXPECT_EQ(parsed("chips=L6470").firmware, defaults);
  EXPECT_EQ(defaults.call_ticks, 4u);   // 1 us
  EXPECT_EQ(defaults.limit_ticks, 60 * kTicksPerSecond);
  EXPECT_EQ(parsed("chips=L6470 limit=1.5ms").firmware.limit_ticks, 6000u);
  EXPECT_TRUE(contains(error_of("chips=L6470 call_time=100ns"),
                       "call_time must be a whole number of 250 ns ticks (the chip's tick), from 250ns to 1s (e.g. "
                       "call_time=1us), not '100ns'"));
  EXPECT_TRUE(contains(error_of("chips=L6470 call_time=2"), "call_time must be a number with a unit (ns, us, ms or s)"));
  EXPECT_TRUE(contains(error_of("chips=L6470 loop_time=2s"), "loop_time must be from 250ns to 1s (e.g. loop_time=10us), not '2s'"));
  EXPECT_TRUE(contains(error_of("chips=L6470 call_time=0us"), "call_time must be from 250ns to 1s"));
  EXPECT_TRUE(contains(error_of("chips=L6470 limit=0.5ms"), "limit must be from 1ms to 1000000s"));
  EXPECT_TRUE(contains(error_of("chips=L6470 limit=-1s"), "limit must be a number with a unit"));
  EXPECT_TRUE(contains(error_of("chips=L6470 limit=inf s"), "expected key=value, got 's'"));
  EXPECT_TRUE(contains(error_of("chips=L6470 apb_clock=84MHz"), "apb_clock must be a frequency in Hz"));
  EXPECT_TRUE(contains(error_of("chips=L6470 limit=10s; limit=20s"), "limit= is given twice"));
  EXPECT_TRUE(contains(error_of("chips=L6470 timelimit=10s"), "unknown key 'timelimit'"));
}

TEST(PinMapConfig, TheDescriptionWritesPinsAndTimingBackAsTheParserReadsThem) {
  const std::string text =
      "chips=3xL6470 cs_pin=D10 busy_pin=3 flag_pin=2,-,PA0 sw_pin=A0 stck_pin=7 stby_rst_pin=6 spi=hspi2\n"
      "chips=L6480 spi=VSPI cs_pin=PB12; call_time=2us loop_time=1ms limit=2min_is_not_a_unit";
  EXPECT_TRUE(contains(error_of(text), "limit must be a number with a unit"));
  const BoardConfig a = parsed(text.substr(0, text.find("limit=")) + "limit=120s numbering=mosi");
  const std::string described = describe_board_config(a);
  EXPECT_TRUE(contains(described, " cs_pin=10 busy_pin=3 flag_pin=2,-,PA0 sw_pin=14 stck_pin=7 stby_rst_pin=6 spi=SPI2\n"))
      << described;
  EXPECT_TRUE(contains(described, "call_time=2us loop_time=1ms limit=120s\n")) << described;
  const BoardConfig b = parsed(described);
  ASSERT_EQ(a.chains.size(), b.chains.size());
  for (std::size_t i = 0; i < a.chains.size(); ++i) {
    EXPECT_EQ(a.chains[i].pins, b.chains[i].pins);
    EXPECT_EQ(a.chains[i].bus, b.chains[i].bus);
    EXPECT_EQ(a.chains[i].cs, b.chains[i].cs);
  }
  EXPECT_EQ(a.firmware, b.firmware);
  EXPECT_FALSE(contains(describe_board_config(parsed("chips=L6470")), "call_time"));
}

}  // namespace
}  // namespace l6470emu::test
