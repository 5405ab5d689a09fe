// Three daisy-chained L6470s on four ordinary pins, no SPI peripheral: the sketch bit-bangs the
// bus itself (software SPI, as boards whose SPI pins are taken do). Mode 3: the clock idles
// high, MOSI changes while it is low, the chips sample it as it rises and move MISO as it
// falls. The board description names the pins (cs_pin=D7 sck_pin=D8 mosi_pin=D9 miso_pin=D12),
// so the emulated chips hear the edges; each motor gets its own MAX_SPEED and the same Move.
const int kChips = 3;
const int kCs = 7, kSck = 8, kMosi = 9, kMiso = 12;

// One byte each way, most significant bit first.
byte transfer(byte out) {
  byte in = 0;
  for (int bit = 7; bit >= 0; --bit) {
    digitalWrite(kSck, LOW);
    digitalWrite(kMosi, bitRead(out, bit));
    digitalWrite(kSck, HIGH);
    in = in << 1 | digitalRead(kMiso);
  }
  return in;
}

// One chip-select frame through the chain: tx[k] reaches chip k, rx[k] is what chip k said.
void frame(const byte* tx, byte* rx) {
  digitalWrite(kCs, LOW);
  for (int k = 0; k < kChips; ++k) {
    byte in = transfer(tx[k]);
    if (rx) rx[k] = in;
  }
  digitalWrite(kCs, HIGH);
}

// The same command to every chip: opcode, then `args` bytes of value[k], then `answer` bytes
// read into value[k] (MSB first). NOP is 0x00.
void command_all(byte opcode, int args, unsigned long* value, int answer) {
  byte tx[kChips], rx[kChips];
  for (int k = 0; k < kChips; ++k) tx[k] = opcode;
  frame(tx, nullptr);
  for (int i = args - 1; i >= 0; --i) {
    for (int k = 0; k < kChips; ++k) tx[k] = byte(value[k] >> (8 * i));
    frame(tx, nullptr);
  }
  for (int k = 0; k < kChips; ++k) tx[k] = 0, value[k] = 0;
  for (int i = 0; i < answer; ++i) {
    frame(tx, rx);
    for (int k = 0; k < kChips; ++k) value[k] = value[k] << 8 | rx[k];
  }
}

bool any_busy() {
  unsigned long status[kChips];
  command_all(0xD0, 0, status, 2);  // GetStatus: BUSY (bit 1) is low while a command runs
  for (int k = 0; k < kChips; ++k)
    if (!bitRead(status[k], 1)) return true;
  return false;
}

void setup() {
  Serial.begin(115200);
  digitalWrite(kCs, HIGH);  // deselected before the pin becomes an output
  pinMode(kCs, OUTPUT);
  digitalWrite(kSck, HIGH);  // mode 3: the clock idles high
  pinMode(kSck, OUTPUT);
  pinMode(kMosi, OUTPUT);
  pinMode(kMiso, INPUT);

  unsigned long max_speed[kChips] = {0x20, 0x30, 0x41};  // SetParam(MAX_SPEED), 15.25 step/s units
  command_all(0x07, 2, max_speed, 0);
  unsigned long steps[kChips] = {3200, 3200, 3200};  // Move(FWD, 3200 microsteps)
  command_all(0x41, 3, steps, 0);
  while (any_busy()) delay(10);

  unsigned long pos[kChips];
  command_all(0x21, 0, pos, 3);  // GetParam(ABS_POS)
  bool exact = true;
  for (int k = 0; k < kChips; ++k) {
    Serial.print("motor ");
    Serial.print(k);
    Serial.print(" at ");
    Serial.println(pos[k]);
    exact = exact && pos[k] == 3200;
  }
  Serial.print("all stopped after ");
  Serial.print(millis());
  Serial.println(" ms");
  exit(exact ? 0 : 1);
}

void loop() {}
