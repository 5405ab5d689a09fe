/* A gpio character-device v2 client (what libgpiod 2.x does), written against linux/gpio.h
 * directly because bookworm packages only libgpiod 1.6. It starts a Move through spidev and
 * watches BUSY with GPIO_V2_GET_LINE edge events, drives SW as an output and checks the
 * kernel's errors. Usage: gpio_v2 /dev/gpiochipN /dev/spidevB.C */
#include <errno.h>
#include <fcntl.h>
#include <linux/gpio.h>
#include <linux/spi/spidev.h>
#include <poll.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <sys/ioctl.h>
#include <time.h>
#include <unistd.h>

static int spi;

static void frame(uint8_t b) {
  struct spi_ioc_transfer x;
  memset(&x, 0, sizeof x);
  x.tx_buf = (uintptr_t)&b;
  x.len = 1;
  ioctl(spi, SPI_IOC_MESSAGE(1), &x);
}

static int find_line(int chip, const char* name, unsigned n) {
  for (unsigned i = 0; i < n; ++i) {
    struct gpio_v2_line_info info;
    memset(&info, 0, sizeof info);
    info.offset = i;
    if (ioctl(chip, GPIO_V2_GET_LINEINFO_IOCTL, &info) == 0 && strcmp(info.name, name) == 0) return (int)i;
  }
  return -1;
}

static void expect_errno(const char* what, int r, int want) {
  printf("%s: %s\n", what, r < 0 && errno == want ? "ok" : "WRONG");
}

