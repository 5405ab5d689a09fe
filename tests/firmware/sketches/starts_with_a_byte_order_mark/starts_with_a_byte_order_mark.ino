// A sketch saved as UTF-8 with a byte-order mark, as some Windows editors save it (issue 35):
// the mark is dropped, as arduino-cli drops it, rather than reaching the compiler as stray bytes.
void setup() {
  Serial.begin(115200);
  const int got = answer();  // defined below: needs its prototype
  const int line = __LINE__;
  Serial.print("answer(): ");
  Serial.print(got);
  Serial.print(", __LINE__ ");
  Serial.println(line);
  const bool ok = got == 42 && line == 6;
  Serial.println(ok ? "PASS" : "FAIL");
  exit(ok ? 0 : 1);
}

void loop() {}

int answer() { return 42; }
