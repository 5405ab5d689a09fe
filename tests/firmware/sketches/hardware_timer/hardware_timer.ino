// STM32duino's HardwareTimer on a NUCLEO-F401RE as ST's L6474 library uses it: the timer and
// channel of D9 from the pin map (TIM3 channel 2), setPWM at 1 kHz, 50 %, with an update
// callback that counts steps and runs at its exact tick (its getCount(), two calls of 1 us after
// the update, reads 84 counts of 42 MHz; micros() 1000 us apart); pauseChannel and a new setPWM
// at 2 kHz from inside the callback (a ramp), pause after 100 updates; ABS_POS moves by exactly
// the pulses made. Then analogWrite's 1 kHz PWM on the same pin.
#include <SPI.h>

const SPISettings kL6474(4000000, MSBFIRST, SPI_MODE3);
int failures = 0;
HardwareTimer* timer = nullptr;
uint32_t channel = 0;
volatile unsigned updates = 0;
unsigned long first_update_us[3];
uint32_t first_count = 0;

void check(bool ok, const String& what) {
  Serial.println((ok ? "ok   " : "FAIL ") + what);
  if (!ok) ++failures;
}

byte xfer(byte b) {
  SPI.beginTransaction(kL6474);
  digitalWrite(D10, LOW);
  const byte answer = SPI.transfer(b);
  digitalWrite(D10, HIGH);
  SPI.endTransaction();
  return answer;
}

long abs_pos() {
  xfer(0x21);
  long v = (long)xfer(0) << 16;
  v |= (long)xfer(0) << 8;
  v |= xfer(0);
  return v & 0x200000 ? v - 0x400000 : v;
}

void on_update() {
  if (updates < 3) first_update_us[updates] = micros();
  if (updates == 0) first_count = timer->getCount();
  ++updates;
  if (updates == 10) {  // from here on 2 kHz, set as the library does it
    timer->pauseChannel(channel);
    timer->setPWM(channel, D9, 2000, 50, on_update);
  }
  if (updates == 100) timer->pause();
}

void setup() {
  Serial.begin(115200);
  pinMode(D10, OUTPUT);
  digitalWrite(D10, HIGH);
  pinMode(D7, OUTPUT);
  digitalWrite(D7, HIGH);
  SPI.begin();
  xfer(0xB8);  // Enable

  TIM_TypeDef* instance = (TIM_TypeDef*)pinmap_peripheral(digitalPinToPinName(D9), PinMap_PWM);
  channel = STM_PIN_CHANNEL(pinmap_function(digitalPinToPinName(D9), PinMap_PWM));
  check(instance == TIM3 && channel == 2, "D9 (PC7) is TIM3 channel 2");
  timer = new HardwareTimer(instance);
  timer->setPWM(channel, D9, 1000, 50, on_update);
  check(timer->getOverflow(HERTZ_FORMAT) == 1000 && timer->getPrescaleFactor() == 2 && timer->getOverflow() == 42000,
        "1 kHz at 84 MHz: prescale factor 2, overflow 42000");
  delay(1000);
  check(updates == 100, "100 updates, then paused");
  check(first_count == 84, "the first update callback's getCount() reads 84 (2 us of 42 MHz after the update)");
  check(first_update_us[1] - first_update_us[0] == 1000 && first_update_us[2] - first_update_us[1] == 1000,
        "update callbacks 1000 us apart exactly");
  // Pulses rise at 0..10 ms (11: the new overflow written at the tenth update waits for the
  // update at 11 ms), then every 0.5 ms from 11 ms to the update at 55.5 ms whose callback
  // pauses the timer: that one's pulse has risen with the counter's reset before the callback
  // runs. 11 + 90 pulses.
  check(abs_pos() == 101, "ABS_POS moved by exactly the 101 pulses made");

  // analogWrite on a NUCLEO: a PWM at analogWriteFrequency (1 kHz) from the pin's timer.
  analogWrite(D9, 128);
  delay(100);
  analogWrite(D9, 0);
  check(abs_pos() == 101 + 101, "analogWrite(D9, 128) for 100 ms: pulses at 0, 1, ..., 100 ms");
  Serial.println(failures ? "FAIL" : "PASS");
  exit(failures ? 1 : 0);
}

void loop() {}
