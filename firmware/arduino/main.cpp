// The Arduino runtime's main: the board first, then setup(), then loop() for ever; each loop()
// iteration costs loop_time= of its own. The run ends at the time limit, or when the sketch exits.
// The model first: Arduino.h's macros (HIGH, DEC, ...) must not reach its headers.
#include "firmware/arduino/arduino_internal.hpp"

#include "Arduino.h"

int main() {
  l6470emu::FirmwareRuntime& r = l6470emu::arduino::runtime();
  setup();
  for (;;) {
    r.spend(r.timing().loop_ticks);
    ++r.loops;
    loop();
  }
}
