/* Reads register ADDRESS (3 bytes) COUNT times, each read one SPI_IOC_MESSAGE(4) with CS
 * released between the transfers, and counts answers that differ from EXPECTED. Two of these
 * on one bus must never see a torn answer: the kernel runs one message at a time.
 * Usage: spidev_reader /dev/spidevB.C COUNT ADDRESS EXPECTED */
#include <fcntl.h>
#include <linux/spi/spidev.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <unistd.h>

int main(int argc, char** argv) {
  if (argc != 5) return 2;
  const int fd = open(argv[1], O_RDWR);
  if (fd < 0) { perror("open"); return 1; }
  uint8_t mode = SPI_MODE_3;
  ioctl(fd, SPI_IOC_WR_MODE, &mode);
  const long count = strtol(argv[2], 0, 0);
  const uint8_t address = (uint8_t)strtol(argv[3], 0, 0);
  const uint32_t expected = (uint32_t)strtoul(argv[4], 0, 0);
  long torn = 0;
  for (long i = 0; i < count; ++i) {
    uint8_t tx[4] = {(uint8_t)(0x20 | address), 0, 0, 0}, rx[4] = {0};
    struct spi_ioc_transfer x[4];
    memset(x, 0, sizeof x);
    for (int k = 0; k < 4; ++k) {
      x[k].tx_buf = (uintptr_t)&tx[k];
      x[k].rx_buf = (uintptr_t)&rx[k];
      x[k].len = 1;
      x[k].cs_change = k < 3;
    }
    if (ioctl(fd, SPI_IOC_MESSAGE(4), x) != 4) { perror("SPI_IOC_MESSAGE"); return 1; }
    if (((uint32_t)rx[1] << 16 | (uint32_t)rx[2] << 8 | rx[3]) != expected) ++torn;
  }
  printf("reads=%ld torn=%ld\n", count, torn);
  return 0;
}
