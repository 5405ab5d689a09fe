/* A bit-banging SPI host on the gpio character device's v2 uAPI (what libgpiod 2.x does), written
 * against linux/gpio.h: one GPIO_V2_GET_LINE_IOCTL request holds CS, SCK, MOSI (outputs) and
 * MISO (an input, by a flags attribute); GPIO_V2_LINE_SET_VALUES_IOCTL sets SCK and MOSI in one
 * call (applied in offset order: SCK falls, then MOSI changes) and GPIO_V2_LINE_GET_VALUES_IOCTL
 * reads MISO. Mode 3, a daisy chain of three chips: reads CONFIG of each, moves chip k by
 * 1000 * (k + 1) microsteps, reads ABS_POS. Usage: gpio_v2_bitbang /dev/gpiochipN */
#include <errno.h>
#include <fcntl.h>
#include <linux/gpio.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <time.h>
#include <unistd.h>

#define CHIPS 3
enum { CS, SCK, MOSI, MISO };  /* positions in the request */
static int req = -1;
static long ioctls = 0, cs_ioctls = 0;

static void set(uint64_t mask, uint64_t bits) {
  struct gpio_v2_line_values v = {.bits = bits, .mask = mask};
  if (ioctl(req, GPIO_V2_LINE_SET_VALUES_IOCTL, &v) != 0) { perror("GPIO_V2_LINE_SET_VALUES_IOCTL"); exit(1); }
  ++ioctls;
}

static int get_miso(void) {
  struct gpio_v2_line_values v = {.bits = 0, .mask = 1u << MISO};
  if (ioctl(req, GPIO_V2_LINE_GET_VALUES_IOCTL, &v) != 0) { perror("GPIO_V2_LINE_GET_VALUES_IOCTL"); exit(1); }
  ++ioctls;
  return (int)((v.bits >> MISO) & 1);
}

static uint8_t clock_byte(uint8_t out) {
  uint8_t in = 0;
  for (int b = 7; b >= 0; --b) {
    set(1u << SCK | 1u << MOSI, (uint64_t)((out >> b) & 1) << MOSI); /* SCK low, then MOSI */
    in = (uint8_t)(in << 1 | get_miso());
    set(1u << SCK, 1u << SCK);
  }
  return in;
}

static void frame(const uint8_t* tx, uint8_t* rx) {
  set(1u << CS, 0);
  for (int k = 0; k < CHIPS; ++k) rx[k] = clock_byte(tx[k]);
  set(1u << CS, 1u << CS);
  cs_ioctls += 2;
}

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

static int find_line(int chip, const char* name, unsigned n) {
  for (unsigned i = 0; i < n; ++i) {
    struct gpio_v2_line_info info;
    memset(&info, 0, sizeof info);
    info.offset = i;
    if (ioctl(chip, GPIO_V2_GET_LINEINFO_IOCTL, &info) == 0 && strcmp(info.name, name) == 0) return (int)i;
  }
  fprintf(stderr, "no line %s\n", name);
  exit(1);
}

int main(int argc, char** argv) {
  const char* path = argc > 1 ? argv[1] : "/dev/gpiochip0";
  const int chip = open(path, O_RDWR | O_CLOEXEC);
  if (chip < 0) { perror(path); return 1; }
  struct gpiochip_info ci;
  memset(&ci, 0, sizeof ci);
  ioctl(chip, GPIO_GET_CHIPINFO_IOCTL, &ci);
  struct gpio_v2_line_request r;
  memset(&r, 0, sizeof r);
  const char* names[] = {"CS", "SCK", "MOSI", "MISO"};
  for (int i = 0; i < 4; ++i) r.offsets[i] = (unsigned)find_line(chip, names[i], ci.lines);
  printf("offsets=%u,%u,%u,%u of %u\n", r.offsets[0], r.offsets[1], r.offsets[2], r.offsets[3], ci.lines);
  r.num_lines = 4;
  strcpy(r.consumer, "bitbang-v2");
  r.config.flags = GPIO_V2_LINE_FLAG_OUTPUT;
  r.config.num_attrs = 2;
  r.config.attrs[0].attr.id = GPIO_V2_LINE_ATTR_ID_FLAGS;
  r.config.attrs[0].attr.flags = GPIO_V2_LINE_FLAG_INPUT;
  r.config.attrs[0].mask = 1u << MISO;
  r.config.attrs[1].attr.id = GPIO_V2_LINE_ATTR_ID_OUTPUT_VALUES;
  r.config.attrs[1].attr.values = 1u << CS | 1u << SCK; /* CS high, the clock idles high */
  r.config.attrs[1].mask = 1u << CS | 1u << SCK | 1u << MOSI;
  if (ioctl(chip, GPIO_V2_GET_LINE_IOCTL, &r) != 0) { perror("GPIO_V2_GET_LINE_IOCTL"); return 1; }
  req = r.fd;
  /* Edge events of an SPI line are not emulated: refused. */
  struct gpio_v2_line_request e;
  memset(&e, 0, sizeof e);
  e.offsets[0] = r.offsets[MISO];
  e.num_lines = 1;
  e.config.flags = GPIO_V2_LINE_FLAG_INPUT | GPIO_V2_LINE_FLAG_EDGE_RISING;
  printf("miso_busy=%s\n", ioctl(chip, GPIO_V2_GET_LINE_IOCTL, &e) != 0 && errno == EBUSY ? "EBUSY" : "WRONG");

  uint32_t v[CHIPS];
  command_all(0x38, 2, v);
  for (int k = 0; k < CHIPS; ++k) printf("config%d=0x%04X\n", k, (unsigned)v[k]);
  uint8_t tx[CHIPS], rx[CHIPS];
  memset(tx, 0x41, sizeof tx);
  frame(tx, rx);
  for (int i = 2; i >= 0; --i) {
    for (int k = 0; k < CHIPS; ++k) tx[k] = (uint8_t)((1000u * (k + 1)) >> (8 * i));
    frame(tx, rx);
  }
  sleep(2);
  command_all(0x21, 3, v);
  for (int k = 0; k < CHIPS; ++k) printf("abs_pos%d=%u\n", k, (unsigned)v[k]);
  printf("ioctls_per_byte=%.1f\n", (double)(ioctls - cs_ioctls) / (CHIPS * (3 + 4 + 4)));
  close(req);
  /* Released, MISO can be requested again: with edge events it is refused. */
  printf("miso_edges=%s\n", ioctl(chip, GPIO_V2_GET_LINE_IOCTL, &e) != 0 && errno == EOPNOTSUPP ? "EOPNOTSUPP" : "WRONG");
  close(chip);
  return 0;
}
