// A sketch driven by text commands on Serial, as bench firmware is: "MOVE n" sends Move(FWD, n),
// waits for BUSY, says where it is and ends; any other line is said to be ignored. Under
// `l6470emu run` the commands come from the scenario's serial: steps (scenarios/serial_move.yaml),
// each at its tick; with no input the sketch runs to its limit.
#include <SPI.h>

const int kCs = 10, kBusy = 3;
const SPISettings kL6470(4000000, MSBFIRST, SPI_MODE3);

byte xfer(byte b) {
  SPI.beginTransaction(kL6470);
  digitalWrite(kCs, LOW);
  const byte answer = SPI.transfer(b);
  digitalWrite(kCs, HIGH);
  SPI.endTransaction();
  return answer;
}

void setup() {
  Serial.begin(115200);
  pinMode(kCs, OUTPUT);
  digitalWrite(kCs, HIGH);
  pinMode(kBusy, INPUT);
  SPI.begin();
  xfer(0xD0);  // GetStatus: the power-up UVLO latch released
  xfer(0);
  xfer(0);
}

void loop() {
  if (!Serial.available()) return;
  const unsigned long at = millis();
  const String line = Serial.readStringUntil('\n');
  if (!line.startsWith("MOVE ")) {
    Serial.print("ignored ");
    Serial.print(line);
    Serial.print(" at ");
    Serial.print(at);
    Serial.println(" ms");
    return;
  }
  const long steps = line.substring(5).toInt();
  Serial.print("MOVE ");
  Serial.print(steps);
  Serial.print(" at ");
  Serial.print(at);
  Serial.println(" ms");
  xfer(0x41);  // Move(FWD, steps)
  xfer(steps >> 16);
  xfer(steps >> 8);
  xfer(steps);
  while (digitalRead(kBusy) == LOW) {
  }
  Serial.print("moved ");
  Serial.println(steps);
  exit(0);
}
