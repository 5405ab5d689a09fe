// A driver that busy-waits: one L6470 on the default pins (CS D10, BUSY D3), a Move of 3200
// microsteps, then `while (digitalRead(BUSY) == LOW) {}` and a `while (millis() ...)` loop.
// Both loops end, and micros() shows the move taking its profile's time: 891 746 ticks of
// 250 ns (222 936.5 us) from the decoded Move to BUSY's release, plus the bytes before it.
#include <SPI.h>

const int kCs = 10;
const int kBusy = 3;
const SPISettings kL6470(4000000, MSBFIRST, SPI_MODE3);
const unsigned long kProfileUs = 222936;  // the move itself, rounded down
int failures = 0;

byte xfer(byte b) {
  SPI.beginTransaction(kL6470);
  digitalWrite(kCs, LOW);
  byte answer = SPI.transfer(b);
  digitalWrite(kCs, HIGH);
  SPI.endTransaction();
  return answer;
}

void check(bool ok, const char* what) {
  Serial.print(ok ? "ok   " : "FAIL ");
  Serial.println(what);
  if (!ok) ++failures;
}

void setup() {
  Serial.begin(115200);
  pinMode(kCs, OUTPUT);
  digitalWrite(kCs, HIGH);
  pinMode(kBusy, INPUT);
  SPI.begin();
  xfer(0xD0);  // GetStatus: clears UVLO
  xfer(0);
  xfer(0);

  const unsigned long start = micros();
  for (byte b : {0x41, 0x00, 0x0C, 0x80}) xfer(b);  // Move(FWD, 3200)
  const unsigned long decoded = micros();
  check(digitalRead(kBusy) == LOW, "BUSY low once the Move is decoded");
  unsigned long polls = 0;
  while (digitalRead(kBusy) == LOW) ++polls;
  const unsigned long took = micros() - decoded;
  Serial.print("BUSY rose after ");
  Serial.print(took);
  Serial.print(" us and ");
  Serial.print(polls);
  Serial.println(" polls");
  check(took >= kProfileUs && took <= kProfileUs + 5, "the loop saw the move take its profile's time (to 5 us)");
  check(decoded - start < 100, "four one-byte frames take tens of microseconds");

  const unsigned long t0 = millis();
  unsigned long spins = 0;
  while (millis() - t0 < 250) ++spins;
  Serial.print("250 ms of millis() polling took ");
  Serial.print(spins);
  Serial.println(" calls");
  check(millis() - t0 == 250, "a millis() busy-wait ends on time");

  Serial.println(failures == 0 ? "PASS" : "FAIL");
  exit(failures == 0 ? 0 : 1);
}

void loop() {}
