/* The plain C API of a firmware run on the desktop (Zephyr, ESP-IDF, libopencm3, bare metal
 * drivers wrap it in their own HAL): an emulated board in virtual time, its SPI buses with chip
 * selects, its pins with edges, a clock and sleeps. Not the Arduino or STM32 HAL API (those are
 * firmware/arduino and firmware/stm32), and not thread-safe: a firmware program has one thread;
 * edge callbacks run inside the calls below, never concurrently. docs/firmware.md has the
 * model; installed as <l6470emu/firmware/firmware.h>, linked as l6470emu::firmware. */
#ifndef L6470EMU_FIRMWARE_FIRMWARE_H
#define L6470EMU_FIRMWARE_FIRMWARE_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Opens the board from `description` (the board description's syntax: "chips=3xL6470
 *  cs_pin=D10 flag_pin=D2"), or with NULL from L6470EMU_CHAIN, L6470EMU_CONFIG, the
 *  description the program was built with, or one L6470 (in that order). Returns 0, or -1 with
 *  l6470emu_fw_error() saying why (a bad description, or a board already open: one per
 *  program). The other calls open the board with NULL if nothing opened it before. */
int l6470emu_fw_open(const char *description);

/** The last error as one line ("" when none). */
const char *l6470emu_fw_error(void);

/** Closes the recordings (trace= / L6470EMU_TRACE) with the pins' levels at the end; exit
 *  does it too. */
void l6470emu_fw_close(void);

/* ---- pins -------------------------------------------------------------------------------- */

/** The number of the microcontroller pin called `name` as the board description writes it
 *  ("D10", "10", "A0", "GPIO5", "PA4"), for the calls below; -1 when it is no pin name. */
int l6470emu_fw_pin(const char *name);

/** Pin modes (l6470emu_fw_pin_mode). */
enum {
  L6470EMU_FW_INPUT = 0,
  L6470EMU_FW_INPUT_PULLUP = 1,
  L6470EMU_FW_INPUT_PULLDOWN = 2,
  L6470EMU_FW_OUTPUT = 3,
  L6470EMU_FW_OUTPUT_OPEN_DRAIN = 4
};

/** Sets a pin's mode. Returns 0, or -1 for a bad pin or mode. */
int l6470emu_fw_pin_mode(int pin, int mode);
/** Sets a pin's output level (0 or 1; it drives it in an output mode). Returns 0 or -1. */
int l6470emu_fw_pin_write(int pin, int level);
/** The level a pin reads now: 0, 1, or -1 for a bad pin. */
int l6470emu_fw_pin_read(int pin);
/** Waits until the pin reads `level`: returns 0 when it does (at once if it already does), 1
 *  when `timeout_ns` of virtual time passed first, -1 for a bad pin. Edge callbacks run on the
 *  way. A BUSY or FLAG pin is waited for to its exact edge; any other pin is looked at each
 *  microsecond. */
int l6470emu_fw_pin_wait(int pin, int level, uint64_t timeout_ns);

/** Edges, as a bit set. */
enum { L6470EMU_FW_EDGE_NONE = 0, L6470EMU_FW_EDGE_RISING = 1, L6470EMU_FW_EDGE_FALLING = 2, L6470EMU_FW_EDGE_BOTH = 3 };
/** An edge callback: the pin, its level after the edge, the caller's argument. */
typedef void (*l6470emu_fw_edge_fn)(int pin, int level, void *arg);
/** Calls `fn(pin, level, arg)` for each edge of the pin in `edges` (an interrupt: it runs at the
 *  first call at or after the edge's tick, or at the edge's tick during a sleep or a wait; never
 *  while interrupts are disabled, nor inside another callback). `edges` NONE removes it.
 *  Returns 0 or -1. */
int l6470emu_fw_pin_on_edge(int pin, int edges, l6470emu_fw_edge_fn fn, void *arg);
/** Interrupts off and on (a critical section); on delivers what became pending meanwhile. */
void l6470emu_fw_irq_disable(void);
void l6470emu_fw_irq_enable(void);

/* ---- SPI --------------------------------------------------------------------------------- */

/** The SPI bus (controller) called `name` ("SPI", "SPI1", "hspi1", "VSPI"; docs/firmware.md),
 *  NULL for the first one; a board with one bus answers to every name. -1 when none. */
int l6470emu_fw_spi_bus(const char *name);

/** How a transfer clocks the bus. Zeros mean: 5 MHz, mode 0, MSB first. */
struct l6470emu_fw_spi_config {
  uint32_t speed_hz;  /**< SCK in Hz: each byte takes 8 / speed_hz of virtual time */
  uint8_t mode;       /**< SPI mode 0 to 3 (CPOL × 2 + CPHA); the chips need 3 */
  uint8_t lsb_first;  /**< non-zero: least significant bit first */
};

/** Clocks `len` bytes of `tx` (NULL: zeros) on `bus` and puts MISO into `rx` (NULL: dropped).
 *  With `cs_pin` >= 0 the call drives that pin low first, lets one call's time pass, clocks the
 *  bytes and drives it high after them (one frame); with -1 the caller drives its chip selects
 *  with l6470emu_fw_pin_write. Returns 0, or -1 for a bad bus, pin, mode or buffer. */
int l6470emu_fw_spi_transfer(int bus, int cs_pin, const struct l6470emu_fw_spi_config *config, const uint8_t *tx,
                             uint8_t *rx, size_t len);

/* ---- time -------------------------------------------------------------------------------- */

/** Virtual nanoseconds since the program started (250 ns steps). */
uint64_t l6470emu_fw_now_ns(void);
/** Lets `ns` of virtual time pass (edge callbacks run at their edges' ticks). */
void l6470emu_fw_sleep_ns(uint64_t ns);
/** Charges one HAL call's cost (call_time=) and runs pending callbacks: for a wrapper's own
 *  calls that do nothing else here, such as a busy loop reading a clock. Every call above
 *  charges it already. */
void l6470emu_fw_call(void);

#ifdef __cplusplus
}
#endif

#endif /* L6470EMU_FIRMWARE_FIRMWARE_H */
