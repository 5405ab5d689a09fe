// Three daisy-chained L6470s driven with no SPI peripheral at all: the sketch bit-bangs the bus
// with digitalWrite and digitalRead on D4 (CS), D5 (SCK), D6 (MOSI) and D7 (MISO), shaped as SPI
// mode 3 (the clock idles high; MOSI is set while it is low, MISO read after it rises). It reads
// CONFIG from each chip, moves all three at once (chip 2 in reverse), polls GetStatus until none
// is busy, and reads ABS_POS back. It checks itself and prints PASS.
const int kChips = 3;
const int kCs = 4, kSck = 5, kMosi = 6, kMiso = 7;

int failures = 0;

void check(bool ok, const String& what) {
  Serial.println((ok ? "ok   " : "FAIL ") + what);
  if (!ok) ++failures;
}

// One byte, most significant bit first: the chips sample MOSI on the rising edge and move MISO
// on the falling one.
byte transfer(byte out) {
  byte in = 0;
  for (int bit = 7; bit >= 0; --bit) {
    digitalWrite(kSck, LOW);
    digitalWrite(kMosi, (out >> bit) & 1);
    digitalWrite(kSck, HIGH);
    in = in << 1 | digitalRead(kMiso);
  }
  return in;
}

// One CS frame: byte k goes to chip k (chip 0 drives MISO), rx[k] is chip k's answer.
void frame(const byte* tx, byte* rx) {
  digitalWrite(kCs, LOW);
  for (int k = 0; k < kChips; ++k) {
    const byte in = transfer(tx[k]);
    if (rx) rx[k] = in;
  }
  digitalWrite(kCs, HIGH);
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

// Move(direction, n_step) to every chip in the same four frames.
void move_all(const byte* opcodes, const unsigned long* steps) {
  byte tx[kChips];
  frame(opcodes, nullptr);
  for (int i = 2; i >= 0; --i) {
    for (int k = 0; k < kChips; ++k) tx[k] = byte(steps[k] >> (8 * i));
    frame(tx, nullptr);
  }
}

bool any_busy() {
  for (int k = 0; k < kChips; ++k)
    if ((get_status(k) & 0x0002) == 0) return true;  // STATUS bit 1 is BUSY, active low
  return false;
}

void setup() {
  Serial.begin(115200);
  digitalWrite(kCs, HIGH);  // the pull-up first, so that the pin never drives CS low
  pinMode(kCs, OUTPUT);
  digitalWrite(kSck, HIGH);  // mode 3: the clock idles high
  pinMode(kSck, OUTPUT);
  pinMode(kMosi, OUTPUT);
  pinMode(kMiso, INPUT);

  for (int k = 0; k < kChips; ++k) {
    const unsigned long config = command(k, 0x38, 0, 0, 2);
    check(config == 0x2E88, "chip " + String(k) + " CONFIG reads 0x" + String(config, HEX));
  }
  for (int k = 0; k < kChips; ++k) get_status(k);  // clear the power-up flags

  const byte opcodes[kChips] = {0x41, 0x41, 0x40};  // Move FWD, FWD, REV
  const unsigned long steps[kChips] = {400, 800, 300};
  move_all(opcodes, steps);
  check(any_busy(), "the chips are busy after Move");
  const unsigned long started = millis();
  while (any_busy() && millis() - started < 10000) delay(5);
  check(!any_busy(), "the moves end (" + String(millis() - started) + " ms)");
  const long expected[kChips] = {400, 800, -300};
  for (int k = 0; k < kChips; ++k) {
    const long pos = abs_pos(k);
    check(pos == expected[k], "chip " + String(k) + " ABS_POS " + String(pos));
  }
  Serial.println(failures == 0 ? "PASS" : "FAIL");
  exit(failures == 0 ? 0 : 1);
}

void loop() {}
