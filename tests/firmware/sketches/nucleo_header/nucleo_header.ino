// A sketch for a NUCLEO-F401RE (ARDUINO_BOARD nucleo_f401re): its Arduino header's D pins are
// port pins (D10 is PB6, D3 is PB3), the numbers 0..15 mean the same pins, and so do the board
// description's D pins. BOARD says cs_pin=D10 busy_pin=PB3 flag_pin=D2: the sketch drives CS as
// 10 and PB6 and reads BUSY as D3 and 3, and they all reach the chip.
#include <SPI.h>

const SPISettings kL6470(4000000, MSBFIRST, SPI_MODE3);
int failures = 0;

void check(bool ok, const String& what) {
  Serial.println((ok ? "ok   " : "FAIL ") + what);
  if (!ok) ++failures;
}

byte xfer(byte b) {
  SPI.beginTransaction(kL6470);
  digitalWrite(10, LOW);
  const byte answer = SPI.transfer(b);
  digitalWrite(PB6, HIGH);
  SPI.endTransaction();
  return answer;
}

void setup() {
  Serial.begin(115200);
  check(D0 == PA3 && D1 == PA2 && D2 == PA10 && D3 == PB3 && D4 == PB5 && D5 == PB4 && D6 == PB10 && D7 == PA8,
        "D0..D7 are PA3 PA2 PA10 PB3 PB5 PB4 PB10 PA8");
  check(D8 == PA9 && D9 == PC7 && D10 == PB6 && D11 == PA7 && D12 == PA6 && D13 == PA5 && D14 == PB9 && D15 == PB8,
        "D8..D15 are PA9 PC7 PB6 PA7 PA6 PA5 PB9 PB8");
  check(A0 == PA0 && A1 == PA1 && A2 == PA4 && A3 == PB0 && A4 == PC1 && A5 == PC0, "A0..A5 are PA0 PA1 PA4 PB0 PC1 PC0");
  check(SS == D10 && MOSI == D11 && MISO == D12 && SCK == D13 && LED_BUILTIN == PA5, "SS, MOSI, MISO, SCK, LED_BUILTIN");
#ifdef ARDUINO_NUCLEO_F401RE
  check(true, "ARDUINO_NUCLEO_F401RE is defined, as the IDE defines it");
#else
  check(false, "ARDUINO_NUCLEO_F401RE is defined, as the IDE defines it");
#endif

  pinMode(D10, OUTPUT);
  digitalWrite(10, HIGH);
  pinMode(3, INPUT);
  SPI.begin();
  xfer(0xD0);  // GetStatus: the power-up UVLO latch released
  xfer(0);
  xfer(0);
  check(digitalRead(D2) == HIGH, "FLAG on D2 (PA10) released");
  xfer(0x38);  // GetParam(CONFIG)
  const unsigned config = xfer(0) << 8 | xfer(0);
  check(config == 0x2E88, "GetParam(CONFIG) with CS driven as 10 and PB6 reads 0x2E88");
  for (byte b : {0x41, 0x00, 0x0C, 0x80}) xfer(b);  // Move(FWD, 3200)
  check(digitalRead(D3) == LOW && digitalRead(3) == LOW && digitalRead(PB3) == LOW, "BUSY (PB3) low as D3, 3 and PB3");
  while (digitalRead(D3) == LOW) {
  }
  check(digitalRead(PB3) == HIGH, "and high once the move ended");

  // One pin, three names: D8, 8 and PA9.
  pinMode(8, OUTPUT);
  digitalWrite(PA9, HIGH);
  check(digitalRead(D8) == HIGH, "a pin written as PA9 reads high as D8");
  digitalWrite(D8, LOW);
  check(digitalRead(PA9) == LOW, "and low as PA9 once written low as D8");
  Serial.println(failures == 0 ? "PASS" : "FAIL");
  exit(failures == 0 ? 0 : 1);
}

void loop() {}
