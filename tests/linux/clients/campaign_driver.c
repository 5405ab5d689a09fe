/* A small L6470 driver with the ways a driver meets (or misses) a fault, for the campaign's
   tests. Usage: campaign_driver MODE, MODE one of
     careful   polls STATUS while it moves; any fault flag (OCD, TH_SD, UVLO) ends it with status 1
     careless  looks only at BUSY and always reports success
     stuck     as careless, then waits for the bridges to be on again (HiZ low): for ever after
               anything that took them off
     crash     as careful, but abort()s on a fault flag
     deadlock  as careful, but then waits on a semaphore nobody posts
   The chip: configured (ACC, DEC, MAX_SPEED), STATUS read once (the power-up UVLO), then Move
   forward 4000 microsteps and GoTo back to 1000. */
#include <fcntl.h>
#include <linux/spi/spidev.h>
#include <semaphore.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <time.h>
#include <unistd.h>

static int fd = -1;
static const char* mode = "careful";

static uint8_t byte(uint8_t out) {
  uint8_t in = 0;
  struct spi_ioc_transfer t;
  memset(&t, 0, sizeof t);
  t.tx_buf = (uintptr_t)&out;
  t.rx_buf = (uintptr_t)&in;
  t.len = 1;
  if (ioctl(fd, SPI_IOC_MESSAGE(1), &t) < 0) {
    perror("SPI_IOC_MESSAGE");
    exit(2);
  }
  return in;
}

static uint32_t cmd(uint8_t op, uint32_t arg, int n) {
  uint32_t answer = 0;
  byte(op);
  for (int i = n - 1; i >= 0; --i) answer = answer << 8 | byte((uint8_t)(arg >> (8 * i)));
  return answer;
}

static uint16_t get_status(void) { return (uint16_t)cmd(0xD0, 0, 2); }

static void sleep_ms(long ms) {
  struct timespec ts = {ms / 1000, (ms % 1000) * 1000000L};
  nanosleep(&ts, NULL);
}

/* A fault flag in STATUS: OCD (bit 12), TH_SD (11), UVLO (9), all active low. */
static int fault_in(uint16_t s) { return !(s & 0x1000) || !(s & 0x0800) || !(s & 0x0200); }

static void on_fault(uint16_t s) {
  if (strcmp(mode, "careful") == 0) {
    printf("fault: STATUS 0x%04X\n", s);
    exit(1);
  }
  if (strcmp(mode, "crash") == 0) abort();
  if (strcmp(mode, "deadlock") == 0) {
    sem_t never;
    sem_init(&never, 0, 0);
    sem_wait(&never);
  }
}

static void wait_idle(void) {
  for (;;) {
    const uint16_t s = get_status();
    if (strcmp(mode, "careless") != 0 && strcmp(mode, "stuck") != 0 && fault_in(s)) on_fault(s);
    if (s & 0x0002) return; /* BUSY high: done */
    sleep_ms(5);
  }
}

int main(int argc, char** argv) {
  if (argc > 1) mode = argv[1];
  setvbuf(stdout, NULL, _IOLBF, 0);
  fd = open("/dev/spidev0.0", O_RDWR);
  if (fd < 0) {
    perror("/dev/spidev0.0");
    return 2;
  }
  uint8_t m = SPI_MODE_3;
  uint32_t speed = 1000000;
  ioctl(fd, SPI_IOC_WR_MODE, &m);
  ioctl(fd, SPI_IOC_WR_MAX_SPEED_HZ, &speed);
  cmd(0x05, 0x040, 2); /* SetParam(ACC) */
  cmd(0x06, 0x040, 2); /* SetParam(DEC) */
  cmd(0x07, 0x030, 2); /* SetParam(MAX_SPEED) */
  get_status();        /* the power-up UVLO, read and cleared */
  cmd(0x41, 4000, 3);  /* Move forward 4000 */
  wait_idle();
  cmd(0x60, 1000, 3);  /* GoTo 1000 */
  wait_idle();
  if (strcmp(mode, "stuck") == 0)
    while (get_status() & 0x0001) sleep_ms(5); /* HiZ: wait for the bridges */
  const uint16_t s = get_status();
  if (strcmp(mode, "careless") != 0 && strcmp(mode, "stuck") != 0 && fault_in(s)) on_fault(s);
  printf("done\n");
  return 0;
}
