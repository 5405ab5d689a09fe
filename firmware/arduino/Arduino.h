/* The Arduino core API on the desktop (l6470emu's firmware front, docs/firmware.md): pins, time,
 * interrupts, Serial and String over an emulated board in virtual time, so that a sketch or a
 * driver library compiles unmodified and runs against emulated chips. It models no AVR, ESP32
 * or STM32 registers, no analog world and no UART timing. */
#ifndef Arduino_h
#define Arduino_h

#include <math.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "avr/pgmspace.h"

/* The IDE version libraries test (#if ARDUINO >= 100), and a name to test for this front. */
#ifndef ARDUINO
#define ARDUINO 10819
#endif
#define L6470EMU_FIRMWARE 1
#define ARDUINO_ARCH_L6470EMU 1
#ifndef F_CPU
#define F_CPU 16000000UL
#endif

#define HIGH 0x1
#define LOW 0x0

#define INPUT 0x0
#define OUTPUT 0x1
#define INPUT_PULLUP 0x2
#define INPUT_PULLDOWN 0x3
#define OUTPUT_OPEN_DRAIN 0x4

#define LSBFIRST 0
#define MSBFIRST 1

/* attachInterrupt modes (LOW fires while the pin reads low). */
#define CHANGE 1
#define FALLING 2
#define RISING 3

#define DEC 10
#define HEX 16
#define OCT 8
#define BIN 2

#define PI 3.1415926535897932384626433832795
#define HALF_PI 1.5707963267948966192313216916398
#define TWO_PI 6.283185307179586476925286766559
#define DEG_TO_RAD 0.017453292519943295769236907684886
#define RAD_TO_DEG 57.295779513082320876798154814105
#define EULER 2.718281828459045235360287471352

#define NOT_A_PIN 0
#define NOT_AN_INTERRUPT -1
/* Every pin can interrupt here, and its interrupt number is its pin number. */
#define digitalPinToInterrupt(p) ((int)(p))
#define digitalPinIsValid(p) ((p) < 256)

#define constrain(amt, low, high) ((amt) < (low) ? (low) : ((amt) > (high) ? (high) : (amt)))
#define radians(deg) ((deg) * DEG_TO_RAD)
#define degrees(rad) ((rad) * RAD_TO_DEG)
#define sq(x) ((x) * (x))

#define lowByte(w) ((uint8_t)((w) & 0xff))
#define highByte(w) ((uint8_t)((w) >> 8))
#define bitRead(value, bit) (((value) >> (bit)) & 0x01)
#define bitSet(value, bit) ((value) |= (1UL << (bit)))
#define bitClear(value, bit) ((value) &= ~(1UL << (bit)))
#define bitToggle(value, bit) ((value) ^= (1UL << (bit)))
#define bitWrite(value, bit, bitvalue) ((bitvalue) ? bitSet(value, bit) : bitClear(value, bit))
#define bit(b) (1UL << (b))
#define _BV(b) (1UL << (b))

#define clockCyclesPerMicrosecond() (F_CPU / 1000000L)
#define clockCyclesToMicroseconds(a) ((a) / clockCyclesPerMicrosecond())
#define microsecondsToClockCycles(a) ((a) * clockCyclesPerMicrosecond())

/* Attributes other cores put on interrupt handlers. */
#ifndef IRAM_ATTR
#define IRAM_ATTR
#endif
#ifndef ICACHE_RAM_ATTR
#define ICACHE_RAM_ATTR
#endif

typedef uint8_t byte;
typedef bool boolean;
typedef uint16_t word;
typedef uint8_t pin_size_t;
typedef int PinStatus;
typedef int PinMode;
typedef int BitOrder;

/* Pin numbers: the imitated board's (pins_arduino.h: an Uno's by default, D0..D19 and A0..A7 =
 * 14..21; a NUCLEO-F401RE's on request, D0..D15 its header's port pins) and the STM32 port pins
 * PA0..PH15 = 128..255 (STM32duino sketches name pins so). */
