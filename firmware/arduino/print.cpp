// Print's number formatting (bases, decimals as the Arduino core rounds them), Stream's timed
// reads in virtual time, and Serial on standard output.
// The model first: Arduino.h's macros (HIGH, DEC, ...) must not reach its headers.
#include "firmware/arduino/arduino_internal.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <string>

#include "Arduino.h"

namespace {

std::string number_text(unsigned long long n, int base) {
  if (base < 2 || base > 36) base = 10;
  char buf[8 * sizeof n + 1];
  char* p = buf + sizeof buf;
  do {
    const int d = static_cast<int>(n % static_cast<unsigned>(base));
    *--p = static_cast<char>(d < 10 ? '0' + d : 'A' + d - 10);
    n /= static_cast<unsigned>(base);
  } while (n);
  return std::string(p, buf + sizeof buf);
}

std::string signed_text(long long n, int base, unsigned bits) {
  if (base == 10 && n < 0) return "-" + number_text(0ull - static_cast<unsigned long long>(n), 10);
  // Other bases show the two's complement of the argument's own width, as the cores do.
  const unsigned long long mask = bits >= 64 ? ~0ull : (1ull << bits) - 1;
  return number_text(static_cast<unsigned long long>(n) & mask, base);
}

// The Arduino core's way of printing a double: "nan", "inf", "ovf" beyond ±4294967040, else the
// value rounded half up at `digits` decimals, then the integer part and the decimals one by one.
std::string float_text(double number, int digits) {
  if (std::isnan(number)) return "nan";
  if (std::isinf(number)) return "inf";
  if (number > 4294967040.0 || number < -4294967040.0) return "ovf";
  std::string out;
  if (number < 0.0) {
    out += '-';
    number = -number;
  }
  if (digits < 0) digits = 0;
  double rounding = 0.5;
  for (int i = 0; i < digits; ++i) rounding /= 10.0;
  number += rounding;
  const auto int_part = static_cast<unsigned long>(number);
  double remainder = number - static_cast<double>(int_part);
  out += std::to_string(int_part);
  if (digits > 0) out += '.';
  while (digits-- > 0) {
    remainder *= 10.0;
    const auto digit = static_cast<unsigned>(remainder);
    out += static_cast<char>('0' + digit % 10);
    remainder -= digit;
  }
  return out;
}

}  // namespace

// ---------------------------------------------------------------- Print

size_t Print::write(const uint8_t* buffer, size_t size) {
  size_t n = 0;
  while (size--) {
    if (!write(*buffer++)) break;
    ++n;
  }
  return n;
}

size_t Print::print(const __FlashStringHelper* str) { return print(reinterpret_cast<const char*>(str)); }
size_t Print::print(const String& s) { return text(s.c_str(), s.length()); }
size_t Print::print(const char str[]) { return str ? text(str, strlen(str)) : 0; }
size_t Print::print(char c) { return write(static_cast<uint8_t>(c)); }
size_t Print::print(unsigned char n, int base) { return print(static_cast<unsigned long>(n), base); }
size_t Print::print(int n, int base) {
  if (base == 0) return write(static_cast<uint8_t>(n));
  const std::string s = signed_text(n, base, 8 * sizeof n);
  return text(s.data(), s.size());
}
size_t Print::print(unsigned int n, int base) { return print(static_cast<unsigned long>(n), base); }
size_t Print::print(long n, int base) {
  if (base == 0) return write(static_cast<uint8_t>(n));
  const std::string s = signed_text(n, base, 8 * sizeof n);
  return text(s.data(), s.size());
}
size_t Print::print(unsigned long n, int base) {
  if (base == 0) return write(static_cast<uint8_t>(n));
  const std::string s = number_text(n, base);
  return text(s.data(), s.size());
}
size_t Print::print(long long n, int base) {
  if (base == 0) return write(static_cast<uint8_t>(n));
  const std::string s = signed_text(n, base, 64);
  return text(s.data(), s.size());
}
size_t Print::print(unsigned long long n, int base) {
  if (base == 0) return write(static_cast<uint8_t>(n));
  const std::string s = number_text(n, base);
  return text(s.data(), s.size());
}
size_t Print::print(double n, int digits) {
  const std::string s = float_text(n, digits);
  return text(s.data(), s.size());
}
size_t Print::print(const Printable& x) { return x.printTo(*this); }

size_t Print::println(void) { return text("\r\n", 2); }
size_t Print::println(const __FlashStringHelper* str) { return print(str) + println(); }
size_t Print::println(const String& s) { return print(s) + println(); }
size_t Print::println(const char str[]) { return print(str) + println(); }
size_t Print::println(char c) { return print(c) + println(); }
size_t Print::println(unsigned char n, int base) { return print(n, base) + println(); }
size_t Print::println(int n, int base) { return print(n, base) + println(); }
size_t Print::println(unsigned int n, int base) { return print(n, base) + println(); }
size_t Print::println(long n, int base) { return print(n, base) + println(); }
size_t Print::println(unsigned long n, int base) { return print(n, base) + println(); }
size_t Print::println(long long n, int base) { return print(n, base) + println(); }
size_t Print::println(unsigned long long n, int base) { return print(n, base) + println(); }
size_t Print::println(double n, int digits) { return print(n, digits) + println(); }
size_t Print::println(const Printable& x) { return print(x) + println(); }

