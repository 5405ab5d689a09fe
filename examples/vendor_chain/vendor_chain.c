/* A vendor-style daisy-chain driver for two L6470s on /dev/spidev0.0, in plain C: commands
 * are first prepared per chip, then sent together, one byte per chip in every CS frame (as
 * ST's dSPIN daisy-chain code does: the first byte of each chip's command in frame 1, the
 * second in frame 2, NOP where a command is shorter). Answers come back the same way.
 * Nothing here knows about the emulator; on a board with two real chips it runs unchanged.
 *
 *   L6470EMU_CHAIN="bus=0 cs=0 chips=2xL6470; time=virtual" \
 *     LD_PRELOAD=build/libl6470emu-preload.so build/examples/vendor_chain
 *
 * Chip 0 moves 3200 microsteps forward and chip 1 6400 in reverse, both started by the same
 * four frames; the program polls both STATUS registers in shared frames until BUSY is released
 * and reads both positions. Exit status 0 when both ended where they were sent, 1 when not. */
#include <errno.h>
#include <fcntl.h>
#include <linux/spi/spidev.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <sys/ioctl.h>
#include <time.h>
#include <unistd.h>

#define CHIPS 2
#define MAX_COMMAND 4 /* opcode and up to three argument bytes */

enum { NOP = 0x00, GET_STATUS = 0xD0, GET_ABS_POS = 0x21, MOVE = 0x40, DIR_FWD = 0x01 };

/* The per-chip queue: what each chip gets in the next perform(). */
struct chain {
  int fd;
  uint8_t command[CHIPS][MAX_COMMAND];
  int length[CHIPS];
  uint8_t answer[CHIPS][MAX_COMMAND]; /* byte j of chip k's reply, from frame j */
};

static void prepare(struct chain *c, int chip, const uint8_t *bytes, int length) {
  memcpy(c->command[chip], bytes, (size_t)length);
  c->length[chip] = length;
}

static void prepare_move(struct chain *c, int chip, int32_t steps) {
  const uint32_t n = (uint32_t)(steps < 0 ? -steps : steps);
  const uint8_t bytes[4] = {(uint8_t)(MOVE | (steps >= 0 ? DIR_FWD : 0)), (uint8_t)(n >> 16 & 0x3F), (uint8_t)(n >> 8),
                            (uint8_t)n};
  prepare(c, chip, bytes, 4);
}

/* Sends every prepared command: frame j carries byte j of each chip's command (chip k's byte
 * at position k, chip 0's first: it is the far end of the chain, the one driving MISO). */
static int perform(struct chain *c) {
  int frames = 0;
  for (int k = 0; k < CHIPS; ++k)
    if (c->length[k] > frames) frames = c->length[k];
  for (int j = 0; j < frames; ++j) {
    uint8_t tx[CHIPS], rx[CHIPS];
    for (int k = 0; k < CHIPS; ++k) tx[k] = j < c->length[k] ? c->command[k][j] : NOP;
    struct spi_ioc_transfer t;
    memset(&t, 0, sizeof t);
    t.tx_buf = (uintptr_t)tx;
    t.rx_buf = (uintptr_t)rx;
    t.len = CHIPS;
    t.speed_hz = 5000000;
    t.bits_per_word = 8;
    if (ioctl(c->fd, SPI_IOC_MESSAGE(1), &t) < 0) {
      fprintf(stderr, "vendor_chain: SPI_IOC_MESSAGE: %s\n", strerror(errno));
      return -1;
    }
    for (int k = 0; k < CHIPS; ++k) c->answer[k][j] = rx[k];
  }
  for (int k = 0; k < CHIPS; ++k) c->length[k] = 0;
  return 0;
}

static int all_get_status(struct chain *c, uint16_t status[CHIPS]) {
  static const uint8_t get_status[3] = {GET_STATUS, NOP, NOP};
  for (int k = 0; k < CHIPS; ++k) prepare(c, k, get_status, 3);
  if (perform(c) < 0) return -1;
  for (int k = 0; k < CHIPS; ++k) status[k] = (uint16_t)(c->answer[k][1] << 8 | c->answer[k][2]);
  return 0;
}

static int all_positions(struct chain *c, int32_t pos[CHIPS]) {
  static const uint8_t get_pos[4] = {GET_ABS_POS, NOP, NOP, NOP};
  for (int k = 0; k < CHIPS; ++k) prepare(c, k, get_pos, 4);
  if (perform(c) < 0) return -1;
  for (int k = 0; k < CHIPS; ++k) {
    uint32_t v = (uint32_t)c->answer[k][1] << 16 | (uint32_t)c->answer[k][2] << 8 | c->answer[k][3];
    pos[k] = (v & 0x200000) ? (int32_t)v - (1 << 22) : (int32_t)v; /* 22-bit two's complement */
  }
  return 0;
}

int main(void) {
  struct chain c;
  memset(&c, 0, sizeof c);
  c.fd = open("/dev/spidev0.0", O_RDWR);
  if (c.fd < 0) {
    fprintf(stderr, "vendor_chain: /dev/spidev0.0: %s\n", strerror(errno));
    return 1;
  }
  const uint8_t mode = SPI_MODE_3;
  if (ioctl(c.fd, SPI_IOC_WR_MODE, &mode) < 0) {
    fprintf(stderr, "vendor_chain: SPI_IOC_WR_MODE: %s\n", strerror(errno));
    return 1;
  }
  uint16_t status[CHIPS];
  int32_t pos[CHIPS];
  if (all_get_status(&c, status) < 0) return 1; /* clears the power-up UVLO flags */

  const int32_t target[CHIPS] = {3200, -6400};
  for (int k = 0; k < CHIPS; ++k) prepare_move(&c, k, target[k]);
  if (perform(&c) < 0) return 1; /* four frames start both moves */

  if (all_get_status(&c, status) < 0) return 1;
  const int started = !(status[0] & 2) && !(status[1] & 2); /* STATUS.BUSY low = busy */
  printf("after the shared Move frames: STATUS 0x%04X 0x%04X (%s)\n", status[0], status[1],
         started ? "both busy" : "NOT both busy");

  int polls = 0;
  do {
    const struct timespec ten_ms = {0, 10 * 1000 * 1000};
    nanosleep(&ten_ms, NULL);
    if (all_get_status(&c, status) < 0) return 1;
    ++polls;
  } while ((!(status[0] & 2) || !(status[1] & 2)) && polls < 1000);
  if (all_positions(&c, pos) < 0) return 1;

  int ok = started;
  for (int k = 0; k < CHIPS; ++k) {
    printf("chip %d at %d (sent %d)\n", k, pos[k], target[k]);
    ok = ok && pos[k] == target[k];
  }
  printf("%s after %d status polls\n", ok ? "ok" : "FAIL", polls);
  close(c.fd);
  return ok ? 0 : 1;
}
