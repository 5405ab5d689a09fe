// tone() and analogWrite() on an L6474's STCK (an Uno, D9): tone(9, 1000, 500) makes exactly
// 500 pulses, tone(9, 2000) stopped by noTone after 100 ms makes 201 (the pulse at 100 ms
// included), analogWrite(9, 128) is the Uno's 490.196 Hz PWM on D9 (4902 pulses rise in 10 s);
// ABS_POS, read over SPI, moves by exactly the pulses. DIR (D7) high: forward.
#include <SPI.h>

const SPISettings kL6474(4000000, MSBFIRST, SPI_MODE3);
int failures = 0;

void check(bool ok, const String& what) {
  Serial.println((ok ? "ok   " : "FAIL ") + what);
  if (!ok) ++failures;
}

byte xfer(byte b) {
  SPI.beginTransaction(kL6474);
  digitalWrite(10, LOW);
  const byte answer = SPI.transfer(b);
  digitalWrite(10, HIGH);
  SPI.endTransaction();
  return answer;
}

long abs_pos() {
  xfer(0x21);  // GetParam(ABS_POS)
  long v = (long)xfer(0) << 16;
  v |= (long)xfer(0) << 8;
  v |= xfer(0);
  return v & 0x200000 ? v - 0x400000 : v;
}

void setup() {
  Serial.begin(115200);
  pinMode(10, OUTPUT);
  digitalWrite(10, HIGH);
  pinMode(7, OUTPUT);
  digitalWrite(7, HIGH);
  pinMode(9, OUTPUT);
  SPI.begin();
  xfer(0xB8);  // Enable

  tone(9, 1000, 500);
  delay(1000);
  check(abs_pos() == 500, "tone(9, 1000, 500) moves ABS_POS by 500");

  tone(9, 2000);
  delay(100);
  noTone(9);
  delay(50);
  check(abs_pos() == 701, "tone(9, 2000) for 100 ms then noTone: 201 more");

  analogWrite(9, 128);
  delay(10000);
  analogWrite(9, 0);
  delay(50);
  check(abs_pos() == 701 + 4902, "analogWrite(9, 128) for 10 s: 4902 pulses at 490.196 Hz");

  tone(9, 500);
  tone(3, 500);  // another pin while a tone plays: nothing
  delay(10);
  noTone(9);
  check(abs_pos() == 701 + 4902 + 6, "tone(9, 500) for 10 ms: 6 pulses");
  Serial.println(failures ? "FAIL" : "PASS");
  exit(failures ? 1 : 0);
}

void loop() {}
