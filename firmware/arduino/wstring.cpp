// String: Arduino's text class over std::string. Numbers in a base are written as the core's
// itoa/ultoa do (lower-case digits, other bases as unsigned), decimals as dtostrf does.
#include "WString.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace {

std::string in_base(unsigned long long n, unsigned base) {
  if (base < 2 || base > 36) base = 10;
  std::string out;
  do {
    const unsigned d = static_cast<unsigned>(n % base);
    out += static_cast<char>(d < 10 ? '0' + d : 'a' + d - 10);
    n /= base;
  } while (n);
  std::reverse(out.begin(), out.end());
  return out;
}

std::string signed_in_base(long long n, unsigned base, unsigned bits) {
  if (base == 10 && n < 0) return "-" + in_base(0ull - static_cast<unsigned long long>(n), 10);
  const unsigned long long mask = bits >= 64 ? ~0ull : (1ull << bits) - 1;
  return in_base(static_cast<unsigned long long>(n) & mask, base);
}

std::string decimals(double v, unsigned places) {
  char buf[64];
  const int n = std::snprintf(buf, sizeof buf, "%.*f", static_cast<int>(std::min(places, 30u)), v);
  return n > 0 && static_cast<size_t>(n) < sizeof buf ? std::string(buf, static_cast<size_t>(n)) : std::string("ovf");
}

}  // namespace

String::String(const char* cstr) : buf_(cstr ? cstr : "") {}
String::String(const char* cstr, unsigned int length) : buf_(cstr ? std::string(cstr, length) : std::string()) {}
String::String(const __FlashStringHelper* str) : String(reinterpret_cast<const char*>(str)) {}
String::String(char c) : buf_(1, c) {}
String::String(unsigned char value, unsigned char base) : buf_(in_base(value, base)) {}
String::String(int value, unsigned char base) : buf_(signed_in_base(value, base, 8 * sizeof value)) {}
String::String(unsigned int value, unsigned char base) : buf_(in_base(value, base)) {}
String::String(long value, unsigned char base) : buf_(signed_in_base(value, base, 8 * sizeof value)) {}
String::String(unsigned long value, unsigned char base) : buf_(in_base(value, base)) {}
String::String(long long value, unsigned char base) : buf_(signed_in_base(value, base, 64)) {}
String::String(unsigned long long value, unsigned char base) : buf_(in_base(value, base)) {}
String::String(float value, unsigned char decimalPlaces) : buf_(decimals(value, decimalPlaces)) {}
String::String(double value, unsigned char decimalPlaces) : buf_(decimals(value, decimalPlaces)) {}

String& String::operator=(const char* cstr) {
  buf_ = cstr ? cstr : "";
  return *this;
}
String& String::operator=(const __FlashStringHelper* str) { return *this = reinterpret_cast<const char*>(str); }

unsigned char String::reserve(unsigned int size) {
  buf_.reserve(size);
  return 1;
}

unsigned char String::concat(const String& str) {
  buf_ += str.buf_;
  return 1;
}
unsigned char String::concat(const char* cstr) {
  if (!cstr) return 0;
  buf_ += cstr;
  return 1;
}
unsigned char String::concat(const char* cstr, unsigned int length) {
  if (!cstr) return 0;
  buf_.append(cstr, length);
  return 1;
}
unsigned char String::concat(char c) {
  buf_ += c;
  return 1;
}
unsigned char String::concat(unsigned char num) { return concat(String(num)); }
unsigned char String::concat(int num) { return concat(String(num)); }
unsigned char String::concat(unsigned int num) { return concat(String(num)); }
unsigned char String::concat(long num) { return concat(String(num)); }
unsigned char String::concat(unsigned long num) { return concat(String(num)); }
unsigned char String::concat(long long num) { return concat(String(num)); }
unsigned char String::concat(unsigned long long num) { return concat(String(num)); }
unsigned char String::concat(float num) { return concat(String(num)); }
unsigned char String::concat(double num) { return concat(String(num)); }
unsigned char String::concat(const __FlashStringHelper* str) { return concat(reinterpret_cast<const char*>(str)); }

int String::compareTo(const String& s) const { return std::strcmp(buf_.c_str(), s.buf_.c_str()); }

unsigned char String::equalsIgnoreCase(const String& s) const {
  if (buf_.size() != s.buf_.size()) return 0;
  for (size_t i = 0; i < buf_.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(buf_[i])) != std::tolower(static_cast<unsigned char>(s.buf_[i]))) return 0;
  return 1;
}

unsigned char String::startsWith(const String& prefix, unsigned int offset) const {
  if (offset > buf_.size() || prefix.buf_.size() > buf_.size() - offset) return 0;
  return buf_.compare(offset, prefix.buf_.size(), prefix.buf_) == 0;
}

unsigned char String::endsWith(const String& suffix) const {
  if (suffix.buf_.size() > buf_.size()) return 0;
  return buf_.compare(buf_.size() - suffix.buf_.size(), suffix.buf_.size(), suffix.buf_) == 0;
}

char String::charAt(unsigned int index) const { return index < buf_.size() ? buf_[index] : 0; }

