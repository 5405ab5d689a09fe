// The STM32F401's timer outputs on its port pins (its datasheet's alternate-function table,
// TIM1 to TIM5 and TIM9 to TIM11), the first listed for a pin being the PWM default.
#include "firmware/timer_pins.hpp"

#include <array>

namespace l6470emu {

namespace {

constexpr unsigned kPortPA = 0, kPortPB = 16, kPortPC = 32;

#define L6470EMU_TIMER_PIN_ROW(port, pin, timer, channel, af, inverted) \
  TimerPin{kPort##port + pin, timer, channel, af, inverted != 0},
constexpr TimerPin kPins[] = {L6470EMU_F401_TIMER_PINS(L6470EMU_TIMER_PIN_ROW)};
#undef L6470EMU_TIMER_PIN_ROW

}  // namespace

std::optional<TimerPin> default_timer_pin(unsigned port_pin) {
  for (const TimerPin& p : kPins)
    if (p.port_pin == port_pin) return p;
  return std::nullopt;
}

std::optional<TimerPin> timer_pin(unsigned port_pin, unsigned timer, unsigned af) {
  for (const TimerPin& p : kPins)
    if (p.port_pin == port_pin && p.timer == timer && p.af == af) return p;
  return std::nullopt;
}

std::optional<TimerPin> timer_channel_pin(unsigned timer, unsigned channel, const unsigned* port_pins, unsigned count) {
  for (unsigned i = 0; i < count; ++i)
    for (const TimerPin& p : kPins)
      if (p.port_pin == port_pins[i] && p.timer == timer && p.channel == channel) return p;
  return std::nullopt;
}

}  // namespace l6470emu
