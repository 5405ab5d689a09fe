/* A plain spidev client for the sanitizer tests: on a chain of two chips it sends, in one
 * SPI_IOC_MESSAGE of two CS frames (cs_change between them), GetStatus to chip 0 and the opcode
 * and first argument byte of a Move to chip 1 -- and ends the message there, so chip 1 still
 * waits for two argument bytes. Then it asks for chip 0's answer. Knows nothing of the emulator.
 * Usage: spidev_split /dev/spidevB.C */
#include <fcntl.h>
#include <linux/spi/spidev.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <sys/ioctl.h>
#include <unistd.h>

int main(int argc, char** argv) {
  const char* path = argc > 1 ? argv[1] : "/dev/spidev0.0";
  int fd = open(path, O_RDWR);
  if (fd < 0) { perror("open"); return 1; }
  uint8_t mode = SPI_MODE_3;
  if (ioctl(fd, SPI_IOC_WR_MODE, &mode) < 0) { perror("WR_MODE"); return 1; }
  /* byte k of a frame goes to chip k (chip 0 drives MISO) */
  uint8_t tx[4] = {0xD0, 0x41, 0x00, 0x00}, rx[4] = {0};
  struct spi_ioc_transfer x[2];
  memset(x, 0, sizeof x);
  for (int i = 0; i < 2; ++i) {
    x[i].tx_buf = (uintptr_t)(tx + 2 * i);
    x[i].rx_buf = (uintptr_t)(rx + 2 * i);
    x[i].len = 2;
    x[i].speed_hz = 1000000;
    x[i].cs_change = i == 0;
  }
  int r = ioctl(fd, SPI_IOC_MESSAGE(2), x);
  printf("message: r=%d status0=%02X\n", r, rx[2]);
  fflush(stdout);
  return 0;
}
