/* A bit-banging SPI host on libgpiod 1.6 (Debian bookworm's libgpiod-dev: gpiod_chip_open,
 * gpiod_line_request_output, gpiod_line_set_value, gpiod_line_get_value), as an spi-gpio-style
 * driver talks to a daisy chain of L6470s whose SPI is on gpio lines CS, SCK, MOSI, MISO.
 * Each libgpiod call is one v1 uAPI ioctl on the line's own handle.
 * Usage: gpiod_bitbang /dev/gpiochipN MODE ACTION [COUNT]
 *   MODE 3 (clock idles high; data set after the falling edge) or 0 (clock idles low)
 *   ACTION config-move: reads CONFIG of every chip, moves chip k by 1000 * (k + 1) microsteps,
 *          reads ABS_POS of every chip (key=value lines)
 *   ACTION partial: one whole byte and three bits of a second, then CS rises
 *   ACTION bench COUNT: COUNT CONFIG reads; prints ioctls per byte and the process's CPU time per ioctl */
#include <gpiod.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#define CHIPS 3

static struct gpiod_line *cs, *sck, *mosi, *miso;
static int mode = 3;
static long ioctls = 0;    /* every line call */
static long cs_ioctls = 0; /* the CS sets among them (two a frame) */

static void set(struct gpiod_line* l, int v) {
  if (gpiod_line_set_value(l, v) != 0) { perror("gpiod_line_set_value"); exit(1); }
  ++ioctls;
}

static int get(struct gpiod_line* l) {
  const int v = gpiod_line_get_value(l);
  if (v < 0) { perror("gpiod_line_get_value"); exit(1); }
  ++ioctls;
  return v;
}

static void clock_bit(int bit, uint8_t* in) {
  if (mode == 3) {
    set(sck, 0);                     /* falling: the chips move SDO */
    set(mosi, bit);                  /* data before the rising edge */
    *in = (uint8_t)(*in << 1 | get(miso));
    set(sck, 1);                     /* rising: the chips sample SDI */
  } else {
    set(mosi, bit);
    *in = (uint8_t)(*in << 1 | get(miso));
    set(sck, 1);
    set(sck, 0);
  }
}

static uint8_t clock_byte(uint8_t out) {
  uint8_t in = 0;
  for (int b = 7; b >= 0; --b) clock_bit((out >> b) & 1, &in);
  return in;
}

/* One CS frame of one byte per chip. */
static void frame(const uint8_t* tx, uint8_t* rx) {
  set(cs, 0);
  for (int k = 0; k < CHIPS; ++k) rx[k] = clock_byte(tx[k]);
  set(cs, 1);
  cs_ioctls += 2;
}

/* The same command byte to every chip, then `answer` bytes of NOPs; `value[k]`: chip k's answer. */
static void command_all(uint8_t cmd, int answer, uint32_t* value) {
  uint8_t tx[CHIPS], rx[CHIPS];
  memset(tx, cmd, sizeof tx);
  frame(tx, rx);
  for (int k = 0; k < CHIPS; ++k) value[k] = 0;
  memset(tx, 0, sizeof tx);
  for (int i = 0; i < answer; ++i) {
    frame(tx, rx);
    for (int k = 0; k < CHIPS; ++k) value[k] = value[k] << 8 | rx[k];
  }
}

static struct gpiod_line* line(struct gpiod_chip* chip, const char* name, int output, int value) {
  struct gpiod_line* l = gpiod_chip_find_line(chip, name);
  if (!l) { fprintf(stderr, "no line %s\n", name); exit(1); }
  const int r = output ? gpiod_line_request_output(l, "bitbang", value) : gpiod_line_request_input(l, "bitbang");
  if (r != 0) { perror(name); exit(1); }
  return l;
}

static double cpu_ns(void) {
  struct timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return t.tv_sec * 1e9 + t.tv_nsec;
}

static double board_ns(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return t.tv_sec * 1e9 + t.tv_nsec;
}

int main(int argc, char** argv) {
  if (argc < 4) { fprintf(stderr, "usage: gpiod_bitbang /dev/gpiochipN 3|0 config-move|partial|bench [COUNT]\n"); return 2; }
  mode = atoi(argv[2]);
  struct gpiod_chip* chip = gpiod_chip_open(argv[1]);
  if (!chip) { perror(argv[1]); return 1; }
  cs = line(chip, "CS", 1, 1);
  sck = line(chip, "SCK", 1, mode == 3);
  mosi = line(chip, "MOSI", 1, 0);
  miso = line(chip, "MISO", 0, 0);
  uint32_t v[CHIPS];
  if (strcmp(argv[3], "config-move") == 0) {
    command_all(0x38, 2, v); /* GetParam CONFIG */
    for (int k = 0; k < CHIPS; ++k) printf("config%d=0x%04X\n", k, (unsigned)v[k]);
    uint8_t tx[CHIPS], rx[CHIPS];
    memset(tx, 0x41, sizeof tx); /* Move forward */
    frame(tx, rx);
    for (int i = 2; i >= 0; --i) {
      for (int k = 0; k < CHIPS; ++k) tx[k] = (uint8_t)((1000u * (k + 1)) >> (8 * i));
      frame(tx, rx);
    }
    sleep(2);
    command_all(0x21, 3, v); /* GetParam ABS_POS */
    for (int k = 0; k < CHIPS; ++k) printf("abs_pos%d=%u\n", k, (unsigned)v[k]);
    command_all(0xD0, 2, v); /* GetStatus */
    for (int k = 0; k < CHIPS; ++k) printf("status%d=0x%04X\n", k, (unsigned)v[k]);
  } else if (strcmp(argv[3], "partial") == 0) {
    command_all(0x38, 2, v);
    set(cs, 0);
    clock_byte(0x00);
    uint8_t in = 0;
    for (int b = 0; b < 3; ++b) clock_bit(0, &in);
    set(cs, 1);
    printf("partial=done\n");
  } else if (strcmp(argv[3], "bench") == 0) {
    const long count = argc > 4 ? atol(argv[4]) : 100;
    const long before = ioctls, cs_before = cs_ioctls;
    const double c0 = cpu_ns(), b0 = board_ns();
    for (long i = 0; i < count; ++i) command_all(0x38, 2, v);
    const double cpu = cpu_ns() - c0, board = board_ns() - b0;
    const double bytes = (double)count * 3 * CHIPS, n = (double)(ioctls - before), in_bytes = n - (double)(cs_ioctls - cs_before);
    /* CPU time of the whole process (the emulator runs in it): what each call costs the host */
    printf("bytes=%.0f\nioctls=%.0f\nioctls_per_byte=%.1f\nns_per_ioctl=%.0f\nns_per_byte=%.0f\nboard_ns_per_byte=%.0f\n",
           bytes, n, in_bytes / bytes, cpu / n, cpu * in_bytes / n / bytes, board / bytes);
    printf("config0=0x%04X\n", (unsigned)v[0]);
  } else {
    fprintf(stderr, "unknown action %s\n", argv[3]);
    return 2;
  }
  gpiod_chip_close(chip);
  return 0;
}
