/* Arduino's String class on the desktop, as far as sketches and driver libraries use it:
 * construction from text and numbers (in a base, with decimals), concatenation, comparison,
 * search, substrings, case, trimming and conversion to numbers. Kept in a std::string; no
 * allocation failure is reported (the desktop has the memory). */
#ifndef L6470EMU_WSTRING_H
#define L6470EMU_WSTRING_H

#ifdef __cplusplus

#include <stddef.h>
#include <stdint.h>

#include <string>

#include "avr/pgmspace.h"

/* Text in program memory on an AVR; on the desktop an ordinary string. */
class __FlashStringHelper;
#define F(string_literal) (reinterpret_cast<const __FlashStringHelper*>(PSTR(string_literal)))
#define FPSTR(pstr_pointer) (reinterpret_cast<const __FlashStringHelper*>(pstr_pointer))

class String {
 public:
  String(const char* cstr = "");
  String(const char* cstr, unsigned int length);
  String(const uint8_t* cstr, unsigned int length) : String(reinterpret_cast<const char*>(cstr), length) {}
  String(const __FlashStringHelper* str);
  String(const String&) = default;
  String(String&&) noexcept = default;
  explicit String(char c);
  explicit String(unsigned char value, unsigned char base = 10);
  explicit String(int value, unsigned char base = 10);
  explicit String(unsigned int value, unsigned char base = 10);
  explicit String(long value, unsigned char base = 10);
  explicit String(unsigned long value, unsigned char base = 10);
  explicit String(long long value, unsigned char base = 10);
  explicit String(unsigned long long value, unsigned char base = 10);
  explicit String(float value, unsigned char decimalPlaces = 2);
  explicit String(double value, unsigned char decimalPlaces = 2);
  ~String() = default;

  String& operator=(const String&) = default;
  String& operator=(String&&) noexcept = default;
  String& operator=(const char* cstr);
  String& operator=(const __FlashStringHelper* str);

  /* Always true: the desktop never fails an allocation. */
  unsigned char reserve(unsigned int size);
  unsigned int length() const { return static_cast<unsigned int>(buf_.size()); }
  bool isEmpty() const { return buf_.empty(); }

  unsigned char concat(const String& str);
  unsigned char concat(const char* cstr);
  unsigned char concat(const char* cstr, unsigned int length);
  unsigned char concat(char c);
  unsigned char concat(unsigned char num);
  unsigned char concat(int num);
  unsigned char concat(unsigned int num);
  unsigned char concat(long num);
  unsigned char concat(unsigned long num);
  unsigned char concat(long long num);
  unsigned char concat(unsigned long long num);
  unsigned char concat(float num);
  unsigned char concat(double num);
  unsigned char concat(const __FlashStringHelper* str);

  template <class T>
  String& operator+=(const T& rhs) {
    concat(rhs);
    return *this;
  }

  int compareTo(const String& s) const;
  unsigned char equals(const String& s) const { return buf_ == s.buf_; }
  unsigned char equals(const char* cstr) const { return buf_ == (cstr ? cstr : ""); }
  unsigned char equalsIgnoreCase(const String& s) const;
  unsigned char equalsConstantTime(const String& s) const { return equals(s); }
  unsigned char startsWith(const String& prefix) const { return startsWith(prefix, 0); }
  unsigned char startsWith(const String& prefix, unsigned int offset) const;
  unsigned char endsWith(const String& suffix) const;
  unsigned char operator==(const String& rhs) const { return equals(rhs); }
  unsigned char operator==(const char* cstr) const { return equals(cstr); }
  unsigned char operator!=(const String& rhs) const { return !equals(rhs); }
  unsigned char operator!=(const char* cstr) const { return !equals(cstr); }
  unsigned char operator<(const String& rhs) const { return compareTo(rhs) < 0; }
  unsigned char operator>(const String& rhs) const { return compareTo(rhs) > 0; }
  unsigned char operator<=(const String& rhs) const { return compareTo(rhs) <= 0; }
  unsigned char operator>=(const String& rhs) const { return compareTo(rhs) >= 0; }

  char charAt(unsigned int index) const;
  void setCharAt(unsigned int index, char c);
  char operator[](unsigned int index) const { return charAt(index); }
  char& operator[](unsigned int index);
  void getBytes(unsigned char* buf, unsigned int bufsize, unsigned int index = 0) const;
  void toCharArray(char* buf, unsigned int bufsize, unsigned int index = 0) const {
    getBytes(reinterpret_cast<unsigned char*>(buf), bufsize, index);
  }
  const char* c_str() const { return buf_.c_str(); }
  char* begin() { return buf_.data(); }
  char* end() { return buf_.data() + buf_.size(); }
  const char* begin() const { return buf_.data(); }
  const char* end() const { return buf_.data() + buf_.size(); }

  int indexOf(char ch) const { return indexOf(ch, 0); }
  int indexOf(char ch, unsigned int fromIndex) const;
  int indexOf(const String& str) const { return indexOf(str, 0); }
  int indexOf(const String& str, unsigned int fromIndex) const;
  int lastIndexOf(char ch) const;
  int lastIndexOf(char ch, unsigned int fromIndex) const;
  int lastIndexOf(const String& str) const;
  int lastIndexOf(const String& str, unsigned int fromIndex) const;
  String substring(unsigned int beginIndex) const { return substring(beginIndex, length()); }
  String substring(unsigned int beginIndex, unsigned int endIndex) const;

  void replace(char find, char replace);
  void replace(const String& find, const String& replace);
  void remove(unsigned int index);
  void remove(unsigned int index, unsigned int count);
  void toLowerCase();
  void toUpperCase();
  void trim();

  long toInt() const;
  float toFloat() const;
  double toDouble() const;

  explicit operator bool() const { return true; }

 private:
  std::string buf_;
};

String operator+(const String& lhs, const String& rhs);
String operator+(const String& lhs, const char* cstr);
String operator+(const char* cstr, const String& rhs);
String operator+(const String& lhs, char c);
String operator+(const String& lhs, unsigned char num);
String operator+(const String& lhs, int num);
String operator+(const String& lhs, unsigned int num);
String operator+(const String& lhs, long num);
String operator+(const String& lhs, unsigned long num);
String operator+(const String& lhs, long long num);
String operator+(const String& lhs, unsigned long long num);
String operator+(const String& lhs, float num);
String operator+(const String& lhs, double num);
String operator+(const String& lhs, const __FlashStringHelper* rhs);

#endif /* __cplusplus */
#endif /* L6470EMU_WSTRING_H */
