/* A small L6470 driver written against board_hal.h (not against l6470emu), run on the emulator
 * through shim.c: a Move, a wait for BUSY, an alarm on FLAG. Exit status 0 when the chip does
 * what the driver expects. Run: build/examples/firmware_shim */
#include <stdio.h>

#include "board_hal.h"

static volatile int alarms;
static void on_alarm(void) { ++alarms; }

static uint8_t byte_frame(uint8_t b) {
  board_cs(0);
  const uint8_t in = board_spi_xfer(b);
  board_cs(1);
  return in;
}

static uint32_t command(uint8_t opcode, int args, uint32_t value, int answer) {
  uint32_t result = 0;
  byte_frame(opcode);
  for (int i = args - 1; i >= 0; --i) byte_frame((uint8_t)(value >> (8 * i)));
  for (int i = 0; i < answer; ++i) result = result << 8 | byte_frame(0);
  return result;
}

int main(void) {
  board_init();
  command(0xD0, 0, 0, 2); /* GetStatus: clears the power-up UVLO flag, FLAG goes high */
  board_on_flag(on_alarm);
  const uint32_t start = board_millis();
  command(0x40, 3, 12800, 0); /* Move(REV, 12800 microsteps) */
  const int was_busy = board_busy();
  board_wait_idle();
  const uint32_t took = board_millis() - start;
  const long pos = (long)command(0x21, 0, 0, 3);
  printf("moved to %ld in %u ms (virtual)\n", pos - (pos & 0x200000 ? 0x400000 : 0), (unsigned)took);
  byte_frame(0xF8); /* an unknown opcode: WRONG_CMD pulls FLAG low */
  printf("FLAG alarms: %d\n", alarms);
  return was_busy && pos == 0x400000 - 12800 && took > 400 && took < 700 && alarms == 1 ? 0 : 1;
}
