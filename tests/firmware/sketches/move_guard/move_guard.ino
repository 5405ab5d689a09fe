// A sketch for `l6470emu run` and `campaign`: one L6470 on the default pins (CS D10), a Move of
// 25600 microsteps, then GetStatus every 10 ms until the chip is no longer busy, and exit(0)
// with ABS_POS printed. Built as is it guards the move: an overcurrent (STATUS.OCD low, in any
// status read, the last one after ABS_POS too) takes the bridges off (HardHiZ) and ends the
// sketch with exit(1). Built with CARELESS defined it
// reads STATUS only for BUSY, so a fault goes by unseen.
#include <SPI.h>

const int kCs = 10;
const SPISettings kL6470(4000000, MSBFIRST, SPI_MODE3);

byte xfer(byte b) {
  SPI.beginTransaction(kL6470);
  digitalWrite(kCs, LOW);
  byte answer = SPI.transfer(b);
  digitalWrite(kCs, HIGH);
  SPI.endTransaction();
  return answer;
}

unsigned int get_status() {
  xfer(0xD0);
  const unsigned int hi = xfer(0);
  return hi << 8 | xfer(0);
}

long abs_pos() {
  xfer(0x21);  // GetParam(ABS_POS): 22 bits
  long v = xfer(0);
  v = v << 8 | xfer(0);
  v = v << 8 | xfer(0);
  return v & 0x200000 ? v - 0x400000 : v;
}

// An overcurrent: bridges off, say so, end with status 1.
void overcurrent() {
  xfer(0xA8);  // HardHiZ
  Serial.print("overcurrent at ABS_POS ");
  Serial.print(abs_pos());
  Serial.println(": bridges off");
  exit(1);
}

void setup() {
  Serial.begin(115200);
  pinMode(kCs, OUTPUT);
  digitalWrite(kCs, HIGH);
  SPI.begin();
  get_status();                                     // clears UVLO
  for (byte b : {0x41, 0x00, 0x64, 0x00}) xfer(b);  // Move(FWD, 25600)
}

void loop() {
  delay(10);
  const unsigned int status = get_status();
#ifndef CARELESS
  if (!(status & 0x1000)) overcurrent();  // OCD is active low
#endif
  if (status & 0x0002) {  // BUSY is active low: the move is over
    const long pos = abs_pos();
#ifndef CARELESS
    if (!(get_status() & 0x1000)) overcurrent();  // and STATUS once more before saying so
#endif
    Serial.print("moved to ABS_POS ");
    Serial.println(pos);
    exit(0);
  }
}