void String::setCharAt(unsigned int index, char c) {
  if (index < buf_.size()) buf_[index] = c;
}

char& String::operator[](unsigned int index) {
  static char dummy;
  if (index >= buf_.size()) {
    dummy = 0;
    return dummy;
  }
  return buf_[index];
}

void String::getBytes(unsigned char* buf, unsigned int bufsize, unsigned int index) const {
  if (!buf || bufsize == 0) return;
  if (index >= buf_.size()) {
    buf[0] = 0;
    return;
  }
  const size_t n = std::min<size_t>(bufsize - 1, buf_.size() - index);
  std::memcpy(buf, buf_.data() + index, n);
  buf[n] = 0;
}

int String::indexOf(char ch, unsigned int fromIndex) const {
  const size_t at = buf_.find(ch, fromIndex);
  return at == std::string::npos ? -1 : static_cast<int>(at);
}

int String::indexOf(const String& str, unsigned int fromIndex) const {
  if (fromIndex > buf_.size()) return -1;
  const size_t at = buf_.find(str.buf_, fromIndex);
  return at == std::string::npos ? -1 : static_cast<int>(at);
}

int String::lastIndexOf(char ch) const { return buf_.empty() ? -1 : lastIndexOf(ch, length() - 1); }

int String::lastIndexOf(char ch, unsigned int fromIndex) const {
  if (fromIndex >= buf_.size()) return -1;
  const size_t at = buf_.rfind(ch, fromIndex);
  return at == std::string::npos ? -1 : static_cast<int>(at);
}

int String::lastIndexOf(const String& str) const {
  if (str.buf_.size() > buf_.size()) return -1;
  return lastIndexOf(str, length() - str.length());
}

int String::lastIndexOf(const String& str, unsigned int fromIndex) const {
  if (str.buf_.empty() || str.buf_.size() > buf_.size() || fromIndex >= buf_.size()) return -1;
  const size_t at = buf_.rfind(str.buf_, fromIndex);
  return at == std::string::npos ? -1 : static_cast<int>(at);
}

String String::substring(unsigned int beginIndex, unsigned int endIndex) const {
  if (beginIndex > endIndex) std::swap(beginIndex, endIndex);
  if (beginIndex >= buf_.size()) return String();
  endIndex = std::min<unsigned int>(endIndex, length());
  return String(buf_.data() + beginIndex, endIndex - beginIndex);
}

void String::replace(char find, char replace) { std::replace(buf_.begin(), buf_.end(), find, replace); }

void String::replace(const String& find, const String& replace) {
  if (find.buf_.empty()) return;
  std::string out;
  size_t i = 0;
  for (size_t at; (at = buf_.find(find.buf_, i)) != std::string::npos; i = at + find.buf_.size())
    out.append(buf_, i, at - i).append(replace.buf_);
  out.append(buf_, i, std::string::npos);
  buf_ = std::move(out);
}

void String::remove(unsigned int index) { remove(index, static_cast<unsigned int>(-1)); }

void String::remove(unsigned int index, unsigned int count) {
  if (index >= buf_.size()) return;
  buf_.erase(index, std::min<size_t>(count, buf_.size() - index));
}

void String::toLowerCase() {
  for (char& c : buf_) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
}

void String::toUpperCase() {
  for (char& c : buf_) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
}

void String::trim() {
  const auto blank = [](char c) { return std::isspace(static_cast<unsigned char>(c)) != 0; };
  size_t b = 0, e = buf_.size();
  while (b < e && blank(buf_[b])) ++b;
  while (e > b && blank(buf_[e - 1])) --e;
  buf_ = buf_.substr(b, e - b);
}

long String::toInt() const { return std::atol(buf_.c_str()); }
float String::toFloat() const { return static_cast<float>(std::atof(buf_.c_str())); }
double String::toDouble() const { return std::atof(buf_.c_str()); }

String operator+(const String& lhs, const String& rhs) {
  String s(lhs);
  s.concat(rhs);
  return s;
}
String operator+(const String& lhs, const char* cstr) {
  String s(lhs);
  s.concat(cstr);
  return s;
}
String operator+(const char* cstr, const String& rhs) {
  String s(cstr);
  s.concat(rhs);
  return s;
}
#define L6470EMU_STRING_PLUS(T)              \
  String operator+(const String& lhs, T v) { \
    String s(lhs);                           \
    s.concat(v);                             \
    return s;                                \
  }
L6470EMU_STRING_PLUS(char)
L6470EMU_STRING_PLUS(unsigned char)
L6470EMU_STRING_PLUS(int)
L6470EMU_STRING_PLUS(unsigned int)
L6470EMU_STRING_PLUS(long)
L6470EMU_STRING_PLUS(unsigned long)
L6470EMU_STRING_PLUS(long long)
L6470EMU_STRING_PLUS(unsigned long long)
L6470EMU_STRING_PLUS(float)
L6470EMU_STRING_PLUS(double)
L6470EMU_STRING_PLUS(const __FlashStringHelper*)
#undef L6470EMU_STRING_PLUS
