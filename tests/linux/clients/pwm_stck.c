/* A program that steps a chip from the Linux pwm sysfs class (/sys/class/pwm/pwmchip0), as a
   host with a hardware PWM on the chip's STCK does. Usage:
     pwm_stck steps L6474|L6470 PERIOD_NS DUTY_NS SECONDS
       exports channel 0, enables the chip (L6474: Enable) or puts it in step-clock mode (L6470:
       StepClock forward), runs the PWM for SECONDS of sleep, disables it and prints the files'
       values and abs_pos=ABS_POS (22-bit, sign-extended).
     pwm_stck errors
       prints name=result/errno of writes and opens the kernel refuses (and of some it takes).
     pwm_stck stdio
       the same through fopen/fprintf/fclose: prints name=result/errno of each fclose.
   Exits 1 on an unexpected failure. */
#define _GNU_SOURCE
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <linux/spi/spidev.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#define CHIP "/sys/class/pwm/pwmchip0"

static int spi = -1;

static uint8_t xfer(uint8_t b) {
  uint8_t rx = 0;
  struct spi_ioc_transfer t;
  memset(&t, 0, sizeof t);
  t.tx_buf = (uintptr_t)&b;
  t.rx_buf = (uintptr_t)&rx;
  t.len = 1;
  t.speed_hz = 1000000;
  if (ioctl(spi, SPI_IOC_MESSAGE(1), &t) != 1) {
    perror("SPI_IOC_MESSAGE");
    exit(1);
  }
  return rx;
}

/* Writes `text` to `path` with write(2): 0, or the errno of the open or the write. */
static int put(const char* path, const char* text) {
  const int fd = open(path, O_WRONLY);
  if (fd < 0) return errno;
  const ssize_t n = write(fd, text, strlen(text));
  const int e = n < 0 ? errno : 0;
  close(fd);
  return n < 0 ? e : (n == (ssize_t)strlen(text) ? 0 : -1);
}

/* The file's contents without the newline ("" and errno printed on failure). */
static const char* get(const char* path) {
  static char buf[64];
  buf[0] = 0;
  const int fd = open(path, O_RDONLY);
  if (fd < 0) {
    snprintf(buf, sizeof buf, "errno%d", errno);
    return buf;
  }
  const ssize_t n = read(fd, buf, sizeof buf - 1);
  close(fd);
  buf[n > 0 ? n : 0] = 0;
  if (n > 0 && buf[n - 1] == '\n') buf[n - 1] = 0;
  return buf;
}

static void must(int r, const char* what) {
  if (r != 0) {
    printf("unexpected: %s -> %d\n", what, r);
    exit(1);
  }
}

static int steps(const char* variant, const char* period, const char* duty, unsigned seconds) {
  spi = open("/dev/spidev0.0", O_RDWR);
  if (spi < 0) {
    perror("/dev/spidev0.0");
    return 1;
  }
  uint8_t mode = SPI_MODE_3;
  ioctl(spi, SPI_IOC_WR_MODE, &mode);
  xfer(0xD0); /* GetStatus: clears the power-up flags */
  xfer(0x00);
  xfer(0x00);
  if (strcmp(variant, "L6474") == 0)
    xfer(0xB8); /* Enable */
  else
    xfer(0x59); /* StepClock, forward */
  must(put(CHIP "/export", "0"), "export");
  must(put(CHIP "/pwm0/period", period), "period");
  must(put(CHIP "/pwm0/duty_cycle", duty), "duty_cycle");
  must(put(CHIP "/pwm0/enable", "1\n"), "enable");
  printf("period=%s\n", get(CHIP "/pwm0/period"));
  printf("duty_cycle=%s\n", get(CHIP "/pwm0/duty_cycle"));
  printf("enable=%s\n", get(CHIP "/pwm0/enable"));
  printf("polarity=%s\n", get(CHIP "/pwm0/polarity"));
  struct timespec start, end;
  clock_gettime(CLOCK_MONOTONIC, &start);
  sleep(seconds);
  clock_gettime(CLOCK_MONOTONIC, &end);
  must(put(CHIP "/pwm0/enable", "0"), "disable");
  printf("slept_ns=%lld\n", (long long)(end.tv_sec - start.tv_sec) * 1000000000LL + (end.tv_nsec - start.tv_nsec));
  printf("enable_after=%s\n", get(CHIP "/pwm0/enable"));
  xfer(0x21); /* GetParam ABS_POS */
  uint32_t v = (uint32_t)xfer(0) << 16;
  v |= (uint32_t)xfer(0) << 8;
  v |= xfer(0);
  int32_t pos = (int32_t)(v << 10) >> 10;
  printf("abs_pos=%d\n", pos);
  must(put(CHIP "/unexport", "0"), "unexport");
  return 0;
}

#define SAY(name, call) printf("%s=%d\n", name, (call))

/* The names opendir/readdir list in `dir`, sorted, joined with commas ("errnoN" on failure). */
static const char* listing(const char* dir) {
  static char out[256];
  char names[16][32];
  int n = 0;
  DIR* d = opendir(dir);
  if (!d) {
    snprintf(out, sizeof out, "errno%d", errno);
    return out;
  }
  struct dirent* e;
  while ((e = readdir(d)) != NULL && n < 16)
    if (e->d_name[0] != '.') snprintf(names[n++], sizeof names[0], "%.31s", e->d_name);
  closedir(d);
  qsort(names, (size_t)n, sizeof names[0], (int (*)(const void*, const void*))strcmp);
  out[0] = 0;
  for (int i = 0; i < n; ++i) {
    if (i) strcat(out, ",");
    strcat(out, names[i]);
  }
  return out;
}

