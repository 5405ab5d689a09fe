/* A plain spidev client for the tests: sends the same dSPIN byte script with the SPI settings
 * given on its command line (mode, bit order, word size, speed, cs_change), or with every
 * combination of them one after the other, changing them between messages. Knows nothing of the
 * emulator. Usage:
 *   spidev_settings DEVICE MODE msb|lsb BITS SPEED_HZ CS_CHANGE   one setting (CS_CHANGE 0 or 1)
 *   spidev_settings DEVICE all                                    every one in turn
 * Prints "miso=HEX..." per setting and exits 0 when every ioctl succeeded (1 otherwise). */
#include <errno.h>
#include <fcntl.h>
#include <linux/spi/spidev.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <unistd.h>

static int fd;

/* GetStatus, GetParam(MAX_SPEED), SetParam(ACC, 0x8A), GetParam(ACC), GetStatus and NOPs: 16
 * bytes, a whole number of 32-bit words. */
static const uint8_t kScript[16] = {0xD0, 0x00, 0x00, 0x27, 0x00, 0x00, 0x05, 0x00,
                                    0x8A, 0x25, 0x00, 0x00, 0xD0, 0x00, 0x00, 0x00};

static int set_up(unsigned mode, int lsb, unsigned bits, uint32_t speed) {
  uint8_t m = (uint8_t)mode, l = (uint8_t)(lsb ? 1 : 0), b = (uint8_t)bits;
  if (ioctl(fd, SPI_IOC_WR_MODE, &m) < 0) { perror("WR_MODE"); return -1; }
  if (ioctl(fd, SPI_IOC_WR_LSB_FIRST, &l) < 0) { perror("WR_LSB_FIRST"); return -1; }
  if (ioctl(fd, SPI_IOC_WR_BITS_PER_WORD, &b) < 0) { perror("WR_BITS_PER_WORD"); return -1; }
  if (ioctl(fd, SPI_IOC_WR_MAX_SPEED_HZ, &speed) < 0) { perror("WR_MAX_SPEED_HZ"); return -1; }
  return 0;
}

static int message(struct spi_ioc_transfer* x, unsigned n) {
  if (ioctl(fd, SPI_IOC_MESSAGE(n), x) < 0) { perror("SPI_IOC_MESSAGE"); return -1; }
  return 0;
}

/* The script in words of `bits`: with cs_change, one message of a transfer per word with CS raised
 * between them, then a frame that spans two messages (cs_change on a message's last transfer keeps
 * CS low); without, a message per word, then one message of two words under one CS. Transfers
 * name the word size and speed themselves when `per_transfer`. */
static int run_script(unsigned bits, uint32_t speed, int cs_change, int per_transfer, uint8_t* rx) {
  const unsigned w = bits / 8, words = sizeof kScript / w;
  struct spi_ioc_transfer x[16];
  memset(x, 0, sizeof x);
  for (unsigned i = 0; i < words; ++i) {
    x[i].tx_buf = (uintptr_t)(kScript + i * w);
    x[i].rx_buf = (uintptr_t)(rx + i * w);
    x[i].len = w;
    if (per_transfer) {
      x[i].bits_per_word = (uint8_t)bits;
      x[i].speed_hz = speed;
    }
  }
  if (cs_change) {
    for (unsigned i = 0; i + 1 < words; ++i) x[i].cs_change = 1;
    if (message(x, words) < 0) return -1;
    struct spi_ioc_transfer a = x[0], b = x[1];
    a.rx_buf = (uintptr_t)(rx + 16);
    b.rx_buf = (uintptr_t)(rx + 16 + w);
    a.cs_change = 1; /* the last of its message: CS stays low */
    b.cs_change = 0;
    if (message(&a, 1) < 0 || message(&b, 1) < 0) return -1;
  } else {
    for (unsigned i = 0; i < words; ++i)
      if (message(&x[i], 1) < 0) return -1;
    struct spi_ioc_transfer two[2] = {x[0], x[1]};
    two[0].rx_buf = (uintptr_t)(rx + 16);
    two[1].rx_buf = (uintptr_t)(rx + 16 + w);
    if (message(two, 2) < 0) return -1;
  }
  return 0;
}

static int one(unsigned mode, int lsb, unsigned bits, uint32_t speed, int cs_change, int per_transfer) {
  uint8_t rx[32];
  memset(rx, 0, sizeof rx);
  if (set_up(mode, lsb, bits, speed) < 0 || run_script(bits, speed, cs_change, per_transfer, rx) < 0) return -1;
  printf("mode=%u order=%s bits=%u speed=%u cs_change=%d miso=", mode, lsb ? "lsb" : "msb", bits, (unsigned)speed,
         cs_change);
  for (unsigned i = 0; i < 16 + 2 * (bits / 8); ++i) printf("%02X", rx[i]);
  printf("\n");
  return 0;
}

int main(int argc, char** argv) {
  if (argc != 3 && argc != 7) {
    fprintf(stderr, "usage: spidev_settings DEVICE MODE msb|lsb BITS SPEED_HZ CS_CHANGE | spidev_settings DEVICE all\n");
    return 2;
  }
  fd = open(argv[1], O_RDWR);
  if (fd < 0) { perror("open"); return 1; }
  if (argc == 7) {
    const int lsb = strcmp(argv[3], "lsb") == 0;
    return one((unsigned)atoi(argv[2]), lsb, (unsigned)atoi(argv[4]), (uint32_t)strtoul(argv[5], 0, 10), atoi(argv[6]), 0) < 0;
  }
  static const unsigned kBits[] = {8, 16, 32};
  static const uint32_t kSpeeds[] = {400000, 5000000, 10000000};
  unsigned k = 0;
  for (unsigned mode = 0; mode < 4; ++mode)
    for (int lsb = 0; lsb < 2; ++lsb)
      for (unsigned b = 0; b < 3; ++b)
        for (unsigned s = 0; s < 3; ++s)
          for (int cs = 0; cs < 2; ++cs, ++k)
            if (one(mode, lsb, kBits[b], kSpeeds[s], cs, k % 3 == 1) < 0) return 1;
  close(fd);
  return 0;
}
