/* SPI_IOC_MESSAGE round trips on a spidev node: the C client of the preload benchmark
 * (bench/preload_bench.sh), run under the preload library in process, through `l6470emu serve`,
 * and under umockdev-run replaying the same exchange. It sets SPI mode 3 and 5 MHz, as a driver
 * of these chips does. Each round trip is one message of one 1-byte transfer, checked:
 *   nop        a NOP (MOSI 0x00, MISO 0x00)
 *   getstatus  GetStatus polled in a tight loop as one-chip drivers send it, one CS frame per
 *              byte: 0xD0, then two NOPs that carry STATUS back (three round trips per poll)
 * Usage: l6470emu_preload_roundtrips /dev/spidevB.C COUNT [nop|getstatus]
 * Prints "COUNT WALL_SECONDS PER_WALL_SECOND HOST_SECONDS CPU_SECONDS": wall time read with the
 * raw system call (the preload cannot see it), host time with clock_gettime (CLOCK_MONOTONIC: the
 * board's time under time=virtual), the process's CPU time (never virtual). COUNT counts round trips. */
#include <fcntl.h>
#include <linux/spi/spidev.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/syscall.h>
#include <time.h>
#include <unistd.h>

static double wall_seconds(void) {
  struct timespec t;
  syscall(SYS_clock_gettime, CLOCK_MONOTONIC, &t);
  return t.tv_sec + t.tv_nsec / 1e9;
}

static double cpu_seconds(void) {
  struct timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return t.tv_sec + t.tv_nsec / 1e9;
}

static double host_seconds(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return t.tv_sec + t.tv_nsec / 1e9;
}

int main(int argc, char** argv) {
  if (argc < 3 || argc > 4 || (argc == 4 && strcmp(argv[3], "nop") != 0 && strcmp(argv[3], "getstatus") != 0)) {
    fprintf(stderr, "usage: %s /dev/spidevB.C COUNT [nop|getstatus]\n", argv[0]);
    return 2;
  }
  const int poll = argc == 4 && strcmp(argv[3], "getstatus") == 0;
  const int fd = open(argv[1], O_RDWR);
  if (fd < 0) { perror("open"); return 1; }
  uint8_t mode = SPI_MODE_3;
  uint32_t hz = 5000000;
  /* (umockdev-run replays only the recorded messages: settings it refuses are left as they are) */
  (void)ioctl(fd, SPI_IOC_WR_MODE, &mode);
  (void)ioctl(fd, SPI_IOC_WR_MAX_SPEED_HZ, &hz);
  const long n = strtol(argv[2], 0, 0);
  uint8_t tx = 0, rx = 0xff;
  struct spi_ioc_transfer x;
  memset(&x, 0, sizeof x);
  x.tx_buf = (uintptr_t)&tx;
  x.rx_buf = (uintptr_t)&rx;
  x.len = 1;
  const double wall0 = wall_seconds(), host0 = host_seconds(), cpu0 = cpu_seconds();
  for (long i = 0; i < n; ++i) {
    tx = poll && i % 3 == 0 ? 0xD0 : 0x00;
    if (ioctl(fd, SPI_IOC_MESSAGE(1), &x) != 1) { perror("SPI_IOC_MESSAGE"); return 1; }
    /* A NOP gets 0x00 back, and so does the command byte of a poll; its two NOPs bring STATUS. */
    if (!poll ? rx != 0 : (i % 3 == 0 && rx != 0)) { fprintf(stderr, "round trip %ld: MISO 0x%02X\n", i, rx); return 1; }
  }
  const double wall = wall_seconds() - wall0, host = host_seconds() - host0, cpu = cpu_seconds() - cpu0;
  printf("%ld %.6f %.0f %.6f %.6f\n", n, wall, n / wall, host, cpu);
  return 0;
}
