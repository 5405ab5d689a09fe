// What vendor libraries use of the Arduino and STM32duino API (issue 34), on an Uno's numbering
// (the default board): D0..D15 and the STM32 port pin names, __NOP() and the other CMSIS
// intrinsics, __disable_irq()/__enable_irq(), binary.h's constants, wiring_private.h's sbi/cbi,
// Serial input from standard input (the test gives "42 steps\nhello\n"), and micros() wrapping
// at 2^32 as on a board (after 71.6 minutes: BOARD limit=4800s).
#include <SPI.h>
#include <binary.h>
#include <wiring_private.h>

const SPISettings kL6470(4000000, MSBFIRST, SPI_MODE3);
volatile int edges = 0;
int failures = 0;

void on_edge() { ++edges; }

void check(bool ok, const String& what) {
  Serial.println((ok ? "ok   " : "FAIL ") + what);
  if (!ok) ++failures;
}

byte xfer(byte b) {
  SPI.beginTransaction(kL6470);
  digitalWrite(D10, LOW);
  const byte answer = SPI.transfer(b);
  digitalWrite(D10, HIGH);
  SPI.endTransaction();
  return answer;
}

void setup() {
  Serial.begin(115200);
  check(D0 == 0 && D3 == 3 && D10 == 10 && D13 == 13 && D15 == 15, "D0..D15 are an Uno's pin numbers");
  check(A0 == 14 && A5 == 19 && D14 == A0 && LED_BUILTIN == 13 && SS == 10, "A0..A5 are D14..D19, SS is D10");
  check(PA0 == 128 && PA4 == 132 && PB3 == 147 && PH15 == 255, "PA0..PH15 are 128..255");
  check(B0 == 0 && B1 == 1 && B00000110 == 6 && B101 == 5 && B0011 == 3 && B11111111 == 255, "binary.h's B constants");
  unsigned char reg = B00000110;
  sbi(reg, 0);
  cbi(reg, 2);
  check(reg == B00000011, "wiring_private.h's sbi and cbi");
  voidFuncPtr handler = on_edge;
  __NOP();
  __DSB();
  __ISB();
  __DMB();

  // The chip on D10 (CS) and D3 (BUSY), named as D pins in the sketch and in its BOARD.
  pinMode(D10, OUTPUT);
  digitalWrite(D10, HIGH);
  pinMode(D3, INPUT);
  SPI.begin();
  xfer(0xD0);  // GetStatus: the power-up UVLO latch released
  xfer(0);
  xfer(0);
  xfer(0x38);  // GetParam(CONFIG)
  const unsigned config = xfer(0) << 8 | xfer(0);
  check(config == 0x2E88, "GetParam(CONFIG) through D10 reads 0x2E88");
  for (byte b : {0x41, 0x00, 0x0C, 0x80}) xfer(b);  // Move(FWD, 3200)
  check(digitalRead(D3) == LOW, "BUSY on D3 reads low while the move runs");
  while (digitalRead(3) == LOW) {
  }
  check(digitalRead(D3) == HIGH, "and high once it ended");

  // __disable_irq holds an edge back; __enable_irq delivers it.
  pinMode(D7, OUTPUT);
  digitalWrite(D7, LOW);
  attachInterrupt(digitalPinToInterrupt(D7), handler, RISING);
  __disable_irq();
  digitalWrite(D7, HIGH);
  delay(1);
  check(edges == 0, "no interrupt while __disable_irq() holds them");
  __enable_irq();
  check(edges == 1, "the edge delivered at __enable_irq()");

  // Serial input: all of standard input has arrived.
  check(Serial.available() == 15, "Serial.available() counts the 15 bytes of standard input");
  check(Serial.peek() == '4', "peek() shows the first without taking it");
  check(Serial.parseInt() == 42, "parseInt() reads 42");
  check(Serial.readStringUntil('\n') == " steps", "readStringUntil() the rest of the line");
  check(Serial.readString() == "hello\n", "readString() what is left");
  check(Serial.available() == 0 && Serial.read() == -1, "then nothing is left");
  check(Serial1.available() == 0 && Serial1.read() == -1, "Serial1 reads nothing");

  // micros() wraps at 2^32 us (4294967.296 ms); the difference in uint32_t survives the wrap.
  // (readString() above waited out its 1 s timeout: `before` is past 1 s.)
  const unsigned long before = micros();
  delay(4294968UL);
  const unsigned long after = micros();
  Serial.print("micros() ");
  Serial.print(before);
  Serial.print(" before, ");
  Serial.print(after);
  Serial.println(" after 4294968 ms");
  const unsigned long now_ms = millis();
  check(now_ms > 4294967UL && after < 10000000UL, "micros() wrapped at 2^32 (virtual time is past 2^32 us)");
  check(static_cast<uint32_t>(after - before) >= 704 && static_cast<uint32_t>(after - before) <= 710,
        "the uint32_t difference across the wrap is the 704 us past 2^32 (and the calls)");
  check(now_ms == 4294968UL + before / 1000, "millis() has not wrapped (that takes 49.7 days)");
  Serial.println(failures == 0 ? "PASS" : "FAIL");
  exit(failures == 0 ? 0 : 1);
}

void loop() {}
