/* The plain C API end to end, in C: an explicit open (and a second one refused), a transfer
 * that drives its own chip select, pins, a sleep, an edge callback held off by irq_disable and
 * delivered by irq_enable, a wait to BUSY's exact edge, the clock. Prints PASS. */
#include <stdio.h>
#include <string.h>

#include <l6470emu/firmware/firmware.h>

static int failures;
static int flag_edges;
static int flag_level = -1;

static void check(int ok, const char* what) {
  printf("%s %s\n", ok ? "ok  " : "FAIL", what);
  if (!ok) ++failures;
}

static void on_flag(int pin, int level, void* arg) {
  (void)pin;
  ++*(int*)arg;
  flag_level = level;
}

static uint32_t command(int bus, int cs, uint8_t opcode, int args, uint32_t value, int answer) {
  const struct l6470emu_fw_spi_config mode3 = {5000000, 3, 0};
  uint32_t result = 0;
  uint8_t in;
  l6470emu_fw_spi_transfer(bus, cs, &mode3, &opcode, NULL, 1);
  for (int i = args - 1; i >= 0; --i) {
    const uint8_t b = (uint8_t)(value >> (8 * i));
    l6470emu_fw_spi_transfer(bus, cs, &mode3, &b, NULL, 1);
  }
  for (int i = 0; i < answer; ++i) {
    l6470emu_fw_spi_transfer(bus, cs, &mode3, NULL, &in, 1);
    result = result << 8 | in;
  }
  return result;
}

int main(void) {
  check(l6470emu_fw_open("chips=L6470 cs_pin=PA4 busy_pin=PB0 flag_pin=PB1 spi=SPI2 call_time=2us") == 0, "open");
  check(l6470emu_fw_open(NULL) == -1 && strstr(l6470emu_fw_error(), "already open") != NULL, "one board per program");
  const int bus = l6470emu_fw_spi_bus("hspi2"), cs = l6470emu_fw_pin("PA4"), busy = l6470emu_fw_pin("PB0"),
            flag = l6470emu_fw_pin("PB1");
  check(bus == 0 && cs >= 0 && busy >= 0 && flag >= 0, "names");
  check(l6470emu_fw_pin("PZ9") == -1 && l6470emu_fw_spi_transfer(7, cs, NULL, NULL, NULL, 1) == -1, "bad names and buses");
  check(l6470emu_fw_pin_read(flag) == 0, "FLAG low at power-up (UVLO)");
  check(command(bus, cs, 0x38, 0, 0, 2) == 0x2E88, "GetParam(CONFIG) with the transfer's own chip select");
  command(bus, cs, 0xD0, 0, 0, 2);
  check(l6470emu_fw_pin_read(flag) == 1, "GetStatus releases FLAG");
  check(l6470emu_fw_pin_on_edge(flag, L6470EMU_FW_EDGE_BOTH, on_flag, &flag_edges) == 0, "an edge callback");

  const uint64_t t0 = l6470emu_fw_now_ns();
  l6470emu_fw_sleep_ns(1000000);
  const uint64_t slept = l6470emu_fw_now_ns() - t0;
  check(slept == 1000000 + 2 * 2000, "a 1 ms sleep and two calls of 2 us");

  command(bus, cs, 0x41, 3, 3200, 0); /* Move(FWD, 3200) */
  const uint64_t decoded = l6470emu_fw_now_ns();
  check(l6470emu_fw_pin_wait(busy, 1, 1000000) == 1, "a wait that times out");
  check(l6470emu_fw_pin_wait(busy, 1, 1000000000) == 0, "a wait that ends on BUSY");
  const uint64_t took = l6470emu_fw_now_ns() - decoded;
  printf("BUSY rose %llu ns after the call that decoded the Move\n", (unsigned long long)took);
  check(took >= 222936500 - 4000 && took <= 222936500 + 4000, "the wait ended at the profile's end");

  l6470emu_fw_irq_disable();
  const uint8_t bad = 0xF8;
  l6470emu_fw_spi_transfer(bus, cs, NULL, &bad, NULL, 1); /* NULL config: mode 0, said once */
  l6470emu_fw_sleep_ns(100000);
  check(flag_edges == 0, "no callback while interrupts are off");
  l6470emu_fw_irq_enable();
  check(flag_edges == 1 && flag_level == 0, "irq_enable delivers FLAG's falling edge");
  command(bus, cs, 0xD0, 0, 0, 2);
  check(flag_edges == 2 && flag_level == 1, "and its rising edge when the flags are read");
  l6470emu_fw_close();
  printf("%s\n", failures == 0 ? "PASS" : "FAIL");
  return failures != 0;
}
