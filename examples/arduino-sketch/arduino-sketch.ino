// One L6470 on an Arduino's SPI bus (CS on D10, BUSY on D3: the default pins), driven the way
// a sketch drives it: SPI transactions in mode 3, a Move, an interrupt when BUSY rises. Built
// against the installed l6470emu by CMakeLists.txt, it runs on the desktop in virtual time.
#include <SPI.h>

const int kCs = 10, kBusy = 3;
volatile bool done = false;

void on_busy_rise() { done = true; }

byte xfer(byte b) {
  SPI.beginTransaction(SPISettings(5000000, MSBFIRST, SPI_MODE3));
  digitalWrite(kCs, LOW);
  byte answer = SPI.transfer(b);
  digitalWrite(kCs, HIGH);
  SPI.endTransaction();
  return answer;
}

long abs_pos() {
  xfer(0x21);  // GetParam(ABS_POS): three answer bytes
  long v = long(xfer(0)) << 16;
  v |= long(xfer(0)) << 8;
  return v | xfer(0);
}

void setup() {
  Serial.begin(115200);
  pinMode(kCs, OUTPUT);
  digitalWrite(kCs, HIGH);
  SPI.begin();
  attachInterrupt(digitalPinToInterrupt(kBusy), on_busy_rise, RISING);
  for (byte b : {0x41, 0x00, 0x32, 0x00}) xfer(b);  // Move(FWD, 12800 microsteps)
}

void loop() {
  if (!done) return;
  Serial.print("at ");
  Serial.print(abs_pos());
  Serial.print(" after ");
  Serial.print(millis());
  Serial.println(" ms");
  exit(abs_pos() == 12800 ? 0 : 1);
}
