/* A driver with some fault handling and some gaps, for `l6470emu campaign` (docs/campaigns.md):
   it moves one L6470 out and back, polling STATUS every 10 ms. It handles an overcurrent and a
   thermal shutdown (bridges off with HardHiZ, a message, exit status 1) but ignores an
   undervoltage, the switch, and a chip that was reset under it: the campaign finds those.
   l6470emu campaign --chain chips=L6470 --json campaign.json -- ./campaign_driver */
#include "../run/dspin.h"

/* Polls until the motion ends; ends the program on the faults it knows. */
static void wait_for_motion(void) {
  for (;;) {
    const uint16_t status = dspin_status();
    if (!(status & 0x1000) || !(status & 0x0800)) { /* OCD or TH_SD (active low) */
      dspin_cmd(0xA8, 0, 0);                        /* HardHiZ */
      printf("%s: bridges disabled\n", !(status & 0x1000) ? "overcurrent" : "thermal shutdown");
      exit(1);
    }
    if (status & 0x0002) return; /* BUSY high: done */
    sleep_ms(10);
  }
}

int main(void) {
  dspin_open("/dev/spidev0.0");
  dspin_cmd(0x05, 0x08A, 2); /* SetParam(ACC) */
  dspin_cmd(0x06, 0x08A, 2); /* SetParam(DEC) */
  dspin_cmd(0x07, 0x041, 2); /* SetParam(MAX_SPEED) */
  dspin_status();            /* clears the power-up UVLO */
  dspin_cmd(0x41, 3200, 3);  /* Move forward 3200 microsteps */
  wait_for_motion();
  dspin_cmd(0x60, 0, 3);     /* GoTo 0 */
  wait_for_motion();
  printf("back at %d\n", (int)dspin_abs_pos());
  return 0;
}
