/* A plain spidev client for the tests: SPI_IOC_MESSAGE with several transfers per message,
 * cs_change between them, tx-only and rx-only transfers, and the kernel's error codes for
 * bad arguments. Knows nothing of the emulator. Usage: spidev_messages /dev/spidevB.C */
#include <errno.h>
#include <fcntl.h>
#include <linux/spi/spidev.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

static int fd;

/* One dSPIN command for a single chip: one transfer per byte, CS raised between them. */
static int command(const uint8_t* tx, uint8_t* rx, unsigned n) {
  struct spi_ioc_transfer x[8];
  memset(x, 0, sizeof x);
  for (unsigned i = 0; i < n; ++i) {
    x[i].tx_buf = (uintptr_t)(tx + i);
    x[i].rx_buf = (uintptr_t)(rx + i);
    x[i].len = 1;
    x[i].cs_change = i + 1 < n;
  }
  return ioctl(fd, SPI_IOC_MESSAGE(n), x);
}

static void expect_errno(const char* what, int r, int want) {
  printf("%s: %s\n", what, r < 0 && errno == want ? "ok" : "WRONG");
  if (!(r < 0 && errno == want)) printf("  got r=%d errno=%d (%s), wanted %s\n", r, errno, strerror(errno), strerror(want));
}

int main(int argc, char** argv) {
  const char* path = argc > 1 ? argv[1] : "/dev/spidev0.0";
  struct stat st;
  if (stat(path, &st) != 0) { perror("stat"); return 1; }
  printf("stat: %s %u:%u\n", S_ISCHR(st.st_mode) ? "char" : "other", major(st.st_rdev), minor(st.st_rdev));
  fd = open(path, O_RDWR);
  if (fd < 0) { perror("open"); return 1; }

  uint8_t mode = SPI_MODE_3, bits = 0;
  uint32_t speed = 4000000, mode32 = 0;
  if (ioctl(fd, SPI_IOC_WR_MODE, &mode) < 0) { perror("WR_MODE"); return 1; }
  if (ioctl(fd, SPI_IOC_WR_MAX_SPEED_HZ, &speed) < 0) { perror("WR_MAX_SPEED_HZ"); return 1; }
  mode = 0xff; speed = 0;
  ioctl(fd, SPI_IOC_RD_MODE, &mode);
  ioctl(fd, SPI_IOC_RD_MODE32, &mode32);
  ioctl(fd, SPI_IOC_RD_BITS_PER_WORD, &bits);
  ioctl(fd, SPI_IOC_RD_MAX_SPEED_HZ, &speed);
  printf("settings: mode %u mode32 %u bits %u speed %u\n", mode, mode32, bits, speed);

  uint8_t tx[4] = {0xD0, 0, 0}, rx[4] = {0};
  int r = command(tx, rx, 3);
  printf("GetStatus: r=%d %02X%02X\n", r, rx[1], rx[2]);

  /* SetParam(MAX_SPEED) = 0x030 as one message of three transfers, then GetParam back. */
  uint8_t set[3] = {0x07, 0x00, 0x30};
  command(set, rx, 3);
  uint8_t get[3] = {0x27, 0, 0};
  command(get, rx, 3);
  printf("MAX_SPEED: %02X%02X\n", rx[1], rx[2]);

  /* The same GetParam with a tx-only transfer for the opcode and an rx-only one for the answer. */
  struct spi_ioc_transfer x[3];
  memset(x, 0, sizeof x);
  uint8_t op = 0x27, answer[2] = {0xAA, 0xAA};
  x[0].tx_buf = (uintptr_t)&op; x[0].len = 1; x[0].cs_change = 1;
  x[1].rx_buf = (uintptr_t)&answer[0]; x[1].len = 1; x[1].cs_change = 1;
  x[2].rx_buf = (uintptr_t)&answer[1]; x[2].len = 1; x[2].delay_usecs = 5;
  r = ioctl(fd, SPI_IOC_MESSAGE(3), x);
  printf("tx-only/rx-only: r=%d %02X%02X\n", r, answer[0], answer[1]);

  /* cs_change on the last transfer keeps CS low: the next message continues the frame. */
  memset(x, 0, sizeof x);
  uint8_t nop = 0, out = 0xEE;
  x[0].tx_buf = (uintptr_t)&op; x[0].len = 1; x[0].cs_change = 1;
  r = ioctl(fd, SPI_IOC_MESSAGE(1), x);
  x[0].tx_buf = (uintptr_t)&nop; x[0].rx_buf = (uintptr_t)&out; x[0].cs_change = 0;
  r = ioctl(fd, SPI_IOC_MESSAGE(1), x);
  printf("held CS: echo %02X\n", out);  /* one chip, CS held: the opcode shifts back out */

  /* write()/read() are one tx-only / rx-only transfer each. */
  uint8_t w = 0xD0, rd[2] = {0};
  r = (int)write(fd, &w, 1);
  printf("write: %d\n", r);
  r = (int)read(fd, rd, 1); r += (int)read(fd, rd + 1, 1);
  printf("read: %d %02X%02X\n", r, rd[0], rd[1]);

  /* The kernel's errors. */
  static uint8_t big[8192];
  memset(x, 0, sizeof x);
  x[0].tx_buf = (uintptr_t)big; x[0].len = 4097;
  expect_errno("EMSGSIZE past bufsiz", ioctl(fd, SPI_IOC_MESSAGE(1), x), EMSGSIZE);
  x[0].len = 4096;
  printf("4096 bytes: %s\n", ioctl(fd, SPI_IOC_MESSAGE(1), x) == 4096 ? "ok" : "WRONG");
  x[0].tx_buf = (uintptr_t)8; x[0].len = 4;
  expect_errno("EFAULT bad tx_buf", ioctl(fd, SPI_IOC_MESSAGE(1), x), EFAULT);
  expect_errno("EFAULT bad transfer array", ioctl(fd, SPI_IOC_MESSAGE(1), (void*)16), EFAULT);
  x[0].tx_buf = (uintptr_t)big; x[0].len = 3; x[0].bits_per_word = 16;
  expect_errno("EINVAL odd length for 16-bit words", ioctl(fd, SPI_IOC_MESSAGE(1), x), EINVAL);
  x[0].bits_per_word = 9; x[0].len = 2;
  expect_errno("EINVAL unsupported word size", ioctl(fd, SPI_IOC_MESSAGE(1), x), EINVAL);
  speed = 0;
  expect_errno("EINVAL zero speed", ioctl(fd, SPI_IOC_WR_MAX_SPEED_HZ, &speed), EINVAL);
  uint32_t bad_mode = SPI_3WIRE;
  expect_errno("EINVAL unsupported mode bit", ioctl(fd, SPI_IOC_WR_MODE32, &bad_mode), EINVAL);
  expect_errno("ENOTTY other ioctl", ioctl(fd, _IOR('x', 1, int), &r), ENOTTY);
  expect_errno("EINVAL message size not a multiple", ioctl(fd, _IOW(SPI_IOC_MAGIC, 0, char[40]), x), EINVAL);
  printf("empty message: %d\n", ioctl(fd, SPI_IOC_MESSAGE(0), x));
  expect_errno("EFAULT RD_MODE to a bad pointer", ioctl(fd, SPI_IOC_RD_MODE, (void*)8), EFAULT);

  int fd2 = dup(fd);
  close(fd);
  fd = fd2;
  r = command(tx, rx, 3);
  printf("after dup+close: r=%d\n", r);
  close(fd);
  return 0;
}
