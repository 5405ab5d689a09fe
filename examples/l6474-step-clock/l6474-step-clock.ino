// An L6474 on an X-NUCLEO-IHM01A1 (NUCLEO-F401RE) stepped by a timer, the way ST's library does
// it: the timer and channel behind STCK (D9) found from the pin map, a 1 kHz PWM at 50 % duty
// from STM32duino's HardwareTimer, DIR (D7) high, the bridges enabled over SPI. Ten minutes of
// stepping later the timer is paused and ABS_POS read: one microstep per pulse, exactly. No
// callback is attached, so the run does not meet the 600 000 pulses one by one: it takes
// milliseconds. Its output is one line: "ABS_POS 600000 after 599999 ms".
#include <SPI.h>

const uint32_t kStck = D9, kDir = D7, kCs = D10;

byte xfer(byte b) {
  SPI.beginTransaction(SPISettings(4000000, MSBFIRST, SPI_MODE3));
  digitalWrite(kCs, LOW);
  byte answer = SPI.transfer(b);
  digitalWrite(kCs, HIGH);
  SPI.endTransaction();
  return answer;
}

long abs_pos() {
  xfer(0x21);  // GetParam(ABS_POS): three answer bytes, 22 bits signed
  long v = long(xfer(0)) << 16;
  v |= long(xfer(0)) << 8;
  v |= xfer(0);
  return v & 0x200000 ? v - 0x400000 : v;
}

void setup() {
  Serial.begin(115200);
  pinMode(kCs, OUTPUT);
  digitalWrite(kCs, HIGH);
  pinMode(kDir, OUTPUT);
  digitalWrite(kDir, HIGH);  // forward
  SPI.begin();
  xfer(0xB8);  // Enable: the L6474 steps on STCK while its bridges are on

  TIM_TypeDef* instance = (TIM_TypeDef*)pinmap_peripheral(digitalPinToPinName(kStck), PinMap_PWM);
  const uint32_t channel = STM_PIN_CHANNEL(pinmap_function(digitalPinToPinName(kStck), PinMap_PWM));
  HardwareTimer* timer = new HardwareTimer(instance);
  const unsigned long start = millis();
  timer->setPWM(channel, kStck, 1000, 50);  // 1 kHz, 50 %: one pulse a millisecond from now
  delay(600000UL - 1);                      // the last of 600000 pulses rises at 599.999 s
  timer->pause();
  const unsigned long elapsed = millis() - start;
  Serial.print("ABS_POS ");
  Serial.print(abs_pos());
  Serial.print(" after ");
  Serial.print(elapsed);
  Serial.println(" ms");
  exit(abs_pos() == 600000 ? 0 : 1);
}

void loop() {}
