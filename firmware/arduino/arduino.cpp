// The Arduino core functions over the FirmwareRuntime: pins, time, interrupts, pulses, random
// numbers. Each is one HAL call (its cost passes first, then pending interrupts run).
// The model first: Arduino.h's macros (HIGH, DEC, ...) must not reach its headers.
#include "firmware/arduino/arduino_internal.hpp"

#include <algorithm>
#include <array>

#include "Arduino.h"

using l6470emu::FirmwareFront;
using l6470emu::FirmwareRuntime;
using l6470emu::Tick;

namespace l6470emu::arduino {

FirmwareRuntime& runtime() { return firmware_runtime(FirmwareFront::arduino); }

namespace {

struct Attached {
  void (*isr)(void) = nullptr;
  void (*isr_arg)(void*) = nullptr;
  void* arg = nullptr;
  int irq = -1;
  bool attached = false;
};
std::array<Attached, 256> g_attached{};

}  // namespace

int irq_of_interrupt(int interrupt_number) {
  if (interrupt_number < 0 || interrupt_number >= 256) return -1;
  return g_attached[static_cast<std::size_t>(interrupt_number)].irq;
}

}  // namespace l6470emu::arduino

using l6470emu::arduino::runtime;

extern "C" {

void pinMode(uint8_t pin, uint8_t mode) {
  FirmwareRuntime& r = runtime();
  r.call();
  l6470emu::McuPinMode m = l6470emu::McuPinMode::input;
  switch (mode) {
    case OUTPUT: m = l6470emu::McuPinMode::output; break;
    case INPUT_PULLUP: m = l6470emu::McuPinMode::input_pullup; break;
    case INPUT_PULLDOWN: m = l6470emu::McuPinMode::input_pulldown; break;
    case OUTPUT_OPEN_DRAIN: m = l6470emu::McuPinMode::output_open_drain; break;
    default: break;
  }
  r.set_pin_mode(r.arduino_pin(pin), m);
}

void digitalWrite(uint8_t pin, uint8_t val) {
  FirmwareRuntime& r = runtime();
  r.call();
  r.write_pin(r.arduino_pin(pin), val != LOW);
}

int digitalRead(uint8_t pin) {
  FirmwareRuntime& r = runtime();
  r.call();
  return r.read_pin(r.arduino_pin(pin)) ? HIGH : LOW;
}

int analogRead(uint8_t) {
  runtime().call();
  return 0;
}

void analogReference(uint8_t) { runtime().call(); }
void analogReadResolution(int) { runtime().call(); }

unsigned long millis(void) {
  FirmwareRuntime& r = runtime();
  r.call();
  return l6470emu::board_millis(r.now());
}

unsigned long micros(void) {
  FirmwareRuntime& r = runtime();
  r.call();
  return l6470emu::board_micros(r.now());
}

void delay(unsigned long ms) {
  FirmwareRuntime& r = runtime();
  r.call();
  r.sleep_until(r.now() + l6470emu::ticks_from_ms(ms));
}

void delayMicroseconds(unsigned int us) {
  FirmwareRuntime& r = runtime();
  r.call();
  r.sleep_until(r.now() + l6470emu::ticks_from_us(us));
}

unsigned long pulseIn(uint8_t pin_number, uint8_t state, unsigned long timeout) {
  FirmwareRuntime& r = runtime();
  r.call();
  const int pin = r.arduino_pin(pin_number);
  const Tick end = r.now() + l6470emu::ticks_from_us(timeout);
  const bool level = state != LOW;
  // A pulse already under way is not counted: wait for it to end, then for one to start.
  if (!r.wait_for_level(pin, !level, end) || !r.wait_for_level(pin, level, end)) return 0;
  const Tick start = r.now();
  if (!r.wait_for_level(pin, !level, end)) return 0;
  return static_cast<unsigned long>((r.now() - start) / l6470emu::kTicksPerMicrosecond);
}

unsigned long pulseInLong(uint8_t pin, uint8_t state, unsigned long timeout) { return pulseIn(pin, state, timeout); }

void shiftOut(uint8_t dataPin, uint8_t clockPin, uint8_t bitOrder, uint8_t val) {
  for (int i = 0; i < 8; ++i) {
    const int b = bitOrder == LSBFIRST ? i : 7 - i;
    digitalWrite(dataPin, (val >> b) & 1);
    digitalWrite(clockPin, HIGH);
    digitalWrite(clockPin, LOW);
  }
}

uint8_t shiftIn(uint8_t dataPin, uint8_t clockPin, uint8_t bitOrder) {
  uint8_t value = 0;
  for (int i = 0; i < 8; ++i) {
    digitalWrite(clockPin, HIGH);
    const int b = bitOrder == LSBFIRST ? i : 7 - i;
    value |= static_cast<uint8_t>(digitalRead(dataPin) << b);
    digitalWrite(clockPin, LOW);
  }
  return value;
}

static void attach(uint8_t number, void (*isr)(void), void (*isr_arg)(void*), void* arg, int mode) {
  FirmwareRuntime& r = runtime();
  r.call();
  auto& a = l6470emu::arduino::g_attached[number];
  const int pin = r.arduino_pin(number);  // digitalPinToInterrupt(p) == p
  a.isr = isr;
  a.isr_arg = isr_arg;
  a.arg = arg;
  if (a.irq < 0)
    a.irq = r.add_irq([number] {
      const auto& at = l6470emu::arduino::g_attached[number];
      if (at.isr) at.isr();
      if (at.isr_arg) at.isr_arg(at.arg);
    });
  r.clear_irq(a.irq);
  r.set_irq_enabled(a.irq, true);
  a.attached = true;
  const int irq = a.irq;
  if (mode == LOW) {
    r.watch_pin(pin, 0, nullptr);
    r.watch_level(pin, false, [&r, irq](bool) { r.pend_irq(irq); });
    return;
  }
  const unsigned edges = mode == RISING ? l6470emu::kEdgeRising : mode == FALLING ? l6470emu::kEdgeFalling : l6470emu::kEdgeBoth;
  r.watch_level(pin, false, nullptr);
  r.watch_pin(pin, edges, [&r, irq](bool) { r.pend_irq(irq); });
}

void attachInterrupt(uint8_t interruptNum, void (*userFunc)(void), int mode) {
  attach(interruptNum, userFunc, nullptr, nullptr, mode);
}

void attachInterruptArg(uint8_t interruptNum, void (*userFunc)(void*), void* arg, int mode) {
  attach(interruptNum, nullptr, userFunc, arg, mode);
}

void detachInterrupt(uint8_t interruptNum) {
  FirmwareRuntime& r = runtime();
  r.call();
  auto& a = l6470emu::arduino::g_attached[interruptNum];
  if (!a.attached) return;
  a.attached = false;
  r.watch_pin(r.arduino_pin(interruptNum), 0, nullptr);
  r.watch_level(r.arduino_pin(interruptNum), false, nullptr);
  r.clear_irq(a.irq);
  r.set_irq_enabled(a.irq, false);
}

void interrupts(void) {
  FirmwareRuntime& r = runtime();
  r.call();
  r.enable_interrupts();
}

void noInterrupts(void) {
  FirmwareRuntime& r = runtime();
  r.call();
  r.disable_interrupts();
}

void __disable_irq(void) { noInterrupts(); }
void __enable_irq(void) { interrupts(); }

void yield(void) { runtime().call(); }

}  // extern "C"

