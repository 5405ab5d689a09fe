/* A driver that must notice an overcurrent: it runs the motor and polls STATUS every 10 ms;
   when OCD (bit 12, active low) shows, it disables the bridges (HardHiZ) and reports it.
   With --careless it only watches BUSY, as a driver with that bug does; the scenario then
   catches it. `l6470emu run --chain "chips=L6470" --scenario overcurrent.yaml -- ./overcurrent` */
#include "dspin.h"

int main(int argc, char** argv) {
  const int careless = argc > 1 && strcmp(argv[1], "--careless") == 0;
  dspin_open("/dev/spidev0.0");
  dspin_status();
  dspin_cmd(0x51, 13422, 3); /* Run(forward, 200 step/s) */
  for (int ms = 0; ms < 2000; ms += 10) {
    const uint16_t status = dspin_status();
    if (!careless && !(status & 0x1000)) {
      dspin_cmd(0xA8, 0, 0); /* HardHiZ: bridges off at once */
      printf("overcurrent after %d ms: bridges disabled\n", ms);
      return 0;
    }
    sleep_ms(10);
  }
  dspin_cmd(0xB0, 0, 0); /* SoftStop after 2 s of running */
  printf("ran 2 s without a fault\n");
  return 0;
}
