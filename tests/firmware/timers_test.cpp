// The runtime's timers (firmware/timers.cpp) without a front: a timer on an L6474's STCK at
// 1 kHz for ten simulated minutes moves ABS_POS by exactly its pulses without meeting them one
// by one; update and compare interrupts run at their exact ticks; a new period takes effect at
// the next update; a stopped timer moves no more; a counted train ends by itself.
#include <gtest/gtest.h>

#include "firmware/runtime.hpp"
#include "support/test_support.hpp"

namespace l6470emu::test {
namespace {

struct Rig {
  explicit Rig(const std::string& description)
      : rt(*parse_board_config(description, "test").config, FirmwareFront::stm32_hal,
           [this](std::string_view l) { log.emplace_back(l); }) {}
  std::vector<std::string> log;
  FirmwareRuntime rt;
  int pin(const char* name) { return FirmwareRuntime::key_of(*parse_mcu_pin(name)); }
  std::int32_t position(std::size_t chip = 0) {
    std::int32_t p = 0;
    rt.board().with_chain(0, [&](Chain& c) { p = c.chip(chip).position(); });
    return p;
  }
  /// Enables the L6474 through the board's backdoor (HardStop's opcode) with DIR high.
  void enable() {
    rt.board().drive_pin(0, 0, Pin::DIR, true);
    rt.board().with_chain(0, [](Chain& c) { c.chip(0).on_byte_at(c.now(), 0xB8); });
  }
  /// A timer clocked as an F401's TIM at 84 MHz: prescaler 84 (1 MHz counts).
  int timer(std::uint64_t period_us, int output) {
    FirmwareTimers& t = rt.timers();
    const int id = t.add("TIM3");
    t.set_clock(id, 84'000'000);
    t.set_prescaler(id, 84);
    t.set_period(id, period_us);
    t.set_compare(id, period_us / 2);
    t.set_output(id, output);
    return id;
  }
};

constexpr const char* kL6474 = "chips=L6474 cs_pin=PB6 stck_pin=PB10 dir_pin=PA8 limit=3600s";

TEST(FirmwareTimers, ATimerOnStckAtOneKilohertzForTenMinutesMovesAbsPosByExactlyItsPulsesInBulk) {
  Rig r(kL6474);
  r.enable();
  const int t = r.timer(1000, r.pin("PB10"));
  const Tick t0 = r.rt.now();
  r.rt.timers().start(t);
  r.rt.sleep_until(t0 + ticks_from_ms(600'000) - 1);
  EXPECT_EQ(r.position(), 600'000) << "pulses rise at 0, 1 ms, ..., 599.999 s";
  EXPECT_EQ(r.rt.board().pulse_train_counts().single_edges, 0u) << "not one pulse simulated by itself";
  EXPECT_EQ(r.rt.board().pulse_train_counts().bulk_pulses, 600'000u);
}

TEST(FirmwareTimers, UpdateAndCompareInterruptsRunAtTheirExactTicks) {
  Rig r(kL6474);
  r.enable();
  const int t = r.timer(100, r.pin("PB10"));
  std::vector<Tick> updates, compares;
  r.rt.timers().set_update_irq(t, r.rt.add_irq([&] { updates.push_back(r.rt.now()); }));
  r.rt.timers().set_compare_irq(t, r.rt.add_irq([&] { compares.push_back(r.rt.now()); }));
  r.rt.sleep_until(1000);
  r.rt.timers().start(t);
  for (int i = 0; i < 50; ++i) r.rt.call();  // calls of 1 us each: the events fall inside them
  r.rt.sleep_until(1000 + ticks_from_us(1000) + 1);
  ASSERT_EQ(updates.size(), 10u);
  ASSERT_EQ(compares.size(), 10u);
  for (std::size_t k = 0; k < 10; ++k) {
    EXPECT_EQ(updates[k], 1000 + ticks_from_us(100) * (k + 1));
    EXPECT_EQ(compares[k], 1000 + ticks_from_us(100) * k + ticks_from_us(50));
  }
  EXPECT_EQ(r.position(), 11);
}

TEST(FirmwareTimers, ANewPeriodSetInTheUpdateInterruptTakesEffectAtTheNextUpdateAndEveryPulseCounts) {
  Rig r(kL6474);
  r.enable();
  const int t = r.timer(400, r.pin("PB10"));
  std::vector<Tick> updates;
  std::uint64_t period = 400;
  r.rt.timers().set_update_irq(t, r.rt.add_irq([&] {
    updates.push_back(r.rt.now());
    if (period > 100) period -= 100;  // a ramp, as the vendor libraries do it
    r.rt.timers().set_period(t, period);
    r.rt.timers().set_compare(t, period / 2);
  }));
  r.rt.timers().start(t);
  r.rt.sleep_until(ticks_from_us(1300) + 1);
  // Each period written in an update is in force from the update after it (the preload): the
  // updates come at 400, 800 (still 400: 300 was written after the first one), 1100, 1300 us.
  EXPECT_EQ(updates, (std::vector<Tick>{ticks_from_us(400), ticks_from_us(800), ticks_from_us(1100), ticks_from_us(1300)}));
  EXPECT_EQ(r.position(), 5) << "pulses rise at 0, 400, 800, 1100 and 1300 us";
  EXPECT_EQ(r.rt.board().pulse_train_rises(0, 0, Pin::STCK), 5u);
  EXPECT_EQ(r.rt.board().pulse_train_counts().bulk_pulses, 5u);
}

TEST(FirmwareTimers, WithoutThePreloadANewPeriodShortensThePeriodUnderWay) {
  Rig r(kL6474);
  r.enable();
  const int t = r.timer(400, r.pin("PB10"));
  r.rt.timers().set_preload(t, false);
  std::vector<Tick> updates;
  r.rt.timers().set_update_irq(t, r.rt.add_irq([&] {
    updates.push_back(r.rt.now());
    r.rt.timers().set_period(t, 100);
    r.rt.timers().set_compare(t, 50);
  }));
  r.rt.timers().start(t);
  r.rt.sleep_until(ticks_from_us(700) + 1);
  // The period written in the update at 400 us is the one under way: updates at 500, 600, 700.
  EXPECT_EQ(updates, (std::vector<Tick>{ticks_from_us(400), ticks_from_us(500), ticks_from_us(600), ticks_from_us(700)}));
  EXPECT_EQ(r.position(), 5) << "pulses rise at 0, 400, 500, 600 and 700 us";
}

TEST(FirmwareTimers, AStoppedTimerMovesNoMoreAndItsPinIsLow) {
  Rig r(kL6474);
  r.enable();
  const int t = r.timer(1000, r.pin("PB10"));
  r.rt.timers().start(t);
  r.rt.sleep_until(ticks_from_ms(10) + ticks_from_us(200));  // pulse 10 high
  r.rt.timers().stop(t);
  EXPECT_FALSE(r.rt.board().pin_level(0, 0, Pin::STCK));
  r.rt.sleep_until(ticks_from_ms(100));
  EXPECT_EQ(r.position(), 11);
  EXPECT_FALSE(r.rt.timers().running(t));
}

TEST(FirmwareTimers, ACountedTrainStopsAfterItsPulses) {
  Rig r(kL6474);
  r.enable();
  const int t = r.timer(1000, r.pin("PB10"));
  r.rt.timers().set_pulse_count(t, 123);
  r.rt.timers().start(t);
  r.rt.sleep_until(ticks_from_ms(1000));
  EXPECT_EQ(r.position(), 123);
}

}  // namespace
}  // namespace l6470emu::test