static int errors(void) {
  struct stat st;
  printf("npwm=%s\n", get(CHIP "/npwm"));
  SAY("stat_chip", stat(CHIP, &st) == 0 && S_ISDIR(st.st_mode) ? 0 : errno);
  SAY("stat_pwm0_before_export", stat(CHIP "/pwm0", &st) == 0 ? 0 : errno);
  SAY("export_past_npwm", put(CHIP "/export", "1"));
  SAY("export_not_a_number", put(CHIP "/export", "zero"));
  SAY("export", put(CHIP "/export", "0"));
  SAY("export_again", put(CHIP "/export", "0"));
  SAY("stat_pwm0", stat(CHIP "/pwm0", &st) == 0 && S_ISDIR(st.st_mode) ? 0 : errno);
  printf("list_chip=%s\n", listing(CHIP));
  printf("list_pwm0=%s\n", listing(CHIP "/pwm0"));
  SAY("stat_period_mode", stat(CHIP "/pwm0/period", &st) == 0 ? (int)(st.st_mode & 0777) : -errno);
  printf("period_at_export=%s\n", get(CHIP "/pwm0/period"));
  SAY("duty_without_period", put(CHIP "/pwm0/duty_cycle", "1000"));
  SAY("enable_without_period", put(CHIP "/pwm0/enable", "1"));
  SAY("period", put(CHIP "/pwm0/period", "1000000"));
  SAY("duty_over_period", put(CHIP "/pwm0/duty_cycle", "1000001"));
  SAY("duty", put(CHIP "/pwm0/duty_cycle", "0x3e8"));
  printf("duty_read=%s\n", get(CHIP "/pwm0/duty_cycle"));
  SAY("period_zero", put(CHIP "/pwm0/period", "0"));
  SAY("period_under_duty", put(CHIP "/pwm0/period", "999"));
  SAY("period_not_a_number", put(CHIP "/pwm0/period", "1ms"));
  SAY("period_negative", put(CHIP "/pwm0/period", "-5"));
  SAY("period_over_64_bits", put(CHIP "/pwm0/period", "18446744073709551616"));
  SAY("enable_two", put(CHIP "/pwm0/enable", "2"));
  SAY("polarity_sideways", put(CHIP "/pwm0/polarity", "sideways"));
  SAY("polarity_inversed", put(CHIP "/pwm0/polarity", "inversed\n"));
  printf("polarity_read=%s\n", get(CHIP "/pwm0/polarity"));
  SAY("enable", put(CHIP "/pwm0/enable", "1"));
  SAY("open_npwm_for_writing", open(CHIP "/npwm", O_WRONLY) >= 0 ? 0 : errno);
  SAY("open_export_for_reading", open(CHIP "/export", O_RDONLY) >= 0 ? 0 : errno);
  SAY("unexport_past_npwm", put(CHIP "/unexport", "7"));
  SAY("unexport", put(CHIP "/unexport", "0"));
  SAY("unexport_again", put(CHIP "/unexport", "0"));
  SAY("stat_pwm0_after_unexport", stat(CHIP "/pwm0", &st) == 0 ? 0 : errno);
  SAY("period_after_unexport", put(CHIP "/pwm0/period", "1000"));
  SAY("stat_pwmchip1", stat("/sys/class/pwm/pwmchip1", &st) == 0 ? 0 : errno);
  return 0;
}

/* fopen, fprintf, fclose: 0 or fclose's errno. */
static int put_stream(const char* path, const char* text) {
  FILE* f = fopen(path, "w");
  if (!f) return errno;
  fputs(text, f);
  errno = 0;
  return fclose(f) == 0 ? 0 : errno;
}

static int stdio(void) {
  SAY("export", put_stream(CHIP "/export", "0\n"));
  SAY("period", put_stream(CHIP "/pwm0/period", "2000\n"));
  SAY("duty_over_period", put_stream(CHIP "/pwm0/duty_cycle", "3000\n"));
  SAY("duty", put_stream(CHIP "/pwm0/duty_cycle", "1000\n"));
  FILE* f = fopen(CHIP "/pwm0/duty_cycle", "r");
  char line[32] = "";
  if (!f || !fgets(line, sizeof line, f)) return 1;
  fclose(f);
  line[strcspn(line, "\n")] = 0;
  printf("duty_read=%s\n", line);
  return 0;
}

int main(int argc, char** argv) {
  setvbuf(stdout, NULL, _IONBF, 0);
  if (argc == 6 && strcmp(argv[1], "steps") == 0) return steps(argv[2], argv[3], argv[4], (unsigned)atoi(argv[5]));
  if (argc == 2 && strcmp(argv[1], "errors") == 0) return errors();
  if (argc == 2 && strcmp(argv[1], "stdio") == 0) return stdio();
  fprintf(stderr, "usage: pwm_stck steps L6474|L6470 PERIOD_NS DUTY_NS SECONDS | pwm_stck errors | pwm_stck stdio\n");
  return 2;
}
