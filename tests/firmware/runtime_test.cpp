// The firmware runtime on its own (no front): what each call costs, the pins as the board
// description wires them (wired BUSY/FLAG, a shared STBY_RST, the chip select), interrupts at
// their edges' ticks and never while disabled, SPI controllers by name, the time limit.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "firmware/runtime.hpp"
#include "support/test_support.hpp"
#include "support/board_config_support.hpp"

namespace l6470emu::test {
namespace {

struct Rig {
  explicit Rig(const std::string& description, FirmwareFront front = FirmwareFront::arduino,
               ArduinoBoard board = ArduinoBoard::uno)
      : rt(config_of(description), front, [this](std::string_view l) { log.emplace_back(l); }, board) {}
  std::vector<std::string> log;
  FirmwareRuntime rt;

  int pin(const char* name) { return FirmwareRuntime::key_of(*parse_mcu_pin(name)); }
  // One byte in its own CS frame on controller 0, mode 3, as a sketch's xfer() does.
  std::uint8_t byte_frame(int cs, std::uint8_t mosi, std::uint32_t hz = 5'000'000, int controller = 0) {
    BusSettings s;
    s.speed_hz = hz;
    std::uint8_t miso = 0;
    rt.call();
    rt.write_pin(cs, false);
    rt.call();
    rt.transfer(controller, s, std::span(&mosi, 1), std::span(&miso, 1));
    rt.call();
    rt.write_pin(cs, true);
    return miso;
  }
  void move(int cs, std::uint32_t n_step, int controller = 0) {
    for (const std::uint8_t b : {std::uint8_t{0x41}, std::uint8_t(n_step >> 16), std::uint8_t(n_step >> 8), std::uint8_t(n_step)})
      byte_frame(cs, b, 5'000'000, controller);
  }
};

TEST(FirmwareTime, EachCallCostsItsCallTimeAndASleepEndsExactlyOnItsTick) {
  Rig r("chips=L6470 call_time=2us loop_time=5us");
  EXPECT_EQ(r.rt.now(), 0u);
  r.rt.call();
  EXPECT_EQ(r.rt.now(), 8u);
  r.rt.spend(r.rt.timing().loop_ticks);
  EXPECT_EQ(r.rt.now(), 28u);
  r.rt.sleep_until(ticks_from_ms(3));
  EXPECT_EQ(r.rt.now(), ticks_from_ms(3));
  r.rt.sleep_until(0);  // the past: nothing happens
  EXPECT_EQ(r.rt.now(), ticks_from_ms(3));
  EXPECT_EQ(r.rt.board().time().now(), ticks_from_ms(3)) << "the board's clock is the program's";
}

TEST(FirmwareSpi, ABytesBusTimePassesAndOnlyTheSelectedChainHearsIt) {
  Rig r("bus=0 cs=0 chips=L6470 cs_pin=10; bus=0 cs=1 chips=L6480 cs_pin=9");
  r.rt.set_pin_mode(10, McuPinMode::output);
  r.rt.write_pin(10, true);
  r.rt.set_pin_mode(9, McuPinMode::output);
  r.rt.write_pin(9, true);
  const Tick before = r.rt.now();
  r.byte_frame(9, 0x3A, 1'000'000);  // GetParam(CONFIG) of the L6480 (0x1A)
  EXPECT_EQ(r.rt.now() - before, 3 * 4 + 32u) << "three calls of 1 us and a byte at 1 MHz (8 us)";
  const unsigned config = r.byte_frame(9, 0) << 8 | r.byte_frame(9, 0);
  EXPECT_EQ(config, 0x2C88u);
  EXPECT_EQ(r.byte_frame(10, 0), 0x00) << "the L6470 had nothing to say";
  EXPECT_TRUE(r.log.empty());
  // A byte with no chip select low is said once.
  std::uint8_t b = 0xD0, in = 0xFF;
  r.rt.transfer(0, BusSettings{}, std::span(&b, 1), std::span(&in, 1));
  r.rt.transfer(0, BusSettings{}, std::span(&b, 1), std::span(&in, 1));
  EXPECT_EQ(in, 0x00);
  ASSERT_EQ(r.log.size(), 1u);
  EXPECT_NE(r.log[0].find("no chip select of the bus is low"), std::string::npos) << r.log[0];
}

TEST(FirmwarePins, OpenDrainBusyOfSeveralChipsReadsLowWhileAnyOfThemIsBusy) {
  Rig r("chips=2xL6470 cs_pin=10 busy_pin=3; bus=1 chips=L6470 cs_pin=9 busy_pin=3 spi=SPI1");
  for (const int cs : {10, 9}) {
    r.rt.set_pin_mode(cs, McuPinMode::output);
    r.rt.write_pin(cs, true);
  }
  EXPECT_TRUE(r.rt.read_pin(3));
  // Chip 1 of the first chain moves 3200 microsteps (two-byte frames: byte 1 is chip 1's).
  auto frame2 = [&](std::uint8_t b) {
    std::array<std::uint8_t, 2> tx{0, b}, rx{};
    r.rt.write_pin(10, false);
    r.rt.transfer(0, BusSettings{}, tx, rx);
    r.rt.write_pin(10, true);
  };
  for (const std::uint8_t b : {0x41, 0x00, 0x0C, 0x80}) frame2(b);
  const Tick first_end = r.rt.now() + move_profile_ticks(true, 3200);
  r.rt.sleep_until(r.rt.now() + ticks_from_ms(10));
  r.move(9, 1600, 1);  // the other chain's chip, on its own controller
  EXPECT_FALSE(r.rt.read_pin(3));
  r.rt.sleep_until(first_end - 1);
  EXPECT_FALSE(r.rt.read_pin(3));
  r.rt.sleep_until(first_end + 1);
  EXPECT_TRUE(r.rt.read_pin(3)) << "both moves over (the second was shorter)";
}

TEST(FirmwarePins, OneStbyRstLineResetsEveryChipOnIt) {
  Rig r("chips=L6470 cs_pin=10 stby_rst_pin=6 flag_pin=2; bus=1 chips=L6470 cs_pin=9 stby_rst_pin=6 flag_pin=2 spi=SPI1");
  EXPECT_FALSE(r.rt.read_pin(2)) << "UVLO latched at power-up: FLAG low";
  for (const int cs : {10, 9}) {
    r.rt.set_pin_mode(cs, McuPinMode::output);
    r.rt.write_pin(cs, true);
  }
  for (const int cs : {10, 9})
    for (const std::uint8_t b : {0xD0, 0x00, 0x00}) r.byte_frame(cs, b, 5'000'000, cs == 10 ? 0 : 1);
  EXPECT_TRUE(r.rt.read_pin(2)) << "flags read: FLAG released by both";
  r.rt.set_pin_mode(6, McuPinMode::output);  // the latch is low: the line drives every chip into reset
  r.rt.sleep_until(r.rt.now() + ticks_from_ms(1));
  r.rt.write_pin(6, true);
  EXPECT_FALSE(r.rt.read_pin(2)) << "both chips were reset: UVLO latched again";
}

TEST(FirmwarePins, AnL6474IsSteppedThroughItsStckAndDirPinsAsOnTheXNucleoIhm01a1) {
  // The shield's wiring: FLAG D2, DIR D7, STBY_RST D8, STCK D9, CS D10.
  Rig r("chips=L6474 cs_pin=D10 flag_pin=D2 dir_pin=D7 stby_rst_pin=D8 stck_pin=D9");
  for (const int p : {10, 9, 8, 7}) {
    r.rt.set_pin_mode(p, McuPinMode::output);
    r.rt.write_pin(p, p != 9 && p != 7);  // CS and STBY_RST high, STCK and DIR low
  }
  for (const std::uint8_t b : {0xD0, 0x00, 0x00}) r.byte_frame(10, b);
  EXPECT_TRUE(r.rt.read_pin(2)) << "flags read: FLAG released";
  r.byte_frame(10, 0xB8);  // Enable
  auto pulses = [&](int n) {
    for (int i = 0; i < n; ++i) {
      r.rt.write_pin(9, true);
      r.rt.sleep_until(r.rt.now() + 40);
      r.rt.write_pin(9, false);
      r.rt.sleep_until(r.rt.now() + 40);
    }
  };
  r.rt.write_pin(7, true);
  pulses(12);
  r.rt.write_pin(7, false);
  pulses(20);
  std::uint32_t abs_pos = 0;
  r.byte_frame(10, 0x21);  // GetParam(ABS_POS)
  for (int i = 0; i < 3; ++i) abs_pos = abs_pos << 8 | r.byte_frame(10, 0x00);
  EXPECT_EQ(sign_extend(abs_pos, 22), -8);
  EXPECT_TRUE(r.rt.read_pin(2)) << "no alarm";
}

TEST(FirmwarePins, AnUnconnectedPinReadsWhatItDrivesOrItsPull) {
  Rig r("chips=L6470 cs_pin=10");
  EXPECT_FALSE(r.rt.read_pin(40));
  r.rt.set_pin_mode(40, McuPinMode::input_pullup);
  EXPECT_TRUE(r.rt.read_pin(40));
  r.rt.set_pin_mode(40, McuPinMode::input);
  EXPECT_FALSE(r.rt.read_pin(40)) << "pinMode(INPUT) clears an Arduino's pull-up";
  r.rt.write_pin(40, true);
  EXPECT_TRUE(r.rt.read_pin(40)) << "HIGH written to an input: its pull-up";
  r.rt.set_pin_mode(40, McuPinMode::output);
  r.rt.write_pin(40, false);
  EXPECT_FALSE(r.rt.read_pin(40));
  EXPECT_FALSE(r.rt.pin_wired(40));
  EXPECT_TRUE(r.rt.pin_wired(10));
}

TEST(FirmwareInterrupts, AnEdgeInASleepRunsItsHandlerAtTheEdgesOwnTick) {
  Rig r("chips=L6470 cs_pin=10 busy_pin=3");
  r.rt.set_pin_mode(10, McuPinMode::output);
  r.rt.write_pin(10, true);
  std::vector<Tick> ran;
  const int irq = r.rt.add_irq([&] { ran.push_back(r.rt.now()); });
  r.rt.watch_pin(3, kEdgeRising, [&](bool) { r.rt.pend_irq(irq); });
  r.move(10, 3200);
  const Tick rise = r.rt.now() + move_profile_ticks(true, 3200);
  r.rt.sleep_until(rise + ticks_from_ms(50));
  ASSERT_EQ(ran.size(), 1u);
  EXPECT_EQ(ran[0], rise);
}

TEST(FirmwareInterrupts, AnEdgeBetweenCallsRunsAtTheFirstCallAtOrAfterIt) {
  Rig r("chips=L6470 cs_pin=10 busy_pin=3 call_time=100us");
  r.rt.set_pin_mode(10, McuPinMode::output);
  r.rt.write_pin(10, true);
  std::vector<Tick> ran;
  const int irq = r.rt.add_irq([&] { ran.push_back(r.rt.now()); });
  r.rt.watch_pin(3, kEdgeBoth, [&](bool) { r.rt.pend_irq(irq); });
  r.move(10, 3200);
  ASSERT_EQ(ran.size(), 1u) << "BUSY fell at the frame that decoded the Move: delivered after that call";
  const Tick rise = r.rt.now() + move_profile_ticks(true, 3200);
  while (r.rt.now() < rise) r.rt.call();  // a busy loop of 100 us calls
  ASSERT_EQ(ran.size(), 2u);
  EXPECT_GE(ran[1], rise);
  EXPECT_LT(ran[1], rise + 400u) << "the call that first reached the edge's tick";
}

TEST(FirmwareInterrupts, NothingRunsWhileDisabledAndEnablingDeliversWhatIsPending) {
  Rig r("chips=L6470");
  int ran = 0;
  const int irq = r.rt.add_irq([&] { ++ran; });
  r.rt.disable_interrupts();
  r.rt.pend_irq(irq);
  r.rt.call();
  r.rt.sleep_until(r.rt.now() + 1000);
  EXPECT_EQ(ran, 0);
  r.rt.enable_interrupts();
  EXPECT_EQ(ran, 1);
  r.rt.set_irq_enabled(irq, false);
  r.rt.pend_irq(irq);
  r.rt.call();
  EXPECT_EQ(ran, 1) << "a masked source waits too";
  r.rt.set_irq_enabled(irq, true);
  r.rt.call();
  EXPECT_EQ(ran, 2);
}

TEST(FirmwareInterrupts, HandlersDoNotNestAndOneThatRepostsItselfCannotHoldTimeStill) {
  Rig r("chips=L6470");
  int outer = 0, inner = 0;
  int second = -1;
  const int first = r.rt.add_irq([&] {
    ++outer;
    EXPECT_TRUE(r.rt.in_interrupt());
    r.rt.pend_irq(second);
    r.rt.call();  // a call inside a handler delivers nothing
    EXPECT_EQ(inner, 0);
  });
  second = r.rt.add_irq([&] {
    ++inner;
    r.rt.pend_irq(second);  // never clears its source
  });
  r.rt.pend_irq(first);
  r.rt.call();
  EXPECT_EQ(outer, 1);
  EXPECT_EQ(inner, 0) << "what a handler makes pending waits for the next call";
  for (int i = 0; i < 5; ++i) r.rt.call();
  EXPECT_EQ(inner, 5) << "once per call, with the call's time between";
}

TEST(FirmwarePinMap, ADescriptionWithoutPinsGetsTheFrontsDefaultsOnItsFirstChain) {
  Rig arduino("chips=3xL6470");
  const ChainPins& a = arduino.rt.config().chains[0].pins;
  EXPECT_EQ(a.cs, parse_mcu_pin("D10"));
  EXPECT_EQ(chip_mcu_pin(a, Pin::FLAG, 2), parse_mcu_pin("D2"));
  EXPECT_EQ(chip_mcu_pin(a, Pin::BUSY, 0), parse_mcu_pin("D3"));
  EXPECT_EQ(chip_mcu_pin(a, Pin::STBY_RST, 1), parse_mcu_pin("D6"));
  Rig hal("chips=L6470", FirmwareFront::stm32_hal);
  const ChainPins& h = hal.rt.config().chains[0].pins;
  EXPECT_EQ(h.cs, parse_mcu_pin("PB6"));  // a Nucleo-64's D10
  EXPECT_EQ(chip_mcu_pin(h, Pin::FLAG, 0), parse_mcu_pin("PA10"));
  EXPECT_EQ(chip_mcu_pin(h, Pin::BUSY, 0), parse_mcu_pin("PB3"));
  EXPECT_EQ(chip_mcu_pin(h, Pin::STBY_RST, 0), parse_mcu_pin("PB10"));
  Rig given("chips=L6470 busy_pin=4; bus=1 chips=L6470");
  EXPECT_FALSE(given.rt.config().chains[0].pins.cs) << "a description with any pin gets no defaults";
  EXPECT_EQ(given.log.size(), 2u) << "each chain without cs_pin= is said to be unreachable";
}

TEST(FirmwarePinMap, OnANucleoTheHeadersPinNumbersAreItsPortPinsInTheSketchAndTheDescription) {
  Rig nucleo("chips=2xL6470 cs_pin=D10 busy_pin=D3,PB5 flag_pin=2 stby_rst_pin=D6 sw_pin=D20", FirmwareFront::arduino,
             ArduinoBoard::nucleo_f401re);
  const ChainPins& n = nucleo.rt.config().chains[0].pins;
  EXPECT_EQ(n.cs, parse_mcu_pin("PB6"));
  EXPECT_EQ(chip_mcu_pin(n, Pin::BUSY, 0), parse_mcu_pin("PB3"));
  EXPECT_EQ(chip_mcu_pin(n, Pin::BUSY, 1), parse_mcu_pin("PB5"));
  EXPECT_EQ(chip_mcu_pin(n, Pin::FLAG, 0), parse_mcu_pin("PA10"));
  EXPECT_EQ(chip_mcu_pin(n, Pin::STBY_RST, 1), parse_mcu_pin("PB10"));
  EXPECT_EQ(chip_mcu_pin(n, Pin::SW, 0), parse_mcu_pin("D20")) << "past the header a number stays itself";
  EXPECT_EQ(nucleo.rt.arduino_pin(10), nucleo.pin("PB6"));
  EXPECT_EQ(nucleo.rt.arduino_pin(0), nucleo.pin("PA3"));
  EXPECT_EQ(nucleo.rt.arduino_pin(15), nucleo.pin("PB8"));
  EXPECT_EQ(nucleo.rt.arduino_pin(16), 16);
  EXPECT_EQ(nucleo.rt.arduino_pin(nucleo.pin("PC13")), nucleo.pin("PC13"));
  Rig defaults("chips=L6470", FirmwareFront::arduino, ArduinoBoard::nucleo_f401re);
  EXPECT_EQ(defaults.rt.config().chains[0].pins.cs, parse_mcu_pin("PB6")) << "the default D10 is the header's";
  Rig uno("chips=L6470 cs_pin=D10");
  EXPECT_EQ(uno.rt.config().chains[0].pins.cs, parse_mcu_pin("D10"));
  EXPECT_EQ(uno.rt.arduino_pin(10), 10);
  Rig hal("chips=L6470 cs_pin=PA4", FirmwareFront::stm32_hal, ArduinoBoard::nucleo_f401re);
  EXPECT_EQ(hal.rt.config().chains[0].pins.cs, parse_mcu_pin("PA4"));
  EXPECT_EQ(parse_arduino_board("NUCLEO_F401RE"), ArduinoBoard::nucleo_f401re);
  EXPECT_EQ(parse_arduino_board("uno"), ArduinoBoard::uno);
  EXPECT_FALSE(parse_arduino_board("nucleo_f411re"));
}

TEST(FirmwareTime, MillisAndMicrosWrapAt2To32AsABoardsCountersDo) {
  EXPECT_EQ(board_micros(ticks_from_us(4'294'967'295)), 4'294'967'295u);
  EXPECT_EQ(board_micros(ticks_from_us(4'294'967'296)), 0u) << "71.58 minutes";
  EXPECT_EQ(board_micros(ticks_from_us(4'294'967'296) + ticks_from_us(704)), 704u);
  EXPECT_EQ(board_millis(ticks_from_ms(4'294'967'295)), 4'294'967'295u);
  EXPECT_EQ(board_millis(ticks_from_ms(4'294'967'296)), 0u) << "49.7 days";
  EXPECT_EQ(board_millis(ticks_from_ms(4'294'967'296) + 3999), 0u) << "a millisecond is whole before it counts";
  EXPECT_EQ(board_millis(ticks_from_ms(4'294'967'296) + 4000), 1u);
  // A sketch's `now - start` in uint32_t holds across the wrap.
  const std::uint32_t start = board_millis(ticks_from_ms(4'294'967'290));
  EXPECT_EQ(static_cast<std::uint32_t>(board_millis(ticks_from_ms(4'294'967'300)) - start), 10u);
}

TEST(FirmwareSerial, InputIsReadInArrivalOrderAndAvailableCountsWhatIsLeft) {
  Rig r("chips=L6470");
  EXPECT_EQ(r.rt.serial_available(), 0u);
  EXPECT_EQ(r.rt.serial_read(), -1);
  EXPECT_EQ(r.rt.serial_peek(), -1);
  r.rt.serial_arrive("ab");
  r.rt.serial_arrive(std::string_view("\xff\0", 2));
  EXPECT_EQ(r.rt.serial_available(), 4u);
  EXPECT_EQ(r.rt.serial_peek(), 'a');
  EXPECT_EQ(r.rt.serial_read(), 'a');
  EXPECT_EQ(r.rt.serial_read(), 'b');
  EXPECT_EQ(r.rt.serial_read(), 0xff) << "bytes, not chars";
  r.rt.serial_arrive("c");
  EXPECT_EQ(r.rt.serial_read(), 0);
  EXPECT_EQ(r.rt.serial_read(), 'c');
  EXPECT_EQ(r.rt.serial_available(), 0u);
  EXPECT_EQ(r.rt.serial_read(), -1);
}

TEST(FirmwareSerial, AScenariosSerialStepArrivesAtItsTickDuringASleep) {
  Rig r("chips=L6470");
  Scenario s;
  ScenarioStep st;
  st.where = "s.yaml:3";
  st.when.tick = ticks_from_ms(250);
  ScenarioAction typed;
  typed.kind = ScenarioAction::Kind::serial;
  typed.text = "G\n";
  st.action = typed;
  s.steps.push_back(st);
  r.rt.bind_scenario(s);
  r.rt.sleep_until(ticks_from_ms(249));
  EXPECT_EQ(r.rt.serial_available(), 0u);
  r.rt.sleep_until(ticks_from_ms(250));
  EXPECT_EQ(r.rt.serial_available(), 2u);
  EXPECT_EQ(r.rt.serial_read(), 'G');
}

TEST(FirmwareSpi, ControllersAreNamedBySpiOrAfterTheirBusAndOneBusAnswersToAnyName) {
  Rig arduino("bus=0 chips=L6470 cs_pin=10; bus=1 chips=L6470 cs_pin=9; bus=2 chips=L6470 cs_pin=8 spi=HSPI");
  EXPECT_EQ(arduino.rt.controller_names(), (std::vector<std::string>{"SPI", "SPI1", "HSPI"}));
  EXPECT_EQ(arduino.rt.controller("SPI"), 0);
  EXPECT_EQ(arduino.rt.controller("spi1"), 1);
  EXPECT_EQ(arduino.rt.controller("VSPI"), -1);
  Rig hal("bus=0 chips=L6470 cs_pin=PA4; bus=1 chips=L6470 cs_pin=PB12", FirmwareFront::stm32_hal);
  EXPECT_EQ(hal.rt.controller_names(), (std::vector<std::string>{"SPI1", "SPI2"}));
  EXPECT_EQ(hal.rt.controller("hspi2"), 1);
  Rig one("chips=L6470 spi=SPI2");
  EXPECT_EQ(one.rt.controller("SPI"), 0) << "one controller: every name reaches it";
  EXPECT_THROW(Rig("bus=0 chips=L6470 spi=SPI1; bus=1 chips=L6470"), std::invalid_argument)
      << "bus 1 is SPI1 by default in an Arduino program, and bus 0 says spi=SPI1";
  EXPECT_THROW(Rig("chips=L6470 socket=/tmp/x.sock"), std::invalid_argument);
}

TEST(FirmwarePins, WaitingForAChipOutputStopsAtItsExactEdge) {
  Rig r("chips=L6470 cs_pin=10 busy_pin=3 call_time=250ns");
  r.rt.set_pin_mode(10, McuPinMode::output);
  r.rt.write_pin(10, true);
  r.move(10, 3200);
  const Tick rise = r.rt.now() + move_profile_ticks(true, 3200);
  EXPECT_FALSE(r.rt.wait_for_level(3, true, rise - 1));
  EXPECT_EQ(r.rt.now(), rise - 1);
  EXPECT_TRUE(r.rt.wait_for_level(3, true, rise + ticks_from_ms(100)));
  EXPECT_EQ(r.rt.now(), rise) << "the rise itself, not a poll after it";
}

[[noreturn]] void run_until_the_limit(const char* description, bool sleeping) {
  FirmwareRuntime rt(config_of(description), FirmwareFront::arduino, [](std::string_view l) {
    std::fprintf(stderr, "l6470emu: %.*s\n", static_cast<int>(l.size()), l.data());
  });
  if (sleeping) rt.sleep_until(ticks_from_ms(60'000));
  for (;;) rt.call();
}

TEST(FirmwareRunDeathTest, TheRunEndsAtItsLimitWithOneLineAndStatusZero) {
  EXPECT_EXIT(run_until_the_limit("chips=L6470 limit=2ms", false), testing::ExitedWithCode(0),
              "firmware run stopped at its time limit: 0.002 s of virtual time \\(limit=2ms\\); loop\\(\\) had run 0 times");
  EXPECT_EXIT(run_until_the_limit("chips=L6470 limit=5ms", true), testing::ExitedWithCode(0),
              "at its time limit: 0.005 s of virtual time \\(limit=5ms\\)");
}

void clock_a_mode0_byte(const char* description) {
  Rig r(description);
  BusSettings mode0;
  mode0.mode = 0;
  std::uint8_t b = 0x00, in = 0;
  r.rt.set_pin_mode(r.pin("10"), McuPinMode::output);
  r.rt.write_pin(r.pin("10"), false);
  r.rt.call();
  r.rt.transfer(0, mode0, std::span(&b, 1), std::span(&in, 1));
  std::fprintf(stderr, "ran on\n");
  std::exit(0);
}

TEST(FirmwareSanitizerDeathTest, UnderCheckErrorTheFirstBrokenRuleEndsTheRunWithStatus86AndTheReport) {
  EXPECT_EXIT(clock_a_mode0_byte("chips=L6470 cs_pin=10 check=error"), testing::ExitedWithCode(86),
              "driver sanitizer: SPI_MODE on spidev0.0, chip 0, frame 1, byte 0");
  EXPECT_EXIT(clock_a_mode0_byte("chips=L6470 cs_pin=10 check=warn"), testing::ExitedWithCode(0), "ran on");
  EXPECT_EXIT(clock_a_mode0_byte("chips=L6470 cs_pin=10 check=error check.allow=SPI_MODE"), testing::ExitedWithCode(0),
              "ran on");
}

}  // namespace
}  // namespace l6470emu::test
