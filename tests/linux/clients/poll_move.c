/* A C driver that moves and polls: Move N full steps (1/128 microstepping, the power-up step
   mode), then GetStatus in a loop (one SPI_IOC_MESSAGE of three one-byte transfers each) until
   BUSY is released; prints the host's CLOCK_MONOTONIC times. Usage: poll_move DEV FULL_STEPS HZ */
#include <fcntl.h>
#include <linux/spi/spidev.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <time.h>
#include <unistd.h>

static int fd;
static uint32_t hz;

static void command(const uint8_t* tx, uint8_t* rx, unsigned n) {
  struct spi_ioc_transfer x[4];
  memset(x, 0, sizeof x);
  for (unsigned i = 0; i < n; ++i) {
    x[i].tx_buf = (uintptr_t)(tx + i);
    x[i].rx_buf = (uintptr_t)(rx + i);
    x[i].len = 1;
    x[i].speed_hz = hz;
    x[i].cs_change = i + 1 < n;
  }
  if (ioctl(fd, SPI_IOC_MESSAGE(n), x) != (int)n) {
    perror("SPI_IOC_MESSAGE");
    exit(1);
  }
}

static double now_s(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + ts.tv_nsec / 1e9;
}

int main(int argc, char** argv) {
  if (argc != 4) {
    fprintf(stderr, "usage: poll_move DEV FULL_STEPS HZ\n");
    return 2;
  }
  fd = open(argv[1], O_RDWR);
  if (fd < 0) {
    perror(argv[1]);
    return 1;
  }
  uint8_t mode = SPI_MODE_3;
  ioctl(fd, SPI_IOC_WR_MODE, &mode);
  hz = (uint32_t)strtoul(argv[3], NULL, 10);
  const uint32_t n = (uint32_t)strtoul(argv[2], NULL, 10) * 128;
  uint8_t status[3] = {0xD0, 0, 0}, rx[4];
  command(status, rx, 3);
  const uint8_t mv[4] = {0x41, (uint8_t)(n >> 16), (uint8_t)(n >> 8), (uint8_t)n};
  const double t0 = now_s();
  command(mv, rx, 4);
  const double sent = now_s();
  unsigned long polls = 0;
  do {
    command(status, rx, 3);
    ++polls;
  } while (!(rx[2] & 0x02));
  printf("start=%.9f sent=%.9f released=%.9f polls=%lu\n", t0, sent, now_s(), polls);
  return 0;
}
