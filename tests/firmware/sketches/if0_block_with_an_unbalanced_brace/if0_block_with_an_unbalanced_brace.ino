// An #if 0 block holding an unbalanced '{' (half an old version, switched off) above the
// functions, as the compiler reads it: nothing (issue 35). Every later function keeps its
// prototype, and the #line after the prototypes is outside the #if 0, so __LINE__ is right.
#if 0
void old_setup() {
  if (ready) {
#endif

void setup() {
  Serial.begin(115200);
  const int got = twice(21);  // defined below: needs its prototype
  const int line = __LINE__;
  Serial.print("twice(21): ");
  Serial.print(got);
  Serial.print(", __LINE__ ");
  Serial.println(line);
  const bool ok = got == 42 && line == 12;
  Serial.println(ok ? "PASS" : "FAIL");
  exit(ok ? 0 : 1);
}

void loop() {}

int twice(int x) { return 2 * x; }
