/* The C driver of bench/campaign_bench.sh: about 10 s of virtual time on one L6470 — configure,
   Move out and GoTo back twice, polling STATUS every 10 ms and stopping on OCD or TH_SD, as a
   careful production driver would. Usage: l6470emu_campaign_workload (under l6470emu run). */
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

static uint8_t byte(uint8_t out) {
  uint8_t in = 0;
  struct spi_ioc_transfer t;
  memset(&t, 0, sizeof t);
  t.tx_buf = (uintptr_t)&out;
  t.rx_buf = (uintptr_t)&in;
  t.len = 1;
  if (ioctl(fd, SPI_IOC_MESSAGE(1), &t) < 0) exit(2);
  return in;
}

static uint32_t cmd(uint8_t op, uint32_t arg, int n) {
  uint32_t answer = 0;
  byte(op);
  for (int i = n - 1; i >= 0; --i) answer = answer << 8 | byte((uint8_t)(arg >> (8 * i)));
  return answer;
}

static void wait_for_motion(void) {
  for (;;) {
    const uint16_t s = (uint16_t)cmd(0xD0, 0, 2);
    if (!(s & 0x1000) || !(s & 0x0800)) exit(1);
    if (s & 0x0002) return;
    struct timespec ts = {0, 10 * 1000 * 1000};
    nanosleep(&ts, NULL);
  }
}

int main(void) {
  fd = open("/dev/spidev0.0", O_RDWR);
  if (fd < 0) return 2;
  uint8_t mode = SPI_MODE_3;
  ioctl(fd, SPI_IOC_WR_MODE, &mode);
  cmd(0x05, 0x010, 2); /* ACC */
  cmd(0x06, 0x010, 2); /* DEC */
  cmd(0x07, 0x020, 2); /* MAX_SPEED */
  cmd(0xD0, 0, 2);
  for (int i = 0; i < 2; ++i) {
    cmd(0x41, 20000, 3); /* Move forward 20000 microsteps */
    wait_for_motion();
    cmd(0x60, 0, 3); /* GoTo 0 */
    wait_for_motion();
  }
  return 0;
}
