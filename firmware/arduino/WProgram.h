/* The pre-1.0 Arduino header some libraries still include (#if ARDUINO < 100). */
#include "Arduino.h"
