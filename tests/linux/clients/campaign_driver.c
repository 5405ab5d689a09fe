/* A small L6470 driver with the ways a driver meets (or misses) a fault, for the campaign's
   tests. Usage: campaign_driver MODE, MODE one of
     careful   polls STATUS while it moves; any fault flag (OCD, TH_SD, UVLO) ends it with status 1
     careless  looks only at BUSY and always reports success
     stuck     as careless, then waits for the bridges to be on again (HiZ low): for ever after
               anything that took them off
     crash     as careful, but abort()s on a fault flag
     deadlock  as careful, but then waits on a semaphore nobody posts
   The chip: configured (ACC, DEC, MAX_SPEED), STATUS read once (the power-up UVLO), then Move
   forward 4000 microsteps and GoTo back to 1000. */
#include <semaphore.h>

#include "../../../examples/run/dspin.h"

static const char* mode = "careful";

/* A fault flag in STATUS: OCD (bit 12), TH_SD (11), UVLO (9), all active low. */
static int fault_in(uint16_t s) { return !(s & 0x1000) || !(s & 0x0800) || !(s & 0x0200); }

static void on_fault(uint16_t s) {
  if (strcmp(mode, "careful") == 0) {
    printf("fault: STATUS 0x%04X\n", s);
    exit(1);
  }
  if (strcmp(mode, "crash") == 0) abort();
  if (strcmp(mode, "deadlock") == 0) {
    sem_t never;
    sem_init(&never, 0, 0);
    sem_wait(&never);
  }
}

static void wait_idle(void) {
  for (;;) {
    const uint16_t s = dspin_status();
    if (strcmp(mode, "careless") != 0 && strcmp(mode, "stuck") != 0 && fault_in(s)) on_fault(s);
    if (s & 0x0002) return; /* BUSY high: done */
    sleep_ms(5);
  }
}

int main(int argc, char** argv) {
  if (argc > 1) mode = argv[1];
  setvbuf(stdout, NULL, _IOLBF, 0);
  dspin_open("/dev/spidev0.0");
  dspin_cmd(0x05, 0x040, 2); /* SetParam(ACC) */
  dspin_cmd(0x06, 0x040, 2); /* SetParam(DEC) */
  dspin_cmd(0x07, 0x030, 2); /* SetParam(MAX_SPEED) */
  dspin_status();            /* the power-up UVLO, read and cleared */
  dspin_cmd(0x41, 4000, 3);  /* Move forward 4000 */
  wait_idle();
  dspin_cmd(0x60, 1000, 3);  /* GoTo 1000 */
  wait_idle();
  if (strcmp(mode, "stuck") == 0)
    while (dspin_status() & 0x0001) sleep_ms(5); /* HiZ: wait for the bridges */
  const uint16_t s = dspin_status();
  if (strcmp(mode, "careless") != 0 && strcmp(mode, "stuck") != 0 && fault_in(s)) on_fault(s);
  printf("done\n");
  return 0;
}
