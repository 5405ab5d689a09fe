// A function signature wrapped with backslash-newline, which the compiler joins (issue 35): its
// prototype, one line, lets setup() call it above its definition, and __LINE__ below the
// prototypes is still the sketch's own line.
void setup() {
  Serial.begin(115200);
  const long sum = add_three(1, 2, 3);
  const int line = __LINE__;
  Serial.print("add_three: ");
  Serial.print(sum);
  Serial.print(", __LINE__ ");
  Serial.println(line);
  const bool ok = sum == 6 && line == 7;
  Serial.println(ok ? "PASS" : "FAIL");
  exit(ok ? 0 : 1);
}

void loop() {}

long add_three(long a, \
               long b, \
               long c) {
  return a + b + c;
}
