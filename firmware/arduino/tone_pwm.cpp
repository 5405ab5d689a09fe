// tone(), noTone() and analogWrite() as the timers of the imitated board make them: a square
// wave of the exact frequency, and a PWM whose frequency is the board's (an Uno's Timer0/1/2 at
// 16 MHz / 64; a NUCLEO-F401RE's TIMx at 84 MHz, analogWriteFrequency). An Uno's phase-correct
// PWM is modelled left-aligned: the same pulses per second and high time, shifted in the period.
// The model first: Arduino.h's macros (HIGH, DEC, ...) must not reach its headers.
#include "firmware/arduino/arduino_internal.hpp"
#include "firmware/timer_pins.hpp"

#include <string>

#include "Arduino.h"

using l6470emu::ArduinoBoard;
using l6470emu::FirmwareRuntime;
using l6470emu::FirmwareTimers;
using l6470emu::arduino::runtime;

namespace {

int g_tone_pin = -1;               // the pin a tone is on (one at a time, as on an Uno)
uint32_t g_write_frequency = 1000;  // analogWriteFrequency (a NUCLEO's PWM)
int g_write_bits = 8;               // analogWriteResolution

/// The runtime timer called `name`, made at its first use.
int timer_named(FirmwareRuntime& r, const std::string& name) {
  FirmwareTimers& t = r.timers();
  const int found = t.find(name);
  return found >= 0 ? found : t.add(name);
}

/// Starts timer `id` afresh with these settings, its output on `key`.
void run_timer(FirmwareRuntime& r, int id, uint64_t clock_hz, uint32_t prescaler, uint64_t period, uint64_t compare,
               int key, uint64_t pulses = 0) {
  FirmwareTimers& t = r.timers();
  t.stop(id);
  t.set_clock(id, clock_hz);
  t.set_prescaler(id, prescaler);
  t.set_period(id, period);
  t.set_compare(id, compare);
  t.set_pulse_count(id, pulses);
  t.set_output(id, key);
  t.start(id);
}

/// How an Uno's pin makes its PWM: Timer0's fast PWM (pins 5, 6), Timer1's and Timer2's
/// phase-correct one (3, 9, 10, 11), or none.
enum class UnoPwm { none, fast, phase_correct };
UnoPwm uno_pwm(uint8_t pin) {
  switch (pin) {
    case 5: case 6: return UnoPwm::fast;
    case 3: case 9: case 10: case 11: return UnoPwm::phase_correct;
    default: return UnoPwm::none;
  }
}

}  // namespace

extern "C" {

void analogWriteResolution(int bits) {
  FirmwareRuntime& r = runtime();
  r.call();
  if (bits < 1 || bits > 16) return r.log("analogWriteResolution(" + std::to_string(bits) + "): 1 to 16 bits; unchanged");
  g_write_bits = bits;
}

void analogWriteFrequency(uint32_t frequency) {
  FirmwareRuntime& r = runtime();
  r.call();
  if (frequency == 0) return r.log("analogWriteFrequency(0): no period; unchanged");
  g_write_frequency = frequency;
}

void analogWrite(uint8_t pin, int val) {
  FirmwareRuntime& r = runtime();
  r.call();
  const int key = r.arduino_pin(pin);
  r.set_pin_mode(key, l6470emu::McuPinMode::output);
  const bool nucleo = r.arduino_board() == ArduinoBoard::nucleo_f401re;
  const long full = nucleo ? (1L << g_write_bits) - 1 : 255;
  const std::string name = "pwm " + std::to_string(key);
  auto steady = [&](bool level) {
    if (const int id = r.timers().find(name); id >= 0) r.timers().stop(id);
    r.write_pin(key, level);
  };
  const auto tp = key >= 128 ? l6470emu::default_timer_pin(static_cast<unsigned>(key - 128)) : std::nullopt;
  const UnoPwm uno = nucleo ? UnoPwm::none : uno_pwm(pin);
  if ((nucleo && !tp) || (!nucleo && uno == UnoPwm::none)) return steady(val >= (full + 1) / 2);  // no PWM on the pin
  if (val <= 0) return steady(false);
  if (val >= full) return steady(true);
  const int id = timer_named(r, name);
  if (nucleo) {
    // STM32duino: HardwareTimer::setPWM at analogWriteFrequency, the duty at the resolution.
    const uint64_t cycles = l6470emu::kF401TimerClockHz / g_write_frequency;
    const auto prescaler = static_cast<uint32_t>(cycles / 0x10000 + 1);
    const uint64_t period = cycles / prescaler;
    run_timer(r, id, l6470emu::kF401TimerClockHz, prescaler, period, period * static_cast<uint64_t>(val) / full, key);
    return;
  }
  // An Uno's timers count 16 MHz / 64 = 250 kHz: Timer0 in fast PWM (256 counts, high for
  // OCR + 1: 976.5625 Hz), Timer1 and Timer2 phase-correct (510 counts, high for 2 × OCR: 490.196 Hz).
  if (uno == UnoPwm::fast)
    run_timer(r, id, 250'000, 1, 256, static_cast<uint64_t>(val) + 1, key);
  else
    run_timer(r, id, 250'000, 1, 510, 2 * static_cast<uint64_t>(val), key);
}

}  // extern "C"

void tone(uint8_t pin, unsigned int frequency, unsigned long duration) {
  FirmwareRuntime& r = runtime();
  r.call();
  const int key = r.arduino_pin(pin);
  if (g_tone_pin >= 0 && g_tone_pin != key) return;  // one tone at a time: another pin's call does nothing
  if (frequency == 0) return noTone(pin);
  r.set_pin_mode(key, l6470emu::McuPinMode::output);
  g_tone_pin = key;
  // A counter at twice the frequency, two counts a period, high for one: exactly `frequency` Hz.
  const uint64_t pulses = duration ? static_cast<uint64_t>(frequency) * duration / 1000 : 0;
  if (duration && pulses == 0) return noTone(pin);
  run_timer(r, timer_named(r, "tone"), 2 * static_cast<uint64_t>(frequency), 1, 2, 1, key, pulses);
}

void noTone(uint8_t pin) {
  FirmwareRuntime& r = runtime();
  r.call();
  if (g_tone_pin < 0 || g_tone_pin != r.arduino_pin(pin)) return;
  r.timers().stop(timer_named(r, "tone"));
  g_tone_pin = -1;
}
