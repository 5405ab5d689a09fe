/* Messages larger than the daemon's shared region (64 KiB): one SPI_IOC_MESSAGE with a full-duplex
 * transfer of BYTES, a write() and a read() of BYTES, then a GetStatus; prints each result and a
 * hash of the bytes read, so that runs through different paths can be compared line by line.
 * Usage: spidev_large /dev/spidevB.C BYTES (the chain's bufsiz must allow BYTES) */
#include <fcntl.h>
#include <linux/spi/spidev.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <unistd.h>

static uint32_t fnv1a(const uint8_t* p, size_t n) {
  uint32_t h = 2166136261u;
  for (size_t i = 0; i < n; ++i) h = (h ^ p[i]) * 16777619u;
  return h;
}

int main(int argc, char** argv) {
  if (argc != 3) return 2;
  const int fd = open(argv[1], O_RDWR);
  if (fd < 0) { perror("open"); return 1; }
  const size_t n = (size_t)strtoul(argv[2], 0, 0);
  uint8_t* tx = malloc(n);
  uint8_t* rx = malloc(n);
  for (size_t i = 0; i < n; ++i) tx[i] = (uint8_t)(i * 7 + 1);
  memset(rx, 0xEE, n);
  struct spi_ioc_transfer x;
  memset(&x, 0, sizeof x);
  x.tx_buf = (uintptr_t)tx; x.rx_buf = (uintptr_t)rx; x.len = (uint32_t)n;
  int r = ioctl(fd, SPI_IOC_MESSAGE(1), &x);
  printf("message: r=%d hash=%08x\n", r, fnv1a(rx, n));
  r = (int)write(fd, tx, n);
  printf("write: r=%d\n", r);
  memset(rx, 0xEE, n);
  r = (int)read(fd, rx, n);
  printf("read: r=%d hash=%08x\n", r, fnv1a(rx, n));
  uint8_t s[3] = {0xD0, 0, 0}, a[3] = {0};
  struct spi_ioc_transfer t[3];
  memset(t, 0, sizeof t);
  for (int k = 0; k < 3; ++k) { t[k].tx_buf = (uintptr_t)&s[k]; t[k].rx_buf = (uintptr_t)&a[k]; t[k].len = 1; t[k].cs_change = k < 2; }
  r = ioctl(fd, SPI_IOC_MESSAGE(3), t);
  printf("GetStatus: r=%d %02X%02X\n", r, a[1], a[2]);
  close(fd);
  return 0;
}