size_t Print::printf(const char* format, ...) {
  va_list args;
  va_start(args, format);
  va_list again;
  va_copy(again, args);
  const int n = std::vsnprintf(nullptr, 0, format, args);
  va_end(args);
  if (n <= 0) {
    va_end(again);
    return 0;
  }
  std::string s(static_cast<size_t>(n) + 1, '\0');
  std::vsnprintf(s.data(), s.size(), format, again);
  va_end(again);
  return text(s.data(), static_cast<size_t>(n));
}

// ---------------------------------------------------------------- Stream

int Stream::timedRead() {
  const unsigned long start = millis();
  do {
    const int c = read();
    if (c >= 0) return c;
    delay(1);
  } while (static_cast<uint32_t>(millis() - start) < timeout_ms_);  // across the wrap too
  return -1;
}

int Stream::timedPeek() {
  const unsigned long start = millis();
  do {
    const int c = peek();
    if (c >= 0) return c;
    delay(1);
  } while (static_cast<uint32_t>(millis() - start) < timeout_ms_);  // across the wrap too
  return -1;
}

size_t Stream::readBytes(char* buffer, size_t length) {
  size_t n = 0;
  while (n < length) {
    const int c = timedRead();
    if (c < 0) break;
    buffer[n++] = static_cast<char>(c);
  }
  return n;
}

size_t Stream::readBytesUntil(char terminator, char* buffer, size_t length) {
  size_t n = 0;
  while (n < length) {
    const int c = timedRead();
    if (c < 0 || c == terminator) break;
    buffer[n++] = static_cast<char>(c);
  }
  return n;
}

String Stream::readString() {
  String s;
  for (int c = timedRead(); c >= 0; c = timedRead()) s += static_cast<char>(c);
  return s;
}

String Stream::readStringUntil(char terminator) {
  String s;
  for (int c = timedRead(); c >= 0 && c != terminator; c = timedRead()) s += static_cast<char>(c);
  return s;
}

long Stream::parseInt() {
  int c = timedPeek();
  while (c >= 0 && c != '-' && (c < '0' || c > '9')) {
    read();
    c = timedPeek();
  }
  bool negative = false;
  long value = 0;
  if (c == '-') {
    negative = true;
    read();
    c = timedPeek();
  }
  while (c >= '0' && c <= '9') {
    value = value * 10 + (c - '0');
    read();
    c = timedPeek();
  }
  return negative ? -value : value;
}

float Stream::parseFloat() { return static_cast<float>(parseInt()); }

bool Stream::find(const char* target) {
  if (!target || !*target) return true;
  size_t matched = 0;
  const size_t len = strlen(target);
  for (int c = timedRead(); c >= 0; c = timedRead()) {
    matched = c == target[matched] ? matched + 1 : (c == target[0] ? 1 : 0);
    if (matched == len) return true;
  }
  return false;
}

// ---------------------------------------------------------------- Serial

HardwareSerial Serial;
HardwareSerial Serial1;
HardwareSerial Serial2;

void HardwareSerial::begin(unsigned long, uint32_t, int8_t, int8_t, bool, unsigned long) {
  l6470emu::arduino::runtime().call();
}
void HardwareSerial::end() { l6470emu::arduino::runtime().call(); }
// Serial reads what has arrived by now (the program's standard input, a scenario's serial:
// steps at their ticks); Serial1 and Serial2 read nothing.
static l6470emu::FirmwareRuntime* input_of(HardwareSerial* port) {
  l6470emu::FirmwareRuntime& r = l6470emu::arduino::runtime();
  r.call();
  if (port != &Serial) return nullptr;
  l6470emu::arduino::take_stdin(r);
  return &r;
}
int HardwareSerial::available() {
  l6470emu::FirmwareRuntime* r = input_of(this);
  return r ? static_cast<int>(std::min<std::size_t>(r->serial_available(), INT_MAX)) : 0;
}
int HardwareSerial::peek() {
  l6470emu::FirmwareRuntime* r = input_of(this);
  return r ? r->serial_peek() : -1;
}
int HardwareSerial::read() {
  l6470emu::FirmwareRuntime* r = input_of(this);
  return r ? r->serial_read() : -1;
}
int HardwareSerial::availableForWrite() { return 64; }
void HardwareSerial::flush() {
  l6470emu::arduino::runtime().call();
  std::fflush(stdout);
}
HardwareSerial::operator bool() {
  l6470emu::arduino::runtime().call();
  return true;
}

size_t HardwareSerial::write(uint8_t c) { return write(&c, 1); }

size_t HardwareSerial::write(const uint8_t* buffer, size_t size) {
  l6470emu::arduino::runtime().call();
  // Each CR that begins a CR LF pair is left out: println's lines end in a newline.
  static bool pending_cr = false;
  for (size_t i = 0; i < size; ++i) {
    const uint8_t c = buffer[i];
    if (pending_cr && c != '\n') std::fputc('\r', stdout);
    pending_cr = c == '\r';
    if (!pending_cr) std::fputc(c, stdout);
  }
  return size;
}
