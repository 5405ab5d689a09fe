/* The plain C API's pin calls bit-banging SPI mode 3 on a board whose description maps the
 * pins (l6470emu_fw_open with cs_pin=, sck_pin=, mosi_pin=, miso_pin=): CONFIG of one L6470,
 * then a Move and ABS_POS read back. Prints PASS. */
#include <stdio.h>

#include <l6470emu/firmware/firmware.h>

static int cs, sck, mosi, miso, failures;

static void check(int ok, const char* what, long value) {
  printf("%s %s: %ld\n", ok ? "ok  " : "FAIL", what, value);
  if (!ok) ++failures;
}

static uint8_t transfer(uint8_t out) {
  uint8_t in = 0;
  for (int bit = 7; bit >= 0; --bit) {
    l6470emu_fw_pin_write(sck, 0);
    l6470emu_fw_pin_write(mosi, (out >> bit) & 1);
    l6470emu_fw_pin_write(sck, 1);
    in = (uint8_t)(in << 1 | l6470emu_fw_pin_read(miso));
  }
  return in;
}

static uint8_t byte_frame(uint8_t out) {
  l6470emu_fw_pin_write(cs, 0);
  const uint8_t in = transfer(out);
  l6470emu_fw_pin_write(cs, 1);
  return in;
}

int main(void) {
  if (l6470emu_fw_open("chips=L6470 cs_pin=PB6 sck_pin=PB3 mosi_pin=PB5 miso_pin=PB4") != 0) {
    printf("FAIL open: %s\n", l6470emu_fw_error());
    return 1;
  }
  cs = l6470emu_fw_pin("PB6");
  sck = l6470emu_fw_pin("PB3");
  mosi = l6470emu_fw_pin("PB5");
  miso = l6470emu_fw_pin("PB4");
  l6470emu_fw_pin_write(cs, 1);
  l6470emu_fw_pin_write(sck, 1);
  l6470emu_fw_pin_mode(cs, L6470EMU_FW_OUTPUT);
  l6470emu_fw_pin_mode(sck, L6470EMU_FW_OUTPUT);
  l6470emu_fw_pin_mode(mosi, L6470EMU_FW_OUTPUT);
  l6470emu_fw_pin_mode(miso, L6470EMU_FW_INPUT);

  byte_frame(0x38); /* GetParam(CONFIG) */
  const long config = byte_frame(0) << 8 | byte_frame(0);
  check(config == 0x2E88, "CONFIG", config);
  const uint8_t move[] = {0x41, 0x00, 0x0C, 0x80}; /* Move FWD 3200 */
  for (int i = 0; i < 4; ++i) byte_frame(move[i]);
  l6470emu_fw_sleep_ns(6000000000ull);
  byte_frame(0x21); /* GetParam(ABS_POS) */
  long pos = 0;
  for (int i = 0; i < 3; ++i) pos = pos << 8 | byte_frame(0);
  check(pos == 3200, "ABS_POS", pos);
  l6470emu_fw_close();
  printf("%s\n", failures == 0 ? "PASS" : "FAIL");
  return failures == 0 ? 0 : 1;
}
