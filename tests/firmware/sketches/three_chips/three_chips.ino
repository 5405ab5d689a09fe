// A driver for three daisy-chained L6470s behind one chip select (D10), their FLAG outputs
// wired together on D2 (an interrupt: FALLING) and their BUSY outputs on D3, one STBY_RST line
// on D6. It resets the chips, moves all three at once by different distances, waits for the
// wired BUSY, then makes chip 1 raise FLAG with an unknown command: the interrupt runs once,
// right after the frame that caused it, and the driver finds the chip by its STATUS. With
// interrupts off, a second alarm waits for interrupts().
#include <SPI.h>

const int kChips = 3;
const int kCs = 10, kFlag = 2, kBusy = 3, kReset = 6;
const SPISettings kL6470(5000000, MSBFIRST, SPI_MODE3);

volatile int flag_interrupts = 0;
volatile unsigned long flag_at_us = 0;
int failures = 0;

void on_flag() {
  ++flag_interrupts;
  flag_at_us = micros();
}

void check(bool ok, const String& what) {
  Serial.println((ok ? "ok   " : "FAIL ") + what);
  if (!ok) ++failures;
}

// One CS frame: byte k goes to chip k (chip 0 drives MISO), rx[k] is chip k's answer.
void frame(const byte* tx, byte* rx) {
  byte buf[kChips];
  memcpy(buf, tx, kChips);
  SPI.beginTransaction(kL6470);
  digitalWrite(kCs, LOW);
  SPI.transfer(buf, kChips);
  digitalWrite(kCs, HIGH);
  SPI.endTransaction();
  if (rx) memcpy(rx, buf, kChips);
}

// A command for one chip, NOP to the others; then `answer` bytes read back (MSB first).
unsigned long command(int chip, byte opcode, int args, unsigned long value, int answer) {
  byte tx[kChips] = {0, 0, 0}, rx[kChips];
  tx[chip] = opcode;
  frame(tx, nullptr);
  for (int i = args - 1; i >= 0; --i) {
    tx[chip] = byte(value >> (8 * i));
    frame(tx, nullptr);
  }
  unsigned long result = 0;
  tx[chip] = 0;
  for (int i = 0; i < answer; ++i) {
    frame(tx, rx);
    result = result << 8 | rx[chip];
  }
  return result;
}

unsigned long get_status(int chip) { return command(chip, 0xD0, 0, 0, 2); }
long abs_pos(int chip) {
  long v = command(chip, 0x21, 0, 0, 3);
  return v & 0x200000 ? v - 0x400000 : v;  // 22-bit two's complement
}

// Move(FWD, steps[k]) to every chip in the same four frames.
void move_all(const unsigned long* steps) {
  byte tx[kChips];
  for (int k = 0; k < kChips; ++k) tx[k] = 0x41;
  frame(tx, nullptr);
  for (int i = 2; i >= 0; --i) {
    for (int k = 0; k < kChips; ++k) tx[k] = byte(steps[k] >> (8 * i));
    frame(tx, nullptr);
  }
}

void setup() {
  Serial.begin(115200);
  pinMode(kCs, OUTPUT);
  digitalWrite(kCs, HIGH);
  pinMode(kFlag, INPUT_PULLUP);
  pinMode(kBusy, INPUT_PULLUP);
  pinMode(kReset, OUTPUT);
  digitalWrite(kReset, LOW);  // reset pulse on the shared STBY_RST line
  delay(1);
  digitalWrite(kReset, HIGH);
  delay(1);
  SPI.begin();

  check(digitalRead(kFlag) == LOW, "FLAG low after the reset (UVLO latched in every chip)");
  for (int k = 0; k < kChips; ++k) {
    const unsigned long status = get_status(k);
    check(status == 0x7C03 || status == 0x7E03, "chip " + String(k) + " GetStatus 0x" + String(status, HEX));
  }
  check(digitalRead(kFlag) == HIGH, "FLAG high once every chip's flags are read");

  attachInterrupt(digitalPinToInterrupt(kFlag), on_flag, FALLING);

  const unsigned long steps[kChips] = {3200, 6400, 1600};
  const unsigned long start = millis();
  move_all(steps);
  check(digitalRead(kBusy) == LOW, "wired BUSY low while any chip moves");
  while (digitalRead(kBusy) == LOW) delay(1);
  const unsigned long took = millis() - start;
  Serial.println("BUSY rose after " + String(took) + " ms");
  check(took >= 300 && took <= 400, "the longest move (6400 microsteps) sets the wired BUSY's time");
  for (int k = 0; k < kChips; ++k) check(abs_pos(k) == long(steps[k]), "chip " + String(k) + " at " + String(abs_pos(k)));
  check(flag_interrupts == 0, "no FLAG interrupt while nothing is wrong");

  // Chip 1 gets an opcode it does not know: WRONG_CMD pulls FLAG low when the frame ends.
  byte bad[kChips] = {0x00, 0xF8, 0x00};
  const unsigned long before = micros();
  frame(bad, nullptr);
  const unsigned long after = micros();
  check(flag_interrupts == 1, "the FLAG interrupt ran once, right after the frame");
  check(flag_at_us > before && flag_at_us < after, "inside the frame's calls (at " + String(flag_at_us - before) + " us)");
  for (int k = 0; k < kChips; ++k) {
    const unsigned long status = get_status(k);
    const bool wrong = status & 0x0100;
    check(wrong == (k == 1), "chip " + String(k) + (wrong ? " reports WRONG_CMD" : " is clean"));
  }
  check(digitalRead(kFlag) == HIGH, "FLAG high again");

  // With interrupts off the second alarm waits; interrupts() delivers it at once.
  noInterrupts();
  byte bad2[kChips] = {0x00, 0x00, 0xF8};
  frame(bad2, nullptr);
  delay(5);
  check(flag_interrupts == 1, "no interrupt while interrupts are off");
  const unsigned long enabled_at = micros();
  interrupts();
  check(flag_interrupts == 2, "interrupts() delivers the pending FLAG interrupt");
  check(flag_at_us >= enabled_at, "at the time interrupts() was called");
  get_status(2);

  Serial.println(failures == 0 ? "PASS" : "FAIL");
  exit(failures == 0 ? 0 : 1);
}

void loop() {}
