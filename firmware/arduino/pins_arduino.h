/* The pin numbers of the Arduino board the front imitates (docs/firmware.md, "Arduino boards"),
 * as the board's core defines them: an Uno by default, a NUCLEO-F401RE when the sketch is built
 * with l6470emu_add_sketch(... ARDUINO_BOARD nucleo_f401re) (the compile definition
 * L6470EMU_ARDUINO_BOARD_NUCLEO_F401RE, or the IDE's ARDUINO_NUCLEO_F401RE). Pin numbers only:
 * no board's peripherals. The STM32 port pins PA0..PH15 are 128..255 on every board
 * (stm32_pin_names.h). */
#ifndef L6470EMU_PINS_ARDUINO_H
#define L6470EMU_PINS_ARDUINO_H

#include <stdint.h>

#include "stm32_pin_names.h"

#if defined(L6470EMU_ARDUINO_BOARD_NUCLEO_F401RE) || defined(ARDUINO_NUCLEO_F401RE)
#ifndef ARDUINO_NUCLEO_F401RE
#define ARDUINO_NUCLEO_F401RE 1
#endif
#define L6470EMU_ARDUINO_BOARD "nucleo_f401re"

/* The Arduino header of a Nucleo-64 (STM32duino's variant_NUCLEO_F401RE.h): D0..D15 are port
 * pins, and the numbers 0..15 mean the same pins (digitalWrite(10, ...) drives PB6), as do
 * 0..15 in the board description (cs_pin=D10 is PB6). A0..A5 are PA0, PA1, PA4, PB0, PC1, PC0. */
#define D0 PA3
#define D1 PA2
#define D2 PA10
#define D3 PB3
#define D4 PB5
#define D5 PB4
#define D6 PB10
#define D7 PA8
#define D8 PA9
#define D9 PC7
#define D10 PB6
#define D11 PA7
#define D12 PA6
#define D13 PA5
#define D14 PB9
#define D15 PB8
/* A6..A15: the other ADC inputs STM32duino numbers so. */
static const uint8_t A0 = PA0;
static const uint8_t A1 = PA1;
static const uint8_t A2 = PA4;
static const uint8_t A3 = PB0;
static const uint8_t A4 = PC1;
static const uint8_t A5 = PC0;
static const uint8_t A6 = PA7;
static const uint8_t A7 = PA6;
static const uint8_t A8 = PC2;
static const uint8_t A9 = PC3;
static const uint8_t A10 = PC5;
static const uint8_t A11 = PB1;
static const uint8_t A12 = PC4;
static const uint8_t A13 = PA3;
static const uint8_t A14 = PA2;
static const uint8_t A15 = PA5;
static const uint8_t SS = PB6;
static const uint8_t MOSI = PA7;
static const uint8_t MISO = PA6;
static const uint8_t SCK = PA5;
#define LED_GREEN PA5
#define LED_BUILTIN LED_GREEN
#define USER_BTN PC13
#define PIN_SERIAL_RX PA3
#define PIN_SERIAL_TX PA2

#else /* an Uno */
#define L6470EMU_ARDUINO_BOARD "uno"

/* An Uno's numbers: D0..D13 are 0..13, A0..A5 14..19 (D14..D19), and A6, A7 20, 21 as on a
 * Nano. */
#define D0 0
#define D1 1
#define D2 2
#define D3 3
#define D4 4
#define D5 5
#define D6 6
#define D7 7
#define D8 8
#define D9 9
#define D10 10
#define D11 11
#define D12 12
#define D13 13
#define D14 14
#define D15 15
#define D16 16
#define D17 17
#define D18 18
#define D19 19
static const uint8_t SS = 10;
static const uint8_t MOSI = 11;
static const uint8_t MISO = 12;
static const uint8_t SCK = 13;
static const uint8_t A0 = 14;
static const uint8_t A1 = 15;
static const uint8_t A2 = 16;
static const uint8_t A3 = 17;
static const uint8_t A4 = 18;
static const uint8_t A5 = 19;
static const uint8_t A6 = 20;
static const uint8_t A7 = 21;
#define LED_BUILTIN 13
#endif

#define NUM_DIGITAL_PINS 256

#ifdef ARDUINO_NUCLEO_F401RE
/* Tells the runtime which board the sketch numbers its pins for (defined in every file that
 * includes this, weak: the linker keeps one). */
#ifdef __cplusplus
extern "C"
#endif
__attribute__((weak)) const char* l6470emu_fw_arduino_board(void) { return L6470EMU_ARDUINO_BOARD; }
#endif

#endif
