// A sketch whose loop() never ends, as most do: it blinks D13 and prints the time. The run ends
// at the board description's limit= with one line saying so, and exit status 0.
void setup() {
  Serial.begin(9600);
  pinMode(LED_BUILTIN, OUTPUT);
}

void loop() {
  digitalWrite(LED_BUILTIN, HIGH);
  delay(100);
  digitalWrite(LED_BUILTIN, LOW);
  delay(100);
  Serial.print("t=");
  Serial.println(millis());
}
