// Homing with the mechanical axis of the board description: the carriage starts 51 200
// microsteps (2 revolutions) above a limit switch at 0 that closes SW. GoUntil in reverse
// until the switch closes, ReleaseSW forward until it opens, then an absolute GoTo. The
// sketch sees the switch on D5 (wired to SW) as the axis moves it; BUSY on D3.
#include <SPI.h>

const int kCs = 10, kBusy = 3, kSwitch = 5;
const SPISettings kL6470(2000000, MSBFIRST, SPI_MODE3);
int failures = 0;

void check(bool ok, const String& what) {
  Serial.println((ok ? "ok   " : "FAIL ") + what);
  if (!ok) ++failures;
}

byte xfer(byte b) {
  SPI.beginTransaction(kL6470);
  digitalWrite(kCs, LOW);
  const byte answer = SPI.transfer(b);
  digitalWrite(kCs, HIGH);
  SPI.endTransaction();
  return answer;
}

unsigned long command(byte opcode, int args, unsigned long value, int answer) {
  xfer(opcode);
  for (int i = args - 1; i >= 0; --i) xfer(byte(value >> (8 * i)));
  unsigned long result = 0;
  for (int i = 0; i < answer; ++i) result = result << 8 | xfer(0);
  return result;
}

long abs_pos() {
  const long v = command(0x21, 0, 0, 3);
  return v & 0x200000 ? v - 0x400000 : v;
}

unsigned long wait_busy() {
  const unsigned long start = millis();
  while (digitalRead(kBusy) == LOW) delay(1);
  return millis() - start;
}

void setup() {
  Serial.begin(115200);
  pinMode(kCs, OUTPUT);
  digitalWrite(kCs, HIGH);
  pinMode(kBusy, INPUT);
  pinMode(kSwitch, INPUT);
  SPI.begin();
  command(0xD0, 0, 0, 2);                                // GetStatus: clears UVLO
  const unsigned long config = command(0x38, 0, 0, 2);   // GetParam(CONFIG)
  command(0x18, 2, config | 0x10, 0);                    // SW_MODE = 1: the switch is the driver's
  check(digitalRead(kSwitch) == HIGH, "the switch is open at the start");

  // GoUntil(ACT = 0: reset ABS_POS, reverse) at 200 full steps/s (SPEED = 200 x 2^28 x 250 ns).
  command(0x82, 3, 13422, 0);
  const unsigned long took = wait_busy();
  Serial.println("GoUntil ended after " + String(took) + " ms at ABS_POS " + String(abs_pos()));
  check(took > 1900 && took < 2300, "400 full steps at 200 steps/s");
  check(digitalRead(kSwitch) == LOW, "the switch is closed: the carriage stopped on it");
  check((command(0xD0, 0, 0, 2) & 0x0004) != 0, "STATUS.SW_F says so too");

  command(0x93, 0, 0, 0);                                // ReleaseSW(ACT = 0, forward)
  wait_busy();
  check(digitalRead(kSwitch) == HIGH, "ReleaseSW leaves the switch open");
  const long home = abs_pos();
  Serial.println("released at ABS_POS " + String(home));
  check(home == 0, "ABS_POS is 0 where the switch opens");

  command(0x60, 3, 10000, 0);                            // GoTo(10000)
  wait_busy();
  check(abs_pos() == 10000, "GoTo(10000) from home");
  check(digitalRead(kSwitch) == HIGH, "away from the switch");

  Serial.println(failures == 0 ? "PASS" : "FAIL");
  exit(failures == 0 ? 0 : 1);
}

void loop() {}
