// The Arduino API as the other cores spell it, on two daisy-chained L6470s behind D10: ESP32's
// SPIClass(HSPI) with transfer16 (one CS frame of two bytes: byte k to chip k), STM32duino's
// SPIClass(mosi, miso, sclk) with transfer(tx, rx, n), SPI.end and begin again, an interrupt on
// both edges of BUSY (CHANGE), delayMicroseconds, and the sketch driving STCK itself (D7, both
// chips' step-clock inputs) after StepClock put chip 0 in step-clock mode.
#include <SPI.h>

const int kCs = 10, kBusy = 3, kStck = 7;
const SPISettings kL6470(4000000, MSBFIRST, SPI_MODE3);

SPIClass hspi(HSPI);
SPIClass stm32_spi(PA7, PA6, PA5);  // SPI1's pins on an STM32F4
volatile int busy_edges = 0;
int failures = 0;

void on_busy() { ++busy_edges; }

void check(bool ok, const String& what) {
  Serial.println((ok ? "ok   " : "FAIL ") + what);
  if (!ok) ++failures;
}

// One frame of two bytes through transfer16: the high byte goes first, to chip 0.
uint16_t frame16(uint16_t both) {
  hspi.beginTransaction(kL6470);
  digitalWrite(kCs, LOW);
  const uint16_t in = hspi.transfer16(both);
  digitalWrite(kCs, HIGH);
  hspi.endTransaction();
  return in;
}

// One frame through the three-argument transfer.
void frame3(const uint8_t* tx, uint8_t* rx) {
  stm32_spi.beginTransaction(kL6470);
  digitalWrite(kCs, LOW);
  stm32_spi.transfer(tx, rx, 2);
  digitalWrite(kCs, HIGH);
  stm32_spi.endTransaction();
}

void setup() {
  Serial.begin(115200);
  pinMode(kCs, OUTPUT);
  digitalWrite(kCs, HIGH);
  pinMode(kBusy, INPUT_PULLUP);
  pinMode(kStck, OUTPUT);
  digitalWrite(kStck, LOW);
  hspi.begin();
  frame16(0xD0D0);  // GetStatus to both: the power-up UVLO latch released
  frame16(0);
  frame16(0);

  // SetParam(MAX_SPEED) to both chips, different values, through transfer16; read back.
  frame16(0x0707);
  frame16(0x0102);  // high bytes: chip 0 0x01, chip 1 0x02
  frame16(0x2345);  // low bytes
  frame16(0x2727);  // GetParam(MAX_SPEED)
  const uint16_t hi = frame16(0), lo = frame16(0);
  const unsigned chip0 = (hi >> 8) << 8 | lo >> 8, chip1 = (hi & 0xFF) << 8 | (lo & 0xFF);
  check(chip0 == 0x123 && chip1 == 0x245, "transfer16: MAX_SPEED 0x" + String(chip0, HEX) + " and 0x" + String(chip1, HEX));
  hspi.end();

  // CONFIG of both through STM32duino's controller and transfer(tx, rx, n).
  stm32_spi.begin();
  uint8_t tx[2] = {0x38, 0x38}, rx[2];
  frame3(tx, rx);
  tx[0] = tx[1] = 0;
  uint8_t hi3[2], lo3[2];
  frame3(tx, hi3);
  frame3(tx, lo3);
  check(hi3[0] == 0x2E && lo3[0] == 0x88 && hi3[1] == 0x2E && lo3[1] == 0x88,
        "transfer(tx, rx, n): CONFIG 0x" + String(hi3[0] << 8 | lo3[0], HEX) + " and 0x" + String(hi3[1] << 8 | lo3[1], HEX));
  stm32_spi.end();

  // SPI.end() and SPI.begin() again: the global controller still reaches the chips.
  SPI.begin();
  SPI.end();
  SPI.begin();
  SPI.beginTransaction(kL6470);
  digitalWrite(kCs, LOW);
  SPI.transfer(0x41);  // Move forward, 800 microsteps, chip 0; NOP to chip 1
  SPI.transfer(0x00);
  digitalWrite(kCs, HIGH);
  const uint8_t steps[3] = {0x00, 0x03, 0x20};
  for (uint8_t b : steps) {
    digitalWrite(kCs, LOW);
    SPI.transfer(b);
    SPI.transfer(0x00);
    digitalWrite(kCs, HIGH);
  }
  SPI.endTransaction();
  attachInterrupt(digitalPinToInterrupt(kBusy), on_busy, CHANGE);
  check(digitalRead(kBusy) == LOW, "BUSY low while chip 0 moves");
  while (digitalRead(kBusy) == LOW) delay(1);
  check(busy_edges == 1, "CHANGE: the rising edge of BUSY interrupted once (" + String(busy_edges) + ")");
  detachInterrupt(digitalPinToInterrupt(kBusy));

  // delayMicroseconds moves virtual time by at least what it was asked.
  const unsigned long t0 = micros();
  delayMicroseconds(250);
  const unsigned long waited = micros() - t0;
  check(waited >= 250 && waited < 260, "delayMicroseconds(250) took " + String(waited) + " us");

  // StepClock(forward) to chip 0, then ten pulses on STCK from the sketch: ten microsteps.
  SPI.beginTransaction(kL6470);
  digitalWrite(kCs, LOW);
  SPI.transfer(0x59);
  SPI.transfer(0x00);
  digitalWrite(kCs, HIGH);
  SPI.endTransaction();
  for (int i = 0; i < 10; ++i) {
    digitalWrite(kStck, HIGH);
    delayMicroseconds(100);
    digitalWrite(kStck, LOW);
    delayMicroseconds(100);
  }
  uint8_t get[2] = {0x21, 0x00}, a[2], b[2], c[2];  // GetParam(ABS_POS) of chip 0
  frame3(get, a);
  get[0] = 0;
  frame3(get, a);
  frame3(get, b);
  frame3(get, c);
  const long pos = long(a[0]) << 16 | long(b[0]) << 8 | c[0];
  check(pos == 800 + 10, "STCK: chip 0 at " + String(pos) + " after its move and ten step-clock pulses");

  Serial.println(failures == 0 ? "PASS" : "FAIL");
  exit(failures == 0 ? 0 : 1);
}

void loop() {}
