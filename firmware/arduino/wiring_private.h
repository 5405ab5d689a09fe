/* The AVR core's internal header that some libraries include: Arduino.h, the interrupt header,
 * the sbi/cbi register-bit macros (on a variable here: no AVR registers are modelled) and the
 * handler pointer types. */
#ifndef WiringPrivate_h
#define WiringPrivate_h

#include "Arduino.h"
#include "avr/interrupt.h"

#ifndef cbi
#define cbi(sfr, bit) ((sfr) &= ~_BV(bit))
#endif
#ifndef sbi
#define sbi(sfr, bit) ((sfr) |= _BV(bit))
#endif

#define EXTERNAL_NUM_INTERRUPTS 256

#ifdef __cplusplus
extern "C" {
#endif
typedef void (*voidFuncPtr)(void);
typedef void (*voidFuncPtrParam)(void*);
#ifdef __cplusplus
}
#endif

#endif
