/* A program spinning on a flag nothing sets without calling the API (as ST's L6474 HelloWorld
 * waits for its timer callback): virtual time stands still, and the runtime's spin watch says so
 * on stderr after a second of CPU time. The program gives up after 2.5 s of CPU and exits 0. */
#include <stdio.h>
#include <time.h>

#include <l6470emu/firmware/firmware.h>

static volatile int done;

int main(void) {
  if (l6470emu_fw_open("chips=L6474") != 0) return 1;
  l6470emu_fw_sleep_ns(10000);
  while (!done && clock() < (clock_t)(2.5 * CLOCKS_PER_SEC)) {
  }
  printf("gave up at %llu ns of virtual time\n", (unsigned long long)l6470emu_fw_now_ns());
  return 0;
}
