/* Homing against a limit switch, as a plain C driver on /dev/spidev0.0 does it: GoUntil in
   reverse until the switch closes (SW_MODE = 0: the chip stops hard), ReleaseSW forward until it
   opens, which sets ABS_POS to 0 at the switch's edge. Knows nothing of the emulator:
   `l6470emu run --board homing.board --scenario homing.yaml -- ./homing` judges it. */
#include "dspin.h"

int main(void) {
  dspin_open("/dev/spidev0.0");
  dspin_status(); /* the power-up UVLO latch released */
  /* GoUntil(ACT = 0, reverse, 200 step/s): SPEED = 200 · 2^28 / 4 000 000 = 13422 */
  dspin_cmd(0x82, 13422, 3);
  if (dspin_wait_idle(60000)) {
    fprintf(stderr, "homing: GoUntil never ended\n");
    return 1;
  }
  dspin_cmd(0x93, 0, 0); /* ReleaseSW(ACT = 0, forward): out of the switch at minimum speed */
  if (dspin_wait_idle(60000)) {
    fprintf(stderr, "homing: ReleaseSW never ended\n");
    return 1;
  }
  printf("homed: ABS_POS %d\n", (int)dspin_abs_pos());
  return 0;
}