int main(int argc, char** argv) {
  const char* chip_path = argc > 1 ? argv[1] : "/dev/gpiochip0";
  const char* spi_path = argc > 2 ? argv[2] : "/dev/spidev0.0";
  int chip = open(chip_path, O_RDWR | O_CLOEXEC);
  spi = open(spi_path, O_RDWR);
  if (chip < 0 || spi < 0) { perror("open"); return 1; }
  uint8_t mode = SPI_MODE_3;
  ioctl(spi, SPI_IOC_WR_MODE, &mode);

  struct gpiochip_info ci;
  memset(&ci, 0, sizeof ci);
  ioctl(chip, GPIO_GET_CHIPINFO_IOCTL, &ci);
  printf("chip: %s [%s] %u lines\n", ci.name, ci.label, ci.lines);
  const int busy = find_line(chip, "BUSY", ci.lines), sw = find_line(chip, "SW", ci.lines);
  printf("BUSY=%d SW=%d\n", busy, sw);

  /* Watch line info changes on the chip fd. */
  struct gpio_v2_line_info watch;
  memset(&watch, 0, sizeof watch);
  watch.offset = (unsigned)busy;
  printf("watch: %d\n", ioctl(chip, GPIO_V2_GET_LINEINFO_WATCH_IOCTL, &watch));

  struct gpio_v2_line_request req;
  memset(&req, 0, sizeof req);
  req.offsets[0] = (unsigned)busy;
  req.num_lines = 1;
  strcpy(req.consumer, "v2-test");
  req.config.flags = GPIO_V2_LINE_FLAG_INPUT | GPIO_V2_LINE_FLAG_EDGE_RISING | GPIO_V2_LINE_FLAG_EDGE_FALLING;
  if (ioctl(chip, GPIO_V2_GET_LINE_IOCTL, &req) < 0) { perror("GET_LINE"); return 1; }
  printf("request fd: %s cloexec=%d\n", req.fd > 2 ? "ok" : "WRONG", (fcntl(req.fd, F_GETFD) & FD_CLOEXEC) != 0);

  struct gpio_v2_line_info_changed changed;
  memset(&changed, 0, sizeof changed);
  const ssize_t got = read(chip, &changed, sizeof changed);
  printf("info event: %s type %u consumer %s\n", got == (ssize_t)sizeof changed ? "ok" : "WRONG", changed.event_type,
         changed.info.consumer);

  expect_errno("EBUSY second request", ioctl(chip, GPIO_V2_GET_LINE_IOCTL, &req), EBUSY);
  struct gpio_v2_line_request bad;
  memset(&bad, 0, sizeof bad);
  bad.offsets[0] = (unsigned)sw;
  bad.num_lines = 1;
  bad.config.flags = GPIO_V2_LINE_FLAG_INPUT | GPIO_V2_LINE_FLAG_OUTPUT;
  expect_errno("EINVAL input and output", ioctl(chip, GPIO_V2_GET_LINE_IOCTL, &bad), EINVAL);
  bad.config.flags = GPIO_V2_LINE_FLAG_EDGE_RISING;
  expect_errno("EINVAL edge without input", ioctl(chip, GPIO_V2_GET_LINE_IOCTL, &bad), EINVAL);
  bad.offsets[0] = 999;
  bad.config.flags = GPIO_V2_LINE_FLAG_INPUT;
  expect_errno("EINVAL offset out of range", ioctl(chip, GPIO_V2_GET_LINE_IOCTL, &bad), EINVAL);
  bad.num_lines = 0;
  expect_errno("EINVAL no lines", ioctl(chip, GPIO_V2_GET_LINE_IOCTL, &bad), EINVAL);

  struct gpio_v2_line_values v = {0, 1};
  ioctl(req.fd, GPIO_V2_LINE_GET_VALUES_IOCTL, &v);
  printf("BUSY before: %llu\n", (unsigned long long)v.bits);
  expect_errno("EPERM set an input", ioctl(req.fd, GPIO_V2_LINE_SET_VALUES_IOCTL, &v), EPERM);
  struct gpio_v2_line_event small;
  expect_errno("EINVAL short read", (int)read(req.fd, &small, 10), EINVAL);

  frame(0xD0); frame(0); frame(0);
  frame(0x40); frame(0x00); frame(0x06); frame(0x40);  /* Move REV 1600 microsteps */
  v.bits = 0; v.mask = 1;
  ioctl(req.fd, GPIO_V2_LINE_GET_VALUES_IOCTL, &v);
  printf("BUSY during move: %llu\n", (unsigned long long)v.bits);

  struct pollfd p = {req.fd, POLLIN, 0};
  unsigned events = 0;
  while (poll(&p, 1, 3000) == 1) {
    struct gpio_v2_line_event ev[4];
    const ssize_t n = read(req.fd, ev, sizeof ev);
    for (ssize_t i = 0; i < n / (ssize_t)sizeof ev[0]; ++i) {
      printf("event: %s offset %u seqno %u line_seqno %u\n", ev[i].id == GPIO_V2_LINE_EVENT_RISING_EDGE ? "rising" : "falling",
             ev[i].offset, ev[i].seqno, ev[i].line_seqno);
      ++events;
      if (ev[i].id == GPIO_V2_LINE_EVENT_RISING_EDGE) goto done;
    }
  }
done:
  ioctl(req.fd, GPIO_V2_LINE_GET_VALUES_IOCTL, &v);
  printf("BUSY after move: %llu (%u events)\n", (unsigned long long)v.bits, events);
  close(req.fd);

  /* SW as an output, active low: logical 1 = switch closed = pin low. */
  struct gpio_v2_line_request out;
  memset(&out, 0, sizeof out);
  out.offsets[0] = (unsigned)sw;
  out.num_lines = 1;
  strcpy(out.consumer, "v2-sw");
  out.config.flags = GPIO_V2_LINE_FLAG_OUTPUT | GPIO_V2_LINE_FLAG_ACTIVE_LOW;
  out.config.num_attrs = 1;
  out.config.attrs[0].attr.id = GPIO_V2_LINE_ATTR_ID_OUTPUT_VALUES;
  out.config.attrs[0].attr.values = 0;
  out.config.attrs[0].mask = 1;
  if (ioctl(chip, GPIO_V2_GET_LINE_IOCTL, &out) < 0) { perror("SW request"); return 1; }
  struct gpio_v2_line_values sv = {1, 1};
  printf("SW closed: %d\n", ioctl(out.fd, GPIO_V2_LINE_SET_VALUES_IOCTL, &sv));
  /* GetStatus: SW_F (bit 2) reads 1 while the switch is closed, SW_EVN (bit 3) latched. */
  uint8_t st[3] = {0};
  struct spi_ioc_transfer x[3];
  uint8_t txb[3] = {0xD0, 0, 0};
  memset(x, 0, sizeof x);
  for (int i = 0; i < 3; ++i) { x[i].tx_buf = (uintptr_t)&txb[i]; x[i].rx_buf = (uintptr_t)&st[i]; x[i].len = 1; x[i].cs_change = i < 2; }
  ioctl(spi, SPI_IOC_MESSAGE(3), x);
  printf("STATUS with SW closed: %02X%02X\n", st[1], st[2]);
  struct gpio_v2_line_info si;
  memset(&si, 0, sizeof si);
  si.offset = (unsigned)sw;
  ioctl(chip, GPIO_V2_GET_LINEINFO_IOCTL, &si);
  printf("SW info: consumer %s output=%d active_low=%d used=%d\n", si.consumer, !!(si.flags & GPIO_V2_LINE_FLAG_OUTPUT),
         !!(si.flags & GPIO_V2_LINE_FLAG_ACTIVE_LOW), !!(si.flags & GPIO_V2_LINE_FLAG_USED));
  close(out.fd);
  close(chip);
  close(spi);
  return 0;
}
