/* avr-libc's cli()/sei() for code written for AVRs: the emulated microcontroller's interrupts
 * off and on (noInterrupts()/interrupts()). AVR interrupt vectors (ISR()) are not modelled. */
#ifndef L6470EMU_AVR_INTERRUPT_H
#define L6470EMU_AVR_INTERRUPT_H

#include "Arduino.h"

#define cli() noInterrupts()
#define sei() interrupts()

#endif