#include "pins_arduino.h"
#include "binary.h"

/* The Cortex-M intrinsics STM32duino sketches and libraries call (CMSIS's): the barriers and
 * wait-for-interrupt do nothing here; __disable_irq/__enable_irq are noInterrupts/interrupts. */
#ifndef __NOP
#define __NOP() ((void)0)
#endif
#ifndef __DSB
#define __DSB() ((void)0)
#endif
#ifndef __ISB
#define __ISB() ((void)0)
#endif
#ifndef __DMB
#define __DMB() ((void)0)
#endif
#ifndef __WFI
#define __WFI() ((void)0)
#endif

#ifdef __cplusplus
extern "C" {
#endif

void pinMode(uint8_t pin, uint8_t mode);
void digitalWrite(uint8_t pin, uint8_t val);
int digitalRead(uint8_t pin);
/* No analog world: analogRead reads 0. analogWrite is a PWM from a timer (docs/firmware.md,
 * "Timers"): on an Uno 490 Hz on pins 3, 9, 10, 11 and 977 Hz on 5 and 6, other pins high from
 * 128 up; on a NUCLEO-F401RE analogWriteFrequency (1 kHz by default) on the pins with a timer.
 * tone() is a 50 % square wave of exactly `frequency` Hz, `frequency` × `duration` / 1000
 * pulses when a duration is given. */
int analogRead(uint8_t pin);
void analogReference(uint8_t mode);
void analogWrite(uint8_t pin, int val);
void analogReadResolution(int bits);
void analogWriteResolution(int bits);
void analogWriteFrequency(uint32_t frequency);

unsigned long millis(void);
unsigned long micros(void);
void delay(unsigned long ms);
void delayMicroseconds(unsigned int us);
unsigned long pulseIn(uint8_t pin, uint8_t state, unsigned long timeout);
unsigned long pulseInLong(uint8_t pin, uint8_t state, unsigned long timeout);

void shiftOut(uint8_t dataPin, uint8_t clockPin, uint8_t bitOrder, uint8_t val);
uint8_t shiftIn(uint8_t dataPin, uint8_t clockPin, uint8_t bitOrder);

void attachInterrupt(uint8_t interruptNum, void (*userFunc)(void), int mode);
void attachInterruptArg(uint8_t interruptNum, void (*userFunc)(void*), void* arg, int mode);
void detachInterrupt(uint8_t interruptNum);
void interrupts(void);
void noInterrupts(void);
void __disable_irq(void);
void __enable_irq(void);

void yield(void);

/* The sketch's own. */
void setup(void);
void loop(void);

#ifdef __cplusplus
} /* extern "C" */

#include "WString.h"
#include "HardwareSerial.h"
#ifdef ARDUINO_NUCLEO_F401RE
#include "HardwareTimer.h" /* as STM32duino's Arduino.h: its timers and the pin map */
#endif

/* C++: the helpers the Arduino core gives sketches as templates and overloads. */
template <class T, class L>
auto min(const T& a, const L& b) -> decltype((b < a) ? b : a) {
  return (b < a) ? b : a;
}
template <class T, class L>
auto max(const T& a, const L& b) -> decltype((b < a) ? b : a) {
  return (a < b) ? b : a;
}

uint16_t makeWord(uint16_t w);
uint16_t makeWord(uint8_t h, uint8_t l);
#define word(...) makeWord(__VA_ARGS__)

unsigned long pulseIn(uint8_t pin, uint8_t state);
void tone(uint8_t pin, unsigned int frequency, unsigned long duration = 0);
void noTone(uint8_t pin);

/* Deterministic pseudo-random numbers (the same sequence every run; randomSeed restarts it). */
long random(long howbig);
long random(long howsmall, long howbig);
void randomSeed(unsigned long seed);
long map(long value, long fromLow, long fromHigh, long toLow, long toHigh);

#endif /* __cplusplus */

#endif /* Arduino_h */
