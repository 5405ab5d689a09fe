// The firmware front's recording benchmark (bench/recording_bench.sh): two daisy-chained L6470s
// behind one chip select (D10), a Move on chip 0, then GetStatus of both chips in a loop for 57 s
// of virtual time: a few hundred thousand repetitions of one 3-frame poll once the move is over,
// which a recording collapses into an open `repeat` line. It prints nothing.
#include <SPI.h>

const int kCs = 10;
const SPISettings kL6470(5000000, MSBFIRST, SPI_MODE3);
const unsigned long kRunMs = 57000;

// One CS frame of two bytes: byte k goes to chip k.
void frame(byte b0, byte b1) {
  byte buf[2] = {b0, b1};
  SPI.beginTransaction(kL6470);
  digitalWrite(kCs, LOW);
  SPI.transfer(buf, 2);
  digitalWrite(kCs, HIGH);
  SPI.endTransaction();
}

void get_status_of_both() {
  frame(0xD0, 0xD0);
  frame(0, 0);
  frame(0, 0);
}

void setup() {
  pinMode(kCs, OUTPUT);
  digitalWrite(kCs, HIGH);
  SPI.begin();
  get_status_of_both();  // clears UVLO
  // Move(FWD, 3200) on chip 0, NOP to chip 1.
  frame(0x41, 0);
  frame(0x00, 0);
  frame(0x0C, 0);
  frame(0x80, 0);
}

void loop() {
  get_status_of_both();
  if (millis() >= kRunMs) exit(0);
}
