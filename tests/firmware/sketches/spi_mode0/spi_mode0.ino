// The most common bring-up mistake with these chips: SPI_MODE0 (the Arduino default) instead
// of SPI_MODE3. The host samples each byte's first bit before the chip has shifted it out, so
// it reads the chip's stale SDO latch there: on an L6470, GetParam(CONFIG) after a NOP reads
// 0x2E08 instead of 0x2E88 (the MSB of the second byte is the MSB of the NOP the chip shifted
// in last). In mode 3 the same bytes read 0x2E88.
#include <SPI.h>

const int kCs = 10;
int failures = 0;

void check(bool ok, const String& what) {
  Serial.println((ok ? "ok   " : "FAIL ") + what);
  if (!ok) ++failures;
}

byte xfer(const SPISettings& settings, byte b) {
  SPI.beginTransaction(settings);
  digitalWrite(kCs, LOW);
  const byte answer = SPI.transfer(b);
  digitalWrite(kCs, HIGH);
  SPI.endTransaction();
  return answer;
}

unsigned int get_config(const SPISettings& settings) {
  xfer(settings, 0x00);  // NOP
  xfer(settings, 0x38);  // GetParam(CONFIG)
  const unsigned int high = xfer(settings, 0x00);
  return high << 8 | xfer(settings, 0x00);
}

void setup() {
  Serial.begin(115200);
  pinMode(kCs, OUTPUT);
  digitalWrite(kCs, HIGH);
  SPI.begin();
  const unsigned int mode0 = get_config(SPISettings(4000000, MSBFIRST, SPI_MODE0));
  Serial.println("SPI_MODE0: CONFIG reads 0x" + String(mode0, HEX));
  check(mode0 == 0x2E08, "mode 0 reads the stale latch in each answer byte's MSB, as silicon does");
  const unsigned int mode3 = get_config(SPISettings(4000000, MSBFIRST, SPI_MODE3));
  Serial.println("SPI_MODE3: CONFIG reads 0x" + String(mode3, HEX));
  check(mode3 == 0x2E88, "mode 3 reads the register");
  Serial.println(failures == 0 ? "PASS" : "FAIL");
  exit(failures == 0 ? 0 : 1);
}

void loop() {}
