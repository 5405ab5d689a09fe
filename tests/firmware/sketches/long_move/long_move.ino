// A move of a minute: MAX_SPEED lowered to 16 (244 full steps/s), Move(FWD, 1 875 000
// microsteps). The sketch sleeps in delay(1000) and prints its progress; an interrupt on BUSY
// rising (D3) notes when the move ends. Virtual time: the minute passes in a fraction of a
// second of wall time, and millis() shows the full minute (checked; wall time is not).
#include <SPI.h>

const int kCs = 10, kBusy = 3;
const SPISettings kL6470(5000000, MSBFIRST, SPI_MODE3);
volatile unsigned long ended_ms = 0;
int failures = 0;

void on_busy_rise() { ended_ms = millis(); }

void check(bool ok, const String& what) {
  Serial.println((ok ? "ok   " : "FAIL ") + what);
  if (!ok) ++failures;
}

byte xfer(byte b) {
  SPI.beginTransaction(kL6470);
  digitalWrite(kCs, LOW);
  const byte answer = SPI.transfer(b);
  digitalWrite(kCs, HIGH);
  SPI.endTransaction();
  return answer;
}

unsigned long command(byte opcode, int args, unsigned long value, int answer) {
  xfer(opcode);
  for (int i = args - 1; i >= 0; --i) xfer(byte(value >> (8 * i)));
  unsigned long result = 0;
  for (int i = 0; i < answer; ++i) result = result << 8 | xfer(0);
  return result;
}

void setup() {
  Serial.begin(115200);
  pinMode(kCs, OUTPUT);
  digitalWrite(kCs, HIGH);
  pinMode(kBusy, INPUT);
  SPI.begin();
  command(0xD0, 0, 0, 2);         // GetStatus
  command(0x07, 2, 16, 0);        // SetParam(MAX_SPEED, 16): 244 full steps/s
  attachInterrupt(digitalPinToInterrupt(kBusy), on_busy_rise, RISING);
  const unsigned long start = millis();
  command(0x41, 3, 1875000, 0);   // Move(FWD, 1 875 000 microsteps)
  while (digitalRead(kBusy) == LOW) {
    delay(1000);
    const unsigned long s = (millis() - start) / 1000;
    if (s % 10 == 0) Serial.println(String(s) + " s: ABS_POS " + String(command(0x21, 0, 0, 3)));
  }
  const unsigned long took = ended_ms - start;
  Serial.println("the move took " + String(took) + " ms of virtual time");
  check(took >= 60000 && took <= 60300, "a minute and the ramps");
  check(command(0x21, 0, 0, 3) == 1875000, "ABS_POS 1875000");
  Serial.println(failures == 0 ? "PASS" : "FAIL");
  exit(failures == 0 ? 0 : 1);
}

void loop() {}
