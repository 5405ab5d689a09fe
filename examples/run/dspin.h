/* The few lines of spidev plumbing the run examples share: one L6470 on /dev/spidev0.0, one byte
   per chip-select frame (a chain of one), as a plain C driver would write them. Not a library. */
#ifndef DSPIN_EXAMPLE_H
#define DSPIN_EXAMPLE_H

#include <fcntl.h>
#include <linux/spi/spidev.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <time.h>
#include <unistd.h>

static int dspin_fd = -1;

static inline void dspin_open(const char* path) {
  dspin_fd = open(path, O_RDWR);
  if (dspin_fd < 0) {
    perror(path);
    exit(2);
  }
  uint8_t mode = SPI_MODE_3;
  uint32_t speed = 1000000;
  if (ioctl(dspin_fd, SPI_IOC_WR_MODE, &mode) < 0 || ioctl(dspin_fd, SPI_IOC_WR_MAX_SPEED_HZ, &speed) < 0) {
    perror("spidev settings");
    exit(2);
  }
}

/* One byte in its own frame; returns the byte the chip shifted out. */
static inline uint8_t dspin_byte(uint8_t out) {
  uint8_t in = 0;
  struct spi_ioc_transfer t;
  memset(&t, 0, sizeof t);
  t.tx_buf = (uintptr_t)&out;
  t.rx_buf = (uintptr_t)&in;
  t.len = 1;
  if (ioctl(dspin_fd, SPI_IOC_MESSAGE(1), &t) < 0) {
    perror("SPI_IOC_MESSAGE");
    exit(2);
  }
  return in;
}

/* A command with `n` argument bytes (MSB first); returns the last `n` answer bytes. */
static inline uint32_t dspin_cmd(uint8_t op, uint32_t arg, int n) {
  uint32_t answer = 0;
  dspin_byte(op);
  for (int i = n - 1; i >= 0; --i) answer = answer << 8 | dspin_byte((uint8_t)(arg >> (8 * i)));
  return answer;
}

static inline uint16_t dspin_status(void) { return (uint16_t)dspin_cmd(0xD0, 0, 2); } /* GetStatus */

static inline int32_t dspin_abs_pos(void) { /* GetParam(ABS_POS), 22 bits signed */
  uint32_t v = dspin_cmd(0x21, 0, 3) & 0x3FFFFF;
  return (v & 0x200000) ? (int32_t)v - (1 << 22) : (int32_t)v;
}

static inline void sleep_ms(long ms) {
  struct timespec ts = {ms / 1000, (ms % 1000) * 1000000L};
  nanosleep(&ts, NULL);
}

/* Polls GetStatus until BUSY (bit 1, active low) is high again; 0 when it did within `limit_ms`. */
static inline int dspin_wait_idle(long limit_ms) {
  for (long t = 0; t < limit_ms; t += 1) {
    if (dspin_status() & 0x0002) return 0;
    sleep_ms(1);
  }
  return -1;
}

#endif
