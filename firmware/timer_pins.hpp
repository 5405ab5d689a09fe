// Which timer channel drives which STM32F401 port pin (the NUCLEO-F401RE's): the pins an
// X-NUCLEO board's STCK can be on, from the F401's alternate-function table, with the
// alternate-function number HAL_GPIO_Init gives them. The timers' input clock on that board.
// Not a full pin table of any other family.
#pragma once

#include <cstdint>
#include <optional>

namespace l6470emu {

/// The table, one X(port, pin, timer, channel, af, complementary) per row, in the F401
/// datasheet's alternate-function order (the first row of a pin is its PWM default). An X-macro:
/// the pin map of the Arduino front (PinMap_PWM) expands the same rows.
#define L6470EMU_F401_TIMER_PINS(X) \
  X(PA, 0, 2, 1, 1, 0) X(PA, 0, 5, 1, 2, 0) X(PA, 1, 2, 2, 1, 0) X(PA, 1, 5, 2, 2, 0) \
  X(PA, 2, 2, 3, 1, 0) X(PA, 2, 5, 3, 2, 0) X(PA, 2, 9, 1, 3, 0) X(PA, 3, 2, 4, 1, 0) \
  X(PA, 3, 5, 4, 2, 0) X(PA, 3, 9, 2, 3, 0) X(PA, 5, 2, 1, 1, 0) X(PA, 6, 3, 1, 2, 0) \
  X(PA, 7, 1, 1, 1, 1) X(PA, 7, 3, 2, 2, 0) X(PA, 8, 1, 1, 1, 0) X(PA, 9, 1, 2, 1, 0) \
  X(PA, 10, 1, 3, 1, 0) X(PA, 11, 1, 4, 1, 0) X(PA, 15, 2, 1, 1, 0) X(PB, 0, 1, 2, 1, 1) \
  X(PB, 0, 3, 3, 2, 0) X(PB, 1, 1, 3, 1, 1) X(PB, 1, 3, 4, 2, 0) X(PB, 3, 2, 2, 1, 0) \
  X(PB, 4, 3, 1, 2, 0) X(PB, 5, 3, 2, 2, 0) X(PB, 6, 4, 1, 2, 0) X(PB, 7, 4, 2, 2, 0) \
  X(PB, 8, 4, 3, 2, 0) X(PB, 8, 10, 1, 3, 0) X(PB, 9, 4, 4, 2, 0) X(PB, 9, 11, 1, 3, 0) \
  X(PB, 10, 2, 3, 1, 0) X(PB, 13, 1, 1, 1, 1) X(PB, 14, 1, 2, 1, 1) X(PB, 15, 1, 3, 1, 1) \
  X(PC, 6, 3, 1, 2, 0) X(PC, 7, 3, 2, 2, 0) X(PC, 8, 3, 3, 2, 0) X(PC, 9, 3, 4, 2, 0)

/// A timer output on a port pin: TIM`timer` channel `channel` (1..4; `complementary` for CHxN)
/// through alternate function `af`.
struct TimerPin {
  std::uint8_t port_pin = 0;  ///< port × 16 + pin (PA0 = 0, PC7 = 39)
  std::uint8_t timer = 0;     ///< TIMx's x
  std::uint8_t channel = 0;
  std::uint8_t af = 0;
  bool complementary = false;
};

/// The timer output on `port_pin` that a PWM on it uses by default (the first the table
/// lists for it); nullopt for a pin without one.
std::optional<TimerPin> default_timer_pin(unsigned port_pin);
/// The output of TIM`timer` on `port_pin` through alternate function `af`, if the F401 has one.
std::optional<TimerPin> timer_pin(unsigned port_pin, unsigned timer, unsigned af);
/// The pin TIM`timer` channel `channel` reaches among
/// `port_pins` (those the program configured), nullopt when none.
std::optional<TimerPin> timer_channel_pin(unsigned timer, unsigned channel, const unsigned* port_pins, unsigned count);

/// The timers' input clock on a NUCLEO-F401RE at 84 MHz (SYSCLK 84 MHz, APB1 42 MHz whose
/// timers run at twice it, APB2 84 MHz): every timer counts 84 MHz before its prescaler.
inline constexpr std::uint64_t kF401TimerClockHz = 84'000'000;

}  // namespace l6470emu
