// An interrupt handler for one platform only, above the other functions, as multi-platform
// sketches have them: on this one (no ESP32) the compiler leaves the group out, so the
// prototypes and their #line must not be inside it, and the handler's own prototype (IRAM_ATTR
// exists on ESP32 only) must stay inside its conditions.
#ifdef ESP32
void IRAM_ATTR on_flag() { flagged = true; }
#endif

void setup() {
  Serial.begin(115200);
  const int got = helper();  // defined below: needs its prototype
  const int line = __LINE__;
  Serial.print("helper(): ");
  Serial.print(got);
  Serial.print(", __LINE__ ");
  Serial.println(line);
  const bool ok = got == 7 && line == 12;
  Serial.println(ok ? "PASS" : "FAIL");
  exit(ok ? 0 : 1);
}

void loop() {}

int helper() { return 7; }
