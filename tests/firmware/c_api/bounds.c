/* The C API at the ends of its argument ranges (argv[1] says which): a sleep of UINT64_MAX ns
 * lasts until the run's time limit (it once wrapped to no time at all), and a transfer of
 * SIZE_MAX bytes from and to NULL buffers clocks zeros until the limit in bounded memory (it
 * once allocated the whole length: a std::length_error through the C API, SIGABRT). Either way
 * the program is stopped at limit= and never prints "returned". */
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include <l6470emu/firmware/firmware.h>

int main(int argc, char** argv) {
  if (l6470emu_fw_open("chips=L6470 cs_pin=PA4 spi=SPI1 limit=20ms") != 0) {
    printf("FAIL open: %s\n", l6470emu_fw_error());
    return 1;
  }
  const int bus = l6470emu_fw_spi_bus("SPI1"), cs = l6470emu_fw_pin("PA4");
  const struct l6470emu_fw_spi_config mode3 = {5000000, 3, 0};
  if (argc > 1 && strcmp(argv[1], "sleep") == 0) {
    l6470emu_fw_sleep_ns(UINT64_MAX);
  } else {
    l6470emu_fw_spi_transfer(bus, cs, &mode3, NULL, NULL, SIZE_MAX);
  }
  printf("returned at %llu ns\n", (unsigned long long)l6470emu_fw_now_ns());
  return 1;
}
