/* board_hal.h on l6470emu's plain C API: the whole port of a driver to the emulator. */
#include <l6470emu/firmware/firmware.h>

#include "board_hal.h"

static int bus, cs, busy, flag;
static const struct l6470emu_fw_spi_config mode3 = {4000000, 3, 0}; /* 4 MHz, CPOL 1 CPHA 1, MSB first */
static void (*flag_handler)(void);
static void on_edge(int pin, int level, void* arg) { (void)pin, (void)level, (void)arg, flag_handler(); }

void board_init(void) {
  bus = l6470emu_fw_spi_bus("SPI1");
  cs = l6470emu_fw_pin("PA4"), busy = l6470emu_fw_pin("PB0"), flag = l6470emu_fw_pin("PB1");
  l6470emu_fw_pin_mode(cs, L6470EMU_FW_OUTPUT);
  l6470emu_fw_pin_write(cs, 1);
}
void board_cs(int level) { l6470emu_fw_pin_write(cs, level); }
uint8_t board_spi_xfer(uint8_t byte) {
  uint8_t in = 0;
  l6470emu_fw_spi_transfer(bus, -1, &mode3, &byte, &in, 1);
  return in;
}
int board_busy(void) { return l6470emu_fw_pin_read(busy) == 0; }
void board_wait_idle(void) { l6470emu_fw_pin_wait(busy, 1, UINT64_MAX); }
void board_on_flag(void (*handler)(void)) {
  flag_handler = handler;
  l6470emu_fw_pin_on_edge(flag, L6470EMU_FW_EDGE_FALLING, on_edge, 0);
}
uint32_t board_millis(void) { return (uint32_t)(l6470emu_fw_now_ns() / 1000000u); }
