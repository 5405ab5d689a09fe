/* A client of the kernel's /dev/spidev0.0 as firmware tools are written: opened relative to a
 * directory descriptor (openat), settings ioctls, a daisy-chain GetParam/SetParam round trip
 * on every chip, a multi-transfer message with cs_change, spidev's error cases, and a timed
 * burst of GetStatus messages. Built statically: no C library interposition can reach it.
 * Usage: kernel_spidev_client CHIPS. Prints what it checked; exits 1 at the first mismatch. */
#include <errno.h>
#include <fcntl.h>
#include <linux/spi/spidev.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <time.h>
#include <unistd.h>

static int fails;
#define CHECK(cond, ...)                          \
  do {                                            \
    if (cond) {                                   \
      printf("ok   ");                            \
    } else {                                      \
      printf("FAIL ");                            \
      ++fails;                                    \
    }                                             \
    printf(__VA_ARGS__);                          \
    printf("\n");                                 \
  } while (0)

static int fd, chips;

/* One CS frame per byte position, one byte per chip: byte k of a frame is chip k's (chip 0 drives MISO). */
static int frames(const uint8_t *tx, uint8_t *rx, int n_frames) {
  struct spi_ioc_transfer x[8];
  memset(x, 0, sizeof x);
  for (int i = 0; i < n_frames; ++i) {
    x[i].tx_buf = (uintptr_t)(tx + i * chips);
    x[i].rx_buf = (uintptr_t)(rx + i * chips);
    x[i].len = chips;
    x[i].cs_change = i + 1 < n_frames;
  }
  return ioctl(fd, SPI_IOC_MESSAGE(n_frames), x);
}

int main(int argc, char **argv) {
  chips = argc > 1 ? atoi(argv[1]) : 1;
  int dir = open("/dev", O_RDONLY | O_DIRECTORY);
  fd = openat(dir, "spidev0.0", O_RDWR);
  CHECK(fd >= 0, "openat(/dev, \"spidev0.0\") -> %d", fd);
  if (fd < 0) return 1;

  uint8_t mode = SPI_MODE_3, bits = 8;
  uint32_t speed = 5000000, back = 0;
  CHECK(ioctl(fd, SPI_IOC_WR_MODE, &mode) == 0, "SPI_IOC_WR_MODE 3");
  CHECK(ioctl(fd, SPI_IOC_WR_BITS_PER_WORD, &bits) == 0, "SPI_IOC_WR_BITS_PER_WORD 8");
  CHECK(ioctl(fd, SPI_IOC_WR_MAX_SPEED_HZ, &speed) == 0 && ioctl(fd, SPI_IOC_RD_MAX_SPEED_HZ, &back) == 0 &&
            back == 5000000,
        "SPI_IOC_WR/RD_MAX_SPEED_HZ 5 MHz (read back %u)", back);
  mode = 0;
  CHECK(ioctl(fd, SPI_IOC_RD_MODE, &mode) == 0 && mode == SPI_MODE_3, "SPI_IOC_RD_MODE -> %u", mode);

  /* SetParam(MAX_SPEED = 0x30 + chip), then GetParam(MAX_SPEED) on every chip. */
  uint8_t tx[8 * 4] = {0}, rx[8 * 4] = {0};
  for (int k = 0; k < chips; ++k) {
    int slot = k;
    tx[slot] = 0x07;
    tx[chips + slot] = 0x00;
    tx[2 * chips + slot] = 0x30 + k;
  }
  CHECK(frames(tx, rx, 3) == 3 * chips, "SetParam(MAX_SPEED) to every chip in one message of 3 frames with cs_change");
  memset(tx, 0, sizeof tx);
  for (int k = 0; k < chips; ++k) tx[k] = 0x27;
  CHECK(frames(tx, rx, 3) == 3 * chips, "GetParam(MAX_SPEED) from every chip");
  for (int k = 0; k < chips; ++k) {
    int slot = k;
    unsigned v = rx[chips + slot] << 8 | rx[2 * chips + slot];
    CHECK(v == 0x30u + k, "chip %d MAX_SPEED reads 0x%03X", k, v);
  }

  /* spidev's errors. */
  static uint8_t big[5000];
  struct spi_ioc_transfer x;
  memset(&x, 0, sizeof x);
  x.tx_buf = (uintptr_t)big;
  x.len = sizeof big;
  errno = 0;
  CHECK(ioctl(fd, SPI_IOC_MESSAGE(1), &x) < 0 && errno == EMSGSIZE, "5000 bytes past bufsiz 4096: %s", strerror(errno));
  x.len = 3;
  x.bits_per_word = 7;
  errno = 0;
  CHECK(ioctl(fd, SPI_IOC_MESSAGE(1), &x) < 0 && errno == EINVAL, "bits_per_word 7: %s", strerror(errno));
  x.bits_per_word = 0;
  x.tx_buf = 8; /* unmapped */
  errno = 0;
  CHECK(ioctl(fd, SPI_IOC_MESSAGE(1), &x) < 0 && errno == EFAULT, "tx_buf at an unmapped address: %s", strerror(errno));
  errno = 0;
  CHECK(ioctl(fd, SPI_IOC_MESSAGE(1), (void *)8) < 0 && errno == EFAULT, "the transfer array unmapped: %s",
        strerror(errno));
  errno = 0;
  CHECK(ioctl(fd, _IOR(SPI_IOC_MAGIC, 99, uint32_t), &back) < 0 && errno == ENOTTY, "unknown ioctl: %s",
        strerror(errno));

  /* read()/write(): half-duplex transfers. */
  uint8_t nop[8] = {0};
  CHECK(write(fd, nop, chips) == chips, "write() of %d NOP bytes", chips);
  CHECK(read(fd, rx, chips) == chips, "read() of %d bytes", chips);

  /* Timed: GetStatus to every chip (3 frames), as fast as the node answers. */
  struct timespec a, b;
  int n = 0;
  memset(tx, 0, sizeof tx);
  for (int k = 0; k < chips; ++k) tx[k] = 0xD0;
  clock_gettime(CLOCK_MONOTONIC, &a);
  do {
    if (frames(tx, rx, 3) != 3 * chips) break;
    ++n;
    clock_gettime(CLOCK_MONOTONIC, &b);
  } while ((b.tv_sec - a.tv_sec) * 1000000000L + (b.tv_nsec - a.tv_nsec) < 2000000000L);
  double s = (b.tv_sec - a.tv_sec) + (b.tv_nsec - a.tv_nsec) / 1e9;
  unsigned status = rx[chips] << 8 | rx[2 * chips];
  CHECK(n > 10, "GetStatus: %d messages in %.2f s = %.0f ioctls/s (STATUS of chip 0: 0x%04X)", n, s, n / s, status);
  close(fd);
  close(dir);
  printf("%s\n", fails ? "kernel_spidev_client: FAILED" : "kernel_spidev_client: all passed");
  return fails ? 1 : 0;
}