unsigned long pulseIn(uint8_t pin, uint8_t state) { return pulseIn(pin, state, 1000000UL); }


uint16_t makeWord(uint16_t w) { return w; }
uint16_t makeWord(uint8_t h, uint8_t l) { return static_cast<uint16_t>(h << 8 | l); }

namespace {
// A small deterministic generator (xorshift64*), so that runs repeat exactly.
std::uint64_t g_random_state = 0x9E3779B97F4A7C15ull;
std::uint64_t next_random() {
  std::uint64_t x = g_random_state;
  x ^= x >> 12;
  x ^= x << 25;
  x ^= x >> 27;
  g_random_state = x;
  return x * 0x2545F4914F6CDD1Dull;
}
}  // namespace

long random(long howbig) {
  if (howbig <= 0) return 0;
  return static_cast<long>(next_random() % static_cast<std::uint64_t>(howbig));
}

long random(long howsmall, long howbig) {
  if (howsmall >= howbig) return howsmall;
  return howsmall + random(howbig - howsmall);
}

void randomSeed(unsigned long seed) {
  if (seed != 0) g_random_state = 0x9E3779B97F4A7C15ull ^ seed;
}

long map(long value, long fromLow, long fromHigh, long toLow, long toHigh) {
  if (fromHigh == fromLow) return toLow;
  return (value - fromLow) * (toHigh - toLow) / (fromHigh - fromLow) + toLow;
}
