/* The HAL a driver was written for: a chip select, one SPI byte at a time, the BUSY pin, a
 * delay and a FLAG interrupt (think of libopencm3's gpio_set/spi_xfer, a Zephyr spi_dt_spec,
 * ESP-IDF's spi_device_transmit). shim.c implements it on l6470emu's C API. */
#ifndef BOARD_HAL_H
#define BOARD_HAL_H
#include <stdint.h>

void board_init(void);
void board_cs(int level);
uint8_t board_spi_xfer(uint8_t byte);
int board_busy(void);
void board_wait_idle(void);
void board_on_flag(void (*handler)(void));
uint32_t board_millis(void);

#endif
