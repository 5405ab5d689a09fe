/* SPI_IOC_MESSAGE round trips per second on a spidev node: the client of the preload
 * benchmark (bench/preload_bench.sh), run under the preload library in process, through
 * `l6470emu serve`, and under umockdev-run replaying the same exchange. Each round trip is
 * one message of one 1-byte transfer (a NOP: MOSI 0x00, MISO 0x00), checked.
 * Usage: l6470emu_preload_roundtrips /dev/spidevB.C COUNT; prints "COUNT SECONDS PER_SECOND". */
#include <fcntl.h>
#include <linux/spi/spidev.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <time.h>
#include <unistd.h>
int main(int argc, char** argv) {
  if (argc != 3) { fprintf(stderr, "usage: %s /dev/spidevB.C COUNT\n", argv[0]); return 2; }
  const int fd = open(argv[1], O_RDWR);
  if (fd < 0) { perror("open"); return 1; }
  const uint8_t mode = SPI_MODE_3;  /* what the chip needs (spidev nodes start in mode 0) */
  if (ioctl(fd, SPI_IOC_WR_MODE, &mode) < 0) { perror("SPI_IOC_WR_MODE"); return 1; }
  long n = strtol(argv[2], 0, 0);
  uint8_t tx = 0, rx = 0xff;
  struct spi_ioc_transfer x; memset(&x, 0, sizeof x);
  x.tx_buf = (uintptr_t)&tx; x.rx_buf = (uintptr_t)&rx; x.len = 1;
  struct timespec a, b; clock_gettime(CLOCK_MONOTONIC, &a);
  for (long i = 0; i < n; ++i) if (ioctl(fd, SPI_IOC_MESSAGE(1), &x) != 1 || rx != 0) { perror("SPI_IOC_MESSAGE"); return 1; }
  clock_gettime(CLOCK_MONOTONIC, &b);
  double s = (b.tv_sec - a.tv_sec) + (b.tv_nsec - a.tv_nsec) / 1e9;
  printf("%ld %.6f %.0f\n", n, s, n / s);
  return 0;
}
