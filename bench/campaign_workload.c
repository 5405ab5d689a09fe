/* The C driver of bench/campaign_bench.sh: about 10 s of virtual time on one L6470 — configure,
   Move out and GoTo back twice, polling STATUS every 10 ms and stopping on OCD or TH_SD, as a
   careful production driver would. Usage: l6470emu_campaign_workload (under l6470emu run). */
#include "../examples/run/dspin.h"

static void wait_for_motion(void) {
  for (;;) {
    const uint16_t s = dspin_status();
    if (!(s & 0x1000) || !(s & 0x0800)) exit(1);
    if (s & 0x0002) return;
    sleep_ms(10);
  }
}

int main(void) {
  dspin_open("/dev/spidev0.0");
  dspin_cmd(0x05, 0x010, 2); /* ACC */
  dspin_cmd(0x06, 0x010, 2); /* DEC */
  dspin_cmd(0x07, 0x020, 2); /* MAX_SPEED */
  dspin_cmd(0xD0, 0, 2);
  for (int i = 0; i < 2; ++i) {
    dspin_cmd(0x41, 20000, 3); /* Move forward 20000 microsteps */
    wait_for_motion();
    dspin_cmd(0x60, 0, 3); /* GoTo 0 */
    wait_for_motion();
  }
  return 0;
}
