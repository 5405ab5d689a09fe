/* Arduino's Print: text and numbers (in a base, with decimals) written through write(). Each
 * print/println/printf call hands its text to write(buffer, size) once (println adds "\r\n" as
 * the Arduino core does; Serial shows it as a newline). */
#ifndef L6470EMU_PRINT_H
#define L6470EMU_PRINT_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "Printable.h"
#include "WString.h"

#define DEC 10
#define HEX 16
#define OCT 8
#define BIN 2

class Print {
 public:
  virtual ~Print() = default;
  virtual size_t write(uint8_t c) = 0;
  virtual size_t write(const uint8_t* buffer, size_t size);
  size_t write(const char* str) { return str ? write(reinterpret_cast<const uint8_t*>(str), strlen(str)) : 0; }
  size_t write(const char* buffer, size_t size) { return write(reinterpret_cast<const uint8_t*>(buffer), size); }
  virtual int availableForWrite() { return 0; }
  virtual void flush() {}
  int getWriteError() { return write_error_; }
  void clearWriteError() { write_error_ = 0; }

  size_t print(const __FlashStringHelper* str);
  size_t print(const String& s);
  size_t print(const char str[]);
  size_t print(char c);
  size_t print(unsigned char n, int base = DEC);
  size_t print(int n, int base = DEC);
  size_t print(unsigned int n, int base = DEC);
  size_t print(long n, int base = DEC);
  size_t print(unsigned long n, int base = DEC);
  size_t print(long long n, int base = DEC);
  size_t print(unsigned long long n, int base = DEC);
  size_t print(double n, int digits = 2);
  size_t print(const Printable& x);

  size_t println(const __FlashStringHelper* str);
  size_t println(const String& s);
  size_t println(const char str[]);
  size_t println(char c);
  size_t println(unsigned char n, int base = DEC);
  size_t println(int n, int base = DEC);
  size_t println(unsigned int n, int base = DEC);
  size_t println(long n, int base = DEC);
  size_t println(unsigned long n, int base = DEC);
  size_t println(long long n, int base = DEC);
  size_t println(unsigned long long n, int base = DEC);
  size_t println(double n, int digits = 2);
  size_t println(const Printable& x);
  size_t println(void);

  /* As the ESP32 and STM32 cores have it: formatted by vsnprintf. */
  size_t printf(const char* format, ...) __attribute__((format(printf, 2, 3)));

 protected:
  void setWriteError(int err = 1) { write_error_ = err; }

 private:
  size_t text(const char* s, size_t n) { return write(reinterpret_cast<const uint8_t*>(s), n); }
  int write_error_ = 0;
};

#endif
